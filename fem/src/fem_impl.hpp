#pragma once
// Internal state of fem::Solver, shared by the deal.II setup (fem_setup.cpp) and the plain-C++
// time-stepping kernels (fem_kernels.cpp). No deal.II include here: the deal.II objects live in
// `Deal`, complete only in fem_setup.cpp.
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "silentmpm/fem.hpp"
#include "silentmpm/output.hpp"

namespace smpm::fem {

struct Deal;  // Triangulation, DoFHandler, FE (fem_setup.cpp)

struct Solver::Impl {
  Impl();
  ~Impl();  // in fem_setup.cpp, where Deal is complete

  Spec spec;
  int degree = 1;
  int threads = 1;
  std::size_t n_cells = 0;
  std::vector<std::uint32_t> cell_nodes;  // nodes of each cell, (degree+1)^2 per cell (coupling)
  std::vector<std::int32_t> cell_region;  // each cell's physical surface (material) tag
  // The snapshots' nodal gradients without deal.II: at each of a cell's nodes a (its support
  // point in the reference cell), the reference gradients of the cell's shape functions b
  // (ref_grad[2 (a nb + b) + j]) and of the bilinear map's vertex functions v (map_grad[2 (4 a + v) + j]).
  std::vector<double> ref_grad, map_grad;
  std::array<double, 4> box{{0, 0, 0, 0}};

  // Per node.
  std::vector<double> x, y, mass, inv_mass;
  std::vector<std::uint8_t> mask;         // bit 0: x held, bit 1: y held
  std::vector<std::int32_t> dash_of_node; // index into dash, or -1

  // Per dof (2 per node, interleaved).
  std::vector<double> u, v, ku, fext;
  // The displacement step() writes u^{n+1} into while it reads u^n from u (then the two swap).
  std::vector<double> u_next;

  // Stiffness, node-block CSR: row i has blocks k in [rowptr[i], rowptr[i+1]), column col[k],
  // values val[4k..4k+3] = Kxx, Kyx, Kxy, Kyy (column by column: K u takes a block's two
  // columns as pairs, times u_x and u_y).
  // Rows equal to another's bit for bit may share values (fem_setup.cpp, share_equal_rows): with
  // row_val non-empty, row i's values start at block row_val[i] of val, not at rowptr[i].
  std::vector<std::uint64_t> rowptr;
  std::vector<std::uint32_t> col;
  std::vector<double> val;
  std::vector<std::uint32_t> row_val;
  // With shared values: per group of four rows 4g .. 4g+3, 1 when they share one row of values
  // and each row's columns are the first's plus its place in the group (consecutive nodes of a
  // structured mesh): K u then reads the four rows' u of a block as one run (fem_kernels.cpp).
  std::vector<std::uint8_t> row4;

  // Dashpot blocks C per dashpot node (their trapezoidal update: dashpot.hpp).
  std::vector<Solver::DashpotBlock> dash;

  // Perfectly matched layers (built in fem_setup.cpp, stepped in fem_kernels.cpp;
  // docs/physics.md section 9.3). Cells that reach into a layer keep their quadrature data and
  // four memory variables per quadrature point (the stretched parts of the x and y derivatives
  // of u_x and u_y); nodes inside a layer keep two per component (the mass term's convolutions).
  struct Pml {
    double alpha = 0;                        // frequency shift (1/s)
    int nb = 0, nq = 0;                      // nodes and quadrature points per cell
    // Cells in colour order (no two cells of a colour share a node): colour k holds cells
    // [colour_start[k], colour_start[k + 1]).
    std::vector<std::uint32_t> colour_start;
    std::vector<std::uint32_t> cell;         // per cell: its index among the mesh's cells
    std::vector<std::uint32_t> cell_nodes;   // nb per cell
    std::vector<std::uint32_t> shape;        // per cell: its table in grad
    std::vector<double> grad;                // per shape, point, node: dN/dx, dN/dy
    // The distinct kinds of point, each (d_y - d_x) JxW (lambda + 2 mu), (d_y - d_x) JxW mu,
    // d_x, d_y (a structured layer has a few dozen), and per cell and point its kind.
    std::vector<double> kl, km, dx, dy;
    std::vector<std::uint32_t> kind;
    std::vector<double> xi;                  // 4 per cell and point
    // Axis-aligned Q1 cells (a box mesh's): per shape, whether its table is that of such a cell
    // (tensor_ok, found at the first step from grad: pml_tensor_weights) and then the 8 weights
    // that blend the cell's edge differences into its points' derivatives.
    bool tensor_found = false;
    std::vector<std::uint8_t> tensor_ok;
    std::vector<double> tensor_w;
    std::vector<std::uint32_t> node;         // nodes with d_x + d_y > 0
    std::vector<double> m_sum, m_prod;       // m_i (d_x + d_y), m_i d_x d_y
    std::vector<double> zeta;                // 4 per node: the memories I1, I2 of u_x, then of u_y
    std::vector<std::uint32_t> touched;      // every node of a layer cell
    // For the step dt_coef: per kind of point kl, km and the recursive-convolution coefficients
    // (e, ca, cb) for alpha + d_x and for alpha + d_y, 8 values packed; those for alpha alone.
    double dt_coef = 0;
    std::vector<double> packed;
    double e_a = 1, ca_a = 0, cb_a = 0;
    // A local model (Solver::localize): each cell's and node's index in the whole model's lists,
    // whether the cell is of this rank's part (its checkpoint share), and the whole lists' sizes.
    std::vector<std::uint32_t> glob_cell, glob_node;
    std::vector<std::uint8_t> own_cell;
    std::size_t whole_cells = 0, whole_nodes = 0;
    bool active() const { return !touched.empty(); }
  };
  Pml pml;
  // The damping layers' stiffness-proportional part (docs/physics.md section 9.2): at each
  // listed node sqrt(beta_i); its force -sqrt(beta_i) (K w)_i, w = sqrt(beta) v, enters through
  // the node's dashpot block as an explicit force (dash_force).
  struct Viscous {
    std::vector<std::uint32_t> node;  // ascending
    std::vector<double> root_beta;    // per listed node
    std::vector<std::uint32_t> rows;  // indices into node of the ones this rank steps
    std::vector<std::uint32_t> row_node;
    std::vector<double> w, kw;        // 2 per node held (zero away from the listed nodes)
    bool active() const { return !node.empty(); }
  };
  Viscous visc;
  // 2 per dashpot block: the explicit forces of the PML and of the damping layers'
  // stiffness-proportional part (else 0).
  std::vector<double> dash_force;

