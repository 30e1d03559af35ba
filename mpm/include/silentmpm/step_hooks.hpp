#pragma once
// The named points of the MPM time step (silentmpm/solver.hpp) where a coupled model adds its work.
namespace smpm {

class Solver;

// Work a coupled model adds to the MPM step at its named points. A hook set is attached to one
// solver (Solver::attach); the step calls the solver's multi-field contact first, when it is on,
// then the attached sets in order of attachment.
class StepHooks {
 public:
  virtual ~StepHooks() = default;
  virtual void after_momentum(Solver&) {}     // p2g done (nodal mass and momentum on every field)
  virtual void after_forces(Solver&) {}       // internal forces and loads on the grid
  // v+ on the grid (before the mass correction, opt.mass_correction; multi-field contact, which
  // runs first, corrects its bodies' fields here), its boundary work not yet booked.
  virtual void after_grid_update(Solver&) {}
  // The consistent-mass correction's product a = M_c t (Solver::correct_increments, one call per
  // velocity field and term, after the particles' share and its sums over the ranks): a hook set adds the mass its
  // nodes carry beyond the particles' (the hybrid: the far field's lumped mass at shared nodes).
  virtual void add_mass_product(Solver&, const double* /*tx*/, const double* /*ty*/,
                                double* /*ax*/, double* /*ay*/) {}
  virtual void before_g2p(Solver&) {}         // boundary work booked; particles not yet updated
  virtual void after_remap(Solver&) {}        // MUSL: re-mapped momenta, not yet divided by mass
  virtual void end_of_step(Solver&) {}        // clock advanced, particles checked
  // MUSL books the boundary work with the re-mapped velocity only when the grid's arrays hold
  // the one re-mapped field the particles carry; a hook set that changes that answers false.
  virtual bool remapped_power() const { return true; }
};

}  // namespace smpm
