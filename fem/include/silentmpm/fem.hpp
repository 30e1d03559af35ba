#pragma once
// The deal.II far-field: 2D plane-strain linear elastodynamics on a gmsh quad mesh.
//
// This header has no deal.II include (the implementation sits behind a pointer), so the driver,
// the tests and the coupling code include it cheaply.
//
// Discretisation
//   * FE_Q(1) or FE_Q(2) for both displacement components; degrees of freedom are numbered by
//     node, dof = 2 node + component, so every per-node array below is indexed by node.
//   * Diagonal (lumped) mass from Gauss-Lobatto nodal quadrature, stiffness K from full Gauss
//     quadrature, stored node-block-wise (2x2 blocks) in a compressed sparse row layout; the
//     internal force -K u is one OpenMP-parallel sparse matrix-vector product.
//   * Explicit central difference with the semi-implicit Lysmer-Kuhlemeyer dashpot at the node:
//       (M + dt/2 C) v^{n+1/2} = (M - dt/2 C) v^{n-1/2} + dt (f_ext^n - K u^n),
//       u^{n+1} = u^n + dt v^{n+1/2},
//     with C one 2x2 block per boundary node, C = rho l [a c_d n n^T + b c_s (I - n n^T)] from
//     Gauss-Lobatto face quadrature (a corner node sums its two faces).
//   * Energies: kinetic 1/2 v^{n+1/2} M v^{n+1/2} and elastic 1/2 u^n K u^{n+1} are the pair the
//     central-difference scheme conserves exactly, so kinetic + elastic + absorbed - external work
//     is zero to round-off (absorbed = sum dt vbar C vbar, external = sum dt f_ext^n vbar, with
//     vbar = (v^{n-1/2} + v^{n+1/2}) / 2).
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "silentmpm/material.hpp"
#include "silentmpm/energies.hpp"
#include "silentmpm/state_io.hpp"
#include "silentmpm/time_function.hpp"

