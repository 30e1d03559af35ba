// A split FE model that keeps only what its rank steps (Solver::localize; docs/parallel.md, "The
// FE far field"): the own nodes and those received, K's own rows, the cells around them. Plain
// arrays and MPI; no deal.II here.
#include <mpi.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <limits>
#include <string>

#include "fem_impl.hpp"
#include "silentmpm/mpi_bytes.hpp"

namespace smpm::fem {

namespace {
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

template <class T>
void release(std::vector<T>& v) {
  std::vector<T>().swap(v);
}
}  // namespace

bool Solver::localized() const { return !impl_->glob.empty(); }

std::vector<std::uint32_t> Solver::global_nodes() const {
  if (localized()) return impl_->glob;
  std::vector<std::uint32_t> all(impl_->x.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  return all;
}

std::size_t Solver::dashpot_count() const {
  return localized() ? impl_->mesh_dashpots : impl_->dash.size();
}

bool Solver::localize() {
  Impl& m = *impl_;
  if (!m.part) throw FemError("FEM: localize() needs a model split over the ranks (distribute())");
  if (localized()) return true;
  if (m.pml.active() || m.visc.active()) return false;
  const Impl::Part& P = *m.part;
  const auto me = static_cast<std::uint32_t>(P.rank);
  const std::size_t nn = m.x.size(), nc = m.n_cells;
  const std::size_t nb = static_cast<std::size_t>((m.degree + 1) * (m.degree + 1));

  auto loc = std::make_unique<Impl>();
  Impl& L = *loc;
  L.described = describe();
  L.mesh_nodes = nn;
  L.mesh_dashpots = m.dash.size();

  // The local nodes: own and received, in the mesh's order (so the own rows keep their order and
  // each row its columns': the same sums).
  std::vector<std::uint32_t>& glob = L.glob;
  glob = P.own;
  for (const auto& l : P.links) glob.insert(glob.end(), l.recv.begin(), l.recv.end());
  std::sort(glob.begin(), glob.end());
  glob.erase(std::unique(glob.begin(), glob.end()), glob.end());
  const std::size_t nl = glob.size();
  std::vector<std::uint32_t> to(nn, kNone);  // mesh node -> local node
  for (std::size_t i = 0; i < nl; ++i) to[glob[i]] = static_cast<std::uint32_t>(i);
  auto local = [&](std::uint32_t n) {
    const std::uint32_t i = to[n];
    if (i == kNone) throw FemError("FEM: internal error localizing the model (node " + std::to_string(n) + " is not this rank's)");
    return i;
  };

  L.spec = m.spec;
  L.spec.mesh.msh.clear();
  L.spec.mesh.msh.shrink_to_fit();
  L.degree = m.degree;
  L.threads = m.threads;
  L.n_cells = nc;
  L.box = m.box;
  L.crit_dt = m.crit_dt;
  L.ku_valid = m.ku_valid;
  L.snapshots = m.snapshots;
  L.snapshot_times = m.snapshot_times;

  // Per node.
  auto pick = [&](const auto& whole, std::size_t width, auto& out) {
    out.resize(width * nl);
    for (std::size_t i = 0; i < nl; ++i)
      for (std::size_t c = 0; c < width; ++c) out[width * i + c] = whole[width * glob[i] + c];
  };
  pick(m.x, 1, L.x);
  pick(m.y, 1, L.y);
  pick(m.mass, 1, L.mass);
  pick(m.inv_mass, 1, L.inv_mass);
  pick(m.mask, 1, L.mask);
  pick(m.u, 2, L.u);
  pick(m.v, 2, L.v);
  pick(m.ku, 2, L.ku);
  pick(m.fext, 2, L.fext);

  // The own nodes' dashpot blocks (only own nodes are advanced) and explicit forces.
  L.dash_of_node.assign(nl, -1);
  for (std::size_t k = 0; k < m.dash.size(); ++k) {
    const std::uint32_t n = m.dash[k].node;
    if (P.node_rank[n] != me) continue;
    Solver::DashpotBlock b = m.dash[k];
    b.node = local(n);
    L.dash_of_node[b.node] = static_cast<std::int32_t>(L.dash.size());
    L.dash.push_back(b);
    L.dash_force.insert(L.dash_force.end(), {m.dash_force[2 * k], m.dash_force[2 * k + 1]});
  }

  // K: the own rows, their columns renumbered; the received nodes' rows are empty.
  const bool shared = !m.row_val.empty();
  L.rowptr.assign(nl + 1, 0);
  for (std::size_t i = 0; i < nl; ++i) {
    const std::uint32_t n = glob[i];
    const bool own = P.node_rank[n] == me;
    const std::uint64_t b = m.rowptr[n], e = m.rowptr[n + 1];
    if (own) {
      for (std::uint64_t k = b; k < e; ++k) L.col.push_back(local(m.col[k]));
      if (!shared) L.val.insert(L.val.end(), m.val.begin() + 4 * b, m.val.begin() + 4 * e);
    }
    L.rowptr[i + 1] = L.col.size();
    if (shared) L.row_val.push_back(own ? m.row_val[n] : 0);
  }
  if (shared) L.val = m.val;  // the kinds of rows: a few

  // Loads on the own nodes.
  for (const auto& ld : m.loads) {
    Impl::Load l;
    l.fn = ld.fn;
    for (std::size_t k = 0; k < ld.nodes.size(); ++k) {
      if (P.node_rank[ld.nodes[k]] != me) continue;
      l.nodes.push_back(local(ld.nodes[k]));
      l.f.insert(l.f.end(), {ld.f[2 * k], ld.f[2 * k + 1]});
    }
    L.loads.push_back(std::move(l));
  }
  for (const auto& [tag, nodes] : m.curve_nodes) {
    std::vector<std::uint32_t>& out = L.curve_nodes[tag];
    for (const auto n : nodes)
      if (to[n] != kNone) out.push_back(to[n]);
  }

  // The cells this rank steps (its part's, and those around its own nodes).
  for (std::size_t c = 0; c < nc; ++c) {
    bool mine = P.cell_rank[c] == me;
    for (std::size_t a = 0; a < nb && !mine; ++a) mine = P.node_rank[m.cell_nodes[c * nb + a]] == me;
    if (!mine) continue;
    for (std::size_t a = 0; a < nb; ++a) L.cell_nodes.push_back(local(m.cell_nodes[c * nb + a]));
  }

  // The probes: the parts in this rank's part of the mesh, with the weights of the whole.
  for (const auto& pr : m.probes) {
    Impl::Probe q;
    q.x = pr.x;
    q.y = pr.y;
    q.w = pr.w;
    for (const auto& part : pr.parts) {
      if (P.cell_rank[part.cell] != me) continue;
      Impl::ProbePart k = part;
      for (auto& d : k.dofs) d = 2 * local(d / 2) + d % 2;
      q.parts.push_back(std::move(k));
    }
    L.probes.push_back(std::move(q));
  }

  // The split: own nodes and links in local numbers; each local node's owner.
  auto part = std::make_unique<Impl::Part>();
  Impl::Part& Q = *part;
  Q.rank = P.rank;
  Q.size = P.size;
  Q.ghosts = P.ghosts;
  Q.work = P.work;
  Q.absorbed = P.absorbed;
  Q.seconds = P.seconds;
  Q.bytes = P.bytes;
  Q.updates = P.updates;
  for (const auto n : P.own) Q.own.push_back(local(n));
  Q.node_rank.assign(nl, me);
  for (const auto& l : P.links) {
    Impl::Part::Link k;
    k.rank = l.rank;
    for (const auto n : l.send) k.send.push_back(local(n));
    for (const auto n : l.recv) {
      k.recv.push_back(local(n));
      Q.node_rank[local(n)] = static_cast<std::uint32_t>(l.rank);
    }
    Q.links.push_back(std::move(k));
  }
  L.part = std::move(part);

  // Rank 0 keeps the whole mesh for the snapshots; the others free it with the rest.
  if (P.rank == 0) {
    Impl& W = m;
    W.part.reset();
    for (auto* v : {&W.mass, &W.inv_mass, &W.ku, &W.fext, &W.val, &W.dash_force})
      release(*v);
    release(W.rowptr);
    release(W.col);
    release(W.row_val);
    release(W.mask);
    release(W.dash_of_node);
    release(W.dash);
    W.loads.clear();
    W.probes.clear();
    W.curve_nodes.clear();
    W.spec.mesh.msh.clear();
    W.spec.mesh.msh.shrink_to_fit();
    L.whole = std::move(impl_);
  }
  impl_ = std::move(loc);  // the whole model goes (on rank 0 but for what the snapshots need)
#if defined(__GLIBC__)
  malloc_trim(0);  // and its pages go back to the system
#endif
  return true;
}

void gather_local(const Solver::Impl& m, const std::vector<const std::vector<double>*>& fields,
                  std::size_t width, std::vector<std::vector<double>>& out) {
  const Solver::Impl::Part& P = *m.part;
  std::vector<double> mine;
  for (const auto i : P.own) {
    mine.push_back(static_cast<double>(m.glob[i]));  // exact below 2^53
    for (const auto* f : fields) mine.insert(mine.end(), f->begin() + width * i, f->begin() + width * (i + 1));
  }
  std::vector<double> all;
  std::vector<long long> counts;
  gather_doubles(mine, all, counts, MPI_COMM_WORLD, gather_piece());
  out.clear();
  if (P.rank != 0) return;
  out.assign(fields.size(), std::vector<double>(width * m.mesh_nodes, 0.0));
  const std::size_t rec = 1 + width * fields.size();
  for (std::size_t k = 0; k + rec <= all.size(); k += rec) {
    const auto n = static_cast<std::size_t>(all[k]);
    for (std::size_t f = 0; f < fields.size(); ++f)
      std::copy_n(all.begin() + static_cast<std::ptrdiff_t>(k + 1 + width * f), width,
                  out[f].begin() + static_cast<std::ptrdiff_t>(width * n));
  }
}

}  // namespace smpm::fem
