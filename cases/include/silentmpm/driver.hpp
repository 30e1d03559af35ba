#pragma once
// The run driver: steps a Case to t_end, samples probes and energies into history.csv, writes
// snapshots and summary.json, prints progress.
#include <string>

#include "silentmpm/case.hpp"

namespace smpm {

struct RunResult {
  long steps = 0;
  double wall_seconds = 0;
  double particle_updates_per_second = 0;
  std::size_t dofs = 0;                 // FEM region
  double dof_updates_per_second = 0;    // FEM region
};

// Runs the case and writes DIR/history.csv, DIR/summary.json, DIR/particles.{h5,xdmf}.
// summary.json is written last, so its presence marks a complete run.
RunResult run_case(Case& c, const std::string& out_dir);

}  // namespace smpm