namespace smpm::fem {

// Any problem with a mesh or an FEM input. The message is complete (it names the file or group).
struct FemError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// ---- meshes ----------------------------------------------------------------------------------
// A mesh read through gmsh: a .geo is meshed (its `DefineConstant[ h = {..., Name
// "Parameters/h"} ]` set to `size` when size > 0), a .msh is read as is. Only first-order
// quadrilaterals are accepted. Physical surfaces give material ids, physical curves boundary ids.
struct PhysicalGroup {
  int tag = 0;
  std::string name;
};

struct Mesh {
  std::string file;        // as given
  double size = 0;         // mesh size asked for (.geo), 0 = the file's default
  std::string msh;         // ASCII MSH 4.1 text, all quads, physical groups of dim 1 and 2 only
  std::vector<PhysicalGroup> surfaces, curves;
  std::size_t quads = 0;   // number of quadrilateral elements
  const PhysicalGroup* surface(int tag) const;
  const PhysicalGroup* curve(int tag) const;
  // Tag of the group named `name` (or written as its number), -1 if absent.
  int surface_tag(const std::string& name_or_tag) const;
  int curve_tag(const std::string& name_or_tag) const;
};

// Reads or meshes `file` (".geo" or ".msh"); a .geo whose size would give more than max_cells
// cells (estimated before meshing) is refused. `parameters` set other numbers of a .geo before it
// is read (its DefineConstant keeps them). Throws FemError naming the file. Under MPI with several
// ranks every rank calls it at once: rank 0 alone reads or meshes its `file` and sends the mesh
// to the others (their arguments are not read); rank 0's error is thrown on every rank. With
// text_to_all false (rank 0's word counts) the others get the groups and counts but no `msh`
// text: a far field set up from rank 0 (Solver::distribute_from_root) needs no more there.
Mesh load_mesh(const std::string& file, double size, double max_cells = 1e7,
               const std::vector<std::pair<std::string, double>>& parameters = {},
               bool text_to_all = true);

// ---- model -------------------------------------------------------------------------------------
struct Boundary {
  enum class Kind { Dashpot, Traction, Fixed, Roller, Damping, Pml };
  Kind kind = Kind::Fixed;
  std::string name;
  std::vector<int> curves;     // physical curve tags (boundary ids)
  // Dashpot: coefficients of the LK dashpot (a = b = 1: standard).
  double a = 1, b = 1;
  // Dashpot with delta > 0: the Kelvin-Voigt boundary, springs k_n = alpha_n rho c_d^2 / delta and
  // k_t = alpha_t rho c_s^2 / delta per unit length beside the dashpots, lumped at the nodes as
  // the dashpots are and added to the stiffness (so internal forces, elastic energy and the
  // critical time step include them).
  double delta = 0, alpha_n = 1, alpha_t = 1;
  // Traction: f(t) * (normal n + tangential s + (vx, vy)), n outward normal, s = (-n_y, n_x).
  double normal = 0, tangential = 0, vx = 0, vy = 0;
  TimeFunction fn;
  // Roller: the component held at zero (0 = x, 1 = y).
  int component = 0;
  // Damping: a graded mass-proportional damping layer of thickness `width` inside the curves,
  // alpha(s) = alpha0 s^power per unit mass, s = 1 - (distance to the curves) / width, alpha0 =
  // -(power + 1) c_d ln(r0) / width (c_d of the material next to the curves); nodal blocks
  // C_i = alpha(x_i) m_i I beside the dashpots (docs/physics.md section 9.2). With beta > 0 (s)
  // also a stiffness-proportional part graded alike, beta_i = beta s_i^power at the nodes, whose
  // force is -B^1/2 K B^1/2 v (B = diag beta_i, K the assembled stiffness), explicit with the
  // last velocity; the critical time step shrinks to dt_c (sqrt(1 + xi^2) - xi), xi = beta / dt_c.
  double width = 0, r0 = 1e-3, power = 2, beta = 0;
  // Pml: a perfectly matched layer of thickness `width` inside the curves, which must form one
  // straight edge parallel to the x or the y axis. Complex coordinate stretching normal to the
  // edge, s = 1 + d / (alpha + i omega), d = d0 s^power (s the depth into the layer over width,
  // 0 at its inner edge), d0 = -(power + 1) c_d ln(r0) / (2 width) with c_d of the material next
  // to the curves, alpha the frequency shift (1/s; the same for every PML of a model). Layers on
  // two edges overlap in the corner, where both stretchings apply (docs/physics.md section 9.3).
  // parallel > 0: the multi-axial layer, the share `parallel` of d along the edge as well (the
  // classical layer grows between two free surfaces; docs/physics.md section 9.3).
  double alpha = 0, parallel = 0;
};

struct Spec {
  Mesh mesh;
  int degree = 1;                          // 1 or 2
  std::vector<Material> materials;         // elastic materials
  std::map<int, int> region_material;      // physical surface tag -> index into materials
  std::vector<Boundary> boundaries;
  int threads = 0;                         // 0: OpenMP default
  double gravity_x = 0, gravity_y = 0;     // body force per unit mass (m/s^2), lumped: f_i = m_i g
  // Rows of K equal bit for bit share one copy of their values (Solver::rows_shared); false
  // keeps every row's own (the tests compare the two).
  bool share_rows = true;
  // A perfectly matched layer's axis-aligned Q1 cells take the tensor-product form of their
  // derivatives (Solver::pml_tensor_cells); false steps every cell through its shape table (the
  // tests compare the two).
  bool pml_tensor = true;
};

// What a probe reads at a point: stresses, velocity, div u and curl u = du_y/dx - du_x/dy.
struct Sample {
  double sxx = 0, syy = 0, szz = 0, sxy = 0, j2 = 0, vx = 0, vy = 0, div = 0, curl = 0;
};

class Solver {
 public:
  // Builds the mesh, the degrees of freedom, the lumped mass, K, the dashpot blocks and the
  // traction load vectors. Throws FemError on a bad model (unknown group, no material...).
  explicit Solver(const Spec& spec);
  // On a rank other than 0 of a far field set up from rank 0 (distribute_from_root): the spec
  // only (a mesh's text is dropped); the part arrives from rank 0. Nothing else may be called
  // on it before distribute_from_root().
  struct Skeleton {};
  Solver(const Spec& spec, Skeleton);
  ~Solver();
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;

