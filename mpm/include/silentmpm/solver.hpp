#pragma once
// The explicit MPM solver: one region of particles on a background grid, and the one time step
// every MPM run takes (Solver::step in solver.cpp):
//
//   reset grid
//   p2g            masses, momenta (USL, MUSL: and internal forces)         -> after_momentum
//   [light nodes: found, their masses and momenta onto the heavy nodes (light_nodes.hpp); each
//    velocity below extended to them, each force and re-mapped momentum folded likewise]
//   [USF: nodal velocities, stress update, p2g of the internal forces]
//   loads          tractions, silent-layer dashpots and Kelvin-Voigt springs of boundary
//                  particles, damping bands, gravity                       -> after_forces
//   grid update    v+ = v + dt f / m (semi-implicit on nodes with a dashpot block), constraints;
//                  a non-finite velocity stops the run here                -> after_grid_update
//   [mass correction of the increment (opt.mass_correction)                 add_mass_product]
//   [symmetric form: also the start velocity's, for the boundary work (USF: before the stress)]
//   boundary work  work of tractions and gravity, energy absorbed by dashpots and bands
//                                                                           -> before_g2p
//   g2p            particle velocities (FLIP/PIC); MUSL re-maps the momenta -> after_remap
//   stress         velocity gradient -> strain increment -> material update; positions advance
//   clock          t += dt; particles still on the grid? health checks     -> end_of_step
//
// Velocity fields: the kernels (kernels.hpp) run over the particles of one field into that
// field's nodal arrays. The ordinary step has one field, the grid's own arrays. Multi-field
// contact (contact.hpp) gives one field per body; the grid's arrays then hold the centre-of-mass
// field, the sum of the bodies' masses, momenta and forces, which takes the loads and the grid
// update. Hook sets (StepHooks: contact, the MPM-FEM hybrid) add their work at the named points.
//
// Particle loops run over contiguous ranges of one material group, so the material model is a
// template argument of the inner loop. Scatters to the grid run in parallel over horizontal
// strips of particles: even strips first, then odd strips, so no two threads write one node.
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "silentmpm/boundary.hpp"
#include "silentmpm/contact.hpp"
#include "silentmpm/decomposition.hpp"
#include "silentmpm/energies.hpp"
#include "silentmpm/grid.hpp"
#include "silentmpm/kernels.hpp"
#include "silentmpm/light_nodes.hpp"
#include "silentmpm/material.hpp"
#include "silentmpm/particles.hpp"
#include "silentmpm/shape.hpp"
#include "silentmpm/state_io.hpp"
#include "silentmpm/step_hooks.hpp"

namespace smpm {

enum class Scheme { USF, USL, MUSL };
const char* scheme_name(Scheme s);

struct SolverOptions {
  Scheme scheme = Scheme::MUSL;
  ShapeKind shape = ShapeKind::Bilinear;  // grid shape functions of every kernel (shape.hpp)
  double flip = 1.0;          // 1 = FLIP, 0 = PIC
  double mass_tolerance = 1e-12;  // nodes lighter than this fraction of the smallest particle mass are void
  int threads = 0;            // 0 = OpenMP default
  double gravity_x = 0, gravity_y = 0;  // body force per unit mass (m/s^2), on every node's mass
  // Health check: stop when the kinetic energy exceeds this multiple of the energy put in
  // (initial + |external work|); 0 turns it off (the hybrid does: energy also enters through
  // its FE region).
  double energy_bound = 10;
  // The number of terms k of the consistent-mass correction of the grid's increment, on every
  // velocity field (correct_increments; docs/physics.md section 1.1). 0 keeps the lumped mass's
  // increment.
  int mass_correction = 0;
  // Its form: false, the series of R^-1 on the increment; true, the symmetric form, the series
  // of R^-1/2 on the increment and on the velocity that strains the particles (MUSL and USF;
  // docs/physics.md section 1.1).
  bool mass_correction_symmetric = false;
  // Light nodes (light_nodes.hpp): 0 keeps every node's own velocity; a ratio in (0, 0.25]
  // extends the velocity of the heavy nodes to a node that much lighter than them beyond a
  // body's face (docs/physics.md section 8.7).
  double light_node_ratio = 0;
};

struct ProbeSample {
  double sxx = 0, syy = 0, szz = 0, sxy = 0, j2 = 0, vx = 0, vy = 0;
  double px = 0, py = 0, mass = 0;  // region probes: momentum and mass in the box (per unit thickness)
  double fcx = 0, fcy = 0;          // region probes of a body: the contact force on it (multi-field)
  bool valid = false;  // false when no particle is near the point
};

// One velocity field: its nodal arrays, the particle ranges mapped to it ([strip * G + group]),
// and the node box its particles touched in the last momentum p2g (the whole grid for the
// grid's own field). A field of one body (body >= 0) has its arrays cleared over its last box
// at each momentum p2g; the grid's own arrays are cleared by the grid reset.
struct VelocityField {
  NodalField f;
  NodeBox box{0, -1, 0, -1};
  int body = -1;
  std::vector<std::array<uint32_t, 2>> ranges;
};

class Solver {
 public:
  Grid grid;
  Particles p;
  std::vector<Material> materials;  // material of group g is materials[g]
  std::vector<NodalConstraint> constraints;
  std::vector<TractionLoad> tractions;
  std::vector<SilentBoundary> silents;
  std::vector<DampingLayer> dampers;
  std::vector<PmlBand> pml_bands;  // perfectly matched layers (every band shares one alpha)
  PmlLayer pml;                    // their particles (built by finalize)
  SolverOptions opt;
  // The grid's write-only passes (its reset and the update's velocities) with streaming stores,
  // past the cache, or plain ones: -1 (default) tries both on the run's first steps where the
  // grid is large and keeps the faster (stores_stream in solver.cpp); 0 plain; 1 streaming.
  // The same values either way.
  int streaming = -1;
  // What the step does now: 0 plain stores, 1 streaming, -1 still trying both.
  int store_mode() const;
  double dt = 0, t = 0;
  long steps = 0;
  Energies energy;
  Contact contact;  // contact of bodies: single velocity field (default) or one per body
  LightNodes light_nodes;  // the light nodes' extension (opt.light_node_ratio)

