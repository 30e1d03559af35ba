// The far field's snapshots (Solver::write_snapshot and the writer's bookkeeping): fem.h5 and
// fem.xdmf through MeshSnapshotWriter, without deal.II. On several ranks a local model
// (docs/parallel.md, "The FE far field") writes the one file from every rank at once: each rank
// computes its own nodes' fields (and, once, its nodes' positions and its part's cells), sends
// each row to the rank that writes it (rank r writes the r-th of P equal runs of rows), and
// every rank writes its run. The file is the one a single process writes.
#include <mpi.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <climits>
#include <new>
#include <cstdio>
#include <string>
#include <vector>

#include "fem_impl.hpp"
#include "silentmpm/material.hpp"

namespace smpm::fem {

namespace {

// A Q1 cell as it is, a Q2 cell as the four quadrilaterals of its nine nodes (counter-clockwise;
// the base element's nodes: vertices (0,0) (1,0) (0,1) (1,1), then the lines x = 0, x = 1,
// y = 0, y = 1, then the centre).
constexpr int kQ1[1][4] = {{0, 1, 3, 2}};
constexpr int kQ2[4][4] = {{0, 6, 8, 4}, {6, 1, 5, 8}, {4, 8, 7, 2}, {8, 5, 3, 7}};

int sub_quads(const Solver::Impl& m) { return m.degree == 1 ? 1 : 4; }
const int (*sub_quad_nodes(const Solver::Impl& m))[4] { return m.degree == 1 ? kQ1 : kQ2; }

// The snapshots' mesh of a model that holds the whole mesh: its nodes, every cell's quadrilaterals
// and their material.
void snapshot_mesh(const Solver::Impl& m, std::vector<double>& xyz,
                   std::vector<std::int64_t>& cells, std::vector<std::int32_t>& material) {
  const std::size_t nn = m.x.size();
  xyz.assign(3 * nn, 0.0);
  for (std::size_t i = 0; i < nn; ++i) {
    xyz[3 * i] = m.x[i];
    xyz[3 * i + 1] = m.y[i];
  }
  const int nb = (m.degree + 1) * (m.degree + 1), parts = sub_quads(m);
  const int(*sub)[4] = sub_quad_nodes(m);
  cells.clear();
  material.clear();
  for (std::size_t c = 0; c < m.n_cells; ++c) {
    const std::uint32_t* cn = m.cell_nodes.data() + c * nb;
    for (int s = 0; s < parts; ++s) {
      for (int a = 0; a < 4; ++a) cells.push_back(cn[sub[s][a]]);
      material.push_back(m.cell_region[c]);
    }
  }
}

// The node fields of m (16 values a node: displacement and velocity as 3-vectors, the stress as
// a 3 x 3 tensor, J2): the stress and J2 at a node are the mean of what the cells m holds give
// there (their displacement gradients at the node through the cell's bilinear map, from
// Impl::ref_grad and map_grad), summed in m's cell order. A local model holds every cell around
// each of its own nodes, in the mesh's order: its own nodes' fields are one process's to the bit.
// The rows of the nodes `which` (null: every node of m, n of them), in that order.
constexpr std::size_t kWidth = 16;
std::vector<double> node_fields(const Solver::Impl& m, const std::uint32_t* which, std::size_t n) {
  const std::size_t nn = m.x.size();
  const auto node = [&](std::size_t r) { return which ? which[r] : r; };
  std::vector<double> out(kWidth * n, 0.0);
  for (std::size_t r = 0; r < n; ++r)
    for (int k = 0; k < 2; ++k) {
      out[kWidth * r + k] = m.u[2 * node(r) + k];
      out[kWidth * r + 3 + k] = m.v[2 * node(r) + k];
    }
  const std::size_t nb = static_cast<std::size_t>((m.degree + 1) * (m.degree + 1));
  const std::size_t ncell = m.cell_nodes.size() / nb;
  std::vector<double> acc(4 * nn, 0.0);
  std::vector<std::uint32_t> count(nn, 0);
  for (std::size_t c = 0; c < ncell; ++c) {
    const std::uint32_t* cn = m.cell_nodes.data() + c * nb;
    const Material& mat = m.spec.materials[m.spec.region_material.at(m.cell_region[c])];
    for (std::size_t a = 0; a < nb; ++a) {
      // J = dx/dxi at node a, from the cell's four vertices (its first four nodes).
      double J[2][2] = {{0, 0}, {0, 0}};
      for (std::size_t v = 0; v < 4; ++v) {
        const double* h = m.map_grad.data() + 2 * (4 * a + v);
        for (int j = 0; j < 2; ++j) {
          J[0][j] += m.x[cn[v]] * h[j];
          J[1][j] += m.y[cn[v]] * h[j];
        }
      }
      const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
      const double inv[2][2] = {{J[1][1] / det, -J[0][1] / det}, {-J[1][0] / det, J[0][0] / det}};
      double g[2][2] = {{0, 0}, {0, 0}};  // du_k/dx_i
      for (std::size_t b = 0; b < nb; ++b) {
        const double* r = m.ref_grad.data() + 2 * (a * nb + b);
        const double dx = inv[0][0] * r[0] + inv[1][0] * r[1];
        const double dy = inv[0][1] * r[0] + inv[1][1] * r[1];
        for (int k = 0; k < 2; ++k) {
          g[k][0] += m.u[2 * cn[b] + k] * dx;
          g[k][1] += m.u[2 * cn[b] + k] * dy;
        }
      }
      const std::uint32_t i = cn[a];
      const double exx = g[0][0], eyy = g[1][1], gxy = g[0][1] + g[1][0];
      const double tr = exx + eyy;
      acc[4 * i] += mat.lambda * tr + 2 * mat.mu * exx;
      acc[4 * i + 1] += mat.lambda * tr + 2 * mat.mu * eyy;
      acc[4 * i + 2] += mat.lambda * tr;
      acc[4 * i + 3] += mat.mu * gxy;
      ++count[i];
    }
  }
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = node(r);
    if (count[i] == 0) continue;
    const double w = 1.0 / count[i];
    const double sxx = acc[4 * i] * w, syy = acc[4 * i + 1] * w, szz = acc[4 * i + 2] * w,
                 sxy = acc[4 * i + 3] * w;
    double* S = out.data() + kWidth * r + 6;
    S[0] = sxx;
    S[1] = S[3] = sxy;
    S[4] = syy;
    S[8] = szz;
    out[kWidth * r + 15] = j2_of(sxx, syy, szz, sxy);
  }
  return out;
}

// The four fields of n nodes, as MeshSnapshotWriter takes them.
struct Fields {
  std::vector<double> disp, vel, sig, j2;
  explicit Fields(std::size_t n) : disp(3 * n), vel(3 * n), sig(9 * n), j2(n) {}
  void set(std::size_t i, const double* r) {  // node i from its row of node_fields
    std::copy_n(r, 3, disp.begin() + 3 * i);
    std::copy_n(r + 3, 3, vel.begin() + 3 * i);
    std::copy_n(r + 6, 9, sig.begin() + 9 * i);
    j2[i] = r[15];
  }
  void write(MeshSnapshotWriter& w, double t) const {
    w.write(t, {{"displacement", 3, "m", disp.data()},
                {"velocity", 3, "m/s", vel.data()},
                {"stress", 9, "Pa", sig.data()},
                {"J2", 1, "Pa^2", j2.data()}});
  }
};

// One process (or rank 0 of the whole model split, which gathered u and v): the whole mesh's.
void write_whole(Solver::Impl& m, const std::string& dir, const std::string& base, double t) {
  if (!m.snap.is_open()) {
    std::vector<double> xyz;
    std::vector<std::int64_t> cells;
    std::vector<std::int32_t> material;
    snapshot_mesh(m, xyz, cells, material);
    m.snap.open(dir, base, xyz, cells, material);
  }
  const std::size_t n = m.x.size();
  const std::vector<double> rows = node_fields(m, nullptr, n);
  Fields f(n);
  for (std::size_t i = 0; i < n; ++i) f.set(i, rows.data() + kWidth * i);
  f.write(m.snap, t);
}

// ---- several ranks, a local model ----------------------------------------------------------------

MPI_Comm g_world = MPI_COMM_WORLD;
MPI_Info g_info = MPI_INFO_NULL;

// The first of rank r's run of rows, of n rows over P ranks.
std::size_t run_first(std::size_t n, int r, int P) {
  const auto R = static_cast<std::size_t>(r), Q = static_cast<std::size_t>(P);
  return n / Q * R + n % Q * R / Q;  // floor(n r / P) without overflow
}

// Rows of `width` values (each with its row number `at`) to the ranks that write them: each row
// of this rank's run (every row of it is some rank's, exactly once) is given to
// place(row within the run, its values). Returns the run's length.
template <class Place>
std::size_t to_runs(const std::vector<std::uint64_t>& at, const std::vector<double>& rows,
                    std::size_t width, std::size_t total, int me, int P, Place&& place) {
  std::vector<std::size_t> first(P + 1);
  for (int r = 0; r <= P; ++r) first[r] = run_first(total, r, P);
  auto dest = [&](std::uint64_t i) {
    return static_cast<int>(std::upper_bound(first.begin(), first.end(), i) - first.begin()) - 1;
  };
  // Every rank takes part in both exchanges; whether any rank's counts overflow an MPI count or
  // its buffers its memory is agreed before the second, so that all stop together.
  std::vector<long long> count(P, 0);
  for (const auto i : at) count[dest(i)] += static_cast<long long>(width + 1);
  std::vector<int> sc(P, 0), sd(P, 0), rc(P, 0), rd(P, 0);
  int bad = 0;
  long long off = 0;
  for (int r = 0; r < P; ++r) {
    if (count[r] > INT_MAX || off + count[r] > INT_MAX) bad = 1;
    if (bad) break;
    sc[r] = static_cast<int>(count[r]);
    sd[r] = static_cast<int>(off);
    off += count[r];
  }
  if (bad) std::fill(sc.begin(), sc.end(), 0);
  std::vector<double> out, got;
  try {
    if (!bad) out.resize(static_cast<std::size_t>(off));
  } catch (const std::bad_alloc&) {
    bad = 1;
  }
  if (!bad) {
    std::vector<long long> put(sd.begin(), sd.end());
    for (std::size_t k = 0; k < at.size(); ++k) {
      double* o = out.data() + put[dest(at[k])];
      o[0] = static_cast<double>(at[k]);  // exact below 2^53
      std::copy_n(rows.begin() + static_cast<std::ptrdiff_t>(width * k), width, o + 1);
      put[dest(at[k])] += static_cast<long long>(width + 1);
    }
  }
  MPI_Alltoall(sc.data(), 1, MPI_INT, rc.data(), 1, MPI_INT, g_world);
  long long in = 0;
  for (int r = 0; r < P && !bad; ++r) {
    rd[r] = static_cast<int>(in);
    in += rc[r];
    if (in > INT_MAX) bad = 1;
  }
  try {
    if (!bad) got.resize(static_cast<std::size_t>(in));
  } catch (const std::bad_alloc&) {
    bad = 1;
  }
  MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT, MPI_MAX, g_world);
  if (bad)
    throw FemError("FEM snapshot: a rank's share of the rows is more than one MPI message holds "
                   "(2^31 - 1 values) or more than its memory holds");
  MPI_Alltoallv(out.data(), sc.data(), sd.data(), MPI_DOUBLE, got.data(), rc.data(), rd.data(),
                MPI_DOUBLE, g_world);
  std::vector<double>().swap(out);
  const std::size_t f0 = first[me];
  for (std::size_t k = 0; k + width + 1 <= got.size(); k += width + 1)
    place(static_cast<std::size_t>(got[k]) - f0, got.data() + k + 1);
  return first[me + 1] - f0;
}