  double dt = 0, t = 0;
  long steps = 0;
  Energies energy;

  // Sizes.
  std::size_t nodes() const;
  std::size_t dofs() const { return 2 * nodes(); }
  // 2 x 2 blocks of the stiffness (node-block CSR: a node and each node it shares a cell with).
  std::size_t matrix_blocks() const;
  // The blocks whose values K stores: matrix_blocks(), or far fewer when rows equal bit for bit
  // share their values (a structured mesh's few kinds of rows; then each row also keeps an
  // offset to its kind's values, rows_shared() true).
  std::size_t stored_blocks() const;
  bool rows_shared() const;
  // With shared rows: the groups of four consecutive rows (4g .. 4g+3) that share one row of
  // values and whose columns are the first's shifted by their place (consecutive nodes of a
  // structured mesh); step() takes each such group at once.
  std::size_t row_groups() const;
  // How step() stores the groups' new displacement and -K u: -1 while its first steps time
  // both ways, 0 plainly, 1 streaming (not reading the lines first; a pass of 32 MB or more).
  int store_mode() const;
  // The perfectly matched layers' cells (this rank's), and those whose forces take the
  // tensor-product form (Spec::pml_tensor; known once the solver has stepped, 0 before).
  std::size_t pml_cells() const;
  std::size_t pml_tensor_cells() const;
  std::size_t cells() const;
  int degree() const;
  int thread_count() const;
  // The body force per unit mass (Spec::gravity_x, gravity_y).
  std::array<double, 2> gravity() const;
  // Bounding box of the mesh: x0, y0, x1, y1.
  std::array<double, 4> bounds() const;

  // Stability: the element bound 2 / sqrt(max over elements of lambda_max(M_e^-1 K_e)), which
  // never exceeds the true critical step of the assembled undamped system.
  double critical_dt() const;
  // Sets dt (throws FemError if dt > critical_dt()); step() checks a dt assigned directly.
  void set_dt(double dt);

  // One explicit step.
  void step();

  // Probes: add_probe returns the probe index, or -1 if the point is outside the mesh.
  int add_probe(double x, double y);
  std::vector<Sample> sample() const;
  // Updates `energy` (kinetic, elastic; absorbed and external work accumulate in step(), and
  // after distribute() are the sums over ranks as of this call).
  void update_energies();

  // Snapshots: DIR/BASE.h5 (the mesh once, then a group per snapshot) and DIR/BASE.xdmf, which
  // grows by one grid per snapshot (MeshSnapshotWriter of output.hpp). Node fields:
  // displacement and velocity (3-vectors, m and m/s), stress (3 x 3 tensor, Pa; each node's the
  // mean over its cells) and J2 (Pa^2); cell field material. Q2 cells are written as 4 quads.
  void write_snapshot(const std::string& dir, const std::string& base);
  // The deflate level of the snapshot datasets (0, the default: none; 1-9: deflated chunks).
  void set_snapshot_compression(int level);
  // Closes DIR/BASE.h5 at the end of a run (on a local model of several ranks every rank
  // together). Throws FemError.
  void close_snapshots();
  int snapshot_count() const;
  // The times of the snapshots written so far.
  std::vector<double> snapshot_times() const;
  // After load_state: reopens DIR/BASE.h5 and lists the earlier run's snapshots in BASE.xdmf
  // again (later ones are removed). Returns how many: all, or 0 when the file or one of them is
  // missing (a note says so; the snapshot count restarts at 0 and the next snapshot starts the
  // file afresh).
  int resume_snapshots(const std::string& dir, const std::string& base);

