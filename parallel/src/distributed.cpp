// Blocks of cells over MPI ranks (distributed.hpp; docs/parallel.md).
#include "silentmpm/distributed.hpp"

#include <petscdmda.h>
#include <petscsf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

#include "silentmpm/mpi_bytes.hpp"
#include "silentmpm/solver.hpp"

namespace smpm {

namespace {

void check(PetscErrorCode e, const char* what) {
  if (e != 0) throw std::runtime_error(std::string("PETSc: ") + what + " failed (error " +
                                       std::to_string(static_cast<int>(e)) + ")");
}

bool g_started_mpi = false;

// Cuts [0, n) into p parts of about equal cost, each at least `least` long.
std::vector<int> cuts(const std::vector<double>& cost, int p, int least) {
  const int n = static_cast<int>(cost.size());
  double total = 0;
  for (double c : cost) total += c;
  std::vector<int> R(p + 1, 0);
  R[p] = n;
  double acc = 0;
  int r = 0;
  for (int o = 1; o < p; ++o) {
    const double target = total * o / p;
    while (r < n && acc + 0.5 * cost[r] < target) acc += cost[r++];
    R[o] = r;
  }
  for (int o = 1; o < p; ++o) R[o] = std::max(R[o], R[o - 1] + least);
  for (int o = p - 1; o >= 1; --o) R[o] = std::min(R[o], R[o + 1] - least);
  return R;
}

// Which part of the cuts R holds cell c.
int part_of(const std::vector<int>& R, int c) {
  return static_cast<int>(std::upper_bound(R.begin(), R.end(), c) - R.begin()) - 1;
}

// The m x n = ranks layout with the fewest halo nodes: (m - 1) node columns of ny + 1 and
// (n - 1) node rows of nx + 1, each shared once; the fewer ranks across on a tie.
int blocks_across(int ranks, int nx, int ny) {
  int best = 1;
  double least = -1;
  for (int m = 1; m <= ranks; ++m) {
    if (ranks % m) continue;
    const int n = ranks / m;
    const double halo = static_cast<double>(m - 1) * (ny + 1) + static_cast<double>(n - 1) * (nx + 1);
    if (least < 0 || halo < least) least = halo, best = m;
  }
  return best;
}

}  // namespace

void parallel_init(int* argc, char*** argv) {
  int up = 0;
  MPI_Initialized(&up);
  if (!up) {
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    g_started_mpi = true;
  }
  PetscBool petsc = PETSC_FALSE;
  PetscInitialized(&petsc);
  if (petsc) return;
  // The program keeps its own signal handling (interrupts end a run cleanly).
  check(PetscOptionsSetValue(nullptr, "-no_signal_handler", nullptr), "PetscOptionsSetValue");
  check(PetscInitializeNoArguments(), "PetscInitialize");
}

void parallel_finalize() {
  PetscBool petsc = PETSC_FALSE;
  PetscInitialized(&petsc);
  if (petsc) PetscFinalize();
  int down = 0;
  MPI_Finalized(&down);
  if (g_started_mpi && !down) MPI_Finalize();
}

struct Distributed::Impl {
  // PETSc's and MPI's objects are freed here, so that a constructor that fails after creating
  // them (a check below) leaves nothing behind either.
  ~Impl() {
    for (auto& [n, s] : sf) PetscSFDestroy(&s);
    if (da) DMDestroy(&da);
    if (graph != MPI_COMM_NULL) MPI_Comm_free(&graph);
  }
  MPI_Comm comm = MPI_COMM_NULL;
  MPI_Comm graph = MPI_COMM_NULL;  // the neighbours, sides and corners
  int rank = 0, size = 1;
  int m = 1, n = 1;                // ranks across x and along y; rank = pj * m + pi
  int pi = 0, pj = 0;
  int w = 2;                       // halo width (nodes)
  std::vector<int> Cx, Ry;         // cells of rank (pi, pj): [Cx[pi], Cx[pi+1]) x [Ry[pj], Ry[pj+1])
  int nnx = 0, nny = 0;            // nodes of the whole grid
  int gx0 = 0, gy0 = 0, gnx = 0, gny = 0;  // window: nodes [gx0, gx0 + gnx) x [gy0, gy0 + gny)
  DM da = nullptr;
  std::vector<long> leaves;        // window nodes owned by others (window indices)
  std::vector<long> roots;         // own nodes the neighbours hold copies of (window indices)
  std::vector<int> nbrs;           // neighbour ranks, ascending
  std::map<int, PetscSF> sf;       // star forest for n fields at once
  std::vector<PetscSFNode> remote; // each leaf's owner and place in its root list
  std::vector<double> leaf, root;
  long sent = 0, received = 0;
  Traffic t;