// The same into an array of the run's rows.
std::vector<double> to_runs(const std::vector<std::uint64_t>& at, const std::vector<double>& rows,
                            std::size_t width, std::size_t total, int me, int P) {
  const std::size_t f0 = run_first(total, me, P), n = run_first(total, me + 1, P) - f0;
  std::vector<double> run(width * n, 0.0);
  to_runs(at, rows, width, total, me, P, [&](std::size_t i, const double* v) {
    std::copy_n(v, width, run.begin() + static_cast<std::ptrdiff_t>(width * i));
  });
  return run;
}

// The writer of a local model on several ranks: the whole mesh's node and cell counts, this
// rank's runs of rows. Before the file is opened or resumed.
void set_runs(Solver::Impl& m) {
  if (m.snap_ranks) return;
  const Solver::Impl::Part& P = *m.part;
  const std::size_t N = m.mesh_nodes, C = m.n_cells * static_cast<std::size_t>(sub_quads(m));
  const std::size_t n0 = run_first(N, P.rank, P.size), n1 = run_first(N, P.rank + 1, P.size);
  const std::size_t c0 = run_first(m.n_cells, P.rank, P.size) * sub_quads(m),
                    c1 = run_first(m.n_cells, P.rank + 1, P.size) * sub_quads(m);
  m.snap.set_ranks(&g_world, &g_info, P.rank, N, C, RowBlock{n0, n1 - n0, 1, 0},
                   RowBlock{c0, c1 - c0, 1, 0});
  m.snap_ranks = true;
}