  // Checkpoints: the state a later step reads (u, v, -K u^n, clock, energies, snapshot times) as
  // blocks named `prefix` + ...; load_state restores it into a solver built from the same case
  // (on a local model of several ranks collectively: rank 0 reads the nodal blocks and sends
  // each rank its nodes', blocks_from_root()).
  void save_state(StateWriter& w, const std::string& prefix) const;
  void load_state(const StateReader& r, const std::string& prefix);
  // A per-node array (2 values a node) in a checkpoint: whole on one process, as this rank's
  // own nodes' part on several (in the order of the block `prefix`nodes that save_state puts);
  // get_nodes reads either form.
  void put_nodes(StateWriter& w, const std::string& name, const std::vector<double>& per_node) const;
  // The blocks (name prefixes) that load_state reads on rank 0 alone on a local model of several
  // ranks (the nodal state and the PMLs' memories, which rank 0 sends each rank its part of):
  // a restart may leave them out of what the other ranks read.
  static std::vector<std::string> blocks_from_root(const std::string& prefix);
  void get_nodes(const StateReader& r, const std::string& prefix, const std::string& name,
                 std::vector<double>& per_node) const;

  // --- access for the MPM-FEM coupling and tests ---------------------------------------------
  const std::vector<double>& node_x() const;
  const std::vector<double>& node_y() const;
  const std::vector<double>& mass() const;          // lumped nodal mass (per component)
  // 2 per node, interleaved. step() writes u^{n+1} into a second buffer and swaps the two: take
  // data() anew after a step.
  std::vector<double>& displacement();
  std::vector<double>& velocity();                   // 2 per node, v^{n+1/2}
  // f = -K u (2 per node; after distribute(), this rank's own rows only). u and f must not alias.
  void internal_force(const double* u, double* f) const;
  struct DashpotBlock {
    std::uint32_t node;
    double cxx, cxy, cyy;
  };
  // (A local model: the blocks of its own and received nodes.)
  const std::vector<DashpotBlock>& dashpots() const;
  // The mesh's nodes with a dashpot block (dashpots() holds a local model's own ones).
  std::size_t dashpot_count() const;
  // Nodes of each cell, (degree + 1)^2 per cell in deal.II's FE_Q order (vertices first:
  // (0,0), (1,0), (0,1), (1,1) in the cell's reference frame).
  const std::vector<std::uint32_t>& cell_nodes() const;
  // The nodes whose update takes an explicit force besides f_int and f_ext: every node of a PML
  // cell and the damping layers' stiffness-proportional nodes (ascending). The hybrid keeps its
  // shared nodes off them (its grid update does not take those forces).
  std::vector<std::uint32_t> explicit_force_nodes() const;
  // Constraint mask per node: bit 0 = x held, bit 1 = y held.
  const std::vector<std::uint8_t>& constraint_mask() const;
  // External nodal force f_ext(t) (2 per node) into f, written on the loaded nodes only: f must
  // hold zero on every other node (start from a zero vector written only by this call), so that
  // a step costs O(loaded nodes), not O(dofs).
  void refresh_external_force(double time, double* f) const;
  // The explicit update of the nodes the caller does not advance itself (skip[i] < 0), from the
  // forces f = f_int + f_ext (2 per node) and the current v: v+ = v + dt f / m, semi-implicit at a
  // node with a dashpot block (dashpot.hpp), constraints; then u += dt v+. Adds the work of f_ext
  // and the energy the dashpots absorb on those nodes to work and absorbed. The MPM-FEM hybrid
  // advances its FE-only nodes with it (its shared nodes follow the grid). Split over ranks:
  // this rank's own nodes, then the ghost update (every rank calls it).
  void advance_free_nodes(const std::int64_t* skip, const double* f_int, const double* f_ext,
                          double dt, double& work, double& absorbed);
  // Nodes on the given boundary ids (physical curve tags), sorted.
  std::vector<std::uint32_t> boundary_nodes(const std::vector<int>& curves) const;

  // Human-readable lines describing the model (mesh, dofs, boundaries).
  std::vector<std::string> describe() const;

