// Slabs of cell rows over MPI ranks (distributed.hpp; docs/parallel.md).
#include "silentmpm/distributed.hpp"

#include <petscdmda.h>
#include <petscsf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

#include "silentmpm/solver.hpp"

namespace smpm {

namespace {

void check(PetscErrorCode e, const char* what) {
  if (e != 0) throw std::runtime_error(std::string("PETSc: ") + what + " failed (error " +
                                       std::to_string(static_cast<int>(e)) + ")");
}

bool g_started_mpi = false;

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
  MPI_Comm comm = MPI_COMM_NULL;
  MPI_Comm graph = MPI_COMM_NULL;  // the neighbours below and above
  int rank = 0, size = 1;
  int w = 2;                       // halo width (node rows)
  std::vector<int> R;              // cell rows of rank r: [R[r], R[r + 1])
  int nnx = 0, nny = 0;
  int g0 = 0, gn = 0;              // window: node rows [g0, g0 + gn)
  int o0 = 0, on = 0;              // own node rows [o0, o0 + on)
  DM da = nullptr;
  std::vector<int> ghost_rows;     // window rows owned by the neighbours (whole-grid numbering)
  std::vector<int> band_rows;      // own rows the neighbours hold copies of
  std::vector<int> nbrs;           // neighbour ranks (below first)
  std::map<int, PetscSF> sf;       // star forest for n fields at once
  std::vector<double> leaf, root;
  long sent = 0, received = 0;
  Traffic t;

  // Node rows of rank o: [R[o], R[o + 1]), the last rank also the grid's top row.
  int own_begin(int o) const { return R[o]; }
  int own_end(int o) const { return o == size - 1 ? nny : R[o + 1]; }
  std::vector<int> band_of(int o) const {
    std::vector<int> b;
    for (int j = own_begin(o); j < own_end(o); ++j)
      if ((o > 0 && j < own_begin(o) + w) || (o < size - 1 && j >= own_end(o) - w)) b.push_back(j);
    return b;
  }
  int owner_of_row(int j) const {
    for (int o = 0; o < size; ++o)
      if (j >= own_begin(o) && j < own_end(o)) return o;
    return -1;
  }