// Every rank of a local model at once: its own nodes' rows (and, once, the mesh: its own nodes'
// positions, its part's cells) to the ranks that write them, then every rank its runs.
void write_local(Solver::Impl& m, const std::string& dir, const std::string& base, double t) {
  const Solver::Impl::Part& P = *m.part;
  set_runs(m);
  const std::vector<std::uint32_t>& own = P.own;
  std::vector<std::uint64_t> at(own.size());
  for (std::size_t k = 0; k < own.size(); ++k) at[k] = m.glob[own[k]];
  if (!m.snap.is_open()) {
    std::vector<double> pos(3 * own.size(), 0.0);
    for (std::size_t k = 0; k < own.size(); ++k) {
      pos[3 * k] = m.x[own[k]];
      pos[3 * k + 1] = m.y[own[k]];
    }
    const std::vector<double> xyz = to_runs(at, pos, 3, m.mesh_nodes, P.rank, P.size);
    // Cells: each of this rank's part, its quadrilaterals' mesh nodes and its material.
    const std::size_t nb = static_cast<std::size_t>((m.degree + 1) * (m.degree + 1));
    const int parts = sub_quads(m);
    const int(*sub)[4] = sub_quad_nodes(m);
    const std::size_t width = static_cast<std::size_t>(parts) * 5;
    std::vector<std::uint64_t> cat;
    std::vector<double> crow;
    for (std::size_t c = 0; c < m.cell_glob.size(); ++c) {
      if (!m.cell_own[c]) continue;
      cat.push_back(m.cell_glob[c]);
      const std::uint32_t* cn = m.cell_nodes.data() + c * nb;
      for (int s = 0; s < parts; ++s) {
        for (int a = 0; a < 4; ++a) crow.push_back(static_cast<double>(m.glob[cn[sub[s][a]]]));
        crow.push_back(static_cast<double>(m.cell_region[c]));
      }
    }
    const std::vector<double> cr = to_runs(cat, crow, width, m.n_cells, P.rank, P.size);
    const std::size_t nq = cr.size() / 5;
    std::vector<std::int64_t> cells(4 * nq);
    std::vector<std::int32_t> material(nq);
    for (std::size_t q = 0; q < nq; ++q) {
      for (int a = 0; a < 4; ++a) cells[4 * q + a] = static_cast<std::int64_t>(cr[5 * q + a]);
      material[q] = static_cast<std::int32_t>(cr[5 * q + 4]);
    }
    m.snap.open(dir, base, xyz, cells, material);
  }
  const std::size_t n = run_first(m.mesh_nodes, P.rank + 1, P.size) - run_first(m.mesh_nodes, P.rank, P.size);
  Fields f(n);
  to_runs(at, node_fields(m, own.data(), own.size()), kWidth, m.mesh_nodes, P.rank, P.size,
          [&](std::size_t i, const double* v) { f.set(i, v); });
  f.write(m.snap, t);
}

}  // namespace

