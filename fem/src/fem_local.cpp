// A split FE model that keeps only what its rank steps (Solver::localize; docs/parallel.md, "The
// FE far field"): the own nodes and those received, K's own rows, the cells around them. Plain
// arrays and MPI; no deal.II here.
#include <mpi.h>
#include <omp.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <limits>
#include <new>
#include <string>

#include "fem_impl.hpp"
#include "silentmpm/mpi_bytes.hpp"

namespace smpm::fem {

namespace {
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
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

// Rank P.rank's local model (Solver::localize) of the whole model m split by P.
static std::unique_ptr<Solver::Impl> local_model(const Solver::Impl& m, const Solver::Impl::Part& P,
                                          std::vector<std::string> described) {
  using Impl = Solver::Impl;
  const auto me = static_cast<std::uint32_t>(P.rank);
  const std::size_t nn = m.x.size(), nc = m.n_cells;
  const std::size_t nb = static_cast<std::size_t>((m.degree + 1) * (m.degree + 1));

  auto loc = std::make_unique<Impl>();
  Impl& L = *loc;
  L.described = std::move(described);
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

  // The local nodes' dashpot blocks and explicit forces (own nodes are advanced with them; a
  // PML cell or a damping band's row puts its forces on its received nodes' too).
  L.dash_of_node.assign(nl, -1);
  for (std::size_t k = 0; k < m.dash.size(); ++k) {
    const std::uint32_t n = m.dash[k].node;
    if (to[n] == kNone) continue;
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

  // The perfectly matched layers: the layer cells this rank steps (P.pml_cells, by colour) and
  // its own layer nodes' memories, in the whole model's order.
  if (m.pml.active()) {
    const Impl::Pml& W = m.pml;
    Impl::Pml& Y = L.pml;
    Y.alpha = W.alpha;
    Y.nb = W.nb;
    Y.nq = W.nq;
    Y.grad = W.grad;
    Y.kl = W.kl;
    Y.km = W.km;
    Y.dx = W.dx;
    Y.dy = W.dy;
    Y.dt_coef = W.dt_coef;
    Y.packed = W.packed;
    Y.e_a = W.e_a;
    Y.ca_a = W.ca_a;
    Y.cb_a = W.cb_a;
    Y.whole_cells = W.cell.size();
    Y.whole_nodes = W.node.size();
    Y.colour_start = P.pml_colour_start;
    const auto cnb = static_cast<std::size_t>(W.nb), cnq = static_cast<std::size_t>(W.nq);
    for (const std::uint32_t c : P.pml_cells) {
      Y.cell.push_back(W.cell[c]);
      Y.glob_cell.push_back(c);
      Y.own_cell.push_back(P.cell_rank[W.cell[c]] == me);
      for (std::size_t a = 0; a < cnb; ++a) Y.cell_nodes.push_back(local(W.cell_nodes[c * cnb + a]));
      Y.shape.push_back(W.shape[c]);
      Y.kind.insert(Y.kind.end(), W.kind.begin() + c * cnq, W.kind.begin() + (c + 1) * cnq);
      Y.xi.insert(Y.xi.end(), W.xi.begin() + 4 * cnq * c, W.xi.begin() + 4 * cnq * (c + 1));
    }
    for (const std::uint32_t j : P.pml_nodes) {
      Y.node.push_back(local(W.node[j]));
      Y.glob_node.push_back(j);
      Y.m_sum.push_back(W.m_sum[j]);
      Y.m_prod.push_back(W.m_prod[j]);
      Y.zeta.insert(Y.zeta.end(), W.zeta.begin() + 4 * j, W.zeta.begin() + 4 * (j + 1));
    }
    for (const std::uint32_t n : W.touched)
      if (to[n] != kNone) Y.touched.push_back(to[n]);
  }
  // The damping bands' stiffness-proportional part: the listed nodes held here, the rows of the
  // own ones.
  if (m.visc.active()) {
    const Impl::Viscous& W = m.visc;
    Impl::Viscous& Y = L.visc;
    for (std::size_t r = 0; r < W.node.size(); ++r) {
      const std::uint32_t n = W.node[r];
      if (to[n] == kNone) continue;
      if (P.node_rank[n] == me) {
        Y.rows.push_back(static_cast<std::uint32_t>(Y.node.size()));
        Y.row_node.push_back(to[n]);
      }
      Y.node.push_back(to[n]);
      Y.root_beta.push_back(W.root_beta[r]);
    }
    Y.w.assign(2 * nl, 0.0);
    Y.kw.assign(2 * nl, 0.0);
  }

  // The cells this rank steps (its part's, and those around its own nodes).
  for (std::size_t c = 0; c < nc; ++c) {
    bool mine = P.cell_rank[c] == me;
    for (std::size_t a = 0; a < nb && !mine; ++a) mine = P.node_rank[m.cell_nodes[c * nb + a]] == me;
    if (!mine) continue;
    for (std::size_t a = 0; a < nb; ++a) L.cell_nodes.push_back(local(m.cell_nodes[c * nb + a]));
    L.cell_glob.push_back(static_cast<std::uint32_t>(c));
    L.cell_own.push_back(P.cell_rank[c] == me);
    L.cell_region.push_back(m.cell_region[c]);
  }
  L.ref_grad = m.ref_grad;  // the snapshots' tables
  L.map_grad = m.map_grad;

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
  for (std::size_t k = 0; k < L.pml.cell.size(); ++k) Q.pml_cells.push_back(static_cast<std::uint32_t>(k));
  Q.pml_colour_start = L.pml.colour_start;
  for (std::size_t k = 0; k < L.pml.node.size(); ++k) Q.pml_nodes.push_back(static_cast<std::uint32_t>(k));
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

  return loc;
}

bool Solver::localize() {
  Impl& m = *impl_;
  if (!m.part) throw FemError("FEM: localize() needs a model split over the ranks (distribute())");
  if (localized()) return true;
  adopt(local_model(m, *m.part, describe()));
  return true;
}

void Solver::adopt(std::unique_ptr<Impl> loc) {
  // The snapshots' writer: its deflate level goes with the model; a file it has open would be
  // started afresh by the ranks together, so the split comes before the first snapshot.
  if (impl_->snap.is_open())
    throw FemError("FEM: the far field is split over the ranks before its first snapshot");
  loc->snap.set_compression(impl_->snap.compression());
  impl_ = std::move(loc);  // the whole model goes
#if defined(__GLIBC__)
  malloc_trim(0);  // and its pages go back to the system
#endif
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

// ---- the parts built on rank 0 and sent (Solver::distribute_from_root) -------------------------

namespace smpm::fem {

namespace {
constexpr int kPartTag = 7305;
constexpr std::uint64_t kFailed = ~std::uint64_t{0};  // a length that says rank 0 failed
int g_part_fault = 0;  // Solver::set_part_fault
constexpr std::size_t kPiece = std::size_t{1} << 30;

void send_pieces(const std::string& b, int to) {
  for (std::size_t o = 0; o < b.size(); o += kPiece)
    MPI_Send(b.data() + o, static_cast<int>(std::min(kPiece, b.size() - o)), MPI_CHAR, to, kPartTag,
             MPI_COMM_WORLD);
}

void recv_pieces(std::string& b, int from) {
  for (std::size_t o = 0; o < b.size(); o += kPiece)
    MPI_Recv(b.data() + o, static_cast<int>(std::min(kPiece, b.size() - o)), MPI_CHAR, from,
             kPartTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

// A rank's part: its length, the rank's word that it could make room for it, then the bytes
// (none if it could not). Returns the rank's word.
bool send_part(const std::string& b, int to) {
  std::uint64_t n = b.size();
  MPI_Send(&n, 1, MPI_UINT64_T, to, kPartTag, MPI_COMM_WORLD);
  int room = 0;
  MPI_Recv(&room, 1, MPI_INT, to, kPartTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  if (room) send_pieces(b, to);
  return room != 0;
}

// Rank 0 could not build a rank's part: the remaining ranks get its reason instead (a short
// message, sent whole).
void send_failure(const std::string& why, int to) {
  std::uint64_t n[2] = {kFailed, why.size()};
  MPI_Send(n, 2, MPI_UINT64_T, to, kPartTag, MPI_COMM_WORLD);
  send_pieces(why, to);
}

// This rank's part from rank 0 (send_part); rank 0's reason (FemError) when it sent
// send_failure; a FemError, told to rank 0, when there is no room for the part.
std::string recv_part(int rank) {
  std::uint64_t n[2] = {0, 0};
  MPI_Status st;
  MPI_Recv(n, 2, MPI_UINT64_T, 0, kPartTag, MPI_COMM_WORLD, &st);
  int got = 0;
  MPI_Get_count(&st, MPI_UINT64_T, &got);
  if (got == 2 && n[0] == kFailed) {
    std::string why(n[1], '\0');
    recv_pieces(why, 0);
    throw FemError(why);
  }
  std::string b;
  int room = 1;
  try {
    if (g_part_fault == -rank - 1) throw std::bad_alloc();
    b.assign(n[0], '\0');
  } catch (const std::bad_alloc&) {
    room = 0;
  }
  MPI_Send(&room, 1, MPI_INT, 0, kPartTag, MPI_COMM_WORLD);
  if (!room)
    throw FemError("FEM: rank " + std::to_string(rank) + " has no room for its part of the far field (" +
                   std::to_string(n[0]) + " bytes)" + (g_part_fault ? " (a fault set by a test)" : ""));
  recv_pieces(b, 0);
  return b;
}

std::string key(const char* what, std::size_t k) { return std::string(what) + "." + std::to_string(k); }
std::string key(const char* what, std::size_t k, std::size_t j) { return key(what, k) + "." + std::to_string(j); }

// fn(name, array) for every array of a local model (pack writes them, unpack reads them).
template <class Fn>
void arrays(Solver::Impl& L, Fn&& fn) {
  fn("x", L.x);
  fn("y", L.y);
  fn("mass", L.mass);
  fn("inv_mass", L.inv_mass);
  fn("u", L.u);
  fn("v", L.v);
  fn("ku", L.ku);
  fn("fext", L.fext);
  fn("val", L.val);
  fn("dash_force", L.dash_force);
  fn("mask", L.mask);
  fn("dash_of_node", L.dash_of_node);
  fn("rowptr", L.rowptr);
  fn("col", L.col);
  fn("row_val", L.row_val);
  fn("dash", L.dash);
  fn("cell_nodes", L.cell_nodes);
  fn("cell_glob", L.cell_glob);
  fn("cell_own", L.cell_own);
  fn("cell_region", L.cell_region);
  fn("ref_grad", L.ref_grad);
  fn("map_grad", L.map_grad);
  fn("glob", L.glob);
  Solver::Impl::Pml& Y = L.pml;
  fn("pml_grad", Y.grad);
  fn("pml_kl", Y.kl);
  fn("pml_km", Y.km);
  fn("pml_dx", Y.dx);
  fn("pml_dy", Y.dy);
  fn("pml_xi", Y.xi);
  fn("pml_m_sum", Y.m_sum);
  fn("pml_m_prod", Y.m_prod);
  fn("pml_zeta", Y.zeta);
  fn("pml_packed", Y.packed);
  fn("pml_colour_start", Y.colour_start);
  fn("pml_cell", Y.cell);
  fn("pml_cell_nodes", Y.cell_nodes);
  fn("pml_shape", Y.shape);
  fn("pml_kind", Y.kind);
  fn("pml_node", Y.node);
  fn("pml_touched", Y.touched);
  fn("pml_glob_cell", Y.glob_cell);
  fn("pml_glob_node", Y.glob_node);
  fn("pml_own_cell", Y.own_cell);
  fn("visc_node", L.visc.node);
  fn("visc_rows", L.visc.rows);
  fn("visc_row_node", L.visc.row_node);
  fn("visc_root_beta", L.visc.root_beta);
}

// A local model's arrays (and the solver's clock), as a message. The spec is not in it: the
// receiving rank read the same case.
std::string pack(const Solver::Impl& L, double dt, double t, long steps, const Energies& e) {
  StateWriter w;
  w.put("dt", dt);
  w.put("t", t);
  w.put("steps", static_cast<std::int64_t>(steps));
  w.put("energy", e);
  w.put("sizes", std::vector<std::uint64_t>{L.mesh_nodes, L.mesh_dashpots, L.n_cells});
  w.put("box", std::vector<double>(L.box.begin(), L.box.end()));
  w.put("crit_dt", L.crit_dt);
  w.put("ku_valid", static_cast<std::uint8_t>(L.ku_valid));
  w.put("snapshot_times", L.snapshot_times);
  arrays(const_cast<Solver::Impl&>(L), [&](const char* name, const auto& v) { w.put(name, v); });
  w.put("loads", static_cast<std::uint64_t>(L.loads.size()));
  for (std::size_t k = 0; k < L.loads.size(); ++k) {
    w.put(key("load_nodes", k), L.loads[k].nodes);
    w.put(key("load_f", k), L.loads[k].f);
  }
  std::vector<std::int32_t> tags;
  for (const auto& [tag, nodes] : L.curve_nodes) {
    w.put(key("curve", tags.size()), nodes);
    tags.push_back(tag);
  }
  w.put("curves", tags);
  w.put("probes", static_cast<std::uint64_t>(L.probes.size()));
  for (std::size_t p = 0; p < L.probes.size(); ++p) {
    const auto& pr = L.probes[p];
    w.put(key("probe", p), std::vector<double>{pr.x, pr.y, pr.w});
    w.put(key("probe_parts", p), static_cast<std::uint64_t>(pr.parts.size()));
    for (std::size_t j = 0; j < pr.parts.size(); ++j) {
      const auto& q = pr.parts[j];
      w.put(key("part_cell", p, j), q.cell);
      w.put(key("part_dofs", p, j), q.dofs);
      w.put(key("part_comp", p, j), q.comp);
      w.put(key("part_values", p, j), [&] {
        std::vector<double> v{q.lambda, q.mu};
        for (const auto* a : {&q.N, &q.dx, &q.dy}) v.insert(v.end(), a->begin(), a->end());
        return v;
      }());
    }
  }
  const Solver::Impl::Pml& Y = L.pml;
  w.put("pml_sizes", std::vector<std::uint64_t>{static_cast<std::uint64_t>(Y.nb), static_cast<std::uint64_t>(Y.nq),
                                                Y.whole_cells, Y.whole_nodes});
  w.put("pml_scalars", std::vector<double>{Y.alpha, Y.dt_coef, Y.e_a, Y.ca_a, Y.cb_a});
  w.put("described", static_cast<std::uint64_t>(L.described.size()));
  for (std::size_t k = 0; k < L.described.size(); ++k) w.put_string(key("line", k), L.described[k]);
  const Solver::Impl::Part& P = *L.part;
  w.put("part_ints", std::vector<std::int64_t>{P.rank, P.size, static_cast<std::int64_t>(P.ghosts)});
  w.put("part_energy", std::vector<double>{P.work, P.absorbed});
  w.put("own", P.own);
  w.put("node_rank", P.node_rank);
  w.put("links", static_cast<std::uint64_t>(P.links.size()));
  for (std::size_t k = 0; k < P.links.size(); ++k) {
    w.put(key("link_rank", k), static_cast<std::int32_t>(P.links[k].rank));
    w.put(key("link_send", k), P.links[k].send);
    w.put(key("link_recv", k), P.links[k].recv);
  }
  return w.bytes();
}

// The message of pack into L (whose spec this rank read), and the solver's clock.
void unpack(const std::string& bytes, Solver::Impl& L, double& dt, double& t, long& steps, Energies& e) {
  const StateReader r(bytes, "the far field's part from rank 0");
  dt = r.get<double>("dt");
  t = r.get<double>("t");
  steps = static_cast<long>(r.get<std::int64_t>("steps"));
  e = r.get<Energies>("energy");
  std::vector<std::uint64_t> sizes;
  r.get("sizes", sizes, 3);
  L.mesh_nodes = sizes[0];
  L.mesh_dashpots = sizes[1];
  L.n_cells = sizes[2];
  std::vector<double> box;
  r.get("box", box, 4);
  std::copy(box.begin(), box.end(), L.box.begin());
  L.crit_dt = r.get<double>("crit_dt");
  L.ku_valid = r.get<std::uint8_t>("ku_valid") != 0;
  r.get("snapshot_times", L.snapshot_times);
  L.snapshots = static_cast<int>(L.snapshot_times.size());
  arrays(L, [&](const char* name, auto& v) { r.get(name, v); });
  // One load per traction, in the order of the spec's boundaries (as the whole model has them).
  std::vector<const TimeFunction*> fns;
  for (const auto& b : L.spec.boundaries)
    if (b.kind == Boundary::Kind::Traction) fns.push_back(&b.fn);
  const auto loads = r.get<std::uint64_t>("loads");
  if (loads != fns.size()) r.fail("its loads are not this case's tractions");
  L.loads.resize(loads);
  for (std::size_t k = 0; k < loads; ++k) {
    L.loads[k].fn = *fns[k];
    r.get(key("load_nodes", k), L.loads[k].nodes);
    r.get(key("load_f", k), L.loads[k].f);
  }
  std::vector<std::int32_t> tags;
  r.get("curves", tags);
  for (std::size_t k = 0; k < tags.size(); ++k) r.get(key("curve", k), L.curve_nodes[tags[k]]);
  L.probes.resize(r.get<std::uint64_t>("probes"));
  for (std::size_t p = 0; p < L.probes.size(); ++p) {
    auto& pr = L.probes[p];
    std::vector<double> xyw;
    r.get(key("probe", p), xyw, 3);
    pr.x = xyw[0];
    pr.y = xyw[1];
    pr.w = xyw[2];
    pr.parts.resize(r.get<std::uint64_t>(key("probe_parts", p)));
    for (std::size_t j = 0; j < pr.parts.size(); ++j) {
      auto& q = pr.parts[j];
      q.cell = r.get<std::uint32_t>(key("part_cell", p, j));
      r.get(key("part_dofs", p, j), q.dofs);
      r.get(key("part_comp", p, j), q.comp, q.dofs.size());
      std::vector<double> v;
      r.get(key("part_values", p, j), v, 2 + 3 * q.dofs.size());
      const auto n = static_cast<std::ptrdiff_t>(q.dofs.size());
      q.lambda = v[0];
      q.mu = v[1];
      q.N.assign(v.begin() + 2, v.begin() + 2 + n);
      q.dx.assign(v.begin() + 2 + n, v.begin() + 2 + 2 * n);
      q.dy.assign(v.begin() + 2 + 2 * n, v.end());
    }
  }
  Solver::Impl::Pml& Y = L.pml;
  std::vector<std::uint64_t> ps;
  r.get("pml_sizes", ps, 4);
  Y.nb = static_cast<int>(ps[0]);
  Y.nq = static_cast<int>(ps[1]);
  Y.whole_cells = ps[2];
  Y.whole_nodes = ps[3];
  std::vector<double> sc;
  r.get("pml_scalars", sc, 5);
  Y.alpha = sc[0];
  Y.dt_coef = sc[1];
  Y.e_a = sc[2];
  Y.ca_a = sc[3];
  Y.cb_a = sc[4];
  Solver::Impl::Viscous& V = L.visc;
  if (V.active()) {
    V.w.assign(L.u.size(), 0.0);
    V.kw.assign(L.u.size(), 0.0);
  }
  L.described.resize(r.get<std::uint64_t>("described"));
  for (std::size_t k = 0; k < L.described.size(); ++k) L.described[k] = r.get_string(key("line", k));
  auto part = std::make_unique<Solver::Impl::Part>();
  Solver::Impl::Part& P = *part;
  std::vector<std::int64_t> ints;
  r.get("part_ints", ints, 3);
  P.rank = static_cast<int>(ints[0]);
  P.size = static_cast<int>(ints[1]);
  P.ghosts = static_cast<std::size_t>(ints[2]);
  std::vector<double> pe;
  r.get("part_energy", pe, 2);
  P.work = pe[0];
  P.absorbed = pe[1];
  r.get("own", P.own);
  r.get("node_rank", P.node_rank);
  P.links.resize(r.get<std::uint64_t>("links"));
  for (std::size_t k = 0; k < Y.cell.size(); ++k) P.pml_cells.push_back(static_cast<std::uint32_t>(k));
  P.pml_colour_start = Y.colour_start;
  for (std::size_t k = 0; k < Y.node.size(); ++k) P.pml_nodes.push_back(static_cast<std::uint32_t>(k));
  for (std::size_t k = 0; k < P.links.size(); ++k) {
    P.links[k].rank = r.get<std::int32_t>(key("link_rank", k));
    r.get(key("link_send", k), P.links[k].send);
    r.get(key("link_recv", k), P.links[k].recv);
  }
  L.part = std::move(part);
}
}  // namespace

Solver::Solver(const Spec& spec, Skeleton) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.spec = spec;
  m.spec.mesh.msh.clear();
  m.spec.mesh.msh.shrink_to_fit();
  m.degree = spec.degree;
  m.threads = spec.threads > 0 ? spec.threads : omp_get_max_threads();
}

void Solver::set_part_fault(int rank) { g_part_fault = rank; }

bool Solver::is_skeleton() const { return !impl_->part && impl_->glob.empty() && impl_->x.empty(); }

void Solver::distribute_from_root() {
  Impl& m = *impl_;
  check_can_split(m);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  // Rank 0 cuts the whole model and checks the cut; whether it could is every rank's to know
  // before any part is sent.
  Impl::Part P;
  P.rank = 0;
  P.size = size;
  std::string why;
  if (rank == 0) {
    try {
      check_enough_cells(m.n_cells, size);
      P.cell_rank = partition_cells(m, static_cast<unsigned>(size));
      check_parts(P.cell_rank, size, m.n_cells);
    } catch (const std::exception& e) {
      why = e.what();
    }
  }
  int ok = why.empty() ? 1 : 0;
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!ok) throw FemError(rank == 0 ? why : "FEM: rank 0 could not cut the mesh");
  // Each rank gets its part or rank 0's reason (a rank with no room for its part says so before
  // rank 0 sends it); then every rank says whether it has its part, so that a failure anywhere
  // (rank 0 or a rank out of memory, a message that does not unpack) stops all of them.
  why.clear();
  std::unique_ptr<Impl> loc;
  if (rank != 0) {
    try {
      unpack(recv_part(rank), m, dt, t, steps, energy);
    } catch (const std::exception& e) {
      why = e.what();
    }
  } else {
    int r = 1;
    try {
      const std::vector<std::string> described = describe();
      for (; r < size; ++r) {  // each other rank's part, built and sent one at a time
        P.rank = r;
        if (g_part_fault == r) throw FemError("a fault set by a test");
        make_part(m, P, static_cast<std::uint32_t>(r));
        P.work = P.absorbed = 0;
        const std::unique_ptr<Impl> part = local_model(m, P, described);
        if (!send_part(pack(*part, dt, t, steps, energy), r)) {
          ++r;  // it knows
          throw FemError("rank " + std::to_string(r - 1) + " has no room for it");
        }
      }
      P.rank = 0;
      make_part(m, P, 0);
      P.work = energy.external_work;  // the booked energies stay with rank 0
      P.absorbed = energy.absorbed;
      loc = local_model(m, P, described);
    } catch (const std::exception& e) {
      why = std::string("FEM: rank 0 could not send the far field's parts: ") + e.what();
      for (; r < size; ++r) send_failure(why, r);
    }
  }
  int failed = why.empty() ? 0 : 1;
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (failed) throw FemError(why.empty() ? "FEM: another rank could not take its part of the far field" : why);
  if (rank == 0) {
    adopt(std::move(loc));
  } else {
#if defined(__GLIBC__)
    malloc_trim(0);  // the message's pages
#endif
  }
}

}  // namespace smpm::fem