  // Nodes of rank part p along an axis with cuts C and `nodes` nodes: [C[p], C[p + 1]), the
  // last part also the grid's last node.
  static int node_end(const std::vector<int>& C, int p, int nodes) {
    return p == static_cast<int>(C.size()) - 2 ? nodes : C[p + 1];
  }
  int owner_of_node(int i, int j) const {
    return std::min(part_of(Ry, j), n - 1) * m + std::min(part_of(Cx, i), m - 1);
  }
  // Own nodes of rank o the neighbours hold: within w of a side it shares, row by row.
  struct Band {
    int x0, x1, y0, y1;  // own nodes [x0, x1) x [y0, y1)
    int L, Rt, B, T;     // band widths on each side (0 where no neighbour)
    std::vector<long> before;  // band nodes in rows before row y0 + r
    bool full(int j) const { return j < y0 + B || j >= y1 - T; }
    int mid() const { return std::min(x1 - x0, L + Rt); }
    bool in(int i, int j) const { return full(j) || i < x0 + L || i >= x1 - Rt; }
    long index(int i, int j) const {  // position among the band's nodes, row-major
      const long base = before[j - y0];
      if (full(j)) return base + (i - x0);
      // The band columns before i: the left band's, then the right band's past the left one.
      return base + std::min(i - x0, L) + std::max(0, i - std::max(x0 + L, x1 - Rt));
    }
  };
  Band band(int o) const {
    const int a = o % m, b = o / m;
    Band B{Cx[a], node_end(Cx, a, nnx), Ry[b], node_end(Ry, b, nny),
           a > 0 ? w : 0, a < m - 1 ? w : 0, b > 0 ? w : 0, b < n - 1 ? w : 0, {}};
    B.before.assign(B.y1 - B.y0 + 1, 0);
    for (int j = B.y0; j < B.y1; ++j)
      B.before[j - B.y0 + 1] = B.before[j - B.y0] + (B.full(j) ? B.x1 - B.x0 : B.mid());
    return B;
  }

