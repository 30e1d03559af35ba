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
    fn(L, Arrays{{&L.nx, 1}, {&L.ny, 1}, {&L.d, 1}, {&L.w, 1}, {&dl.alpha, 1}});
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
  dashpot_mark_.assign(grid.nodes(), 0);
  // This rank's share of the energy account: its particles' energies, nothing booked yet.
  update_energies();
  energy.initial = energy.kinetic + energy.elastic;
  energy.dissipated = energy.absorbed = energy.external_work = 0;
  strips_ok_ = false;
}

// After the last particle was mapped: masses and momenta (unless summed already, USF), forces
// and dashpot blocks. A node whose block only a neighbour assembled is listed here, so that the
// grid update integrates it like the others.
void Solver::sum_halo(bool momentum, bool force) {
  double* f[8];
  int n = 0;
  if (momentum)
    for (auto* v : {&grid.m, &grid.px, &grid.py}) f[n++] = v->data();
  if (force) {
    for (auto* v : {&grid.fx, &grid.fy}) f[n++] = v->data();
    if (halo_dashpots_)
      for (auto* v : {&grid.cxx, &grid.cxy, &grid.cyy}) f[n++] = v->data();
  }
  dist_->sum_halo(f, n);
  if (!force || !halo_dashpots_) return;
  if (dashpot_mark_.size() != grid.nodes()) dashpot_mark_.assign(grid.nodes(), 0);
  auto scan = [&](long i) {
    if (grid.cxx[i] != 0 || grid.cxy[i] != 0 || grid.cyy[i] != 0) {
      add_dashpot_node(i);
      has_nodal_dashpot_ = true;
    }
  };
  // The shared nodes: those of the window within the halo's width of this rank's box's edges
  // (inside it or beyond).
  const long nnx = grid.nnx, w = halo_;
  for (long j = 0; j < grid.nny; ++j) {
    if (j < own_[2] + w || j > own_[3] - w) {
      for (long i = 0; i < nnx; ++i) scan(j * nnx + i);
      continue;
    }
    for (long i = 0; i < std::min<long>(nnx, own_[0] + w); ++i) scan(j * nnx + i);
    for (long i = std::max<long>(own_[0] + w, own_[1] - w + 1); i < nnx; ++i) scan(j * nnx + i);
  }
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
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (keep[k]) continue;
    std::vector<double>& b = out[to[k]];
    p.pack(k, b);
    b.push_back(static_cast<double>(entries[k].size()));
    int l = 0;
    std::size_t e = 0;
    for_each_layer([&](BoundaryLayer&, Arrays a) {
      for (; e < entries[k].size() && entries[k][e].first == l; ++e) {
        const std::size_t q = entries[k][e].second;
        b.push_back(l);
        for (auto& [v, st] : a) b.insert(b.end(), v->data() + st * q, v->data() + st * (q + 1));
      }
      ++l;
    });
  }
  compact(keep);
}

void Solver::import_particles(const std::vector<double>& in) {
  std::size_t r = 0;
  while (r < in.size()) {
    const std::size_t k = p.size();
    r += p.unpack(in.data() + r);
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