  // Leaf (f, ghost node l) -> root (owner, f * its band size + place of the node in its band).
  PetscSF forest(int n) {
    auto it = sf.find(n);
    if (it != sf.end()) return it->second;
    const PetscInt nl = static_cast<PetscInt>(ghost_rows.size()) * nnx;
    const PetscInt nr = static_cast<PetscInt>(band_rows.size()) * nnx;
    std::vector<std::vector<int>> bands(size);
    for (int o = 0; o < size; ++o) bands[o] = band_of(o);
    std::vector<PetscSFNode> remote(static_cast<std::size_t>(nl) * n);
    for (int f = 0; f < n; ++f)
      for (std::size_t r = 0; r < ghost_rows.size(); ++r) {
        const int j = ghost_rows[r], o = owner_of_row(j);
        const auto& b = bands[o];
        const auto pos = std::find(b.begin(), b.end(), j) - b.begin();
        if (pos == static_cast<long>(b.size()))
          throw std::logic_error("halo: a ghost row is not in its owner's band");
        const PetscInt band_n = static_cast<PetscInt>(b.size()) * nnx;
        for (int i = 0; i < nnx; ++i) {
          PetscSFNode& s = remote[f * nl + r * nnx + i];
          s.rank = o;
          s.index = f * band_n + pos * nnx + i;
        }
      }
    PetscSF s;
    check(PetscSFCreate(comm, &s), "PetscSFCreate");
    check(PetscSFSetGraph(s, nr * n, nl * n, nullptr, PETSC_COPY_VALUES, remote.data(),
                          PETSC_COPY_VALUES),
          "PetscSFSetGraph");
    check(PetscSFSetUp(s), "PetscSFSetUp");
    sf[n] = s;
    return s;
  }
};

Distributed::Distributed(Solver& s, MPI_Comm comm) : d_(std::make_unique<Impl>()) {
  Impl& d = *d_;
  d.comm = comm;
  MPI_Comm_rank(comm, &d.rank);
  MPI_Comm_size(comm, &d.size);
  if (s.contact.multi())
    throw std::runtime_error("multi-field contact does not run on several MPI ranks yet");
  const Grid& g = s.grid;
  const int P = d.size, ny = g.ny;
  d.nnx = g.nnx;
  d.nny = g.nny;
  // The window must hold every node a particle of the slab writes: its stencil, and a boundary
  // anchor up to a cell away.
  d.w = s.opt.shape == ShapeKind::Bilinear ? 2 : 3;
  if (ny < d.w * P)
    throw std::runtime_error(std::to_string(P) + " MPI ranks need a grid of at least " +
                             std::to_string(d.w * P) + " cell rows (" + std::to_string(d.w) +
                             " per rank, the halo's width); this one has " + std::to_string(ny));
  // Cost per cell row: particles, the film's J2-softening ones counting 5 (their update costs
  // about five elastic ones).
  std::vector<double> cost(ny, 0.0);
  double total = 0;
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    const int r = std::clamp(static_cast<int>(std::floor((s.p.y[k] - g.y0) * g.inv_h)), 0, ny - 1);
    const double c = s.materials[s.p.group[k]].model == Model::J2Film ? 5.0 : 1.0;
    cost[r] += c;
    total += c;
  }
  d.R.assign(P + 1, 0);
  d.R[P] = ny;
  {
    double acc = 0;
    int r = 0;
    for (int o = 1; o < P; ++o) {
      const double target = total * o / P;
      while (r < ny && acc + 0.5 * cost[r] < target) acc += cost[r++];
      d.R[o] = r;
    }
    for (int o = 1; o < P; ++o) d.R[o] = std::max(d.R[o], d.R[o - 1] + d.w);
    for (int o = P - 1; o >= 1; --o) d.R[o] = std::min(d.R[o], d.R[o + 1] - d.w);
  }
  // The DMDA of the nodes: one column of ranks, each owning the node rows of its slab's cells.
  std::vector<PetscInt> ly(P);
  for (int o = 0; o < P; ++o) ly[o] = d.own_end(o) - d.own_begin(o);
  check(DMDACreate2d(comm, DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, DMDA_STENCIL_BOX, d.nnx, d.nny, 1,
                     P, 1, d.w, nullptr, ly.data(), &d.da),
        "DMDACreate2d");
  check(DMSetUp(d.da), "DMSetUp");
  PetscInt xs, ys, xm, ym, gxs, gys, gxm, gym;
  check(DMDAGetCorners(d.da, &xs, &ys, nullptr, &xm, &ym, nullptr), "DMDAGetCorners");
  check(DMDAGetGhostCorners(d.da, &gxs, &gys, nullptr, &gxm, &gym, nullptr), "DMDAGetGhostCorners");
  if (xs != 0 || xm != d.nnx || ys != d.own_begin(d.rank) || ym != ly[d.rank])
    throw std::logic_error("DMDA ownership differs from the slabs");
  d.o0 = static_cast<int>(ys);
  d.on = static_cast<int>(ym);
  d.g0 = static_cast<int>(gys);
  d.gn = static_cast<int>(gym);
  for (int j = d.g0; j < d.g0 + d.gn; ++j)
    if (j < d.o0 || j >= d.o0 + d.on) d.ghost_rows.push_back(j);
  d.band_rows = d.band_of(d.rank);
  if (d.rank > 0) d.nbrs.push_back(d.rank - 1);
  if (d.rank < P - 1) d.nbrs.push_back(d.rank + 1);
  const int nn = static_cast<int>(d.nbrs.size());
  MPI_Dist_graph_create_adjacent(comm, nn, d.nbrs.data(), MPI_UNWEIGHTED, nn, d.nbrs.data(),
                                 MPI_UNWEIGHTED, MPI_INFO_NULL, 0, &d.graph);

  // This rank's particles (by the whole grid's rows), then its window of the grid.
  const bool dashpots = [&] {
    for (const auto& sl : s.silents)
      if (sl.form == SilentForm::Nodal) return true;
    return !s.dampers.empty() || !s.pml_bands.empty();
  }();
  std::vector<std::uint8_t> keep(s.p.size(), 0);
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    const int r = std::clamp(static_cast<int>(std::floor((s.p.y[k] - g.y0) * g.inv_h)), 0, ny - 1);
    keep[k] = r >= d.R[d.rank] && r < d.R[d.rank + 1];
  }
  Grid w;
  w.init(g.x0, g.y0 + d.g0 * g.h, g.h, g.nx, d.gn - 1);
  std::copy(g.fix.begin() + static_cast<long>(d.g0) * d.nnx,
            g.fix.begin() + static_cast<long>(d.g0 + d.gn) * d.nnx, w.fix.begin());
  s.grid = std::move(w);
  s.keep_particles(keep);
  s.set_decomposition(this, d.o0 - d.g0, d.o0 + d.on - 1 - d.g0, dashpots);
}