  // Leaf (f, l) -> root (owner, f * its band size + the node's place in its band).
  PetscSF forest(int nf) {
    auto it = sf.find(nf);
    if (it != sf.end()) return it->second;
    const PetscInt nl = static_cast<PetscInt>(leaves.size());
    const PetscInt nr = static_cast<PetscInt>(roots.size());
    std::map<int, PetscInt> band_size;
    for (int o : nbrs) band_size[o] = band(o).before.back();
    std::vector<PetscSFNode> r(static_cast<std::size_t>(nl) * nf);
    for (int f = 0; f < nf; ++f)
      for (PetscInt l = 0; l < nl; ++l) {
        r[f * nl + l].rank = remote[l].rank;
        r[f * nl + l].index = f * band_size[static_cast<int>(remote[l].rank)] + remote[l].index;
      }
    PetscSF s;
    check(PetscSFCreate(comm, &s), "PetscSFCreate");
    check(PetscSFSetGraph(s, nr * nf, nl * nf, nullptr, PETSC_COPY_VALUES, r.data(),
                          PETSC_COPY_VALUES),
          "PetscSFSetGraph");
    check(PetscSFSetUp(s), "PetscSFSetUp");
    sf[nf] = s;
    return s;
  }
};

namespace {

constexpr int kScatterTag = 7304;

// Rank 0 sends `v` to `to`, which receives it (its length first, then pieces of at most 2^30).
void send_doubles(const std::vector<double>& v, int to, MPI_Comm comm) {
  unsigned long long n = v.size();
  MPI_Send(&n, 1, MPI_UNSIGNED_LONG_LONG, to, kScatterTag, comm);
  for (unsigned long long at = 0; at < n;) {
    const int piece = static_cast<int>(std::min<unsigned long long>(n - at, 1ull << 30));
    MPI_Send(v.data() + at, piece, MPI_DOUBLE, to, kScatterTag, comm);
    at += static_cast<unsigned long long>(piece);
  }
}
std::vector<double> receive_doubles(int from, MPI_Comm comm) {
  unsigned long long n = 0;
  MPI_Recv(&n, 1, MPI_UNSIGNED_LONG_LONG, from, kScatterTag, comm, MPI_STATUS_IGNORE);
  std::vector<double> v(n);
  for (unsigned long long at = 0; at < n;) {
    const int piece = static_cast<int>(std::min<unsigned long long>(n - at, 1ull << 30));
    MPI_Recv(v.data() + at, piece, MPI_DOUBLE, from, kScatterTag, comm, MPI_STATUS_IGNORE);
    at += static_cast<unsigned long long>(piece);
  }
  return v;
}

}  // namespace

Distributed::Distributed(Solver& s, MPI_Comm comm, int across, bool scatter)
    : d_(std::make_unique<Impl>()) {
  Impl& d = *d_;
  // (The symmetric form's probes read the corrected nodal velocity of one window.)
  if (s.symmetric_correction())
    throw std::runtime_error("scheme.mass_correction_form \"symmetric\" runs on one process; "
                             "run without mpirun, or use \"increment\"");
  // (A light node and the nodes its extension reads may lie in two windows.)
  if (s.opt.light_node_ratio > 0)
    throw std::runtime_error("scheme.light_nodes \"extend\" runs on one process; "
                             "run without mpirun, or use \"keep\"");
  d.comm = comm;
  MPI_Comm_rank(comm, &d.rank);
  MPI_Comm_size(comm, &d.size);
  const Grid& g = s.grid;
  const int P = d.size;
  d.nnx = g.nnx;
  d.nny = g.nny;
  // The window must hold every node a particle of the block writes: its stencil, and a
  // boundary anchor up to a cell away.
  d.w = s.opt.shape == ShapeKind::Bilinear ? 2 : 3;
  d.m = across > 0 ? across : blocks_across(P, g.nx, g.ny);
  if (P % d.m)
    throw std::runtime_error(std::to_string(P) + " MPI ranks cannot form blocks " +
                             std::to_string(d.m) + " ranks across");
  d.n = P / d.m;
  if (g.nx < d.w * d.m || g.ny < d.w * d.n)
    throw std::runtime_error(std::to_string(P) + " MPI ranks (" + std::to_string(d.m) + " x " +
                             std::to_string(d.n) + ") need a grid of at least " +
                             std::to_string(d.w * d.m) + " x " + std::to_string(d.w * d.n) +
                             " cells (" + std::to_string(d.w) + " per rank each way, the halo's "
                             "width); this one has " + std::to_string(g.nx) + " x " +
                             std::to_string(g.ny));
  d.pi = d.rank % d.m;
  d.pj = d.rank / d.m;
  // Cost per cell column and row: particles, the film's J2-softening ones counting 5 (their
  // update costs about five elastic ones).
  std::vector<double> cx(g.nx, 0.0), cy(g.ny, 0.0);
  auto cell = [&](std::size_t k, int& ci, int& cj) {
    ci = std::clamp(static_cast<int>(std::floor((s.p.x[k] - g.x0) * g.inv_h)), 0, g.nx - 1);
    cj = std::clamp(static_cast<int>(std::floor((s.p.y[k] - g.y0) * g.inv_h)), 0, g.ny - 1);
  };
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    int ci, cj;
    cell(k, ci, cj);
    const double c = s.materials[s.p.group[k]].model == Model::J2Film ? 5.0 : 1.0;
    cx[ci] += c;
    cy[cj] += c;
  }
  if (scatter) {  // rank 0 holds the body: its costs, its grid's constraints and body scalars
    broadcast_all(cx, MPI_DOUBLE, comm);
    broadcast_all(cy, MPI_DOUBLE, comm);
    broadcast_all(s.grid.fix, MPI_UNSIGNED_CHAR, comm);
    std::array<double, 4> b = s.body_scalars();
    MPI_Bcast(b.data(), 4, MPI_DOUBLE, 0, comm);
    s.set_body_scalars(b);
    if (s.contact.multi()) {  // the material groups split by body (the particles carry them)
      std::vector<int> layout;
      if (d.rank == 0) layout = s.contact.split_layout();
      broadcast_all(layout, MPI_INT, comm);
      if (d.rank != 0) s.contact.adopt_split(s, layout);
    }
  }
  d.Cx = cuts(cx, d.m, d.w);
  d.Ry = cuts(cy, d.n, d.w);
  // The DMDA of the nodes, its ownership the blocks' cells (the last block of a row or column
  // also the grid's last node).
  std::vector<PetscInt> lx(d.m), ly(d.n);
  for (int a = 0; a < d.m; ++a) lx[a] = Impl::node_end(d.Cx, a, d.nnx) - d.Cx[a];
  for (int b = 0; b < d.n; ++b) ly[b] = Impl::node_end(d.Ry, b, d.nny) - d.Ry[b];
  check(DMDACreate2d(comm, DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, DMDA_STENCIL_BOX, d.nnx, d.nny,
                     d.m, d.n, 1, d.w, lx.data(), ly.data(), &d.da),
        "DMDACreate2d");
  check(DMSetUp(d.da), "DMSetUp");
  PetscInt xs, ys, xm, ym, gxs, gys, gxm, gym;
  check(DMDAGetCorners(d.da, &xs, &ys, nullptr, &xm, &ym, nullptr), "DMDAGetCorners");
  check(DMDAGetGhostCorners(d.da, &gxs, &gys, nullptr, &gxm, &gym, nullptr), "DMDAGetGhostCorners");
  if (xs != d.Cx[d.pi] || xm != lx[d.pi] || ys != d.Ry[d.pj] || ym != ly[d.pj])
    throw std::logic_error("DMDA ownership differs from the blocks");
  d.gx0 = static_cast<int>(gxs);
  d.gy0 = static_cast<int>(gys);
  d.gnx = static_cast<int>(gxm);
  d.gny = static_cast<int>(gym);
  // Neighbours: the ranks whose nodes the window holds (sides and corners).
  for (int b = std::max(0, d.pj - 1); b <= std::min(d.n - 1, d.pj + 1); ++b)
    for (int a = std::max(0, d.pi - 1); a <= std::min(d.m - 1, d.pi + 1); ++a)
      if (b * d.m + a != d.rank) d.nbrs.push_back(b * d.m + a);
  const int nn = static_cast<int>(d.nbrs.size());
  MPI_Dist_graph_create_adjacent(comm, nn, d.nbrs.data(), MPI_UNWEIGHTED, nn, d.nbrs.data(),
                                 MPI_UNWEIGHTED, MPI_INFO_NULL, 0, &d.graph);
  // Leaves (row-major over the window) and this rank's roots (its band, row-major).
  std::map<int, Impl::Band> bands;
  for (int o : d.nbrs) bands.emplace(o, d.band(o));
  for (int j = d.gy0; j < d.gy0 + d.gny; ++j)
    for (int i = d.gx0; i < d.gx0 + d.gnx; ++i) {
      const int o = d.owner_of_node(i, j);
      if (o == d.rank) continue;
      const Impl::Band& B = bands.at(o);
      if (!B.in(i, j)) throw std::logic_error("halo: a window node outside its owner's band");
      d.leaves.push_back(static_cast<long>(j - d.gy0) * d.gnx + (i - d.gx0));
      d.remote.push_back({o, static_cast<PetscInt>(B.index(i, j))});
    }
  {
    const Impl::Band B = d.band(d.rank);
    for (int j = B.y0; j < B.y1; ++j)
      for (int i = B.x0; i < B.x1; ++i)
        if (B.in(i, j)) d.roots.push_back(static_cast<long>(j - d.gy0) * d.gnx + (i - d.gx0));
  }