  // --- setup -------------------------------------------------------------------------------
  // A rank's skeleton (several MPI ranks; docs/parallel.md "Set-up"): seeding counts the
  // particles it would add and adds none, so that the solver has the case's structure (its
  // materials, layers, loads and settings) without the body, which rank 0 sends it in blocks.
  bool seed_nothing = false;
  // Fill the rectangle [x0, x1] x [y0, y1] with particles on a lattice of n x n per cell
  // (n = 1, 2, 3), spacing adjusted so the rectangle is covered exactly. Returns the number added
  // (with seed_nothing, the number it would add). Seeding::Gauss puts them at the n x n
  // Gauss-Legendre points of each cell of the rectangle's lattice, each with its weight's share
  // of the cell's volume (docs/physics.md section 1.1): the rectangle must then be a whole number
  // of cells (std::invalid_argument otherwise).
  using Seeding = smpm::Seeding;
  std::size_t seed_rectangle(double x0, double y0, double x1, double y1, int n_per_side,
                             int group, int body, double vx0, double vy0,
                             Seeding seeding = Seeding::Uniform);
  // Point j (0 .. n-1) of n Gauss-Legendre points on a cell side, as a fraction of the side from
  // its start, and its weight (the weights sum to 1).
  static void gauss_point(int n, int j, double& at, double& weight);
  // Particles of `body` within `width` inside the straight edge p0 -> p1 whose outward normal is
  // (nx, ny) (the edge is the segment; particles must project onto it).
  BoundaryLayer select_layer(const std::string& name, int body, double ex0, double ey0,
                             double ex1, double ey1, double nx, double ny, double width) const;
  // Grid nodes whose position lies in [x0, x1] x [y0, y1] (inclusive, with a tolerance of h/1000).
  std::vector<uint32_t> nodes_in_box(double x0, double y0, double x1, double y1) const;
  // Call once after seeding and adding boundary conditions.
  void finalize();
  // What finalize() and the time step take from the whole body: dt, the void threshold, the
  // largest beta at a particle and the energy bound's floor. A skeleton takes rank 0's.
  std::array<double, 4> body_scalars() const {
    return {dt, mass_floor_, viscous_beta_, energy_floor_};
  }
  void set_body_scalars(const std::array<double, 4>& v) {
    dt = v[0];
    mass_floor_ = v[1];
    viscous_beta_ = v[2];
    energy_floor_ = v[3];
  }
  // h / max c_d over materials present, lowered by the damping layers' stiffness parts (the
  // largest sum of beta over the layers at one particle, taken at finalize() on the whole body).
  double critical_dt() const;