void Solver::write_snapshot(const std::string& dir, const std::string& base) {
  Impl& m = *impl_;
  std::string why;
  if (local_on_ranks(m)) {
    // Every rank writes its runs; a failure on any stops them all.
    try {
      write_local(m, dir, base, t);
    } catch (const std::exception& e) {
      why = dir + ": cannot write the FEM snapshot: " + e.what();
    }
#if defined(__GLIBC__)
    malloc_trim(0);  // the snapshot's buffers (a few times the rank's nodes' fields) go back
#endif
    double failed = why.empty() ? 0.0 : 1.0;
    sum_over_ranks(m, &failed, 1);
    if (failed > 0)
      throw FemError(!why.empty() ? why : dir + ": another rank could not write the FEM snapshot");
  } else if (m.part && m.glob.empty()) {
    // The whole model split: every node's u and v from its owner to rank 0, which writes;
    // whether it could is told to every rank, so that a failure stops them all.
    std::vector<std::vector<double>> all;
    gather_on_root(m, m.part->node_rank, {&m.u, &m.v}, 2, all);
    if (m.part->rank == 0) {
      m.u = std::move(all[0]);  // every node current (its own and received ones as they were)
      m.v = std::move(all[1]);
      try {
        write_whole(m, dir, base, t);
      } catch (const std::exception& e) {
        why = dir + ": cannot write the FEM snapshot: " + e.what();
      }
    }
    double failed = why.empty() ? 0.0 : 1.0;
    sum_over_ranks(m, &failed, 1);
    if (failed > 0)
      throw FemError(m.part->rank == 0 ? why : dir + ": rank 0 could not write the FEM snapshot");
  } else {
    try {
      write_whole(m, dir, base, t);
    } catch (const std::exception& e) {
      throw FemError(dir + ": cannot write the FEM snapshot: " + e.what());
    }
  }
  m.snapshot_times.push_back(t);
  ++m.snapshots;
}