  // This rank's particles (by the whole grid's cells), then its window of the grid.
  const bool dashpots = [&] {
    for (const auto& sl : s.silents)
      if (sl.form == SilentForm::Nodal) return true;
    return !s.dampers.empty() || !s.pml_bands.empty();
  }();
  auto owner = [&](std::size_t k) {
    int ci, cj;
    cell(k, ci, cj);
    return std::clamp(part_of(d.Ry, cj), 0, d.n - 1) * d.m + std::clamp(part_of(d.Cx, ci), 0, d.m - 1);
  };
  std::vector<int> rank_of(s.p.size());
  for (std::size_t k = 0; k < s.p.size(); ++k) rank_of[k] = owner(k);
  if (scatter && d.rank == 0) {  // every other rank's particles, with their layer entries
    // Grouped by owner (stably: each rank receives them in the whole case's order), so that
    // each rank's share is one range: one pass to pack it, one to keep rank 0's at the end.
    const std::vector<std::size_t> start = s.group_by_rank(rank_of, P);
    for (int r = 1; r < P; ++r) {
      std::vector<double> out;
      s.export_range(start[r], start[r + 1], out);
      send_doubles(out, r, comm);
    }
  } else if (scatter) {
    s.import_particles(receive_doubles(0, comm));
    rank_of.assign(s.p.size(), d.rank);  // what rank 0 sent is this rank's
  }
  std::vector<std::uint8_t> keep(s.p.size(), 0);
  for (std::size_t k = 0; k < s.p.size(); ++k) keep[k] = rank_of[k] == d.rank;
  Grid win;
  win.init(g.x0 + d.gx0 * g.h, g.y0 + d.gy0 * g.h, g.h, d.gnx - 1, d.gny - 1);
  for (int j = 0; j < d.gny; ++j)
    std::copy_n(g.fix.begin() + static_cast<long>(d.gy0 + j) * d.nnx + d.gx0, d.gnx,
                win.fix.begin() + static_cast<long>(j) * d.gnx);
  s.grid = std::move(win);
  if (s.contact.multi()) s.contact.resize(s);  // the bodies' fields over the window
  s.keep_particles(keep);
  const NodeBox own{static_cast<int>(xs - gxs), static_cast<int>(xs + xm - 1 - gxs),
                    static_cast<int>(ys - gys), static_cast<int>(ys + ym - 1 - gys)};
  s.set_decomposition(this, own, d.w, dashpots);
}

