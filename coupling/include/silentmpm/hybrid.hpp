#pragma once
// MPM-FEM coupling through shared nodes (docs/physics.md section 7).
//
// With bilinear grid shape functions MPM is a Q1 Galerkin method whose quadrature points are the
// particles. A Q1 far-field whose interface nodes coincide with grid nodes forms one
// discretisation with it: at a shared node the lumped masses, the momenta and the forces of both
// regions add, and one explicit update serves both. Each coupled step (USL or MUSL):
//
//   MPM p2g + particle loads        masses, momenta, internal and boundary forces on the grid
//   FE  f = -K u^n + f_ext(t^n)      on every FE node
//   shared nodes                     grid m += m_FE, p += m_FE v_FE, f += f_FE
//   grid update                      v+ = v + dt f / m (semi-implicit where a dashpot block sits,
//                                    FE dashpot blocks included at shared nodes)
//   FE nodes not shared              (m + dt/2 C) v+ = (m - dt/2 C) v + dt f, constraints
//   FE nodes shared                  v_FE+ = grid v+ (with scheme.mass_correction the corrected
//                                    increment, the FE mass joining the particles' consistent
//                                    mass in its product: add_mass_product)
//   particles                        g2p: the FLIP increment at a shared node is v+ - p_MPM/m_MPM
//                                    (the particles' own old velocity there), so that
//                                    Sum_p m_p dv_p + m_FE dv_FE = dt f: momentum is exact;
//                                    stress update and positions (USL: with v+; MUSL: with the
//                                    re-mapped q / m, the FE momentum of a shared node in q)
//   u^{n+1} = u^n + dt v             FE displacements; at a shared node v = v+ (USL) or the same
//                                    re-mapped q / m that strains the particles (MUSL), so both
//                                    sides see one displacement increment (halves the interface
//                                    reflection of MUSL: 0.86 % instead of 1.5 % for 20 cells)
//
// The interface is found automatically: an FE node that lies within h 1e-6 of a grid node is
// mapped to it; the shared nodes are those FE nodes at grid nodes that are a corner of a grid cell
// not covered by the FE mesh (a cell particles may occupy). Guards (HybridError, at setup unless
// said otherwise):
//   * FE degree 1 only; FE cells touching the MPM region must be exactly one grid cell (same
//     spacing h, nodes on grid nodes); an FE node on an occupied MPM cell must sit on a grid node;
//   * a particle inside an FE cell (at setup and after every step);
//   * an MPM cell touching the interface must be full (particle volume h^2 within 0.1 %), and
//     with scheme.mass_correction hold no particle of more than 0.3 of a cell (at 1 particle per
//     cell side the correction makes the interface reflect more; checked at every step too);
//   * no MPM traction on an interface node (setup) and no FE load on an interface node carrying
//     MPM mass (checked every step: the FE load is evaluated there anyway);
//   * the same gravity in both regions (a shared node's weight is (m_MPM + m_FE) g: the MPM
//     step puts m_MPM g on the grid and books the work of the whole nodal mass, the coupling
//     adds m_FE g).
//
// Over MPI ranks (distribute(); docs/parallel.md) the grid is cut into blocks and the FE mesh by
// METIS, independently, and each rank keeps only its part of the far field. A shared node's
// grid copies lie in the windows of one or more ranks, its FE row on one: the step sums three
// short vectors over the ranks, each value written by one rank only and each guard's entry a
// count of the ranks that found the fault (so the sums are exact):
// the FE forces of the shared nodes from their FE owners (with the FE-load guard's verdict,
// after the MPM forces), their v and v+ from their MPM owners (after the grid update), and the
// velocity that advances their displacement (with the particle check's verdict, at the end).
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "silentmpm/decomposition.hpp"
#include "silentmpm/fem.hpp"
#include "silentmpm/solver.hpp"

namespace smpm {

struct HybridError : std::runtime_error {
  using std::runtime_error::runtime_error;
  // A fault of one case key's value: "hybrid: KEY DETAIL", with the key and the detail apart (a
  // case file's error names the key; the others are the FEM region's, "fem").
  HybridError(const std::string& key_, const std::string& detail_)
      : std::runtime_error("hybrid: " + key_ + " " + detail_), key(key_), detail(detail_) {}
  std::string key, detail;
};

// A hook set on the MPM solver's step (step_hooks.hpp): constructing a Hybrid attaches it, so
// that every mpm.step() (or hybrid.step()) is the coupled step above; destroying it detaches it.
class Hybrid : public StepHooks {
 public:
  // Both solvers fully built (mpm.finalize() called). Finds and checks the interface; throws
  // HybridError with a complete message on any guard. dt must then be set with set_dt.
  Hybrid(Solver& mpm, fem::Solver& fe);
  ~Hybrid() override;
  Hybrid(const Hybrid&) = delete;
  Hybrid& operator=(const Hybrid&) = delete;

  // Sets the common time step on both regions (throws HybridError if it exceeds the FE element
  // bound or the MPM limit h / c_d).
  void set_dt(double dt);
  double dt() const { return mpm_.dt; }
  double time() const { return mpm_.t; }
  long steps() const { return mpm_.steps; }
  // Largest stable step of the coupled system: min of both regions' limits.
  double critical_dt() const;

  // One coupled step: the MPM solver's step with this set's hooks.
  void step() { mpm_.step(); }