  // --- run ---------------------------------------------------------------------------------
  // One time step (the sequence at the top of this file).
  void step();
  // Hook sets: attach before the first step; a set must outlive its attachment.
  void attach(StepHooks* h);
  void detach(StepHooks* h);
  // Multi-field contact (its after_grid_update hook): the mass correction of every body's
  // field, after the bodies' own updates and before their contact correction.
  void correct_body_increments();
  // USL with the mass correction, from the correction to the end of the step: node i's extra
  // increment in the first field, which its particles take beyond v+ (0 otherwise).
  double correction_extra_x(long i) const {
    return correcting_usl() ? mc_ex_[static_cast<std::size_t>(i)] : 0.0;
  }
  double correction_extra_y(long i) const {
    return correcting_usl() ? mc_ey_[static_cast<std::size_t>(i)] : 0.0;
  }
  bool correcting_usl() const {
    return opt.mass_correction > 0 && opt.scheme == Scheme::USL && !mc_ex_.empty();
  }
  // One field per body (multi-field contact; called from finalize): the bodies' nodal arrays,
  // and the body of every material group (groups must not mix bodies).
  void use_body_fields(const std::vector<NodalField>& fields, const std::vector<int>& body_of_group);
  const std::vector<VelocityField>& fields() const { return fields_; }
  // Recompute kinetic and elastic energies (a pass over the particles).
  void update_energies();
  // Mass-weighted projection of particle fields to the nodes of the cell holding (x, y), then
  // bilinear interpolation at the point.
  ProbeSample sample(double x, double y) const;
  // Several points in one pass over the particles.
  std::vector<ProbeSample> sample(const std::vector<std::array<double, 2>>& points) const;
  // Same, each point sampling only the particles of body bodies[q] (-1: every body).
  std::vector<ProbeSample> sample(const std::vector<std::array<double, 2>>& points,
                                  const std::vector<int>& bodies) const;
  // The mean over the particles (of `body`, or all for -1) whose centres lie in the box
  // [x0, x1] x [y0, y1]: stresses and J2 weighted by volume, velocity by mass (the region's
  // momentum over its mass), with that momentum and mass, and for a body under multi-field
  // contact the contact force on it in the last step. Not valid when no particle is inside.
  ProbeSample region_mean(double x0, double y0, double x1, double y1, int body = -1) const;
  // The particles projected onto the grid nodes with the run's shape functions, mass-weighted:
  // m_I = sum N_I m_p, and v_I, sigma_I = sum N_I m_p (v_p, sigma_p) / m_I (0 where m_I is 0).
  // The grid's picture of the particles at this instant, for snapshots (output.grid); node
  // (i, j) is entry j * nnx + i. Split over ranks, every rank takes part and gets its window's.
  struct NodalProjection {
    std::vector<double> mass, vx, vy, sxx, syy, szz, sxy;
  };
  NodalProjection nodal_projection() const;
  // Per particle (current order): 1 silent layer, 2 traction, 4 Kelvin-Voigt springs, 8 damping
  // layer, 16 perfectly matched layer (the snapshot field "layer").
  std::vector<std::uint8_t> layer_flags() const;
  int thread_count() const { return nthreads_; }
  // The consistent dashpot mean of the silent layers under MUSL and USF (docs/physics.md
  // section 4), over the run (kept in checkpoints): the steps that solved for it, their
  // iterations (sum and largest), the steps left unconverged after kCmMaxIterations (their last
  // iterate stands) and the zones of particles found again because a node's particles were short.
  struct DashpotSolveStats {
    long steps = 0, iterations = 0, max_iterations = 0, unconverged = 0, rescans = 0;
  } dashpot_solve;
  static constexpr int kCmMaxIterations = 200;
  // Nodes lighter than this are void (opt.mass_tolerance times the lightest particle).
  double mass_floor() const { return mass_floor_; }
  // The light nodes an extension with `ratio` would take from the particles as they lie now, the
  // nodes the boundary layers weigh left out (bilinear shapes, one velocity field, after
  // finalize; 0 otherwise): for the case's note. The grid's arrays are left cleared.
  std::size_t light_nodes_at_start(double ratio);
  // Cell rows the particles occupied after the last step that moved them (lo > hi: none).
  void occupied_rows(long& lo, long& hi) const;
  // Shape functions (S: Bilinear, UGimp, BSpline2) of boundary particle q of layer L at its
  // anchor point; fills nodes[S::kNodes].
  template <class S>
  void layer_shape(const BoundaryLayer& L, std::size_t q, Anchor anchor, S& sf, long* nodes) const;
  // Check every particle is inside the grid; returns the index of the first outside, or -1.
  long first_particle_outside() const;