void Solver::set_snapshot_compression(int level) { impl_->snap.set_compression(level); }

void Solver::close_snapshots() {
  try {
    impl_->snap.close();  // a local model's ranks together; elsewhere the writer's alone
  } catch (const std::exception& e) {
    throw FemError(std::string("cannot close the FEM snapshots: ") + e.what());
  }
}

int Solver::resume_snapshots(const std::string& dir, const std::string& base) {
  Impl& m = *impl_;
  const bool local = local_on_ranks(m);
  // Who opens the file: every rank of a local model together, else rank 0 (or one process).
  const bool writer = !m.part || !m.glob.empty() || m.part->rank == 0;
  int found = 0;
  std::string why;
  try {
    if (local) set_runs(m);
    if (writer) found = m.snap.resume(dir, base, m.snapshot_times);
  } catch (const std::exception& e) {
    why = dir + ": cannot reopen the FEM snapshots: " + e.what();
    found = -1;
  }
  if (m.part) {  // every rank takes the same count, or stops
    int f = local || writer ? found : INT_MAX;
    MPI_Allreduce(MPI_IN_PLACE, &f, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    found = f;
  }
  if (found < 0)
    throw FemError(!why.empty() ? why : dir + ": another rank could not reopen the FEM snapshots");
  if (found == 0 && !m.snapshot_times.empty()) {
    // The earlier snapshots are gone: the file starts afresh and the count with it, so that a
    // later checkpoint lists only what the file holds.
    if (!m.part || m.part->rank == 0)
      std::fprintf(stderr, "note: %s/%s.h5 does not hold the %zu FE snapshot(s) written before the "
                           "checkpoint; %s.xdmf lists the snapshots from the restart on\n",
                   dir.c_str(), base.c_str(), m.snapshot_times.size(), base.c_str());
    m.snapshot_times.clear();
    m.snapshots = 0;
  }
  return found;
}

}  // namespace smpm::fem