Distributed::~Distributed() {
  for (auto& [n, s] : d_->sf) PetscSFDestroy(&s);
  if (d_->da) DMDestroy(&d_->da);
  if (d_->graph != MPI_COMM_NULL) MPI_Comm_free(&d_->graph);
}

int Distributed::rank() const { return d_->rank; }
int Distributed::size() const { return d_->size; }
const std::vector<int>& Distributed::rows() const { return d_->R; }
int Distributed::halo_width() const { return d_->w; }
int Distributed::window_row0() const { return d_->g0; }
long Distributed::sent() const { return d_->sent; }
long Distributed::received() const { return d_->received; }

// Ghost rows' partial sums go to their owners and are added there (the owner's value first);
// the sums come back to every copy.
void Distributed::sum_halo(double* const* fields, int n) {
  Impl& d = *d_;
  if (d.size == 1 || n == 0) return;
  const double t0 = MPI_Wtime();
  PetscSF sf = d.forest(n);
  const std::size_t nl = d.ghost_rows.size() * d.nnx, nr = d.band_rows.size() * d.nnx;
  d.leaf.resize(nl * n);
  d.root.resize(nr * n);
  auto rows = [&](const std::vector<int>& list, double* buf, std::size_t len, bool to_buf) {
    for (int f = 0; f < n; ++f)
      for (std::size_t r = 0; r < list.size(); ++r) {
        double* field = fields[f] + static_cast<std::size_t>(list[r] - d.g0) * d.nnx;
        double* b = buf + f * len + r * d.nnx;
        if (to_buf) std::memcpy(b, field, d.nnx * sizeof(double));
        else std::memcpy(field, b, d.nnx * sizeof(double));
      }
  };
  rows(d.ghost_rows, d.leaf.data(), nl, true);
  rows(d.band_rows, d.root.data(), nr, true);
  check(PetscSFReduceBegin(sf, MPI_DOUBLE, d.leaf.data(), d.root.data(), MPI_SUM), "PetscSFReduce");
  check(PetscSFReduceEnd(sf, MPI_DOUBLE, d.leaf.data(), d.root.data(), MPI_SUM), "PetscSFReduce");
  check(PetscSFBcastBegin(sf, MPI_DOUBLE, d.root.data(), d.leaf.data(), MPI_REPLACE), "PetscSFBcast");
  check(PetscSFBcastEnd(sf, MPI_DOUBLE, d.root.data(), d.leaf.data(), MPI_REPLACE), "PetscSFBcast");
  rows(d.band_rows, d.root.data(), nr, false);
  rows(d.ghost_rows, d.leaf.data(), nl, false);
  d.t.halo_seconds += MPI_Wtime() - t0;
  d.t.halo_bytes += static_cast<double>((nl + nr) * n * sizeof(double));  // leaves out, roots back
}

// After the step's last move: a particle whose cell row (in the window's numbering, as the
// solver sorts it) left the slab goes to the neighbour on that side (a particle moves less than
// a cell per step, and a slab has at least the halo's width of rows).
bool Distributed::migrate(Solver& s) {
  Impl& d = *d_;
  if (d.size == 1) return false;
  const double t0 = MPI_Wtime();
  const int lo = d.R[d.rank] - d.g0, hi = d.R[d.rank + 1] - d.g0;  // own cell rows [lo, hi)
  const int below = d.rank > 0 ? 0 : -1;
  const int above = d.rank < d.size - 1 ? static_cast<int>(d.nbrs.size()) - 1 : -1;
  std::vector<int> to(s.p.size(), -1);
  bool leaving = false;
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    const int r = s.cell_row(k);
    if (r >= lo && r < hi) continue;
    const int slot = r < lo ? below : above;
    if (slot < 0 || r < lo - d.w || r >= hi + d.w)
      throw std::runtime_error("particle " + std::to_string(s.p.id[k]) +
                               " left rank " + std::to_string(d.rank) + "'s rows by more than " +
                               "the halo in one step (at y = " + std::to_string(s.p.y[k]) + ")");
    to[k] = slot;
    leaving = true;
  }
  const int nn = static_cast<int>(d.nbrs.size());
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

void Distributed::sum(double* v, int n) {
  if (d_->size > 1) MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_SUM, d_->comm);
}
void Distributed::max(double* v, int n) {
  if (d_->size > 1) MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_MAX, d_->comm);
}
bool Distributed::any(bool b) {
  int v = b ? 1 : 0;
  if (d_->size > 1) MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT, MPI_LOR, d_->comm);
  return v != 0;
}

}  // namespace smpm