  // --- processes (solver_exchange.cpp; decomposition.hpp) ----------------------------------
  // Splits the step over ranks: d sums the halo and moves particles; the nodes of `own`
  // ({i0, i1, j0, j1}, inclusive, in this solver's grid) are this rank's (the rest are copies of
  // its neighbours' nodes within `halo` nodes of it, left out of sums over nodes); `dashpots`:
  // whether any rank assembles nodal dashpot blocks (they are then summed over the halo too).
  // Called after finalize and after the grid, particles and layers were cut to this rank's
  // share; the solver does not own d.
  void set_decomposition(Decomposition* d, NodeBox own, int halo, bool dashpots);
  // Keeps the particles with keep[k] != 0 and their boundary-layer entries (order kept).
  void keep_particles(const std::vector<std::uint8_t>& keep);
  // Appends to out[to[k]] a record of each particle with to[k] >= 0: its fields and its entries
  // in every boundary layer; then removes those particles. export_particles and
  // import_particles leave the particles unsorted: sort_particles() before they are used.
  void export_particles(const std::vector<int>& to, std::vector<std::vector<double>>& out);
  // Orders the particles by `rank` (one per particle, in [0, P); kept in step), stably, so that
  // each rank's particles are one range, and returns the ranges' starts (P + 1 of them).
  std::vector<std::size_t> group_by_rank(std::vector<int>& rank, int P);
  // Appends to out export_particles' record of each particle in [begin, end), keeping them.
  void export_range(std::size_t begin, std::size_t end, std::vector<double>& out);
  // Appends the particles of records written by export_particles (of a solver built from the
  // same case).
  void import_particles(const std::vector<double>& in);
  void sort_particles();
  // The energy account over every rank (this rank's own without a decomposition).
  Energies total_energy() const;
  // Whether the mass correction acts in its symmetric form (opt.mass_correction_symmetric, with
  // terms).
  bool symmetric_correction() const {
    return opt.mass_correction > 0 && opt.mass_correction_symmetric;
  }
  // Whether node i of this solver's grid is this rank's own (every node without a decomposition).
  bool owns_node(long i) const {
    if (own_[1] < own_[0]) return true;
    const long ii = i % grid.nnx, jj = i / grid.nnx;
    return ii >= own_[0] && ii <= own_[1] && jj >= own_[2] && jj <= own_[3];
  }
  // The cell row and column of a particle in this solver's grid.
  int cell_row(std::size_t k) const {
    return static_cast<int>(std::floor((p.y[k] - grid.y0) * grid.inv_h));
  }
  int cell_column(std::size_t k) const {
    return static_cast<int>(std::floor((p.x[k] - grid.x0) * grid.inv_h));
  }

  // --- checkpoints (solver_state.cpp) --------------------------------------------------------
  // The state a later step reads, as blocks named `prefix` + ...: clock, energies, every particle
  // array in the current order, the strips, spring displacements, contact dissipation.
  void save_state(StateWriter& w, const std::string& prefix) const;
  // Restores it into a solver built from the same case (finalize() called). Returns false when
  // the checkpoint was cut into another number of strips (another thread count): the particles
  // are then re-sorted, and sums over them run in another order. Throws StateError.
  bool load_state(const StateReader& r, const std::string& prefix);
  // The part of load_state that is not the particles' (the clock, the time step's check, the
  // energy account, contact dissipation, USF's kept edge velocities, the delayed closure's
  // histories): what a rank whose particles rank 0 sends it reads (docs/parallel.md "Set-up").
  void load_clock(const StateReader& r, const std::string& prefix);
  // The prefixes of the blocks that hold the particles and their layer entries (what
  // load_clock does not read).
  static std::vector<std::string> particle_blocks(const std::string& prefix);
  // Split over ranks (collective): every rank puts its particles and its layer entries (with
  // their particles' ids) as its parts of the blocks (StateWriter::put_part), the clock and the
  // energy account summed over the ranks as whole blocks, and no strips (a restart re-sorts).
  // Written by every rank at once, the file is the state of the whole body, which load_state
  // reads into a solver built whole, on one process or before it is split again.
  void save_state_parts(StateWriter& w, const std::string& prefix) const;