Distributed::~Distributed() = default;

int Distributed::rank() const { return d_->rank; }
int Distributed::size() const { return d_->size; }
int Distributed::across() const { return d_->m; }
const std::vector<int>& Distributed::rows() const { return d_->Ry; }
const std::vector<int>& Distributed::columns() const { return d_->Cx; }
int Distributed::halo_width() const { return d_->w; }
int Distributed::window_row0() const { return d_->gy0; }
int Distributed::window_column0() const { return d_->gx0; }
long Distributed::sent() const { return d_->sent; }
long Distributed::received() const { return d_->received; }

// Ghost nodes' partial sums go to their owners and are added there (the owner's value first);
// the sums come back to every copy.
void Distributed::sum_halo(double* const* fields, int nf, const int* strides) {
  Impl& d = *d_;
  if (d.size == 1 || nf == 0) return;
  const double t0 = MPI_Wtime();
  PetscSF sf = d.forest(nf);
  const std::size_t nl = d.leaves.size(), nr = d.roots.size();
  d.leaf.resize(nl * nf);
  d.root.resize(nr * nf);
  for (int f = 0; f < nf; ++f) {
    const double* v = fields[f];
    const std::size_t st = strides ? static_cast<std::size_t>(strides[f]) : 1;
    double* lb = d.leaf.data() + f * nl;
    double* rb = d.root.data() + f * nr;
    for (std::size_t q = 0; q < nl; ++q) lb[q] = v[st * d.leaves[q]];
    for (std::size_t q = 0; q < nr; ++q) rb[q] = v[st * d.roots[q]];
  }
  check(PetscSFReduceBegin(sf, MPI_DOUBLE, d.leaf.data(), d.root.data(), MPI_SUM), "PetscSFReduce");
  check(PetscSFReduceEnd(sf, MPI_DOUBLE, d.leaf.data(), d.root.data(), MPI_SUM), "PetscSFReduce");
  check(PetscSFBcastBegin(sf, MPI_DOUBLE, d.root.data(), d.leaf.data(), MPI_REPLACE), "PetscSFBcast");
  check(PetscSFBcastEnd(sf, MPI_DOUBLE, d.root.data(), d.leaf.data(), MPI_REPLACE), "PetscSFBcast");
  for (int f = 0; f < nf; ++f) {
    double* v = fields[f];
    const std::size_t st = strides ? static_cast<std::size_t>(strides[f]) : 1;
    const double* lb = d.leaf.data() + f * nl;
    const double* rb = d.root.data() + f * nr;
    for (std::size_t q = 0; q < nr; ++q) v[st * d.roots[q]] = rb[q];
    for (std::size_t q = 0; q < nl; ++q) v[st * d.leaves[q]] = lb[q];
  }
  d.t.halo_seconds += MPI_Wtime() - t0;
  d.t.halo_bytes += static_cast<double>((nl + nr) * nf * sizeof(double));  // leaves out, roots back
}

