// The MPM solver's state for checkpoints (Solver::save_state / load_state): everything a step
// reads that an earlier step wrote. What setup computes from the case (grid, materials, layer
// selections, dashpot and spring coefficients, damping) is rebuilt from the case file itself.
#include <algorithm>
#include <cmath>
#include <limits>

#include "silentmpm/solver.hpp"
#include "silentmpm/state_io.hpp"

namespace smpm {

namespace {

// fn(name, array) for every particle array the run carries (the film block only when on).
template <class P, class Fn>
void particle_arrays(P& p, Fn&& fn) {
  fn("x", p.x); fn("y", p.y); fn("x0", p.x0); fn("y0", p.y0); fn("vx", p.vx); fn("vy", p.vy); fn("mass", p.mass);
  fn("vol", p.vol); fn("sxx", p.sxx); fn("syy", p.syy); fn("szz", p.szz); fn("sxy", p.sxy);
  fn("eps_p", p.eps_p); fn("id", p.id); fn("body", p.body); fn("group", p.group);
  if (!p.has_film()) return;
  fn("state", p.state); fn("dnx", p.dnx); fn("dny", p.dny); fn("dL", p.dL); fn("dtnf", p.dtnf);
  fn("dttf", p.dttf); fn("jump_n", p.jump_n); fn("jump_t", p.jump_t); fn("ubar", p.ubar);
}

// A checkpoint written by several ranks (save_state_parts) lists a layer's entries by particle id
// (NAME.ids), in another order than this solver's: its arrays (value, stride) are put in this
// solver's entry order. The ids must be exactly the layer's.
void reorder_by_ids(const StateReader& r, const std::string& name, const BoundaryLayer& L,
                    std::size_t n, std::vector<std::pair<std::vector<double>*, int>> arrays) {
  const std::size_t m = L.ids.size();
  std::vector<std::uint32_t> ids;
  r.get(name + ".ids", ids, m);
  std::vector<long> at(n, -1);
  for (std::size_t q = 0; q < m; ++q)
    if (L.ids[q] < n) at[L.ids[q]] = static_cast<long>(q);
  std::vector<std::uint8_t> hit(m, 0);
  std::vector<long> to(m);
  for (std::size_t q = 0; q < m; ++q) {
    if (ids[q] >= n || at[ids[q]] < 0 || hit[at[ids[q]]]++)
      r.fail(name + ": its entries are not this case's layer particles (a checkpoint of another "
                    "case)");
    to[q] = at[ids[q]];
  }
  for (auto& [v, st] : arrays) {
    std::vector<double> out(v->size());
    for (std::size_t q = 0; q < m; ++q)
      std::copy_n(v->begin() + st * q, st, out.begin() + st * to[q]);
    v->swap(out);
  }
}

// The clock, the energy account and the particles' arrays: the head of a solver's state (the
// arrays as this rank's parts when `parts`).
void put_head(StateWriter& w, const std::string& pre, double dt, double t, long steps,
              const Energies& e, double contact_dissipated, const Particles& p, bool parts) {
  w.put(pre + "dt", dt);
  w.put(pre + "t", t);
  w.put(pre + "steps", static_cast<std::int64_t>(steps));
  w.put(pre + "energy", e);
  w.put(pre + "contact_dissipated", contact_dissipated);
  w.put(pre + "film", static_cast<std::uint8_t>(p.has_film()));
  particle_arrays(p, [&](const char* n, const auto& v) {
    if (parts) w.put_part(pre + "p." + n, v);
    else w.put(pre + "p." + n, v);
  });
}

// Per-node records keyed by the whole grid's node (i, j) in their first two values, `stride`
// values each (USF's kept edge velocities, Solver::edge_velocity_; the delayed closure's
// histories, Solver::delay_): those of the nodes in `own` (window numbering, origin o; i1 < i0:
// every node), ordered by the whole grid's (j, i), so that a rank's part does not depend on the
// order nodes were met (the reader keys each record by its node).
std::vector<double> own_node_records(const std::vector<double>& all, std::size_t stride,
                                     const NodeBox& own, std::array<int, 2> o) {
  std::vector<std::size_t> at;
  for (std::size_t k = 0; k + stride <= all.size(); k += stride) {
    const long i = static_cast<long>(all[k]) - o[0], j = static_cast<long>(all[k + 1]) - o[1];
    if (own[1] >= own[0] && (i < own[0] || i > own[1] || j < own[2] || j > own[3])) continue;
    at.push_back(k);
  }
  std::sort(at.begin(), at.end(), [&](std::size_t a, std::size_t b) {
    return all[a + 1] != all[b + 1] ? all[a + 1] < all[b + 1] : all[a] < all[b];
  });
  std::vector<double> out;
  out.reserve(at.size() * stride);
  for (const std::size_t k : at) out.insert(out.end(), all.begin() + k, all.begin() + k + stride);
  return out;
}

}  // namespace

void Solver::save_state(StateWriter& w, const std::string& pre) const {
  put_head(w, pre, dt, t, steps, energy, contact.dissipated, p, false);
  for (std::size_t k = 0; k < silents.size(); ++k) {
    if (!silents[k].springs()) continue;
    w.put(pre + "silent" + std::to_string(k) + ".ux", silents[k].ux);
    w.put(pre + "silent" + std::to_string(k) + ".uy", silents[k].uy);
  }
  for (std::size_t k = 0; k < dampers.size(); ++k)  // a stiffness part's viscous stresses
    if (dampers[k].beta0 > 0) w.put(pre + "damper" + std::to_string(k) + ".sv", dampers[k].sv);
  if (pml.active()) {  // a perfectly matched layer's particles: displacements and memories
    w.put(pre + "pml.H", pml.H);
    w.put(pre + "pml.u", pml.u);
    w.put(pre + "pml.xi", pml.xi);
    w.put(pre + "pml.zeta", pml.zeta);
  }
  // The particle order and the strips it was cut into (a re-sort happens only when the strips
  // conflict, so the order is part of the state: sums over particles follow it).
  w.put(pre + "strips", static_cast<std::int32_t>(nstrips_));
  std::vector<std::uint32_t> ranges;
  for (const auto& r : ranges_) ranges.insert(ranges.end(), {r[0], r[1]});
  w.put(pre + "ranges", ranges);
  std::vector<std::int32_t> boxes;
  for (const auto& F : fields_) boxes.insert(boxes.end(), F.box.begin(), F.box.end());
  w.put(pre + "field_boxes", boxes);
  put_dashpot_solve(w, pre);
  if (usf_edges())
    w.put(pre + "edge_velocity", own_node_records(edge_velocity_, 5, NodeBox{0, -1, 0, -1},
                                                  window_origin()));
  if (!delay_rho_.empty())  // the delayed closure's histories (records of delay_cap_needed())
    w.put(pre + "delay", own_node_records(delay_, delay_stride(), NodeBox{0, -1, 0, -1},
                                          window_origin()));
}

void Solver::save_state_parts(StateWriter& w, const std::string& pre) const {
  // The whole account (collective), rank 0's contact dissipation (every rank holds the same).
  put_head(w, pre, dt, t, steps, total_energy(), contact.dissipated, p, true);
  // A layer's entries with their particles' ids, then its arrays (in entry order).
  auto layer = [&](const std::string& name, const BoundaryLayer& L,
                   std::vector<std::pair<const char*, const std::vector<double>*>> arrays) {
    std::vector<std::uint32_t> ids(L.idx.size());
    for (std::size_t q = 0; q < ids.size(); ++q) ids[q] = p.id[L.idx[q]];
    w.put_part(name + ".ids", ids);
    for (const auto& [suffix, v] : arrays) w.put_part(name + "." + suffix, *v);
  };
  for (std::size_t k = 0; k < silents.size(); ++k)
    if (silents[k].springs())
      layer(pre + "silent" + std::to_string(k), silents[k].layer,
            {{"ux", &silents[k].ux}, {"uy", &silents[k].uy}});
  for (std::size_t k = 0; k < dampers.size(); ++k)
    if (dampers[k].beta0 > 0)
      layer(pre + "damper" + std::to_string(k), dampers[k].layer, {{"sv", &dampers[k].sv}});
  if (!pml_bands.empty())
    layer(pre + "pml", pml.layer, {{"H", &pml.H}, {"u", &pml.u}, {"xi", &pml.xi}, {"zeta", &pml.zeta}});
  w.put(pre + "strips", static_cast<std::int32_t>(0));  // no strips: the reader re-sorts
  w.put(pre + "ranges", std::vector<std::uint32_t>{});
  w.put(pre + "field_boxes", std::vector<std::int32_t>{});
  put_dashpot_solve(w, pre);
  // USF's kept edge velocities: each node's from its owner.
  if (usf_edges())
    w.put_part(pre + "edge_velocity", own_node_records(edge_velocity_, 5, own_, window_origin()));
  // The delayed closure's histories: each node's from its owner.
  if (!delay_rho_.empty())
    w.put_part(pre + "delay", own_node_records(delay_, delay_stride(), own_, window_origin()));
}

std::vector<std::string> Solver::particle_blocks(const std::string& pre) {
  return {pre + "p.", pre + "silent", pre + "damper", pre + "pml"};
}

// The counts of the dashpots' solve (dashpot_solve), the same on every rank: a restarted run's
// summary counts the whole run.
void Solver::put_dashpot_solve(StateWriter& w, const std::string& pre) const {
  if (!consistent_) return;
  const auto& d = dashpot_solve;
  w.put(pre + "dashpot_solve",
        std::vector<std::int64_t>{d.steps, d.iterations, d.max_iterations, d.unconverged, d.rescans});
}

void Solver::load_clock(const StateReader& r, const std::string& pre) {
  const double dt_saved = r.get<double>(pre + "dt");
  if (dt_saved != dt)
    r.fail("time step " + std::to_string(dt_saved) + " s in the checkpoint, " + std::to_string(dt) +
           " s in this case (a checkpoint of another case)");
  t = r.get<double>(pre + "t");
  steps = static_cast<long>(r.get<std::int64_t>(pre + "steps"));
  energy = r.get<Energies>(pre + "energy");
  contact.dissipated = r.get<double>(pre + "contact_dissipated");
  dashpot_solve = {};
  if (consistent_ && r.has(pre + "dashpot_solve")) {
    std::vector<std::int64_t> d;
    r.get(pre + "dashpot_solve", d, 5);
    dashpot_solve = {d[0], d[1], d[2], d[3], d[4]};
  }
  edge_velocity_.clear();
  if (usf_edges()) read_node_records(r, pre, "edge_velocity", 5, edge_velocity_);
  delay_.clear();
  if (!delay_rho_.empty()) {  // records of the ring this case's dt and materials need
    delay_cap_ = delay_cap_needed();
    read_node_records(r, pre, "delay", delay_stride(), delay_);
    delay_map();
  }
}

// Records keyed by the whole grid's node (i, j) in their first two values (own_node_records):
// a whole number of them, each naming a node of the grid.
void Solver::read_node_records(const StateReader& r, const std::string& pre, const std::string& name,
                               std::size_t stride, std::vector<double>& v) const {
  r.get(pre + name, v);
  if (v.size() % stride != 0)
    r.fail(name + " holds " + std::to_string(v.size()) + " values, not a multiple of " +
           std::to_string(stride) + " (corrupt checkpoint)");
  for (std::size_t k = 0; k < v.size(); k += stride) {
    const double i = v[k], j = v[k + 1];
    if (!(i >= 0 && i < grid.nnx && j >= 0 && j < grid.nny && i == std::floor(i) &&
          j == std::floor(j)))
      r.fail(name + " names a node outside the grid (corrupt checkpoint)");
  }
}

bool Solver::load_state(const StateReader& r, const std::string& pre) {
  const std::size_t n = p.size();
  if (r.get<std::uint8_t>(pre + "film") != static_cast<std::uint8_t>(p.has_film()))
    r.fail("the film model's history is " + std::string(p.has_film() ? "absent" : "present") +
           " in the checkpoint and the opposite in this case (a checkpoint of another case)");
  particle_arrays(p, [&](const char* name, auto& v) { r.get(pre + "p." + name, v, n); });
  ++order_version_;  // positions and order from the file
  for (std::size_t k = 0; k < silents.size(); ++k) {
    if (!silents[k].springs()) continue;
    const std::size_t m = silents[k].layer.ids.size();
    const std::string name = pre + "silent" + std::to_string(k);
    r.get(name + ".ux", silents[k].ux, m);
    r.get(name + ".uy", silents[k].uy, m);
    if (r.has(name + ".ids"))
      reorder_by_ids(r, name, silents[k].layer, n, {{&silents[k].ux, 1}, {&silents[k].uy, 1}});
  }
  for (std::size_t k = 0; k < dampers.size(); ++k) {
    if (!(dampers[k].beta0 > 0)) continue;
    const std::string name = pre + "damper" + std::to_string(k);
    r.get(name + ".sv", dampers[k].sv, 3 * dampers[k].layer.ids.size());
    if (r.has(name + ".ids")) reorder_by_ids(r, name, dampers[k].layer, n, {{&dampers[k].sv, 3}});
  }
  if (pml.active()) {
    const std::size_t m = pml.layer.ids.size();
    r.get(pre + "pml.H", pml.H, 4 * m);
    r.get(pre + "pml.u", pml.u, 2 * m);
    r.get(pre + "pml.xi", pml.xi, 4 * m);
    r.get(pre + "pml.zeta", pml.zeta, 4 * m);
    if (r.has(pre + "pml.ids"))
      reorder_by_ids(r, pre + "pml", pml.layer, n,
                     {{&pml.H, 4}, {&pml.u, 2}, {&pml.xi, 4}, {&pml.zeta, 4}});
  }
  load_clock(r, pre);
  // What the step indexes with must be valid whatever the file says (a checksum guards against
  // accidents, not edits): ids a permutation, groups and bodies in range, particles finite and
  // on the grid.
  const std::size_t G = std::max<std::size_t>(1, materials.size());
  std::vector<uint8_t> seen(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    if (p.id[k] >= n || seen[p.id[k]]++)
      r.fail("particle ids are not a permutation (corrupt checkpoint)");
    if (p.group[k] >= G) r.fail("particle material group out of range (corrupt checkpoint)");
    if (!std::isfinite(p.x[k]) || !std::isfinite(p.y[k]) || !grid.inside(p.x[k], p.y[k]))
      r.fail("particle " + std::to_string(p.id[k]) + " is not on the grid (corrupt checkpoint)");
  }
  where_.assign(n, 0);
  for (std::size_t k = 0; k < n; ++k) where_[p.id[k]] = static_cast<uint32_t>(k);
  auto reindex = [&](BoundaryLayer& L) {
    for (std::size_t k = 0; k < L.ids.size(); ++k) L.idx[k] = where_[L.ids[k]];
  };
  for (auto& tl : tractions) reindex(tl.layer);
  for (auto& sl : silents) reindex(sl.layer);
  for (auto& dl : dampers) reindex(dl.layer);
  reindex(pml.layer);

  const int saved_strips = r.get<std::int32_t>(pre + "strips");
  if (saved_strips != nstrips_) {
    // Another thread count: the particles are re-cut into this run's strips. The continuation is
    // the same computation with sums over particles in another order (round-off differences).
    sort_particles();
    return false;
  }
  // The ranges must tile [0, n) in order, each holding particles of its own group.
  std::vector<std::uint32_t> ranges;
  r.get(pre + "ranges", ranges, 2 * nstrips_ * G);
  std::uint32_t next = 0;
  for (std::size_t k = 0; k < ranges_.size(); ++k) {
    if (ranges[2 * k] != next || ranges[2 * k + 1] < next || ranges[2 * k + 1] > n)
      r.fail("particle ranges do not tile the particles (corrupt checkpoint)");
    for (std::uint32_t q = ranges[2 * k]; q < ranges[2 * k + 1]; ++q)
      if (p.group[q] != k % G) r.fail("particle ranges mix material groups (corrupt checkpoint)");
    ranges_[k] = {ranges[2 * k], ranges[2 * k + 1]};
    next = ranges[2 * k + 1];
  }
  if (next != n) r.fail("particle ranges do not tile the particles (corrupt checkpoint)");
  // The strip rows and their conflict flag follow from the positions and the ranges exactly as
  // the last step's moving pass left them (the same floor of the same coordinates).
  refresh_strip_rows();
  strips_ok_ = !strips_conflict();
  refresh_fields();
  std::vector<std::int32_t> boxes;
  r.get(pre + "field_boxes", boxes, 4 * fields_.size());
  for (std::size_t k = 0; k < fields_.size(); ++k) {
    NodeBox b{boxes[4 * k], boxes[4 * k + 1], boxes[4 * k + 2], boxes[4 * k + 3]};
    if (!box_empty(b) && (b[0] < 0 || b[1] >= grid.nnx || b[2] < 0 || b[3] >= grid.nny))
      r.fail("a node box lies outside the grid (corrupt checkpoint)");
    fields_[k].box = b;
  }
  return true;
}

}  // namespace smpm
