#pragma once
// The energy account of a run (history.csv's energy.* columns, summary.json's "energy"), the same
// for the MPM region, the FE far field and the hybrid (docs/physics.md section 4).
namespace smpm {

struct Energies {
  double kinetic = 0, elastic = 0;
  double dissipated = 0;      // plastic (+ decohesion, + contact friction) dissipation, accumulated
  double absorbed = 0;        // energy taken out by silent-layer dashpots, accumulated
  double external_work = 0;   // work of tractions, accumulated
  double initial = 0;         // kinetic + elastic at t = 0
  // (kinetic + elastic + dissipated + absorbed) - (initial + external_work)
  double imbalance() const { return kinetic + elastic + dissipated + absorbed - initial - external_work; }
};

}  // namespace smpm