  // ---- several processes (docs/parallel.md, "The FE far field") --------------------------------
  // Splits the stepping over the ranks of MPI_COMM_WORLD (MPI initialised by the caller; every
  // rank built the same model). METIS cuts the cells into one part per rank; a node belongs to
  // the lowest rank among its cells; each rank steps its own nodes' rows of K, and the layer
  // cells around them, and receives its neighbours' nodes it reads (u and v) after every step.
  // Probes, energies, snapshots and checkpoints are reduced or gathered: rank 0 writes what one
  // process would, and every other rank calls the same functions (they are collective). Throws
  // FemError, on every rank, when MPI is not running, the model is split already, METIS fails,
  // the mesh has fewer cells than ranks or a part is empty. Call it once, before or after
  // load_state. The arrays (node_x(), displacement() ...) keep the whole mesh's size; on a rank
  // only its own nodes and the ones it receives hold current values. The hybrid's calls work on
  // a split model too: internal_force fills the own rows, advance_free_nodes advances the own
  // nodes and then receives the neighbours' (collective).
  void distribute();
  // After distribute(): keeps only what this rank steps (each rank its part of the cut that
  // distribute() shared; nothing is sent). Its arrays then hold its
  // own nodes and those it receives, numbered in the mesh's order (global_nodes() gives each
  // local node's mesh number), K only its own rows, cell_nodes() its cells; every rank frees
  // deal.II's mesh and the rest of the whole model. The step, probes, energies, snapshots (which
  // every rank then writes at once, its runs of the file's rows) and checkpoints give the same
  // bits as the split whole model. nodes(),
  // dofs(), cells(), dashpot_count() and describe() still tell the whole mesh's; own_nodes(),
  // node_owner() and the per-node arrays (node_x(), displacement(), put_nodes ...) are local;
  // gathered() takes a local array and gives rank 0 the whole mesh's. Probes are added before.
  // The PMLs keep the layer cells the rank steps and its own layer nodes, the damping bands'
  // stiffness-proportional part the listed nodes it holds. Returns true; throws FemError when
  // the model is not split.
  bool localize();
  bool localized() const;
  // The same parts, built on rank 0 alone: rank 0 holds the whole model (as built from the
  // spec, its probes added and dt set), the other ranks a Skeleton of the same spec; rank 0 cuts
  // it, builds each rank's local model (as localize() would) and sends it with the clock, and
  // keeps its own. So only rank 0 ever holds the whole model. Collective; throws FemError on
  // every rank when the cut fails, or building, sending or unpacking a part fails on any rank.
  void distribute_from_root();
  bool is_skeleton() const;
  // The mesh number of each local node (every node on a model that holds the whole mesh).
  std::vector<std::uint32_t> global_nodes() const;
  int ranks() const;  // 1 on one process
  // The nodes this rank steps, ascending (every node on one process).
  std::vector<std::uint32_t> own_nodes() const;
  // The rank that steps `node` (0 on one process).
  int node_owner(std::uint32_t node) const;
  // A per-node array (2 values a node, the whole mesh's size) as each node's owner holds it,
  // on rank 0 (collective: the other ranks get an empty vector); on one process a copy.
  std::vector<double> gathered(const std::vector<double>& per_node) const;
  // Gathers on rank 0 (gathered(), checkpoints) go rank by rank in messages of at most this
  // many values (default 2^30; an MPI count is an int), so the whole has no count limit. A
  // test sets it small.
  static void set_gather_piece(std::size_t n);
  // A test's fault: distribute_from_root() fails on rank 0 while it builds rank `rank`'s part
  // (rank >= 1), or rank r finds no room for its own (rank = -r - 1); 0 clears it.
  static void set_part_fault(int rank);
  // The ghost updates so far over all ranks (every rank calls it): the slowest rank's seconds,
  // the bytes all ranks sent, and the largest rank's counts; held_nodes: the nodes whose arrays
  // a rank holds (the whole mesh's, or after localize() its own and received ones).
  struct Traffic {
    double seconds = 0, bytes = 0;
    long updates = 0;
    std::size_t own_nodes = 0, ghost_nodes = 0, neighbours = 0, held_nodes = 0;
  };
  Traffic traffic() const;

  struct Impl;

 private:
  // Takes a local model in place of the whole one and gives the freed pages back.
  void adopt(std::unique_ptr<Impl> loc);
  std::unique_ptr<Impl> impl_;
};

}  // namespace smpm::fem