 private:
  int nthreads_ = 1;
  int nstrips_ = 2;
  bool strips_ok_ = false;
  int stencil_rows_ = 1;  // a particle in cell row r writes node rows [r - b, r + stencil_rows_ - b]
  bool has_nodal_dashpot_ = false;
  // The nodes holding a dashpot block this step, each once (in the order they were first
  // assembled; the blocks' update is per node, so the order does not matter), each marked in
  // grid.fix (Grid::kDashpotNode) with its index in the list.
  std::vector<long> dashpot_nodes_;
  std::vector<int> dashpot_index_;
  // grid_update: a bit per cache line of the velocity arrays that holds a dashpot node (made
  // afresh each step from dashpot_nodes_), so that its pass finds those lines without reading
  // every node's flags.
  std::vector<std::uint64_t> dash_lines_;
  std::vector<double> dn_work_;        // boundary_work: each node's terms (scratch)
  std::vector<std::uint8_t> dn_terms_; // and how many
  void add_dashpot_node(long i) {
    if (grid.fix[i] & Grid::kDashpotNode) return;
    grid.fix[i] |= Grid::kDashpotNode;
    dashpot_index_[i] = static_cast<int>(dashpot_nodes_.size());
    dashpot_nodes_.push_back(i);
  }
  // MUSL or USF, one velocity field: per grid node, the full LK impedance (rho c_d times the
  // edge length) the dashpots of layers strained with the updated velocity put on it this step
  // (SilentBoundary::updated_velocity; summed over the halo with the blocks); empty when no
  // layer is.
  std::vector<double> updated_weight_;
  // MUSL and USF, one velocity field: the dashpot blocks of the silent layers with the default
  // edge velocity (and the tangential component of the delayed closure's) act on the mean of the
  // velocities the particles map to the node at the start and at the end of the step
  // (consistent_dashpots; docs/physics.md section 4): whether the scheme and the layers take it
  // (the weight w N rho c_d those layers put on a node is in grid.dash, summed over the halo
  // with the blocks); the nodes solved so this step, the particles whose shape functions reach
  // them, and per node its slot (-1: none).
  bool consistent_ = false;
  std::vector<long> cm_nodes_;
  std::vector<long> cm_next_;           // the list being made (scratch)
  std::vector<long> cm_dk_;             // per slot: its node's place in dashpot_nodes_
  std::vector<int> cm_slot_;
  std::vector<std::uint8_t> cm_cell_;   // per cell: 1 in the zone, 2 reaches a listed node
  std::vector<long> cm_cells_;          // the cells marked 1
  std::vector<long> cm_reach_;          // and 2
  std::vector<std::uint8_t> cm_reaches_;  // per zone particle: whether it reaches a listed node
  std::vector<std::uint32_t> cm_hits_;  // the places in the zone of those that do
  std::vector<double> cm_pN_;           // per zone particle: its shape values (K)
  std::vector<int> cm_ps_;              // and their nodes' slots (-1: none)
  std::vector<double> cm_pm_;           // their masses
  std::vector<double> cm_s_;            // 2 per particle: its sum N . dv (scratch)
  std::vector<double> cm_dv_;           // 2 per slot: dt f / m (scratch)
  std::vector<double> cm_g_;            // 2 per slot: an iteration's new g (scratch)
  static constexpr int kCmRow = 24;     // the slots a row of the consistent mass can hold
  std::vector<int> cm_cnt_, cm_col_;    // the consistent mass between slots, kCmRow per row
  std::vector<double> cm_w_;
  struct CmPair {
    int place, hit, a, b;  // the entry kCmRow * row + its place; hit t's product N_a N_b
  };
  std::vector<CmPair> cm_pair_;         // the products in the order they are summed
  std::vector<int> cm_key_, cm_key_next_;  // the hits' slots (K each) the pattern was made for
  static constexpr int kCmNode = 10;    // per slot: its equation (see consistent_dashpots)
  std::vector<double> cm_node_;         // by columns
  std::vector<double> cm_vb_, cm_o_;    // per slot: vbar and o, x's then y's (scratch)
  std::vector<double> cm_g0_;           // 2 per slot: an iteration's g (scratch)
  static constexpr int kCm = 8;
  std::vector<double> cm_;              // per slot: kCm values (see consistent_dashpots)
  std::vector<double> cm_halo_;         // several ranks: grid-sized arrays for the halo sums
  std::vector<std::uint32_t> cm_zone_;  // the particles of the zone around the nodes
  std::vector<std::uint8_t> cm_cover_;  // per node: covered by the zone (1), moves its particles
                                        // (2) (see consistent_dashpots)
  std::vector<long> cm_covered_;        // the nodes marked 1
  std::vector<long> cm_moving_;         // the nodes marked 2
  long cm_scan_version_ = -1;           // the particles' order and count when the zone was found
  std::size_t cm_scan_size_ = 0;
  double cm_drift_ = 0;                 // how far a particle may have moved since (m)
  // grid_update's record of each dashpot node for consistent_dashpots (kDn values per node, in
  // the order of dashpot_nodes_): m, f, v, v+, the block, the consistent weight, and the flags
  // (the fix bits; kDnSkip: not in the solve; kDnHeldX, Y: that component held, see
  // update_dashpot_node).
  enum : int { kDnM, kDnFx, kDnFy, kDnVx, kDnVy, kDnUx, kDnUy, kDnCxx, kDnCxy, kDnCyy, kDnWeight,
               kDnFlags, kDn };
  static constexpr int kDnSkip = 4, kDnHeldX = 8, kDnHeldY = 16;
  std::vector<double> dn_rec_;
  long order_version_ = 0;              // bumped whenever the particles' order or count changes
  template <class S> void consistent_dashpots();
  void cm_sum(int first, int count);    // sum slot values [first, first + count) over the halo
  void put_dashpot_solve(StateWriter& w, const std::string& pre) const;
  // USF with such layers: the last step's updated velocity at their dashpot nodes, which the
  // next step strains the particles with (start_velocities). Per node: the whole grid's node
  // (i, j), its weight (updated_weight_) and v+ (x, y); part of a checkpoint.
  std::vector<double> edge_velocity_;
  bool usf_edges() const { return !updated_weight_.empty() && opt.scheme == Scheme::USF; }
  void keep_edge_velocities();
  // Layers with SilentBoundary::delayed: per window node, the sum of w N rho they put on it this
  // step (empty when there are none); and per node they have reached, a record in delay_ of
  // delay_stride() values, the fields of Delay, then a ring of its start velocity and force less
  // gravity (x, y, fx, fy) over the last delay_cap_ steps (delay_cap_needed(), from dt and the
  // materials). delay_slot_ maps a window node to its record (-1: none). Part of a checkpoint.
  enum Delay : int {
    kDelayI, kDelayJ,          // the whole grid's node
    kDelayCxx, kDelayCyy,      // the last step's blocks
    kDelayRho,                 // and weight, sum of w N rho
    kDelayAt,                  // the step it was last treated as delayed (-1: none yet)
    kDelayFx, kDelayFy,        // that step's force less gravity
    kDelayVx, kDelayVy,        // its delayed velocity
    kDelayDgx, kDelayDgy,      // the change of the strain velocity (boundary_work's account)
    kDelayWritten,             // the last step its ring was written
    kDelayRunFrom,             // the first of that unbroken run of steps
    kDelayBookedAt,            // the step boundary_work last booked it, and then
    kDelayBookedDgx, kDelayBookedDgy,  // the change of the strain velocity
    kDelayBookedFx, kDelayBookedFy,    // and the force less gravity
    kDelayHead
  };
  std::vector<double> delay_rho_;
  std::vector<double> delay_;
  std::vector<int> delay_slot_;
  int delay_cap_ = 0;
  double delay_cmin_ = 0;
  int delay_cap_needed() const;
  // How far an edge node's mass may be from half its layer's weight times h (an end that has
  // drifted by 5 % of a cell) and still take the delayed closure.
  static constexpr double kDelayMassTolerance = 0.1;
  // Whether the closure takes the component whose block is c against the other's c_other: the
  // normal one (c_d against c_s), and both at a corner, where the two are alike. Delayed, the
  // tangential one fed energy into motion along the edge (docs/physics.md section 4).
  static bool delayed_axis(double c, double c_other) { return !(c_other > c); }
  std::size_t delay_stride() const { return kDelayHead + 4 * static_cast<std::size_t>(delay_cap_); }
  double* delay_record(long n) {
    return delay_slot_[n] < 0 ? nullptr : delay_.data() + delay_stride() * delay_slot_[n];
  }
  void delay_prepare();
  void read_node_records(const StateReader& r, const std::string& pre, const std::string& name,
                         std::size_t stride, std::vector<double>& v) const;
  void delay_map();  // delay_slot_ from the records' nodes
  double delay_value(const double* rec, int field, double d, long back) const;
  // A record's node in this window (o its origin, window_origin()), or -1 outside it.
  long delay_window_node(const double* rec, const std::array<int, 2>& o) const {
    const long i = static_cast<long>(rec[kDelayI]) - o[0], j = static_cast<long>(rec[kDelayJ]) - o[1];
    return i >= 0 && j >= 0 && i < grid.nnx && j < grid.nny ? j * grid.nnx + i : -1;
  }
  void delay_strain_velocities(double* gx, double* gy, bool current);
  // Whether node n, holding `weight` of such layers' impedance, takes v+: it must hold at least
  // dt/2 times that weight of mass (remapped_velocities()).
  bool takes_updated(long n, double weight) const {
    return weight > 0 && grid.m[n] > mass_floor_ && 0.5 * dt * weight <= grid.m[n];
  }
  std::array<int, 2> window_origin() const;  // the whole grid's node of the window's (0, 0)
  // The whole grid's origin (finalize, before a split). A window's origin x0 + i0 h differs
  // from it in round-off: a point's cell is found from this one, the same on every rank.
  double whole_x0_ = 0, whole_y0_ = 0;
  bool usf_remapped_power() const;
  double mass_floor_ = 0;
  double viscous_beta_ = -1;  // the largest beta at a particle (finalize()); -1: not yet
  double viscous_beta() const;
  // ranges_[s * G + g] = [begin, end) of particles of strip s and group g.
  std::vector<std::array<uint32_t, 2>> ranges_;
  std::vector<int> strip_lo_, strip_hi_;  // cell-row range each strip touches
  std::vector<int> strip_out_;            // particles of each strip outside the grid columns
  std::vector<uint32_t> where_;           // permanent id -> current index
  std::vector<VelocityField> fields_;     // empty: the grid's own field (set up by the step)
  std::vector<int> body_of_group_;        // with body fields: the body of each material group
  std::vector<StepHooks*> hooks_;
  Decomposition* dist_ = nullptr;
  NodeBox own_{0, -1, 0, -1};  // this rank's nodes (i1 < i0: every node)
  int halo_ = 0;               // the halo's width (nodes)
  bool halo_dashpots_ = false;
  void sum_halo(bool momentum, bool force);
  // fn(layer, its per-entry arrays with their strides) for every boundary layer, in a fixed order.
  template <class Fn> void for_each_layer(Fn&& fn);