  // Traction loads: f_ext(t) = sum_l fn_l(t) F_l, F_l sparse over its nodes.
  struct Load {
    TimeFunction fn;
    std::vector<std::uint32_t> nodes;
    std::vector<double> f;  // 2 per listed node
  };
  std::vector<Load> loads;

  // Nodes per boundary id (physical curve tag).
  std::map<int, std::vector<std::uint32_t>> curve_nodes;

  double crit_dt = 0;
  bool ku_valid = false;  // ku holds K u for the current u
  // The step's groups of four rows (row4) store the new displacement and -K u streaming (not
  // reading the lines first) or plainly: -1 while the first steps time both ways (a pass of at
  // least kStreamTrialBytes; a smaller one, whose arrays the cache may hold, stores plainly),
  // then 0 plain, 1 streaming (fem_kernels.cpp, Solver::step).
  int stream_mode = -1;
  int stream_trial = 0;
  double stream_time[2][4] = {};

  // Probes: shape values and gradients of the dofs of every cell containing the point (a point on
  // a cell edge or node belongs to 2 or 4 cells; their stresses are averaged).
  struct ProbePart {
    std::uint32_t cell = 0;  // the cell's index among the mesh's cells
    std::vector<std::uint32_t> dofs;
    std::vector<std::uint8_t> comp;
    std::vector<double> N, dx, dy;
    double lambda, mu;
  };
  struct Probe {
    double x, y;
    std::vector<ProbePart> parts;
    double w = 0;  // each part's weight: 1 / the number of cells around the point
  };
  std::vector<Probe> probes;

  // Several processes (fem_parallel.cpp; docs/parallel.md): what this rank steps, whom it sends
  // its nodes' values after each step and whose it receives. Null on one process.
  struct Part {
    int rank = 0, size = 1;
    std::vector<std::uint32_t> cell_rank;   // per cell: the rank of its part (METIS)
    std::vector<std::uint32_t> node_rank;   // per node: the lowest rank among its cells
    std::vector<std::uint32_t> own;         // this rank's nodes, ascending
    std::size_t ghosts = 0;
    // The layer cells this rank steps (indices into pml's cells, by colour: colour k holds
    // pml_cells[pml_colour_start[k] .. pml_colour_start[k + 1])), and the entries of pml.node
    // that are its own nodes.
    std::vector<std::uint32_t> pml_cells, pml_colour_start, pml_nodes;
    struct Link {
      int rank = 0;
      std::vector<std::uint32_t> send, recv;  // nodes, ascending, the same lists on both sides
    };
    std::vector<Link> links;
    std::vector<double> sendbuf, recvbuf;
    double work = 0, absorbed = 0;  // this rank's share of the booked energies
    double seconds = 0, bytes = 0;
    long updates = 0;
  };
  std::unique_ptr<Part> part;