// After the step's last move: a particle whose cell (in the window's numbering, as the solver
// sorts it) left the block goes to the rank that owns it, a neighbour (a particle moves less
// than a cell per step, and a block is at least the halo's width each way).
bool Distributed::migrate(Solver& s) {
  Impl& d = *d_;
  if (d.size == 1) return false;
  const double t0 = MPI_Wtime();
  const int c0 = d.Cx[d.pi] - d.gx0, c1 = d.Cx[d.pi + 1] - d.gx0;  // own cells, window numbering
  const int r0 = d.Ry[d.pj] - d.gy0, r1 = d.Ry[d.pj + 1] - d.gy0;
  const int nn = static_cast<int>(d.nbrs.size());
  std::vector<int> to(s.p.size(), -1);
  bool leaving = false;
  // Slabs: the rows the step's moving pass saw tell whether any particle left (no pass over
  // the particles then).
  long seen0 = 0, seen1 = -1;
  if (d.m == 1) s.occupied_rows(seen0, seen1);
  const bool stayed = d.m == 1 && (seen0 > seen1 || (seen0 >= r0 && seen1 < r1));
  for (std::size_t k = 0; k < s.p.size() && !stayed; ++k) {
    const int r = s.cell_row(k), c = s.cell_column(k);
    if (r >= r0 && r < r1 && c >= c0 && c < c1) continue;
    const int a = std::clamp(part_of(d.Cx, c + d.gx0), 0, d.m - 1);
    const int b = std::clamp(part_of(d.Ry, r + d.gy0), 0, d.n - 1);
    const auto it = std::find(d.nbrs.begin(), d.nbrs.end(), b * d.m + a);
    if (it == d.nbrs.end())
      throw std::runtime_error("particle " + std::to_string(s.p.id[k]) + " left rank " +
                               std::to_string(d.rank) + "'s cells for a rank that is not its " +
                               "neighbour in one step (at (" + std::to_string(s.p.x[k]) + ", " +
                               std::to_string(s.p.y[k]) + "))");
    to[k] = static_cast<int>(it - d.nbrs.begin());
    leaving = true;
  }
  std::vector<std::vector<double>> out(nn);
  if (leaving) s.export_particles(to, out);
  std::vector<int> scount(nn), rcount(nn), sdisp(nn), rdisp(nn);
  std::vector<double> sbuf;
  for (int q = 0; q < nn; ++q) {
    scount[q] = static_cast<int>(out[q].size());
    sdisp[q] = static_cast<int>(sbuf.size());
    sbuf.insert(sbuf.end(), out[q].begin(), out[q].end());
  }
  MPI_Neighbor_alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, d.graph);
  int rtotal = 0;
  for (int q = 0; q < nn; ++q) {
    rdisp[q] = rtotal;
    rtotal += rcount[q];
  }
  std::vector<double> rbuf(rtotal);
  MPI_Neighbor_alltoallv(sbuf.data(), scount.data(), sdisp.data(), MPI_DOUBLE, rbuf.data(),
                         rcount.data(), rdisp.data(), MPI_DOUBLE, d.graph);
  const std::size_t before = s.p.size();
  if (rtotal > 0) s.import_particles(rbuf);
  d.received += static_cast<long>(s.p.size() - before);
  for (int k : to) d.sent += k >= 0;
  d.t.particles_sent = d.sent;
  d.t.migration_bytes += static_cast<double>(sbuf.size() * sizeof(double) + nn * sizeof(int));
  d.t.migration_seconds += MPI_Wtime() - t0;
  return leaving || rtotal > 0;
}

Decomposition::Traffic Distributed::traffic() const { return d_->t; }

std::array<int, 4> Distributed::own_nodes() const {
  const Impl& d = *d_;
  return {d.Cx[d.pi], Impl::node_end(d.Cx, d.pi, d.nnx) - 1, d.Ry[d.pj],
          Impl::node_end(d.Ry, d.pj, d.nny) - 1};
}
std::array<int, 2> Distributed::window_origin() const { return {d_->gx0, d_->gy0}; }


void Distributed::sum(double* v, int n) {
  if (d_->size > 1) MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_SUM, d_->comm);
}
void Distributed::max(double* v, int n) {
  if (d_->size > 1) MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_MAX, d_->comm);
}

}  // namespace smpm