  void compact(const std::vector<std::uint8_t>& keep);
  // One particle's record (export_particles) with its layer entries (layer number, entry).
  void pack_record(std::size_t k, const std::vector<std::pair<int, std::size_t>>& entries,
                   std::vector<double>& out);
  void refresh_strip_rows();
  void refresh_fields();
  bool strips_conflict() const;
  void reset_grid();
  // The grid's stores (stores_stream): -1 still timing both ways, 0 plain, 1 streaming; the
  // trial's step (from -2: two steps first), and its times.
  static constexpr double kStreamTrialBytes = 32e6;
  int stream_choice_ = -1;
  int stream_trial_ = -2;
  double stream_time_[2][4] = {};
  bool stores_stream() const;  // whether this step's write-only passes stream
  int reset_arrays() const;
  void time_stores(double seconds);  // a trial step's time
  template <class Fn> void scatter(const std::vector<std::array<uint32_t, 2>>& ranges, Fn&& fn);
  template <class Fn> void parallel(const std::vector<std::array<uint32_t, 2>>& ranges, Fn&& fn);
  template <class Fn> void call(Fn&& fn);
  double inv_rho(int group) const;  // 1 / density of a group's material (0 if none)
  double stretch_limit(int group) const;  // V/m past which dt is above the stability limit
  // The step and its stages, on the shape S of opt.shape.
  template <class S> void step_with();
  template <class S> void project(NodalProjection& out) const;
  template <class S>
  void load_weights(const BoundaryLayer& L, std::size_t q, Anchor anchor, S& sf, long* nodes) const;
  template <class S> void p2g(unsigned what);
  void start_velocities();
  template <class S> void apply_loads();
  // Every entry's weights of layer L (into wn, wN; K per entry), each entry its own: in
  // parallel, the same values as in order. Entries with skip(q) keep what they held.
  template <class S, class Skip>
  void layer_weights(const BoundaryLayer& L, Anchor anchor, std::vector<long>& wn,
                     std::vector<double>& wN, Skip&& skip);
  // Per-entry scratch of the layers' loads and work (computed in parallel, then summed or
  // scattered in entry order, so the sums are those of one pass in order).
  std::vector<double> layer_scratch_;
  template <class S> void pml_shapes();
  template <class S> void pml_loads();
  template <class S> void pml_pic();
  template <class S> void pml_damping(bool remapped);
  // The perfectly matched layer's damping acts on its particles (MUSL and USF, which strain them
  // with their mapped velocities) or through the nodal dashpot blocks (USL, which strains them
  // with the updated grid velocity).
  bool pml_damps_particles() const { return opt.scheme != Scheme::USL; }
  template <class S> void pml_advance(const std::vector<double>& vx, const std::vector<double>& vy);
  void grid_update();
  // Whether grid_update's pass adds gravity's force m g (apply_loads then does not): no hook's
  // after_forces runs between the two.
  bool gravity_in_update() const { return hooks_.empty(); }
  int update_dashpot_node(long i, bool delayed, double gx, double gy);
  // Its trapezoidal update (no delayed closure) from node i's velocity (vx, vy) into (ux, uy);
  // a node not heavier than the mass floor keeps them.
  void trapezoidal_dashpot(long i, double vx, double vy, double& ux, double& uy) const;
  // The same for nodes j .. j+3 at once, where each is a dashpot node, free and heavier than the
  // floor (false, and nothing written, otherwise): velocities from vx, vy into ux, uy (four each).
  bool trapezoidal_dashpots4(long j, const double* vx, const double* vy, double* ux,
                             double* uy) const;
  // The grid's increment v+ - v replaced with sum_{j=0..k} (I - R)^j (v+ - v), R = M^-1 M_c the
  // lumped mass's inverse times the particles' consistent mass, k = opt.mass_correction: the
  // velocity the particles then map back to the grid has nearly taken the lumped mass's
  // increment (docs/physics.md section 1.1). Held components and void nodes take none.
  template <class S> void correct_increments();
  template <class S> void correct_field(const VelocityField& F, double* ex, double* ey);
  // Both forms' terms from the zeroth in mc_tx_, mc_ty_ into (ex, ey); `half`: the symmetric
  // form's coefficients.
  template <class S> void series_terms(const VelocityField& F, double* ex, double* ey, bool half);
  // The symmetric form (opt.mass_correction_symmetric): u <- sum_{j=0..k} c_j (I - R)^j u on the
  // grid's own field, c_j the coefficients of (1 - x)^-1/2's series (1, 1/2, 3/8, ...); held
  // components and void nodes take none. sym_vx_, sym_vy_: the start velocity so corrected, the
  // velocity the boundary work takes at the step's start (USF: the one the stress takes).
  template <class S> void symmetric_velocity(double* ux, double* uy);
  template <class S> void symmetric_start_velocity();
  std::vector<double> sym_vx_, sym_vy_;
  // grid.qx, grid.qy hold the corrected re-mapped velocity of the last step (the probes' field;
  // not after a restart until a step has been taken).
  bool sym_field_ = false;
  template <class Fn> void field_nodes(const VelocityField& F, Fn&& fn);
  std::vector<double> mc_tx_, mc_ty_, mc_ax_, mc_ay_;  // its term and product (per node)
  // USL: the correction's extra increment (per node, one block of nodes per field).
  std::vector<double> mc_ex_, mc_ey_;
  // MUSL and USF: each dashpot node's v+ before the correction (x, y in the order of
  // dashpot_nodes_), the velocity its trapezoidal force acted with (boundary_work); empty when
  // nothing was corrected this step.
  std::vector<double> mc_dash_v_;
  void shift_start_velocities();
  template <class S> void boundary_work(bool remapped);
  template <class S> void g2p(bool remap, bool move);
  // The re-mapped momenta summed over the halo, the hooks' share added (after_remap), made
  // velocities q / m; updated_edges: v+ at the updated layers' dashpot nodes (MUSL).
  void remapped_velocities(bool updated_edges);
  // (start_field with the symmetric form: the corrected start velocity sym_vx_, sym_vy_.)
  template <class S> void update_stress(bool remapped_field, bool start_field, bool move);
  void begin_moving_pass();
  void merge_rows(int strip, const RowSpan& r);
  void check_outside();
  [[noreturn]] void fail_nonfinite() const;
  template <class S> const std::vector<char>& layer_nodes();
  std::vector<char> layer_mask_;       // layer_nodes: the mask and its scratch
  std::vector<long> mask_nodes_;
  std::vector<double> mask_N_;
  void extend_updated(bool start);  // the light nodes' v+ (and v) from the heavy ones'
  void check_health();
  long outside_ = -1;  // index of a particle that left the grid in the last pass
  bool has_springs_ = false;  // a silent boundary carries Kelvin-Voigt springs (finalize)
  // Health-check reductions of the current step (check_health).
  long collapsed_ = 0;         // strips holding a particle with J < 0 (internal-force p2g)
  long stretched_ = 0;         // strips holding a particle stretched past the stability limit
  double step_kinetic_ = 0;    // particles' kinetic energy from g2p
  double step_speed2_ = 0;     // largest squared particle speed from g2p
  double energy_floor_ = 0;    // 1e-12 sum(m c_d^2): the energy bound's floor
};

}  // namespace smpm
