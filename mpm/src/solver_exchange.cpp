// The solver's side of a decomposition over processes (decomposition.hpp): the halo sums of the
// step, and particles leaving and joining the solver with their boundary-layer entries.
#include <algorithm>
#include <stdexcept>
#include <utility>

#include "silentmpm/solver.hpp"

namespace smpm {

namespace {
using Arrays = std::vector<std::pair<std::vector<double>*, int>>;  // per-entry array, stride
}

// The boundary layers whose entries travel with their particles, and each one's per-entry data.
// Both ends of an exchange hold the same layers with the same arrays (they were built from one
// case), so a record lists them in this order. Per-step caches (the band's and the PML's shape
// functions) are rebuilt by the step and do not travel; nor do the PML's recursion coefficients
// (sized at the first step): they are recomputed after particles left or arrived.
template <class Fn>
void Solver::for_each_layer(Fn&& fn) {
  for (auto& tl : tractions) {
    BoundaryLayer& L = tl.layer;
    fn(L, Arrays{{&L.nx, 1}, {&L.ny, 1}, {&L.d, 1}, {&L.w, 1}});
  }
  for (auto& sl : silents) {
    BoundaryLayer& L = sl.layer;
    Arrays a{{&L.nx, 1}, {&L.ny, 1}, {&L.d, 1}, {&L.w, 1}, {&sl.zn, 1}, {&sl.zt, 1}};
    if (sl.springs())
      for (auto* v : {&sl.kn, &sl.kt, &sl.ux, &sl.uy}) a.push_back({v, 1});
    fn(L, std::move(a));
  }
  for (auto& dl : dampers) {
    BoundaryLayer& L = dl.layer;
    fn(L, Arrays{{&L.nx, 1}, {&L.ny, 1}, {&L.d, 1}, {&L.w, 1}, {&dl.alpha, 1}, {&dl.beta, 1},
                 {&dl.sv, 3}});
  }
  if (!pml_bands.empty()) {
    PmlLayer& P = pml;
    fn(P.layer, Arrays{{&P.dx, 1}, {&P.dy, 1}, {&P.pic, 1}, {&P.H, 4}, {&P.u, 2}, {&P.xi, 4},
                       {&P.zeta, 4}, {&P.f, 6}});
  }
}

void Solver::set_decomposition(Decomposition* d, NodeBox own, int halo, bool dashpots) {
  dist_ = d;
  own_ = own;
  halo_ = halo;
  halo_dashpots_ = dashpots;
  dashpot_nodes_.clear();
  dashpot_index_.assign(grid.nodes(), -1);
  for (auto& f : grid.fix) f &= static_cast<uint8_t>(~Grid::kDashpotNode);
  if (consistent_) {  // the window's nodes and cells
    cm_slot_.assign(grid.nodes(), -1);
    cm_cover_.assign(grid.nodes(), 0);
    cm_covered_.clear();
    cm_moving_.clear();
    cm_cell_.assign(static_cast<std::size_t>(grid.nx) * grid.ny, 0);
    cm_nodes_.clear();
    cm_cells_.clear();
    cm_reach_.clear();
  }
  if (!delay_rho_.empty()) {  // the window's nodes
    delay_rho_.assign(grid.nodes(), 0.0);
    delay_map();
  }
  // This rank's share of the energy account: its particles' energies, nothing booked yet.
  update_energies();
  energy.initial = energy.kinetic + energy.elastic;
  energy.dissipated = energy.absorbed = energy.external_work = 0;
  strips_ok_ = false;
}

// fn(i) for every node of the window within the halo's width of this rank's box's edges (inside
// it or beyond): the nodes ranks share.
template <class Fn>
static void for_shared_nodes(const Grid& g, const NodeBox& own, long w, Fn&& fn) {
  const long nnx = g.nnx;
  for (long j = 0; j < g.nny; ++j) {
    if (j < own[2] + w || j > own[3] - w) {
      for (long i = 0; i < nnx; ++i) fn(i, j);
      continue;
    }
    for (long i = 0; i < std::min<long>(nnx, own[0] + w); ++i) fn(i, j);
    for (long i = std::max<long>(own[0] + w, own[1] - w + 1); i < nnx; ++i) fn(i, j);
  }
}

// After the last particle was mapped: masses and momenta (momentum: after the momentum p2g),
// forces and dashpot blocks (force: after the loads). The bodies' fields of multi-field contact
// too: their masses, momenta, mass gradients and centroid sums with the momenta, their forces
// with the momenta where that p2g formed them (USL, MUSL) and with the loads under USF; a body's
// node box then grows to the shared nodes where it now has mass. A node whose dashpot block
// only a neighbour assembled is listed here, so that the grid update integrates it like the
// others.
void Solver::sum_halo(bool momentum, bool force) {
  std::vector<double*> f;
  std::vector<int> stride;  // 1 but for the dashpot blocks and weights
  const bool usf = opt.scheme == Scheme::USF;
  if (momentum)
    for (auto* v : {&grid.m, &grid.px, &grid.py}) f.push_back(v->data());
  if (force) {
    for (auto* v : {&grid.fx, &grid.fy}) f.push_back(v->data());
    if (halo_dashpots_) {
      if (!updated_weight_.empty()) f.push_back(updated_weight_.data());
      if (!delay_rho_.empty()) f.push_back(delay_rho_.data());
      stride.assign(f.size(), 1);
      for (int c = 0; c < (consistent_ ? 4 : 3); ++c) {  // the block, the solve's weight
        f.push_back(grid.dash.data() + c);
        stride.push_back(Grid::kDash);
      }
    }
  }
  const bool bodies = !body_of_group_.empty();
  if (bodies)
    for (const VelocityField& F : fields_) {
      const NodalField& b = F.f;
      if (momentum) f.insert(f.end(), {b.m, b.px, b.py, b.gx, b.gy, b.xm, b.ym, b.sm});
      if ((momentum && !usf) || (force && usf)) f.insert(f.end(), {b.fx, b.fy});
    }
  stride.resize(f.size(), 1);
  dist_->sum_halo(f.data(), static_cast<int>(f.size()), stride.data());
  if (bodies && momentum)
    for (VelocityField& F : fields_)
      for_shared_nodes(grid, own_, halo_, [&](long i, long j) {
        if (F.f.m[j * grid.nnx + i] == 0) return;
        NodeBox& x = F.box;
        x = {std::min<int>(x[0], i), std::max<int>(x[1], i), std::min<int>(x[2], j),
             std::max<int>(x[3], j)};
      });
  if (!force || !halo_dashpots_) return;
  if (dashpot_index_.size() != grid.nodes()) dashpot_index_.assign(grid.nodes(), -1);
  for_shared_nodes(grid, own_, halo_, [&](long i, long j) {
    const long n = j * grid.nnx + i;
    if (grid.cxx(n) != 0 || grid.cxy(n) != 0 || grid.cyy(n) != 0) {
      add_dashpot_node(n);
      has_nodal_dashpot_ = true;
    }
  });
}

// consistent_dashpots: the slots' values [first, first + count) summed over the ranks that
// share their nodes, through grid-sized arrays (zero but at this rank's slots).
void Solver::cm_sum(int first, int count) {
  if (!dist_) return;
  // Every copy of a shared slot node is a slot on its other ranks too (the choice reads only
  // values summed over the halo), so the arrays are zero again once the slots are read back.
  const std::size_t nn = grid.nodes();
  if (cm_halo_.size() < nn * count) cm_halo_.assign(nn * count, 0.0);
  std::vector<double*> f(count);
  for (int c = 0; c < count; ++c) f[c] = cm_halo_.data() + nn * c;
  for (std::size_t k = 0; k < cm_nodes_.size(); ++k)
    for (int c = 0; c < count; ++c) f[c][cm_nodes_[k]] = cm_[kCm * k + first + c];
  dist_->sum_halo(f.data(), count, nullptr);
  for (std::size_t k = 0; k < cm_nodes_.size(); ++k)
    for (int c = 0; c < count; ++c) {
      cm_[kCm * k + first + c] = f[c][cm_nodes_[k]];
      f[c][cm_nodes_[k]] = 0;
    }
  // A shared node listed on another rank only would leave its sum here, for every later sum
  // to carry: the ranks' choices must agree.
  for_shared_nodes(grid, own_, halo_, [&](long i, long j) {
    for (int c = 0; c < count; ++c)
      if (f[c][j * grid.nnx + i] != 0)
        throw std::logic_error("cm_sum: a shared node is a slot on another rank only");
  });
}

void Solver::keep_particles(const std::vector<std::uint8_t>& keep) {
  compact(keep);
  sort_particles();
}

// keep_particles without the sort: the layers' indices point at the kept particles' new places,
// the strips are stale (the caller sorts before the particles are used).
void Solver::compact(const std::vector<std::uint8_t>& keep) {
  std::vector<uint32_t> perm, now(p.size(), 0);
  perm.reserve(p.size());
  for (std::size_t k = 0; k < p.size(); ++k)
    if (keep[k]) {
      now[k] = static_cast<uint32_t>(perm.size());
      perm.push_back(static_cast<uint32_t>(k));
    }
  for_each_layer([&](BoundaryLayer& L, Arrays a) {
    std::size_t out = 0;
    for (std::size_t q = 0; q < L.ids.size(); ++q) {
      if (!keep[L.idx[q]]) continue;
      L.ids[out] = L.ids[q];
      L.idx[out] = now[L.idx[q]];
      for (auto& [v, st] : a)
        std::copy_n(v->data() + st * q, st, v->data() + st * out);
      ++out;
    }
    L.ids.resize(out);
    L.idx.resize(out);
    for (auto& [v, st] : a) v->resize(st * out);
  });
  p.permute(perm);
  ++order_version_;
  pml.dt_coef = 0;
  strips_ok_ = false;
}

void Solver::export_particles(const std::vector<int>& to, std::vector<std::vector<double>>& out) {
  std::vector<std::uint8_t> keep(p.size(), 1);
  bool any = false;
  for (std::size_t k = 0; k < p.size(); ++k)
    if (to[k] >= 0) keep[k] = 0, any = true;
  if (!any) return;
  // The layer entries of each leaving particle: (layer number, entry) in the visiting order.
  std::vector<std::vector<std::pair<int, std::size_t>>> entries(p.size());
  int nl = 0;
  for_each_layer([&](BoundaryLayer& L, Arrays) {
    for (std::size_t q = 0; q < L.ids.size(); ++q)
      if (!keep[L.idx[q]]) entries[L.idx[q]].push_back({nl, q});
    ++nl;
  });
  for (std::size_t k = 0; k < p.size(); ++k)
    if (!keep[k]) pack_record(k, entries[k], out[to[k]]);
  compact(keep);
}

void Solver::pack_record(std::size_t k, const std::vector<std::pair<int, std::size_t>>& entries,
                         std::vector<double>& b) {
  p.pack(k, b);
  b.push_back(static_cast<double>(entries.size()));
  int l = 0;
  std::size_t e = 0;
  for_each_layer([&](BoundaryLayer&, Arrays a) {
    for (; e < entries.size() && entries[e].first == l; ++e) {
      const std::size_t q = entries[e].second;
      b.push_back(l);
      for (auto& [v, st] : a) b.insert(b.end(), v->data() + st * q, v->data() + st * (q + 1));
    }
    ++l;
  });
}

std::vector<std::size_t> Solver::group_by_rank(std::vector<int>& rank, int P) {
  const std::size_t n = p.size();
  std::vector<std::size_t> start(static_cast<std::size_t>(P) + 1, 0);
  for (const int r : rank) ++start[static_cast<std::size_t>(r) + 1];
  for (int r = 0; r < P; ++r) start[r + 1] += start[r];
  std::vector<std::size_t> at(start.begin(), start.end() - 1);
  std::vector<uint32_t> perm(n), now(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t to = at[rank[k]]++;
    perm[to] = static_cast<uint32_t>(k);
    now[k] = static_cast<uint32_t>(to);
  }
  for_each_layer([&](BoundaryLayer& L, Arrays) {
    for (auto& i : L.idx) i = now[i];
  });
  p.permute(perm);
  ++order_version_;
  std::vector<int> sorted(n);
  for (std::size_t k = 0; k < n; ++k) sorted[k] = rank[perm[k]];
  rank.swap(sorted);
  pml.dt_coef = 0;
  strips_ok_ = false;
  return start;
}

void Solver::export_range(std::size_t begin, std::size_t end, std::vector<double>& out) {
  std::vector<std::vector<std::pair<int, std::size_t>>> entries(end - begin);
  int nl = 0;
  for_each_layer([&](BoundaryLayer& L, Arrays) {
    for (std::size_t q = 0; q < L.ids.size(); ++q)
      if (L.idx[q] >= begin && L.idx[q] < end) entries[L.idx[q] - begin].push_back({nl, q});
    ++nl;
  });
  for (std::size_t k = begin; k < end; ++k) pack_record(k, entries[k - begin], out);
}

void Solver::import_particles(const std::vector<double>& in) {
  std::size_t r = 0;
  while (r < in.size()) {
    const std::size_t k = p.size();
    r += p.unpack(in.data() + r);
    ++order_version_;
    const auto ne = static_cast<std::size_t>(in[r++]);
    for (std::size_t e = 0; e < ne; ++e) {
      const int want = static_cast<int>(in[r++]);
      int l = 0;
      for_each_layer([&](BoundaryLayer& L, Arrays a) {
        if (l++ != want) return;
        L.ids.push_back(p.id[k]);
        L.idx.push_back(static_cast<uint32_t>(k));
        for (auto& [v, st] : a) {
          v->insert(v->end(), in.data() + r, in.data() + r + st);
          r += st;
        }
      });
    }
  }
  if (r != in.size()) throw std::logic_error("import_particles: a record ran past the buffer");
  pml.dt_coef = 0;
  strips_ok_ = false;
}

Energies Solver::total_energy() const {
  Energies e = energy;
  if (!dist_) return e;
  double v[6] = {e.kinetic, e.elastic, e.dissipated, e.absorbed, e.external_work, e.initial};
  dist_->sum(v, 6);
  e.kinetic = v[0];
  e.elastic = v[1];
  e.dissipated = v[2];
  e.absorbed = v[3];
  e.external_work = v[4];
  e.initial = v[5];
  return e;
}

}  // namespace smpm