  // The hooks (see the sequence at the top of this file).
  void after_momentum(Solver& s) override;     // guards: scheme, contact
  void after_forces(Solver& s) override;       // FE forces, masses and momenta on shared nodes
  void after_grid_update(Solver& s) override;  // FE dashpot blocks at shared nodes
  void add_mass_product(Solver& s, const double* tx, const double* ty, double* ax,
                        double* ay) override;  // the mass correction: m_FE t at shared nodes
  void before_g2p(Solver& s) override;         // FE-only nodes advance; the particles' own v
  void after_remap(Solver& s) override;        // MUSL: FE momentum at shared nodes in q
  void end_of_step(Solver& s) override;        // shared displacements, FE clock, particle check
  // The loads' power is taken with v+ (the coupled MUSL step books it before the re-map).
  bool remapped_power() const override { return false; }

  // Several processes: call once on every rank, after the MPM solver was cut by `d` (which
  // must outlive the steps) and the FE far field split (fem::Solver::distribute). Maps the
  // shared nodes to this rank's window of the grid, and keeps only this rank's part of the far
  // field (fem::Solver::localize: its own nodes and those it receives); the energy booked so
  // far stays with rank 0.
  void distribute(Decomposition& d);

  // Energies of both regions summed (kinetic, elastic; dissipated, absorbed and external work
  // accumulate in step()); also refreshes mpm.energy and fe.energy (split over ranks: the sums
  // over the ranks, collective; mpm.energy keeps this rank's share, mpm_energy() the sum).
  void update_energies();
  Energies energy;
  const Energies& mpm_energy() const { return mpm_total_; }
  // Split over ranks: this rank's seconds in the interface's sums over the ranks so far, and
  // the values it put into them.
  double interface_seconds() const { return share_seconds_; }
  double interface_values() const { return share_values_; }

  // Interface: (FE node, grid node) pairs of the shared nodes, and how many of them carry MPM
  // mass at setup (the interface proper).
  const std::vector<std::array<std::uint32_t, 2>>& shared() const { return shared_; }
  std::size_t interface_nodes() const { return interface_count_; }
  // 1 for grid cells covered by the FE mesh.
  const std::vector<std::uint8_t>& fe_cells() const { return fe_cell_; }

  // Total momentum of both regions (particles + FE nodes not shared + FE mass at shared nodes
  // with the shared velocity); over ranks, the sum (collective).
  std::array<double, 2> momentum() const;

  // Checkpoints: both regions (blocks "mpm." and "fem.") and the coupling's accounts. load_state
  // returns Solver::load_state's answer (false: particles re-sorted for another thread count).
  void save_state(StateWriter& w) const;
  bool load_state(const StateReader& r);

  Solver& mpm() { return mpm_; }
  fem::Solver& fe() { return fe_; }

 private:
  Solver& mpm_;
  fem::Solver& fe_;
  std::vector<std::array<std::uint32_t, 2>> shared_;
  // Shared grid node of each FE node the far field holds (its local nodes once split), or -1.
  std::vector<std::int64_t> grid_of_fe_;
  std::vector<std::uint8_t> fe_cell_;      // per grid cell
  long fe_row_lo_ = 0, fe_row_hi_ = -1;    // grid rows holding an FE cell (empty: lo > hi)
  std::vector<std::uint8_t> has_mpm_mass_; // per shared pair: node had MPM mass at setup
  std::size_t interface_count_ = 0;
  std::vector<double> fint_, fext_;        // FE per-dof work arrays
  double gx_ = 0, gy_ = 0;                 // gravity (both regions')
  std::vector<double> mpm_v_, sum_v_;      // per shared node: p_MPM / m_MPM, (p_MPM + m_FE v_FE) / m
  double step_absorbed_ = 0;               // FE dashpot energy of this step at shared nodes
  double fe_kinetic_ = 0, fe_elastic_ = 0;
  double fe_absorbed_ = 0, fe_work_ = 0;
  double fe_initial_ = 0;
  Energies mpm_total_;
  // Per shared node: its node in the solver's grid (this rank's window when split; -1 when the
  // window lacks it), whether this rank owns its FE row and its grid node (both 1 on one
  // process); the vectors the step sums over the ranks.
  std::vector<std::int64_t> node_;
  std::vector<std::uint8_t> fe_own_, mpm_own_;
  std::vector<double> force_, vel_, disp_;
  std::vector<std::uint32_t> fe_own_nodes_;  // split: this rank's FE nodes
  // Per shared node, what a rank whose window holds its grid node needs of the FE side even
  // where its part of the far field lacks the node: the FE node in the far field's arrays (-1:
  // not held), its lumped mass, its velocity (refreshed from the far field where held, else the
  // shared v+ of the last step), its dashpot block (cxx, cxy, cyy; zero if none) and position.
  std::vector<std::int64_t> fe_at_;
  std::vector<double> fe_m_, fe_v_, fe_c_, fe_xy_;
  std::vector<std::uint8_t> fe_dash_;
  Decomposition* dist_ = nullptr;
  mutable double share_seconds_ = 0, share_values_ = 0;
  // The whole grid (the particle check works in its cells) and this rank's window's origin.
  double gx0_ = 0, gy0_ = 0;
  long gnx_ = 0, gny_ = 0, org_i_ = 0, org_j_ = 0;

  // The particle inside an FE cell with the lowest id (this rank's index), or -1; the error
  // naming the one with the lowest id over all ranks (every rank calls it when any found one).
  long particle_in_fe_cell(bool at_setup) const;
  [[noreturn]] void report_particle_in_fe_cell(long k, bool at_setup) const;
  // Sums v over the ranks (nothing on one process).
  void share(std::vector<double>& v) const;
  // The first MPM cell next to the interface whose particles are a cell side wide (described;
  // empty if none), and the guard that refuses the mass correction there.
  std::string coarse_cell_;
  void check_mass_correction(const Solver& S) const;
  void fe_energies(bool with_step_force);
};

}  // namespace smpm