  // A local model (Solver::localize, fem_local.cpp): the arrays hold this rank's nodes only
  // (its own and those it receives), numbered in the mesh's order, glob[i] the mesh node of
  // local node i; the rows of K are its own nodes' (the others' rows empty); cell_nodes lists
  // the cells it steps; the probes keep the parts of its cells. Empty glob: the whole mesh.
  std::vector<std::uint32_t> glob;
  std::size_t mesh_nodes = 0, mesh_dashpots = 0;  // the whole mesh's counts (a local model)
  std::vector<std::string> described;             // describe() of the whole model (a local model)
  // A local model's cells (those of cell_nodes): each one's index among the mesh's cells, and
  // whether it is of this rank's part (cell_region is then the local cells').
  std::vector<std::uint32_t> cell_glob;
  std::vector<std::uint8_t> cell_own;

  std::unique_ptr<Deal> deal;
  // DIR/BASE.h5 + BASE.xdmf (Solver::write_snapshot, fem_snapshot.cpp); snap_ranks: set up for
  // a local model's ranks writing it together.
  MeshSnapshotWriter snap;
  bool snap_ranks = false;
  int snapshots = 0;
  std::vector<double> snapshot_times;  // every snapshot's time (a restart's earlier ones too)
};

// The cells' parts for `parts` ranks (METIS through deal.II), in the mesh's cell order
// (fem_setup.cpp).
std::vector<std::uint32_t> partition_cells(Solver::Impl& m, unsigned parts);

// Several processes (fem_parallel.cpp). A model already split, or MPI not running, is an error
// (FemError); so is a part METIS leaves empty.
void check_can_split(const Solver::Impl& m);
void check_enough_cells(std::size_t cells, int ranks);
void check_parts(const std::vector<std::uint32_t>& cell_rank, int size, std::size_t nc);
// Rank me's share of the whole model m under the cut P.cell_rank (P.size ranks): the nodes'
// owners, its own nodes, its links to the others, its PML cells and nodes.
void make_part(const Solver::Impl& m, Solver::Impl::Part& P, std::uint32_t me);
// Copies the owners' u and v to the nodes this rank receives; sums n values over the ranks, in
// place.
void exchange_ghosts(Solver::Impl& m);
void sum_over_ranks(const Solver::Impl& m, double* v, int n);
// A local model on more than one rank: its ranks write the snapshots together and rank 0 alone
// reads a checkpoint's nodal blocks. (On one rank it holds the whole mesh, in order, and reads
// and writes as one process does.)
inline bool local_on_ranks(const Solver::Impl& m) {
  return m.part && !m.glob.empty() && m.part->size > 1;
}
// A block of `width` values per item (`items` of them) of a checkpoint, whole or as parts with
// the items' numbers in the block `numbers` (which must name every item once); fem_kernels.cpp.
void get_items(const StateReader& r, const std::string& name, const std::string& numbers,
               std::size_t items, std::size_t width, std::vector<double>& v);
// A local model on several ranks (Solver::load_state): rank 0 reads the checkpoint's nodal blocks
// (u, v, K u, the flag of K u) and the PMLs' memories from r, whole, and sends each rank its
// nodes' and layer cells' values; the other ranks' r need not hold them. Collective; rank 0's
// error reading them (StateError) is every rank's.
void load_from_root(Solver::Impl& m, const StateReader& r, const std::string& pre);
// Each rank's items `mine` (mesh numbers of nodes, layer cells ...) of per-item arrays that
// rank 0 alone holds whole (`whole`: `widths[f]` values an item of field f; ignored on the other
// ranks): every rank receives its items' values into `out` (one array per field, in the order of
// `mine`). Collective; rank 0 answers the ranks one by one, in messages of at most
// gather_piece() values.
void slices_from_root(const std::vector<std::uint32_t>& mine,
                      const std::vector<const std::vector<double>*>& whole,
                      const std::vector<std::size_t>& widths,
                      const std::vector<std::vector<double>*>& out);
// Items (nodes, layer cells ...) with an owning rank each: rank 0 receives every item's `width`
// values of each array in `fields` from its owner into `out` (one array per field, the whole
// size); the others send their own items' and leave `out` empty.
void gather_on_root(const Solver::Impl& m, const std::vector<std::uint32_t>& owner,
                    const std::vector<const std::vector<double>*>& fields, int width,
                    std::vector<std::vector<double>>& out);

// A local model's per-node arrays (`width` values a node, each of `fields`) on rank 0 as the
// whole mesh's, each node's from its owner (collective: the other ranks get `out` empty;
// fem_local.cpp). Messages of at most gather_piece() values (fem_parallel.cpp).
void gather_local(const Solver::Impl& m, const std::vector<const std::vector<double>*>& fields,
                  std::size_t width, std::vector<std::vector<double>>& out);
long long gather_piece();

// Largest eigenvalue of the symmetric n x n matrix a (row-major; destroyed), cyclic Jacobi.
double symmetric_max_eigenvalue(std::vector<double>& a, int n);

}  // namespace smpm::fem
