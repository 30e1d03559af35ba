#include "silentmpm/solver.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "silentmpm/dashpot.hpp"
#include "silentmpm/film.hpp"
#include "silentmpm/shape.hpp"

namespace smpm {

const char* scheme_name(Scheme s) {
  switch (s) {
    case Scheme::USF: return "USF";
    case Scheme::USL: return "USL";
    case Scheme::MUSL: return "MUSL";
  }
  return "?";
}

const char* shape_name(ShapeKind s) {
  switch (s) {
    case ShapeKind::Bilinear: return "bilinear";
    case ShapeKind::UGimp: return "gimp";
    case ShapeKind::BSpline2: return "bspline";
  }
  return "?";
}

const char* model_name(Model m) {
  switch (m) {
    case Model::Elastic: return "elastic";
    case Model::VonMises: return "von_mises";
    case Model::J2Film: return "j2_softening";
  }
  return "?";
}

// ------------------------------------------------------------------------------------------
// Setup
// ------------------------------------------------------------------------------------------

void Solver::gauss_point(int n, int j, double& at, double& weight) {
  if (n == 1) {
    at = 0.5;
    weight = 1;
  } else if (n == 2) {
    at = 0.5 + (j == 0 ? -0.5 : 0.5) / std::sqrt(3.0);
    weight = 0.5;
  } else if (n == 3) {
    at = 0.5 + 0.5 * (j - 1) * std::sqrt(0.6);
    weight = j == 1 ? 8.0 / 18.0 : 5.0 / 18.0;
  } else {
    throw std::invalid_argument("gauss_point: 1 to 3 points per cell side, got " +
                                std::to_string(n));
  }
}

std::size_t Solver::seed_rectangle(double x0, double y0, double x1, double y1, int n, int group,
                                   int body, double vx0, double vy0, Seeding seeding) {
  const double sp = grid.h / n;
  const long cx = std::max(1L, std::lround((x1 - x0) / sp));
  const long cy = std::max(1L, std::lround((y1 - y0) / sp));
  const double dx = (x1 - x0) / cx, dy = (y1 - y0) / cy;
  const double rho = materials.at(group).rho;
  if (seeding == Seeding::Gauss && (cx % n != 0 || cy % n != 0))
    throw std::invalid_argument("seed_rectangle: Gauss points need a whole number of cells, got " +
                                std::to_string((x1 - x0) / grid.h) + " x " +
                                std::to_string((y1 - y0) / grid.h));
  if (seed_nothing) return cx * cy;
  const std::size_t first = p.size();
  p.resize(first + cx * cy);
  ++order_version_;
  std::size_t k = first;
  if (seeding == Seeding::Gauss) {
    // Sub-lattice point i lies in cell i / n at its Gauss point i % n.
    const double wx = n * dx, wy = n * dy;
    for (long j = 0; j < cy; ++j) {
      double ay, sy;
      gauss_point(n, static_cast<int>(j % n), ay, sy);
      for (long i = 0; i < cx; ++i, ++k) {
        double ax, sx;
        gauss_point(n, static_cast<int>(i % n), ax, sx);
        p.place(k, x0 + (static_cast<double>(i / n) + ax) * wx,
                y0 + (static_cast<double>(j / n) + ay) * wy, sx * sy * wx * wy, rho, vx0, vy0,
                body, group);
      }
    }
    return cx * cy;
  }
  for (long j = 0; j < cy; ++j)
    for (long i = 0; i < cx; ++i, ++k)
      p.place(k, x0 + (i + 0.5) * dx, y0 + (j + 0.5) * dy, dx * dy, rho, vx0, vy0, body, group);
  return cx * cy;
}

BoundaryLayer Solver::select_layer(const std::string& name, int body, double ex0, double ey0,
                                   double ex1, double ey1, double nx, double ny,
                                   double width) const {
  BoundaryLayer L;
  L.name = name;
  L.depth = width;
  const double nn = std::hypot(nx, ny);
  nx /= nn; ny /= nn;
  const double tx = ex1 - ex0, ty = ey1 - ey0;
  L.length = std::hypot(tx, ty);
  const double tol = 1e-9 * grid.h;
  double vsum = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (p.body[k] != body) continue;
    const double rx = p.x[k] - ex0, ry = p.y[k] - ey0;
    const double dist = -(rx * nx + ry * ny);  // depth inside the body
    const double s = (rx * tx + ry * ty) / (L.length * L.length);
    if (dist < -tol || dist >= width - tol || s < -1e-9 || s > 1 + 1e-9) continue;
    L.ids.push_back(p.id[k]);
    L.idx.push_back(static_cast<uint32_t>(k));
    L.nx.push_back(nx);
    L.ny.push_back(ny);
    L.w.push_back(p.vol[k]);
    L.d.push_back(std::max(dist, 0.0));
    vsum += p.vol[k];
  }
  if (vsum > 0) {
    L.width = vsum / L.length;
    for (double& w : L.w) w /= L.width;
  }
  return L;
}

std::vector<uint32_t> Solver::nodes_in_box(double x0, double y0, double x1, double y1) const {
  std::vector<uint32_t> out;
  const double tol = 1e-3 * grid.h;
  for (int j = 0; j < grid.nny; ++j) {
    const double y = grid.node_y(j);
    if (y < y0 - tol || y > y1 + tol) continue;
    for (int i = 0; i < grid.nnx; ++i) {
      const double x = grid.node_x(i);
      if (x < x0 - tol || x > x1 + tol) continue;
      out.push_back(static_cast<uint32_t>(j * grid.nnx + i));
    }
  }
  return out;
}

double Solver::viscous_beta() const {
  bool any = false;
  for (const auto& dl : dampers) any = any || dl.beta0 > 0;
  if (!any) return 0;
  std::vector<double> sum(p.size(), 0.0);
  for (const auto& dl : dampers) {
    if (!(dl.beta0 > 0)) continue;
    const BoundaryLayer& L = dl.layer;
    for (std::size_t q = 0; q < L.idx.size(); ++q)
      sum[L.idx[q]] += dl.beta0 * std::pow(std::clamp(1.0 - L.d[q] / L.depth, 0.0, 1.0), dl.power);
  }
  return sum.empty() ? 0.0 : *std::max_element(sum.begin(), sum.end());
}

double Solver::critical_dt() const {
  double cmax = 0;
  for (const auto& m : materials) cmax = std::max(cmax, m.cd);
  if (!(cmax > 0)) return std::numeric_limits<double>::infinity();
  double dt_c = grid.h / cmax;
  // A damping layer's stiffness-proportional part, explicit: central differences with a lagged
  // viscous force are stable for dt <= (2 / w)(sqrt(1 + xi^2) - xi), xi = beta w / 2, at the
  // grid's highest frequency w = 2 / dt_c; beta at a particle in two layers (a corner) is the
  // sum of theirs.
  const double beta = viscous_beta_ >= 0 ? viscous_beta_ : viscous_beta();
  if (beta > 0) {
    const double xi = beta / dt_c;
    dt_c *= std::sqrt(1 + xi * xi) - xi;
  }
  return dt_c;
}

long Solver::first_particle_outside() const {
  for (std::size_t k = 0; k < p.size(); ++k)
    if (!grid.inside(p.x[k], p.y[k])) return static_cast<long>(k);
  return -1;
}

void Solver::finalize() {
  nthreads_ = opt.threads > 0 ? opt.threads : omp_get_max_threads();
  if (!dist_) {
    whole_x0_ = grid.x0;
    whole_y0_ = grid.y0;
  }
  if (contact.multi()) contact.setup(*this);  // splits material groups, one field per body
  // The mass correction (correct_increments): 0 to 8 terms.
  if (opt.mass_correction < 0 || opt.mass_correction > 8)
    throw std::invalid_argument("mass_correction: terms must be 0 to 8, got " +
                                std::to_string(opt.mass_correction));
  if (symmetric_correction() && opt.scheme == Scheme::USL)
    throw std::invalid_argument("mass_correction: the symmetric form needs MUSL or USF");
  if (symmetric_correction() && contact.multi())
    throw std::invalid_argument("mass_correction: the symmetric form with multi-field contact");
  if (opt.light_node_ratio < 0 || opt.light_node_ratio > 0.25)
    throw std::invalid_argument("light_node_ratio: must be 0 (off) or in (0, 0.25], got " +
                                std::to_string(opt.light_node_ratio));
  if (opt.light_node_ratio > 0 && contact.multi())
    throw std::invalid_argument("light_nodes: the extension with multi-field contact");
  for (const Material& m : materials)
    if (m.model == Model::J2Film && !p.has_film()) p.enable_film();
  nstrips_ = 2 * nthreads_;
  stencil_rows_ = opt.shape == ShapeKind::Bilinear ? Bilinear::kRowsBelow + Bilinear::kRowsAbove
                                                   : BSpline2::kRowsBelow + BSpline2::kRowsAbove;
  double mmin = std::numeric_limits<double>::infinity();
  for (double m : p.mass) mmin = std::min(mmin, m);
  mass_floor_ = p.size() ? opt.mass_tolerance * mmin : 0.0;
  light_nodes.ratio = opt.light_node_ratio;
  std::fill(grid.fix.begin(), grid.fix.end(), 0);
  for (const auto& c : constraints)
    for (uint32_t n : c.nodes) grid.fix[n] |= c.mask;
  // Dashpot coefficients from the material of each layer particle.
  has_springs_ = false;
  for (auto& s : silents) {
    has_springs_ = has_springs_ || s.springs();
    s.zn.resize(s.layer.idx.size());
    s.zt.resize(s.layer.idx.size());
    for (std::size_t k = 0; k < s.layer.idx.size(); ++k) {
      const Material& m = materials[p.group[s.layer.idx[k]]];
      s.zn[k] = s.a * m.rho * m.cd;
      s.zt[k] = s.b * m.rho * m.cs;
    }
    if (!s.springs()) continue;
    s.kn.resize(s.zn.size());
    s.kt.resize(s.zn.size());
    s.ux.assign(s.zn.size(), 0.0);
    s.uy.assign(s.zn.size(), 0.0);
    for (std::size_t k = 0; k < s.layer.idx.size(); ++k) {
      const Material& m = materials[p.group[s.layer.idx[k]]];
      s.kn[k] = s.alpha_n * m.rho * m.cd * m.cd / s.delta;
      s.kt[k] = s.alpha_t * m.rho * m.cs * m.cs / s.delta;
    }
  }
  bool updated = false;  // a layer strained with the updated velocity (MUSL or USF, one field)
  for (const auto& s : silents)
    updated = updated || (s.form == SilentForm::Nodal && s.updated_velocity);
  updated = updated && (opt.scheme == Scheme::MUSL || opt.scheme == Scheme::USF) &&
            body_of_group_.empty();
  updated_weight_.assign(updated ? grid.nodes() : 0, 0.0);
  edge_velocity_.clear();
  // A nodal layer with the default edge velocity or the delayed closure (whose tangential
  // component takes the particles' mean), MUSL or USF, one field.
  bool consistent = false;
  for (const auto& s : silents)
    consistent = consistent || (s.form == SilentForm::Nodal && !s.updated_velocity);
  consistent = consistent && (opt.scheme == Scheme::MUSL || opt.scheme == Scheme::USF) &&
               body_of_group_.empty();
  consistent_ = consistent;
  // The solve's weights start from zero (apply_loads clears only the nodes it listed).
  for (std::size_t n = 0; n < grid.dash.size() / Grid::kDash; ++n) grid.dash_weight(n) = 0;
  cm_nodes_.clear();
  cm_slot_.assign(consistent ? grid.nodes() : 0, -1);
  cm_cover_.assign(consistent ? grid.nodes() : 0, 0);
  cm_covered_.clear();
  cm_moving_.clear();
  cm_cell_.assign(consistent ? static_cast<std::size_t>(grid.nx) * grid.ny : 0, 0);
  cm_cells_.clear();
  cm_reach_.clear();
  bool delayed = false;  // a layer with the delayed closure (MUSL or USF, one field)
  for (const auto& s : silents) delayed = delayed || (s.form == SilentForm::Nodal && s.delayed);
  delayed = delayed && (opt.scheme == Scheme::MUSL || opt.scheme == Scheme::USF) &&
            body_of_group_.empty();
  delay_rho_.assign(delayed ? grid.nodes() : 0, 0.0);
  delay_.clear();
  delay_cap_ = 0;
  if (delayed) {  // the slowest wave speed of the materials (delay_prepare); of every material,
                  // not the layers' particles': a rank's skeleton has none yet
    double cmin = 0;
    for (const Material& m : materials) {
      const double c = m.cs > 0 ? m.cs : m.cd;
      if (c > 0) cmin = cmin > 0 ? std::min(cmin, c) : c;
    }
    delay_cmin_ = cmin;
  }
  delay_map();
  // Damping of each layer particle from its depth and its material's c_d.
  for (auto& dl : dampers) {
    const BoundaryLayer& L = dl.layer;
    dl.alpha.resize(L.idx.size());
    for (std::size_t k = 0; k < L.idx.size(); ++k) {
      const Material& m = materials[p.group[L.idx[k]]];
      const double a0 = -(dl.power + 1) * m.cd * std::log(dl.r0) / L.depth;
      const double sdep = std::clamp(1.0 - L.d[k] / L.depth, 0.0, 1.0);
      dl.alpha[k] = a0 * std::pow(sdep, dl.power);
    }
    dl.beta.assign(L.idx.size(), 0.0);
    dl.sv.assign(3 * L.idx.size(), 0.0);
    if (dl.beta0 > 0)
      for (std::size_t k = 0; k < L.idx.size(); ++k)
        dl.beta[k] = dl.beta0 * std::pow(std::clamp(1.0 - L.d[k] / L.depth, 0.0, 1.0), dl.power);
  }
  viscous_beta_ = viscous_beta();  // the whole body's (a rank keeps it after the split)
  // Perfectly matched layers: every particle of a band's body inside it, with d_x and d_y summed
  // over the bands (both at a corner) from its position at the start.
  pml = PmlLayer{};
  for (std::size_t k = 0; k < p.size() && !pml_bands.empty(); ++k) {
    const Material& m = materials[p.group[k]];
    double dx = 0, dy = 0;
    for (const PmlBand& b : pml_bands) {
      if (b.body != p.body[k]) continue;
      const double pos = b.axis == 0 ? p.x[k] : p.y[k];
      const double s = (pos - (b.c - b.side * b.width)) * b.side / b.width;  // 0 at the inner edge
      if (!(s > 0)) continue;
      const double d0 = pml_d0(m.cd, b.r0, b.power, b.width);
      const double d = d0 * std::pow(std::min(s, 1.0), b.power);
      (b.axis == 0 ? dx : dy) += d;
      (b.axis == 0 ? dy : dx) += b.parallel * d;  // a multi-axial layer's share along the side
    }
    if (!(dx + dy > 0)) continue;
    pml.layer.ids.push_back(p.id[k]);
    pml.layer.idx.push_back(static_cast<uint32_t>(k));
    pml.dx.push_back(dx);
    pml.dy.push_back(dy);
    // The share of the grid's velocity the particle takes (pml_pic): (depth / width)^5 in its
    // deepest band.
    double depth = 0;
    for (const PmlBand& b : pml_bands)
      if (b.body == p.body[k]) {
        const double pos = b.axis == 0 ? p.x[k] : p.y[k];
        depth = std::max(depth, (pos - (b.c - b.side * b.width)) * b.side / b.width);
      }
    pml.pic.push_back(std::pow(std::min(depth, 1.0), kPmlPicPower));
  }
  if (!pml_bands.empty()) {  // (a skeleton too: its particles arrive later)
    pml.layer.name = "pml";
    pml.alpha = pml_bands.front().alpha;
  }
  if (pml.active()) {
    const std::size_t n = pml.layer.ids.size();
    pml.H.assign(4 * n, 0.0);
    pml.u.assign(2 * n, 0.0);
    pml.xi.assign(4 * n, 0.0);
    pml.zeta.assign(4 * n, 0.0);
    pml.f.assign(6 * n, 0.0);
  }
  sort_particles();
  update_energies();
  energy.initial = energy.kinetic + energy.elastic;
  double mc2 = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double c = p.group[k] < materials.size() ? materials[p.group[k]].cd : 0.0;
    mc2 += p.mass[k] * c * c;
  }
  energy_floor_ = 1e-12 * mc2;
}

// Order particles by (strip, material group, cell row) with a stable counting sort. Strips are
// bands of cell rows holding about the same number of particles.
void Solver::sort_particles() {
  const std::size_t n = p.size();
  const int G = static_cast<int>(std::max<std::size_t>(1, materials.size()));
  const int ny = grid.ny;
  std::vector<int> row(n);
  std::vector<std::size_t> per_row(ny, 0);
  for (std::size_t k = 0; k < n; ++k) {
    int r = static_cast<int>(std::floor((p.y[k] - grid.y0) * grid.inv_h));
    r = std::clamp(r, 0, ny - 1);
    row[k] = r;
    ++per_row[r];
  }
  std::vector<int> strip_of_row(ny);
  {
    std::size_t acc = 0;
    for (int r = 0; r < ny; ++r) {
      int s = n ? static_cast<int>((acc + per_row[r] / 2) * nstrips_ / n) : 0;
      strip_of_row[r] = std::min(s, nstrips_ - 1);
      acc += per_row[r];
    }
  }
  const std::size_t nkeys = static_cast<std::size_t>(nstrips_) * G * ny;
  std::vector<uint32_t> count(nkeys + 1, 0);
  std::vector<uint32_t> key(n);
  for (std::size_t k = 0; k < n; ++k) {
    key[k] = (static_cast<uint32_t>(strip_of_row[row[k]]) * G + p.group[k]) * ny + row[k];
    ++count[key[k] + 1];
  }
  for (std::size_t i = 0; i < nkeys; ++i) count[i + 1] += count[i];
  ranges_.assign(static_cast<std::size_t>(nstrips_) * G, {0, 0});
  for (int s = 0; s < nstrips_; ++s)
    for (int g = 0; g < G; ++g) {
      const std::size_t k0 = (static_cast<std::size_t>(s) * G + g) * ny;
      ranges_[s * G + g] = {count[k0], count[k0 + ny]};
    }
  std::vector<uint32_t> perm(n);
  for (std::size_t k = 0; k < n; ++k) perm[count[key[k]]++] = static_cast<uint32_t>(k);
  p.permute(perm);
  ++order_version_;
  // Ids run over 0 .. n - 1, except on a rank of a decomposition, which holds some of them.
  uint32_t id_end = 0;
  for (std::size_t k = 0; k < n; ++k) id_end = std::max(id_end, p.id[k] + 1);
  where_.assign(id_end, 0);
  for (std::size_t k = 0; k < n; ++k) where_[p.id[k]] = static_cast<uint32_t>(k);
  for (auto& tl : tractions)
    for (std::size_t k = 0; k < tl.layer.ids.size(); ++k) tl.layer.idx[k] = where_[tl.layer.ids[k]];
  for (auto& sl : silents)
    for (std::size_t k = 0; k < sl.layer.ids.size(); ++k) sl.layer.idx[k] = where_[sl.layer.ids[k]];
  for (auto& dl : dampers)
    for (std::size_t k = 0; k < dl.layer.ids.size(); ++k) dl.layer.idx[k] = where_[dl.layer.ids[k]];
  for (std::size_t k = 0; k < pml.layer.ids.size(); ++k) pml.layer.idx[k] = where_[pml.layer.ids[k]];
  refresh_strip_rows();
  strips_ok_ = !strips_conflict();
  refresh_fields();
}

void Solver::refresh_strip_rows() {
  const int G = static_cast<int>(std::max<std::size_t>(1, materials.size()));
  strip_lo_.assign(nstrips_, std::numeric_limits<int>::max());
  strip_hi_.assign(nstrips_, std::numeric_limits<int>::min());
  strip_out_.assign(nstrips_, 0);
  for (int s = 0; s < nstrips_; ++s)
    for (int g = 0; g < G; ++g)
      for (uint32_t k = ranges_[s * G + g][0]; k < ranges_[s * G + g][1]; ++k) {
        const int r = static_cast<int>(std::floor((p.y[k] - grid.y0) * grid.inv_h));
        strip_lo_[s] = std::min(strip_lo_[s], r);
        strip_hi_[s] = std::max(strip_hi_[s], r);
      }
}

// Two strips of one colour must not write a common node row: a strip touching cell rows
// [lo, hi] writes node rows [lo - below, hi + above] (bilinear: [lo, hi + 1]; 3 x 3 shapes:
// [lo - 1, hi + 2]), so two strips conflict when they are less than below + above rows apart.
bool Solver::strips_conflict() const {
  if (nthreads_ == 1) return false;
  const int d = stencil_rows_;
  for (int a = 0; a < nstrips_; ++a) {
    if (strip_lo_[a] > strip_hi_[a]) continue;
    for (int b = a + 2; b < nstrips_; b += 2) {
      if (strip_lo_[b] > strip_hi_[b]) continue;
      if (strip_lo_[a] <= strip_hi_[b] + d && strip_lo_[b] <= strip_hi_[a] + d) return true;
    }
  }
  return false;
}

// ------------------------------------------------------------------------------------------
// Fields, hooks and loop helpers
// ------------------------------------------------------------------------------------------

void Solver::attach(StepHooks* h) { hooks_.push_back(h); }

void Solver::detach(StepHooks* h) {
  hooks_.erase(std::remove(hooks_.begin(), hooks_.end(), h), hooks_.end());
}

double Solver::inv_rho(int g) const {
  return g < static_cast<int>(materials.size()) ? 1.0 / materials[g].rho : 0.0;
}

// V/m above which a particle of group g is stretched past the stability limit: with constant
// moduli and the current density rho0 / J its dilatational speed is c_d sqrt(J), so dt stays
// below h / (c_d sqrt(J)) while J <= (h / (c_d dt))^2 = 1 / CFL^2, i.e. V/m <= 1 / (CFL^2 rho0).
// The check allows 10 % over that (kStretchMargin): at CFL 1 a particle's elastic strain alone
// crosses 1 / CFL^2, and runs at CFL 1 stay stable through it (SilentStability.* in the column
// tests); a particle 10 % past is stretched by far more than elasticity. Off (infinite) for the
// film model, whose decohered particles carry no stress and may open freely.
double Solver::stretch_limit(int g) const {
  constexpr double kStretchMargin = 1.1;
  if (g >= static_cast<int>(materials.size())) return std::numeric_limits<double>::infinity();
  const Material& m = materials[g];
  if (m.model == Model::J2Film || !(m.cd > 0) || !(dt > 0))
    return std::numeric_limits<double>::infinity();
  const double r = grid.h / (m.cd * dt);
  return kStretchMargin * r * r / m.rho;
}

template <class Fn>
void Solver::call(Fn&& fn) {
  if (contact.multi()) fn(contact);
  for (StepHooks* h : hooks_) fn(*h);
}

void Solver::use_body_fields(const std::vector<NodalField>& fields,
                             const std::vector<int>& body_of_group) {
  fields_.assign(fields.size(), VelocityField());
  for (std::size_t b = 0; b < fields.size(); ++b) {
    fields_[b].f = fields[b];
    fields_[b].body = static_cast<int>(b);
  }
  body_of_group_ = body_of_group;
}

// The particle ranges of every field after a re-sort: the grid's own field takes every range, a
// body's field the ranges of that body's groups (the others emptied).
void Solver::refresh_fields() {
  if (body_of_group_.empty()) {
    fields_.resize(1);
    VelocityField& F = fields_[0];
    Grid& g = grid;
    F.f = NodalField{g.m.data(),  g.px.data(),  g.py.data(),  g.fx.data(), g.fy.data(),
                     g.vx.data(), g.vy.data(),  g.vnx.data(), g.vny.data(), g.qx.data(),
                     g.qy.data()};
    F.box = {0, g.nnx - 1, 0, g.nny - 1};
    F.body = -1;
    F.ranges = ranges_;
    return;
  }
  const int G = static_cast<int>(std::max<std::size_t>(1, materials.size()));
  for (VelocityField& F : fields_) {
    F.ranges = ranges_;
    for (int st = 0; st < nstrips_; ++st)
      for (int g = 0; g < G; ++g)
        if (body_of_group_[g] != F.body) F.ranges[st * G + g] = {0, 0};
  }
}

void Solver::occupied_rows(long& lo, long& hi) const {
  lo = std::numeric_limits<long>::max();
  hi = std::numeric_limits<long>::min();
  for (int s = 0; s < nstrips_; ++s)
    if (strip_lo_[s] <= strip_hi_[s]) {
      lo = std::min<long>(lo, strip_lo_[s]);
      hi = std::max<long>(hi, strip_hi_[s]);
    }
}

// fn(begin, end, group, strip) for every range; no two concurrent ranges write one node.
template <class Fn>
void Solver::scatter(const std::vector<std::array<uint32_t, 2>>& ranges, Fn&& fn) {
  const int G = static_cast<int>(std::max<std::size_t>(1, materials.size()));
  if (!strips_ok_ || nthreads_ == 1) {
    for (int s = 0; s < nstrips_; ++s)
      for (int g = 0; g < G; ++g) fn(ranges[s * G + g][0], ranges[s * G + g][1], g, s);
    return;
  }
  for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(static, 1) num_threads(nthreads_)
    for (int s = colour; s < nstrips_; s += 2)
      for (int g = 0; g < G; ++g) fn(ranges[s * G + g][0], ranges[s * G + g][1], g, s);
  }
}

// fn(begin, end, group, strip) for every range, strips in parallel (no scatter allowed).
template <class Fn>
void Solver::parallel(const std::vector<std::array<uint32_t, 2>>& ranges, Fn&& fn) {
  const int G = static_cast<int>(std::max<std::size_t>(1, materials.size()));
#pragma omp parallel for schedule(static, 1) num_threads(nthreads_)
  for (int s = 0; s < nstrips_; ++s)
    for (int g = 0; g < G; ++g) fn(ranges[s * G + g][0], ranges[s * G + g][1], g, s);
}

// ------------------------------------------------------------------------------------------
// Stages
// ------------------------------------------------------------------------------------------

namespace {
// This thread's share [i0, i1) of [0, n), as schedule(static) splits it.
void omp_range(long n, long& i0, long& i1) {
  const long t = omp_get_thread_num(), nt = omp_get_num_threads();
  const long q = n / nt, r = n % nt;
  i0 = t * q + std::min(t, r);
  i1 = i0 + q + (t < r ? 1 : 0);
}
}  // namespace

// Streaming stores write lines to memory without reading them first (a plain store reads each
// line into the cache before it writes it); the x86 targets have them (SSE2 and up).
#if defined(__SSE2__)
constexpr bool kStreamingStores = true;
#else
constexpr bool kStreamingStores = false;
#endif
// Orders this thread's streaming stores before what follows (the barrier at a pass's end).
static void fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

// Zeros into [a, a + n), with streaming stores where the target has them.
static void stream_zero(double* a, long n) {
  long i = 0;
#if defined(__AVX512F__)
  for (; i < n && (reinterpret_cast<std::uintptr_t>(a + i) & 63) != 0; ++i) a[i] = 0;
  const __m512d z = _mm512_setzero_pd();
  for (; i + 8 <= n; i += 8) _mm512_stream_pd(a + i, z);
#elif defined(__AVX__)
  for (; i < n && (reinterpret_cast<std::uintptr_t>(a + i) & 31) != 0; ++i) a[i] = 0;
  const __m256d z = _mm256_setzero_pd();
  for (; i + 4 <= n; i += 4) _mm256_stream_pd(a + i, z);
#elif defined(__SSE2__)
  for (; i < n && (reinterpret_cast<std::uintptr_t>(a + i) & 15) != 0; ++i) a[i] = 0;
  const __m128d z = _mm_setzero_pd();
  for (; i + 2 <= n; i += 2) _mm_stream_pd(a + i, z);
#endif
  for (; i < n; ++i) a[i] = 0;
  fence();
}

// Whether this step's write-only grid passes (the reset, the update's four velocity arrays)
// stream their stores. Where those arrays fit the cache, the next pass reads them back from
// there, and streaming them past it costs (+20 % a step at 10^5 particles on the Intel host of
// the README, for the reset alone); where they do not, it saves the reads of lines about to be
// overwritten (the reset's traffic halved: -5 to -8 % a step at 4 * 10^6, -10 % with the update's).
// How much fits depends on the host, so a grid whose reset clears at least kStreamTrialBytes
// takes both ways in turn on steps 3 to 10 of the run, timed, and keeps streaming only if its
// fastest step is faster by 2 % (Solver::streaming overrides). Either way, the same values.
int Solver::store_mode() const {
  return !kStreamingStores ? 0 : streaming >= 0 ? (streaming > 0 ? 1 : 0) : stream_choice_;
}

bool Solver::stores_stream() const {
  const int mode = store_mode();
  return mode > 0 || (mode < 0 && stream_trial_ >= 0 && stream_trial_ % 2 == 1);
}

void Solver::time_stores(double seconds) {
  if (store_mode() >= 0) return;
  const double bytes = 8.0 * static_cast<double>(grid.nodes()) * reset_arrays();
  if (!kStreamingStores || bytes < kStreamTrialBytes) {
    stream_choice_ = 0;
    return;
  }
  if (stream_trial_ >= 0) stream_time_[stream_trial_ % 2][stream_trial_ / 2] = seconds;
  if (++stream_trial_ < 8) return;
  const double plain = *std::min_element(stream_time_[0], stream_time_[0] + 4);
  const double streamed = *std::min_element(stream_time_[1], stream_time_[1] + 4);
  stream_choice_ = streamed < 0.98 * plain ? 1 : 0;
}

// The grid arrays the reset clears: mass, momenta and forces, and the re-mapped momenta of
// MUSL's re-map (USF: for the loads' power).
int Solver::reset_arrays() const { return opt.scheme != Scheme::USL ? 7 : 5; }

void Solver::reset_grid() {
  const long n = static_cast<long>(grid.nodes());
  if (stores_stream()) {
    double* a[7] = {grid.m.data(),  grid.px.data(), grid.py.data(), grid.fx.data(),
                    grid.fy.data(), grid.qx.data(), grid.qy.data()};
#pragma omp parallel num_threads(nthreads_)
    {
      long i0, i1;
      omp_range(n, i0, i1);
      for (int k = 0; k < reset_arrays(); ++k) stream_zero(a[k] + i0, i1 - i0);
    }
    return;
  }
  double* m = grid.m.data();
  double* px = grid.px.data();
  double* py = grid.py.data();
  double* fx = grid.fx.data();
  double* fy = grid.fy.data();
#pragma omp parallel for simd schedule(static) num_threads(nthreads_)
  for (long i = 0; i < n; ++i) {
    m[i] = 0; px[i] = 0; py[i] = 0; fx[i] = 0; fy[i] = 0;
  }
  if (reset_arrays() == 7) {  // the re-mapped momenta too
    std::fill(grid.qx.begin(), grid.qx.end(), 0.0);
    std::fill(grid.qy.begin(), grid.qy.end(), 0.0);
  }
}

// p2g over every field. A body's field clears its arrays over last step's box first and finds
// its new box; with body fields the grid's arrays (cleared by reset_grid) then receive their sum,
// the centre-of-mass field.
template <class S>
void Solver::p2g(unsigned what) {
  const bool momentum = (what & kMomentum) != 0, force = (what & kForce) != 0;
  const long nnx = grid.nnx;
  for (VelocityField& F : fields_) {
    const NodalField& f = F.f;
    const bool body = F.body >= 0;
    std::vector<NodeBox> sbox;
    if (body && momentum) {
      double* a[10] = {f.m, f.px, f.py, f.gx, f.gy, f.xm, f.ym, f.sm, f.fx, f.fy};
      kernels::for_box(F.box, nnx, nthreads_, [&](long i) {
        for (double* v : a) v[i] = 0;
      });
      sbox.assign(nstrips_, NodeBox{1 << 30, -1, 1 << 30, -1});
    }
    auto run = [&](auto what_c) {
      constexpr unsigned W = decltype(what_c)::value;
      std::vector<unsigned> flags(nstrips_, 0);
      scatter(F.ranges, [&](uint32_t b, uint32_t e, int g, int s) {
        flags[s] |= kernels::p2g<S, W>(grid, p, b, e, f, inv_rho(g),
                                       (W & kContact) ? &sbox[s] : nullptr, stretch_limit(g));
      });
      for (unsigned n : flags) {
        collapsed_ += (n & kernels::kInverted) != 0;
        stretched_ += (n & kernels::kStretched) != 0;
      }
    };
    using std::integral_constant;
    if (body && momentum && force) run(integral_constant<unsigned, kMomentum | kForce | kContact>());
    else if (body && momentum) run(integral_constant<unsigned, kMomentum | kContact>());
    else if (momentum && force) run(integral_constant<unsigned, kMomentum | kForce>());
    else if (momentum) run(integral_constant<unsigned, kMomentum>());
    else run(integral_constant<unsigned, kForce>());
    if (body && momentum) {
      NodeBox u{1 << 30, -1, 1 << 30, -1};
      for (const NodeBox& q : sbox)
        u = {std::min(u[0], q[0]), std::max(u[1], q[1]), std::min(u[2], q[2]), std::max(u[3], q[3])};
      F.box = u;
    }
  }
  if (body_of_group_.empty()) return;
  Grid& gw = grid;
  for (const VelocityField& F : fields_) {
    const NodalField& f = F.f;
    kernels::for_box(F.box, nnx, nthreads_, [&](long i) {
      if (momentum) { gw.m[i] += f.m[i]; gw.px[i] += f.px[i]; gw.py[i] += f.py[i]; }
      if (force) { gw.fx[i] += f.fx[i]; gw.fy[i] += f.fy[i]; }
    });
  }
}

// USF: every field's start-of-step velocity p / m, with the constraints.
void Solver::start_velocities() {
  for (const VelocityField& F : fields_)
    kernels::nodal_velocity(grid, F.box, F.f.m, grid.fix.data(), F.f.px, F.f.py, F.f.vx, F.f.vy,
                            mass_floor_, nthreads_);
  // Layers strained with the updated velocity: the last step's v+ at their dashpot nodes, under
  // the mass condition of remapped_velocities() (docs/physics.md section 4).
  const std::array<int, 2> o = window_origin();
  for (std::size_t e = 0; e < edge_velocity_.size(); e += 5) {
    const long i = static_cast<long>(edge_velocity_[e]) - o[0];
    const long j = static_cast<long>(edge_velocity_[e + 1]) - o[1];
    if (i < 0 || j < 0 || i >= grid.nnx || j >= grid.nny) continue;
    const long n = j * grid.nnx + i;
    if (takes_updated(n, edge_velocity_[e + 2])) {
      grid.vx[n] = edge_velocity_[e + 3];
      grid.vy[n] = edge_velocity_[e + 4];
    }
  }
  if (!delay_rho_.empty() && delay_cap_ > 0)
    delay_strain_velocities(grid.vx.data(), grid.vy.data(), false);
}

// USF with layers strained with the updated velocity: this step's v+ at their dashpot nodes
// (those with a weight), for the next step's start_velocities().
void Solver::keep_edge_velocities() {
  edge_velocity_.clear();
  const std::array<int, 2> o = window_origin();
  for (const long n : dashpot_nodes_) {
    if (!(updated_weight_[n] > 0)) continue;
    const double i = static_cast<double>(n % grid.nnx + o[0]);
    const double j = static_cast<double>(n / grid.nnx + o[1]);
    edge_velocity_.insert(edge_velocity_.end(),
                          {i, j, updated_weight_[n], grid.vnx[n], grid.vny[n]});
  }
}

// The delayed closure of the LK edge at 1 particle per cell (SilentBoundary::delayed;
// docs/physics.md section 4). MUSL and USF then accelerate a particle with its two neighbours'
// stresses and strain it with their velocities: two sublattices, each a staggered scheme of
// spacing 2h. A right-going wave of such a scheme satisfies sigma(x + h) = -rho c v(x, t - h/c)
// exactly, where LK sets sigma(x) = -rho c v(x, t). At an edge node the closure gives the last
// particle that ghost stress: the dashpot acts with the node's start velocity of h/c - dt/2
// earlier (the half step of the leapfrog) on the node weighed as a whole one. The normal
// strain velocity there is the mean of the re-mapped one and the force of as long ago over
// the dashpot's coefficient, which keeps long runs bounded (delay_strain_velocities).
int Solver::delay_cap_needed() const {
  if (!(delay_cmin_ > 0 && dt > 0)) return 3;
  // (Bounded: a delay of a million steps would mean a wave that never crosses a cell.)
  return static_cast<int>(std::min(std::floor(grid.h / (delay_cmin_ * dt)), 1e6)) + 3;
}

void Solver::delay_map() {
  delay_slot_.assign(delay_rho_.empty() ? 0 : grid.nodes(), -1);
  if (delay_rho_.empty() || delay_cap_ == 0) return;
  const std::array<int, 2> o = window_origin();
  const std::size_t R = delay_stride();
  for (std::size_t r = 0; r * R < delay_.size(); ++r)
    if (const long n = delay_window_node(delay_.data() + r * R, o); n >= 0)
      delay_slot_[n] = static_cast<int>(r);
}

// A record for every node the delayed layers reach this step (in the order of the dashpot
// nodes, serially), the ring sized for this dt.
void Solver::delay_prepare() {
  const int cap = delay_cap_needed();
  if (cap != delay_cap_) {  // a new time step: the history restarts
    delay_cap_ = cap;
    delay_.clear();
    delay_map();
  }
  const std::array<int, 2> o = window_origin();
  const std::size_t R = delay_stride();
  for (const long n : dashpot_nodes_) {
    if (!(delay_rho_[n] > 0) || delay_slot_[n] >= 0) continue;
    delay_slot_[n] = static_cast<int>(delay_.size() / R);
    delay_.resize(delay_.size() + R, 0.0);
    double* rec = delay_.data() + delay_.size() - R;
    rec[kDelayI] = static_cast<double>(n % grid.nnx + o[0]);
    rec[kDelayJ] = static_cast<double>(n / grid.nnx + o[1]);
    rec[kDelayAt] = -1;
    rec[kDelayWritten] = -2;
    rec[kDelayBookedAt] = -2;
  }
}

// Field f (0, 1: start velocity x, y; 2, 3: force less gravity) of a record's ring, d steps
// (fractional) before the entry of `back` steps ago.
double Solver::delay_value(const double* rec, int field, double d, long back) const {
  d = std::clamp(d, 0.0, static_cast<double>(delay_cap_ - 2 - back));
  const long k = static_cast<long>(std::floor(d));
  const double f = d - static_cast<double>(k);
  const double* ring = rec + kDelayHead;
  auto at = [&](long b) {
    const long s = ((steps - b) % delay_cap_ + delay_cap_) % delay_cap_;
    return ring[4 * s + field];
  };
  return (1 - f) * at(back + k) + f * at(back + k + 1);
}

// The strain velocity at the delayed nodes: g <- (g + C^-1 f(t - tau)) / 2 per component
// (C diagonal: edges along the grid's axes). MUSL (current): the nodes delayed in this step's
// grid_update, with this step's ring entry the latest; USF (before the forces): those delayed
// in the last step, with its blocks. The change is kept for boundary_work's account.
void Solver::delay_strain_velocities(double* gx, double* gy, bool current) {
  const std::size_t R = delay_stride();
  const long back = current ? 0 : 1;
  const double want = static_cast<double>(steps - back);
  const std::array<int, 2> o = window_origin();
  for (std::size_t r = 0; r * R < delay_.size(); ++r) {
    double* rec = delay_.data() + r * R;
    rec[kDelayDgx] = rec[kDelayDgy] = 0;
    if (rec[kDelayAt] != want) continue;
    const long n = delay_window_node(rec, o);
    if (n < 0 || !(grid.m[n] > mass_floor_)) continue;
    const double c[2] = {rec[kDelayCxx], rec[kDelayCyy]};
    double* g[2] = {gx, gy};
    for (int a = 0; a < 2; ++a) {
      // The normal component only (the larger block: c_d against c_s; none at a corner, where
      // the two are alike): the tangential one made the column's edge unstable within 2 000
      // steps, and without the normal one a run grew after 4-9 * 10^4 (docs/physics.md).
      if ((grid.fix[n] & (1 << a)) || !(c[a] > c[1 - a])) continue;
      const double d = grid.h / (c[a] / rec[kDelayRho] * dt) - 0.5;
      const double ng = 0.5 * (g[a][n] + delay_value(rec, 2 + a, d, back) / c[a]);
      rec[kDelayDgx + a] = ng - g[a][n];
      g[a][n] = ng;
    }
  }
}

// USF takes the loads' power with the velocity the particles carry back, their momenta
// re-mapped as MUSL's (one more scatter in its g2p), when the step books any: tractions,
// dashpots, damping bands, gravity.
bool Solver::usf_remapped_power() const {
  return !tractions.empty() || !silents.empty() || !dampers.empty() || opt.gravity_x != 0 ||
         opt.gravity_y != 0;
}

std::array<int, 2> Solver::window_origin() const {
  return dist_ ? dist_->window_origin() : std::array<int, 2>{0, 0};
}

// MUSL, and USF for the loads' power: every field's re-mapped momentum q (summed over the
// halo, with the hooks' share) becomes the velocity q / m, with the constraints. MUSL
// (updated_edges): at the dashpot nodes of layers strained with the updated velocity (their
// weight > 0), v+ instead: the velocity the dashpots acted on (docs/physics.md section 4) --
// where the node holds at least dt/2 times the full LK impedance rho c_d of its share of the
// edge, the mass of a matched edge node times the CFL number. A lighter node (of a nearly
// empty cell) keeps the re-mapped value: there v+ = v + dt f / m amplifies the internal force,
// and a strong dashpot makes the trapezoidal update ring. The boundary work, the springs and
// the stress update then all take the velocity chosen here.
void Solver::remapped_velocities(bool updated_edges) {
  if (dist_) {  // every field's re-mapped momenta
    std::vector<double*> q;
    for (const VelocityField& F : fields_) q.insert(q.end(), {F.f.qx, F.f.qy});
    dist_->sum_halo(q.data(), static_cast<int>(q.size()), nullptr);
  }
  call([&](StepHooks& h) { h.after_remap(*this); });
  if (light_nodes.active()) {
    light_nodes.fold(grid.qx.data());
    light_nodes.fold(grid.qy.data());
  }
  for (const VelocityField& F : fields_)
    kernels::nodal_velocity(grid, F.box, F.f.m, grid.fix.data(), F.f.qx, F.f.qy, F.f.qx, F.f.qy,
                            mass_floor_, nthreads_);
  if (updated_edges && !delay_rho_.empty())
    delay_strain_velocities(grid.qx.data(), grid.qy.data(), true);
  if (updated_edges && !updated_weight_.empty())
    for (const long i : dashpot_nodes_) {
      if (takes_updated(i, updated_weight_[i])) {
        grid.qx[i] = grid.vnx[i];
        grid.qy[i] = grid.vny[i];
      }
    }
  if (light_nodes.active()) {
    light_nodes.extend(grid.qx.data());
    light_nodes.extend(grid.qy.data());
  }
}

// Shape functions of boundary particle q of layer L at its anchor point; fills nodes[]. Inlined
// into the layers' per-entry loops (GCC kept it a call per entry: a damping band's 10 cells cost
// 3.7-3.8 free cells per layer cell that way, 3.4-3.5 inlined; the same bits).
template <class S>
__attribute__((always_inline)) inline void Solver::layer_shape(const BoundaryLayer& L,
                                                               std::size_t q, Anchor anchor,
                                                               S& sf, long* nodes) const {
  const uint32_t k = L.idx[q];
  double x = p.x[k], y = p.y[k];
  if (anchor == Anchor::Boundary) {
    x += L.d[q] * L.nx[q];
    y += L.d[q] * L.ny[q];
  }
  if constexpr (S::kSized) sf.size(p.mass[k], 1.0 / materials[p.group[k]].rho, grid.inv_h);
  sf.eval_clamped(grid, x, y);
  sf.node_indices(grid.nnx, nodes);
}
template void Solver::layer_shape<Bilinear>(const BoundaryLayer&, std::size_t, Anchor, Bilinear&,
                                            long*) const;

// The weights a load of boundary particle q puts on the nodes. With the 3 x 3 shapes the support
// of a point on the body's edge reaches a node row outside the body (the quadratic B-spline
// gives it 1/8 at a node-aligned edge, uGIMP lp/(4h)); that node has no mass, its share of a
// traction or dashpot would never act (a silent end that loses 1/8 of its impedance reflects
// 6.7 % of the amplitude). Such shares go to the particle's other nodes in proportion to their
// weights, so the load still sums to t w_q and acts where the body is. With bilinear weights
// the same happens once a boundary point has moved out of its body's last cell (an edge on a
// node line that moves outward by u puts u/h of the load on the void node beyond): a
// Kelvin-Voigt end settled 3 % short of its static force before this was done for every shape.
// A node that holds only a sliver of mass keeps a share in proportion to its mass: at most
// m_i / (kLightShare m_q) of the load's particle q. Its share's acceleration stays below
// 1 / kLightShare times the particle's own, where a whole share on a node whose mass falls to
// nothing would accelerate it without bound (the wide shapes reach the node row beyond an edge,
// which a moving free surface fills with a sliver of the particles' domains; docs/physics.md
// section 8.5). Nodes the particle itself weighs as much as its share (the particle anchor) and
// those of an edge on or near a node line (at least half the share's mass at one ppc) keep theirs.
template <class S>
void Solver::load_weights(const BoundaryLayer& L, std::size_t q, Anchor anchor, S& sf,
                          long* nodes) const {
  layer_shape(L, q, anchor, sf, nodes);
  constexpr double kLightShare = 0.25;
  const double mq = kLightShare * p.mass[L.idx[q]];
  double kept = 0, lost = 0, theta[S::kNodes];
  for (int a = 0; a < S::kNodes; ++a) {
    const double m = grid.m[nodes[a]], w = sf.N[a];
    theta[a] = !(m > mass_floor_) ? 0.0 : m >= mq * w ? 1.0 : m / (mq * w);
    kept += theta[a] * w;
    lost += (1 - theta[a]) * w;
  }
  if (lost == 0 || kept <= 0) return;
  for (int a = 0; a < S::kNodes; ++a) sf.N[a] = theta[a] * sf.N[a] / kept;
}

// Traction vector of load tl on particle q of its layer at the current time.
static inline void traction_of(const TractionLoad& tl, std::size_t q, double f, double& tx,
                               double& ty) {
  const double nx = tl.layer.nx[q], ny = tl.layer.ny[q];
  tx = f * (tl.normal * nx - tl.tangential * ny + tl.vx);
  ty = f * (tl.normal * ny + tl.tangential * nx + tl.vy);
}

// The traction -[a (u.n) n + b (u - (u.n) n)] of a normal / tangential pair of coefficients.
static inline void normal_tangential(double a, double b, double nx, double ny, double ux,
                                     double uy, double& tx, double& ty) {
  const double un = ux * nx + uy * ny;
  tx = -(a * un * nx + b * (ux - un * nx));
  ty = -(a * un * ny + b * (uy - un * ny));
}

// LK dashpot traction for velocity (ux, uy) on particle q of layer sl (Eq. 21).
static inline void dashpot_of(const SilentBoundary& sl, std::size_t q, double ux, double uy,
                              double& tx, double& ty) {
  normal_tangential(sl.zn[q], sl.zt[q], sl.layer.nx[q], sl.layer.ny[q], ux, uy, tx, ty);
}

// Kelvin-Voigt spring traction on particle q of layer sl for its displacement (ux, uy).
static inline void spring_of(const SilentBoundary& sl, std::size_t q, double ux, double uy,
                             double& tx, double& ty) {
  normal_tangential(sl.kn[q], sl.kt[q], sl.layer.nx[q], sl.layer.ny[q], ux, uy, tx, ty);
}

// A Kelvin-Voigt spring's displacement advances with the grid velocity (vx, vy) at its anchor,
// through the weights that map its force: the velocity the scheme strains the particles with,
// so the spring and the body's stresses see one displacement history.
template <int K>
static inline void advance_spring(SilentBoundary& sl, std::size_t q, const double* N,
                                  const long* nodes, const std::vector<double>& vx,
                                  const std::vector<double>& vy, double dt) {
  double dx = 0, dy = 0;
  for (int a = 0; a < K; ++a) {
    dx += N[a] * vx[nodes[a]];
    dy += N[a] * vy[nodes[a]];
  }
  sl.ux[q] += dt * dx;
  sl.uy[q] += dt * dy;
}

// Perfectly matched layers on particles (docs/physics.md section 9.3; the FE far field's
// formulation, with the particle in the role of the quadrature point). Each layer particle
// accumulates its displacement u and gradient H from the grid velocity the scheme strains it with,
// through the same shape functions (pml_advance). At the start of a step it loads the grid with
// the stretched parts of its stress, V_p grad N . [(d_y - d_x) C_x psi_x + (d_x - d_y) C_y psi_y]
// with psi_x, psi_y the convolutions of H's x and y rows with exp(-(alpha + d) t), and the mass
// term m_p N (pml_mass_term), and (USL) puts m_p (d_x + d_y) N into the nodal dashpot blocks; MUSL
// damps the particles themselves (pml_pic, pml_damping).
template <class S>
void Solver::pml_loads() {
  PmlLayer& P = pml;
  const std::size_t n = P.layer.idx.size();
  if (P.dt_coef != dt) {
    convolution_tables(P.alpha, P.dx, P.dy, dt, P.cx, P.cy, P.e_a, P.ca_a, P.cb_a);
    P.dt_coef = dt;
  }
  pml_shapes<S>();
  // USF strains the particles with the start-of-step velocity, before the forces.
  if (opt.scheme == Scheme::USF) {
    const bool sym = symmetric_correction();
    pml_advance<S>(sym ? sym_vx_ : grid.vx, sym ? sym_vy_ : grid.vy);
  }
  constexpr int K = S::kNodes;
  const bool nodal = !pml_damps_particles();
  if (nodal) has_nodal_dashpot_ = true;
  // The arrays as local pointers: add_dashpot_node's flag stores (bytes, which may alias
  // anything) would otherwise have every array's address loaded again for each particle.
  const uint32_t* __restrict idx = P.layer.idx.data();
  const long* __restrict nodes_of = P.nodes.data();
  const double* __restrict N_of = P.N.data();
  const double* __restrict dNx_of = P.dNx.data();
  const double* __restrict dNy_of = P.dNy.data();
  const double* __restrict H_of = P.H.data();
  double* __restrict xi_of = P.xi.data();
  const double* __restrict cx_of = P.cx.data();
  const double* __restrict cy_of = P.cy.data();
  const double* __restrict pdx = P.dx.data();
  const double* __restrict pdy = P.dy.data();
  const double* __restrict pu = P.u.data();
  double* __restrict zeta = P.zeta.data();
  double* __restrict f_of = P.f.data();
  const double* __restrict vol = p.vol.data();
  const double* __restrict mass = p.mass.data();
  const auto* __restrict group = p.group.data();
  double* __restrict gfx = grid.fx.data();
  double* __restrict gfy = grid.fy.data();
  double* __restrict dash = grid.dash.data();
  const double alpha = P.alpha, e_a = P.e_a, ca_a = P.ca_a, cb_a = P.cb_a;
  for (std::size_t q = 0; q < n; ++q) {
    const uint32_t k = idx[q];
    const long* nodes = nodes_of + K * q;
    const double* N = N_of + K * q;
    const double* dNx = dNx_of + K * q;
    const double* dNy = dNy_of + K * q;
    const Material& m = materials[group[k]];
    const double L = m.lambda + 2 * m.mu, mu = m.mu;
    const double* H = H_of + 4 * q;
    double* xi = xi_of + 4 * q;
    const double* cx = cx_of + 3 * q;
    const double* cy = cy_of + 3 * q;
    const double pxx = xi[0] + cx[2] * H[0], pxy = xi[1] + cx[2] * H[1];
    const double pyx = xi[2] + cy[2] * H[2], pyy = xi[3] + cy[2] * H[3];
    xi[0] = cx[0] * pxx + cx[1] * H[0];
    xi[1] = cx[0] * pxy + cx[1] * H[1];
    xi[2] = cy[0] * pyx + cy[1] * H[2];
    xi[3] = cy[0] * pyy + cy[1] * H[3];
    const double kx = (pdy[q] - pdx[q]) * vol[k];
    double* f = f_of + 6 * q;
    f[0] = kx * L * pxx;
    f[1] = kx * mu * pxy;
    f[2] = -kx * mu * pyx;
    f[3] = -kx * L * pyy;
    const double sum = pdx[q] + pdy[q], prod = pdx[q] * pdy[q];
    for (int c = 0; c < 2; ++c)
      f[4 + c] = mass[k] * pml_mass_term(sum, prod, alpha, pu[2 * q + c], zeta + 4 * q + 2 * c,
                                         e_a, ca_a, cb_a);
    const double cm = sum * mass[k];
    for (int a = 0; a < K; ++a) {
      gfx[nodes[a]] += f[4] * N[a] - (f[0] * dNx[a] + f[2] * dNy[a]);
      gfy[nodes[a]] += f[5] * N[a] - (f[1] * dNx[a] + f[3] * dNy[a]);
      if (!nodal) continue;
      dash[Grid::kDash * nodes[a]] += cm * N[a];
      dash[Grid::kDash * nodes[a] + 2] += cm * N[a];
      add_dashpot_node(nodes[a]);
    }
  }
}

// Layer particles take a share w of the grid's velocity (PIC): the particle velocity becomes
// w v_grid(start) + (1 - w) v_p, so that g2p's increment (FLIP, PIC or a blend) leaves it with
// w v_grid(end) + (1 - w) v_p(FLIP). The layer's equations know the grid's unknowns only; the FLIP
// particle velocity is a memory they do not contain, and with it the layer grew after a few
// thousand steps. w grows from 0 at the layer's inner edge as (depth / width)^5: an earlier
// switch to PIC reflects and converts waves (PIC smooths the velocity over the stencil each
// step), a later one (power 6 and more, under USL) leaves enough FLIP for the growth to return
// (docs/physics.md section 9.3). Under MUSL the particle velocity then takes the first part of the
// layer's damping (pml_damping).
template <class S>
void Solver::pml_pic() {
  constexpr int K = S::kNodes;
  const long n = static_cast<long>(pml.layer.idx.size());
  const bool damp = pml_damps_particles();
  if (damp) pml.vd.resize(4 * static_cast<std::size_t>(n));
  // Each particle its own: in parallel, the same values as in order.
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (n >= 1024)
  for (long q = 0; q < n; ++q) {
    const uint32_t k = pml.layer.idx[q];
    const NodalField* f = &fields_[0].f;
    if (!body_of_group_.empty())
      for (const VelocityField& F : fields_)
        if (F.body == body_of_group_[p.group[k]]) f = &F.f;
    const long* nodes = pml.nodes.data() + K * q;
    const double* N = pml.N.data() + K * q;
    double wx = 0, wy = 0;
    for (int a = 0; a < K; ++a) {
      wx += N[a] * f->vx[nodes[a]];
      wy += N[a] * f->vy[nodes[a]];
    }
    const double w = pml.pic[q];
    p.vx[k] = w * wx + (1 - w) * p.vx[k];
    p.vy[k] = w * wy + (1 - w) * p.vy[k];
    if (damp) {  // the first half of the trapezoidal damping (pml_damping)
      double* vd = pml.vd.data() + 4 * q;
      const double a = 0.5 * (pml.dx[q] + pml.dy[q]) * dt;
      vd[0] = p.vx[k];
      vd[1] = p.vy[k];
      p.vx[k] *= (1 - a) / (1 + a);
      p.vy[k] *= (1 - a) / (1 + a);
      vd[2] = p.vx[k];
      vd[3] = p.vy[k];
    }
  }
}

// Under MUSL and USF the layer's damping m_p (d_x + d_y) v acts on its particles, not on the
// nodes: trapezoidal, v' = [(1 - a) v + N dv] / (1 + a) with a = (d_x + d_y) dt / 2 and N dv
// g2p's increment. pml_pic took the particle velocity to (1 - a) v / (1 + a) before g2p; here the
// increment is divided by 1 + a, the re-mapped momenta (`remapped`: MUSL, and USF when it books
// the loads' power with them) lose what the particles lost (so that MUSL's stress update strains
// them with their damped velocities; USF strains them so at the next step's start) and the
// damping's work, dt m_p (d_x + d_y) |(v + v')/2|^2, is booked as absorbed. On the nodes, whose
// trapezoidal mean is not the particles' (docs/physics.md section 4), MUSL's layer grew within
// 2 000 steps; on the particles it is stable at 4 and 9 particles per cell, and at 1 with a
// frequency shift (docs/physics.md section 9.3). Serial in layer order: the sums into the nodes
// and the work in one order.
template <class S>
void Solver::pml_damping(bool remapped) {
  constexpr int K = S::kNodes;
  if (!body_of_group_.empty())
    throw std::logic_error("pml_damping: a particle-damped layer with one velocity field per body");
  double work = 0;
  for (std::size_t q = 0; q < pml.layer.idx.size(); ++q) {
    const uint32_t k = pml.layer.idx[q];
    const double* vd = pml.vd.data() + 4 * q;
    const double a = 0.5 * (pml.dx[q] + pml.dy[q]) * dt;
    const double ux = vd[2] + (p.vx[k] - vd[2]) / (1 + a);
    const double uy = vd[3] + (p.vy[k] - vd[3]) / (1 + a);
    const double lx = p.vx[k] - ux, ly = p.vy[k] - uy;
    p.vx[k] = ux;
    p.vy[k] = uy;
    const double m = p.mass[k];
    if (remapped)
      for (int b = 0; b < K; ++b) {
        const long n = pml.nodes[K * q + b];
        grid.qx[n] -= m * pml.N[K * q + b] * lx;
        grid.qy[n] -= m * pml.N[K * q + b] * ly;
      }
    const double bx = 0.5 * (vd[0] + ux), by = 0.5 * (vd[1] + uy);
    work += m * 2 * a * (bx * bx + by * by);
  }
  energy.absorbed += work;
}

template <class S>
void Solver::pml_advance(const std::vector<double>& vx, const std::vector<double>& vy) {
  constexpr int K = S::kNodes;
  const long n = static_cast<long>(pml.layer.idx.size());
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (n >= 1024)
  for (long q = 0; q < n; ++q) {
    const long* nodes = pml.nodes.data() + K * q;
    const double* N = pml.N.data() + K * q;
    const double* dNx = pml.dNx.data() + K * q;
    const double* dNy = pml.dNy.data() + K * q;
    double* H = pml.H.data() + 4 * q;
    double* u = pml.u.data() + 2 * q;
    // The sums in registers (the stores to H and u could otherwise alias the velocities'
    // loads); each term added in the same order.
    double h0 = H[0], h1 = H[1], h2 = H[2], h3 = H[3], u0 = u[0], u1 = u[1];
    for (int a = 0; a < K; ++a) {
      const double wx = vx[nodes[a]], wy = vy[nodes[a]];
      h0 += dt * dNx[a] * wx;
      h1 += dt * dNx[a] * wy;
      h2 += dt * dNy[a] * wx;
      h3 += dt * dNy[a] * wy;
      u0 += dt * N[a] * wx;
      u1 += dt * N[a] * wy;
    }
    H[0] = h0; H[1] = h1; H[2] = h2; H[3] = h3;
    u[0] = u0; u[1] = u1;
  }
}

// The shape functions of the layer's particles at their positions at the start of the step.
template <class S>
void Solver::pml_shapes() {
  constexpr int K = S::kNodes;
  const std::size_t n = pml.layer.idx.size();
  pml.nodes.resize(K * n);
  pml.N.resize(K * n);
  pml.dNx.resize(K * n);
  pml.dNy.resize(K * n);
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (n >= 1024)
  for (std::size_t q = 0; q < n; ++q) {
    S sf;
    layer_shape(pml.layer, q, Anchor::Particle, sf, pml.nodes.data() + K * q);
    for (int a = 0; a < K; ++a) {
      pml.N[K * q + a] = sf.N[a];
      pml.dNx[K * q + a] = sf.dNx[a];
      pml.dNy[K * q + a] = sf.dNy[a];
    }
  }
}

template <class S, class Skip>
void Solver::layer_weights(const BoundaryLayer& L, Anchor anchor, std::vector<long>& wn,
                           std::vector<double>& wN, Skip&& skip) {
  constexpr int K = S::kNodes;
  const long n = static_cast<long>(L.idx.size());
  wn.resize(K * n);
  wN.resize(K * n);
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (n >= 256)
  for (long q = 0; q < n; ++q) {
    if (skip(q)) continue;
    S sf;
    load_weights(L, q, anchor, sf, wn.data() + K * q);
    std::copy(sf.N, sf.N + K, wN.data() + K * q);
  }
}

// Tractions and silent-layer dashpots carried by boundary particles (Eq. 16, 20, 21). Each
// layer's per-entry part (weights, tractions, blocks: the particles' and grid's data read at
// the entries) runs in parallel; the sums into the nodes then go in entry order, as one pass.
template <class S>
void Solver::apply_loads() {
  constexpr int K = S::kNodes;
  const auto none = [](long) { return false; };
  for (auto& tl : tractions) {
    const double f = tl.fn(t);
    if (f == 0.0) continue;
    layer_weights<S>(tl.layer, tl.anchor, tl.nodes, tl.N, none);
    for (std::size_t q = 0; q < tl.layer.idx.size(); ++q) {
      double tx, ty;
      traction_of(tl, q, f, tx, ty);
      const long* nodes = tl.nodes.data() + K * q;
      const double* N = tl.N.data() + K * q;
      for (int a = 0; a < K; ++a) {
        grid.fx[nodes[a]] += tx * tl.layer.w[q] * N[a];
        grid.fy[nodes[a]] += ty * tl.layer.w[q] * N[a];
      }
    }
  }
  // Nodal dashpot blocks: clear the nodes assembled last step, then assemble
  // C_i += (V_p / h) N_i [a rho c_d n n^T + b rho c_s (I - n n^T)].
  if (dashpot_index_.size() != grid.nodes()) dashpot_index_.assign(grid.nodes(), -1);
  {
    // One pass (in parallel): along an edge every node lies on its own cache lines.
    const long nd = static_cast<long>(dashpot_nodes_.size());
    const long* dn = dashpot_nodes_.data();
    double* uw = updated_weight_.empty() ? nullptr : updated_weight_.data();
    double* dr = delay_rho_.empty() ? nullptr : delay_rho_.data();
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (nd >= 256)
    for (long k = 0; k < nd; ++k) {
      const long i = dn[k];
      double* c = grid.dash.data() + Grid::kDash * i;  // the block and the weight
      c[0] = c[1] = c[2] = c[3] = 0;
      grid.fix[i] &= static_cast<uint8_t>(~Grid::kDashpotNode);
      if (uw) uw[i] = 0;
      if (dr) dr[i] = 0;
    }
  }
  dashpot_nodes_.clear();
  has_nodal_dashpot_ = false;
  for (auto& sl : silents) {
    const auto& L = sl.layer;
    const long n = static_cast<long>(L.idx.size());
    layer_weights<S>(L, sl.anchor, sl.nodes, sl.N, none);
    // Per entry, with springs or the particle form: the spring's traction (2), the particle
    // form's dashpot traction (2). The nodal form's block is a few products, taken in the sum.
    const bool particle = sl.form == SilentForm::Particle;
    double* sc = nullptr;
    if (sl.springs() || particle) {
      layer_scratch_.resize(4 * static_cast<std::size_t>(n));
      sc = layer_scratch_.data();
      const bool usf = opt.scheme == Scheme::USF;
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (n >= 256)
      for (long q = 0; q < n; ++q) {
        const long* nodes = sl.nodes.data() + K * q;
        double* o = sc + 4 * q;
        if (sl.springs()) {  // explicit: the displacement at the start of the step
          // USF strains the particles with the start-of-step velocity before the forces: the
          // springs do the same.
          if (usf) advance_spring<K>(sl, q, sl.N.data() + K * q, nodes, grid.vx, grid.vy, dt);
          spring_of(sl, q, sl.ux[q], sl.uy[q], o[0], o[1]);
        }
        if (particle)  // lagged: the particle velocity of the last step
          dashpot_of(sl, q, p.vx[L.idx[q]], p.vy[L.idx[q]], o[2], o[3]);
      }
    }
    const bool updated = !updated_weight_.empty() && sl.updated_velocity;
    const bool delayed = !delay_rho_.empty() && sl.delayed;
    const bool consistent = consistent_ && !sl.updated_velocity;
    for (long q = 0; q < n; ++q) {
      const long* nodes = sl.nodes.data() + K * q;
      const double* N = sl.N.data() + K * q;
      const double* o = sc ? sc + 4 * q : nullptr;
      if (sl.springs())
        for (int a = 0; a < K; ++a) {
          grid.fx[nodes[a]] += o[0] * L.w[q] * N[a];
          grid.fy[nodes[a]] += o[1] * L.w[q] * N[a];
        }
      if (sl.form == SilentForm::Particle) {
        for (int a = 0; a < K; ++a) {
          grid.fx[nodes[a]] += o[2] * L.w[q] * N[a];
          grid.fy[nodes[a]] += o[3] * L.w[q] * N[a];
        }
        continue;
      }
      has_nodal_dashpot_ = true;
      double bxx, bxy, byy;
      lk_block(sl.zn[q], sl.zt[q], L.nx[q], L.ny[q], bxx, bxy, byy);
      for (int a = 0; a < K; ++a) {
        const double wn = L.w[q] * N[a];
        if (wn == 0) continue;  // a node the anchor's weights miss: no block, the plain update
        grid.cxx(nodes[a]) += wn * bxx;
        grid.cxy(nodes[a]) += wn * bxy;
        grid.cyy(nodes[a]) += wn * byy;
        add_dashpot_node(nodes[a]);
      }
      if (!updated && !delayed && !consistent) continue;
      // The entry's material (one material: no read of the particle's group).
      const Material& mq = materials.size() == 1 ? materials[0] : materials[p.group[L.idx[q]]];
      if (updated)  // (w N rho) c_d
        for (int a = 0; a < K; ++a) updated_weight_[nodes[a]] += L.w[q] * N[a] * mq.rho * mq.cd;
      if (delayed)
        for (int a = 0; a < K; ++a) delay_rho_[nodes[a]] += L.w[q] * N[a] * mq.rho;
      if (consistent)
        for (int a = 0; a < K; ++a) grid.dash_weight(nodes[a]) += L.w[q] * N[a] * mq.rho * mq.cd;
    }
  }
  // Damping layers: C_i += alpha_q m_q N_i(x_q) I, at the particle (a volume term).
  for (auto& dl : dampers) {
    const auto& L = dl.layer;
    layer_weights<S>(L, Anchor::Particle, dl.nodes, dl.N,
                     [&](long q) { return dl.alpha[q] == 0; });
    for (std::size_t q = 0; q < L.idx.size(); ++q) {
      if (dl.alpha[q] == 0) continue;
      const long* dn = dl.nodes.data() + K * q;
      const double* N = dl.N.data() + K * q;
      has_nodal_dashpot_ = true;
      const double c = dl.alpha[q] * p.mass[L.idx[q]];
      for (int a = 0; a < K; ++a) {
        if (N[a] == 0) continue;  // no block: the plain update
        grid.cxx(dn[a]) += c * N[a];
        grid.cyy(dn[a]) += c * N[a];
        add_dashpot_node(dn[a]);
      }
    }
    // The stiffness-proportional part: the last step's viscous stress, -V sigma_v grad N_i,
    // with the gradients at the step's start kept for boundary_work.
    if (dl.beta0 > 0) {
      const long n = static_cast<long>(L.idx.size());
      dl.gnodes.resize(K * n);
      dl.dNx.resize(K * n);
      dl.dNy.resize(K * n);
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (n >= 256)
      for (long q = 0; q < n; ++q) {
        if (dl.beta[q] == 0) continue;
        S sf;
        layer_shape(L, q, Anchor::Particle, sf, dl.gnodes.data() + K * q);
        std::copy(sf.dNx, sf.dNx + K, dl.dNx.data() + K * q);
        std::copy(sf.dNy, sf.dNy + K, dl.dNy.data() + K * q);
      }
      for (long q = 0; q < n; ++q) {
        if (dl.beta[q] == 0) continue;
        const double* sv = dl.sv.data() + 3 * q;
        if (sv[0] == 0 && sv[1] == 0 && sv[2] == 0) continue;
        const long* dn = dl.gnodes.data() + K * q;
        const double* dNx = dl.dNx.data() + K * q;
        const double* dNy = dl.dNy.data() + K * q;
        const double V = p.vol[L.idx[q]];
        for (int a = 0; a < K; ++a) {
          grid.fx[dn[a]] -= V * (sv[0] * dNx[a] + sv[2] * dNy[a]);
          grid.fy[dn[a]] -= V * (sv[2] * dNx[a] + sv[1] * dNy[a]);
        }
      }
    }
  }
  if (pml.active()) pml_loads<S>();
  // Split over ranks: every load is in; the shared nodes sum their forces.
  if (dist_) sum_halo(false, true);
  // Gravity: f_i += m_i g, the nodal form of sum_p m_p g N_i (the lumped mass is sum_p m_p N_i).
  // On the grid's field; in multi-field contact the bodies' fields differ from it by their own
  // deviation, in which g cancels. Without hooks, whose after_forces comes between, grid_update's
  // pass adds it (the same operation at every node; one pass over the nodes fewer).
  if ((opt.gravity_x != 0 || opt.gravity_y != 0) && !gravity_in_update()) {
    const double gx = opt.gravity_x, gy = opt.gravity_y;
    const long n = static_cast<long>(grid.nodes());
    const double* m = grid.m.data();
    double* fx = grid.fx.data();
    double* fy = grid.fy.data();
#pragma omp parallel for schedule(static) num_threads(nthreads_)
    for (long i = 0; i < n; ++i) {
      fx[i] += m[i] * gx;
      fy[i] += m[i] * gy;
    }
  }
}

// v+ = v + dt f / m on every node; then, on the few nodes that carry a dashpot block C,
// (m + dt/2 C) v+ = (m - dt/2 C) v + dt f  (trapezoidal, unconditionally stable for C).
// The dashpot nodes are updated again in the same pass, so the silent layer costs O(boundary).
namespace {

// Whether the four nodes of these flags are dashpot nodes and free (trapezoidal_dashpots4's
// first condition, asked before the call).
inline bool four_free_dashpots(const uint8_t* fix) {
  std::uint32_t f4;
  std::memcpy(&f4, fix, sizeof f4);
  return f4 == 0x01010101u * Grid::kDashpotNode;
}

// grid_update's pass over nodes [i0, i1): the start velocity p / m (as kernels::nodal_velocity
// computes it) and the updated one, without reading the nodes' mass and flags twice. Health
// check at no extra pass: a NaN or Inf anywhere in the particles' mass, momentum or stress
// reaches the nodes' updated velocities this step (x - x is 0 only for finite x). Returns 1 if
// one is not finite. Called with its own copy per thread, so its pointers stay in registers.
struct NodeUpdate {
  const double *m, *px, *py;
  double *fx, *fy;
  const uint8_t* fix;
  double *vx, *vy, *ux, *uy;
  double floor, dt;
  bool stream;  // the velocities with streaming stores (see stores_stream), SSE2's two halves
  // Gravity's force first, f += m g at every node (apply_loads' pass, which then does not run).
  bool gravity;
  double gx, gy;
  int run(long i0, long i1) const {
    if (gravity) return run_on<true>(i0, i1);
    return run_on<false>(i0, i1);
  }
  template <bool GRAVITY>
  int run_on(long i0, long i1) const {
    if (!stream) return run_with<false, GRAVITY>(i0, i1);
    // The first node of four on an even index, as the streaming halves want.
    const long a = std::min(i1, i0 + (i0 & 1));
    return run_with<false, GRAVITY>(i0, a) | run_with<true, GRAVITY>(a, i1);
  }
  template <bool STREAM>
  static void put(double* a, kernels::simd::V4 v) {
#if defined(__SSE2__)
    if constexpr (STREAM) {
      _mm_stream_pd(a, _mm_set_pd(v[1], v[0]));
      _mm_stream_pd(a + 2, _mm_set_pd(v[3], v[2]));
      return;
    }
#endif
    kernels::simd::store(a, v);
  }
  template <bool STREAM, bool GRAVITY>
  int run_with(long i0, long i1) const {
    // Four nodes at a time (each lane the scalar loop's operations), then the rest one by one.
    using kernels::simd::V4;
    using kernels::simd::M4;
    long i = i0;
    M4 any_bad = {0, 0, 0, 0};
    const V4 zero = {0, 0, 0, 0};
    for (; i + 4 <= i1; i += 4) {
      const V4 mi = kernels::simd::load(m + i);
      if constexpr (GRAVITY) {
        kernels::simd::store(fx + i, kernels::simd::load(fx + i) + mi * gx);
        kernels::simd::store(fy + i, kernels::simd::load(fy + i) + mi * gy);
      }
      M4 hx, hy;
      kernels::simd::held(fix + i, hx, hy);
      const M4 heavy = mi > floor, light = mi <= floor;
      const V4 vxi = (heavy & ~hx) ? kernels::simd::load(px + i) / mi : zero;
      const V4 vyi = (heavy & ~hy) ? kernels::simd::load(py + i) / mi : zero;
      put<STREAM>(vx + i, vxi);
      put<STREAM>(vy + i, vyi);
      const V4 uxi = (light | hx) ? zero : vxi + dt * kernels::simd::load(fx + i) / mi;
      const V4 uyi = (light | hy) ? zero : vyi + dt * kernels::simd::load(fy + i) / mi;
      put<STREAM>(ux + i, uxi);
      put<STREAM>(uy + i, uyi);
      any_bad |= ~((uxi - uxi == 0) & (uyi - uyi == 0));
    }
    int bad = (any_bad[0] | any_bad[1] | any_bad[2] | any_bad[3]) != 0;
    for (; i < i1; ++i) {
      const double mi = m[i];
      if constexpr (GRAVITY) {
        fx[i] += mi * gx;
        fy[i] += mi * gy;
      }
      const bool heavy = mi > floor;
      const double vxi = heavy && !(fix[i] & 1) ? px[i] / mi : 0.0;
      const double vyi = heavy && !(fix[i] & 2) ? py[i] / mi : 0.0;
      vx[i] = vxi;
      vy[i] = vyi;
      if (mi <= floor) {  // not !heavy: a NaN mass goes on to the check
        ux[i] = 0;
        uy[i] = 0;
        continue;
      }
      ux[i] = (fix[i] & 1) ? 0.0 : vxi + dt * fx[i] / mi;
      uy[i] = (fix[i] & 2) ? 0.0 : vyi + dt * fy[i] / mi;
      bad |= !(ux[i] - ux[i] == 0 && uy[i] - uy[i] == 0);
    }
    return bad;
  }
};
}  // namespace

void Solver::grid_update() {
  const long n = static_cast<long>(grid.nodes());
  const double* m = grid.m.data();
  const uint8_t* fix = grid.fix.data();
  const double* vx = grid.vx.data(); const double* vy = grid.vy.data();
  double* fx = grid.fx.data(); double* fy = grid.fy.data();
  const double* ux = grid.vnx.data(); const double* uy = grid.vny.data();
  // Streaming in halves of four nodes wants each array 16-byte aligned (as the allocator gives
  // them). The dashpot nodes' lines below are vx's; large arrays, each mapped on its own pages,
  // start their lines at the same node.
  const std::uintptr_t ax = reinterpret_cast<std::uintptr_t>(grid.vx.data());
  const long phase = static_cast<long>((64 - ax % 64) % 64 / 8);
  bool aligned = true;
  for (const double* a : {grid.vx.data(), grid.vy.data(), grid.vnx.data(), grid.vny.data()})
    aligned = aligned && reinterpret_cast<std::uintptr_t>(a) % 16 == 0;
  const NodeUpdate nodes{m, grid.px.data(), grid.py.data(), fx, fy, fix, grid.vx.data(),
                         grid.vy.data(), grid.vnx.data(), grid.vny.data(), mass_floor_, dt,
                         aligned && stores_stream(),
                         (opt.gravity_x != 0 || opt.gravity_y != 0) && gravity_in_update(),
                         opt.gravity_x, opt.gravity_y};
  int bad = 0;
  if (!has_nodal_dashpot_) {
#pragma omp parallel num_threads(nthreads_) reduction(| : bad)
    {
      const NodeUpdate u = nodes;
      long i0, i1;
      omp_range(n, i0, i1);
      bad |= u.run(i0, i1);
      if (u.stream) fence();
    }
    if (bad) fail_nonfinite();
    return;
  }
  // A dashpot node (grid.fix's kDashpotNode) is updated again right after, while its values
  // are in cache (each node its own: in parallel, the same values). For consistent_dashpots,
  // each one's values go into one record (kDn per node, in the order of dashpot_nodes_): along
  // an edge every node lies on its own cache lines of a dozen grid-sized arrays.
  const bool track = consistent_;
  if (track) dn_rec_.resize(kDn * dashpot_nodes_.size());
  const bool delayed = !delay_rho_.empty();
  if (delayed) delay_prepare();
  const double gx = opt.gravity_x, gy = opt.gravity_y;
  double* rec_all = dn_rec_.data();
  // Node i's record from its velocities (v, v+).
  auto record = [&](long i, double vxi, double vyi, double uxi, double uyi, int closure) {
    double* r = rec_all + kDn * dashpot_index_[i];
    const double* c = grid.dash.data() + Grid::kDash * i;
    r[kDnWeight] = c[3];
    if (c[3] <= 0) return;  // no silent layer's weight (a band's or PML's node): not in the solve
    r[kDnM] = m[i];
    r[kDnFx] = fx[i];
    r[kDnFy] = fy[i];
    r[kDnVx] = vxi;
    r[kDnVy] = vyi;
    r[kDnUx] = uxi;
    r[kDnUy] = uyi;
    r[kDnCxx] = c[0];
    r[kDnCxy] = c[1];
    r[kDnCyy] = c[2];
    // Strained with v+: not in the solve.
    const int skip = !updated_weight_.empty() && updated_weight_[i] > 0 ? kDnSkip : 0;
    r[kDnFlags] = static_cast<double>((fix[i] & 3) | skip | closure);
  };
  auto dashpot = [&](long i) {
    const int closure = update_dashpot_node(i, delayed, gx, gy);
    if (track) record(i, vx[i], vy[i], ux[i], uy[i], closure);
  };
  // Node by node in order; each line's worth of nodes (eight, where the four velocity arrays
  // start their cache lines) that holds a dashpot node takes plain stores and then its dashpot
  // nodes' update, which reads those values back while they are in cache (where the step streams
  // and no closure is delayed, a whole line goes through a buffer instead, below). The runs
  // between go whole, streamed where the step streams: whole lines, never a line shared with
  // plain stores.
  // The lines that hold a dashpot node, as bits: line l holds nodes [8 l - 8 + phase,
  // 8 l + phase).
  auto line_of = [phase](long i) { return (i + 8 - phase) / 8; };
  dash_lines_.assign(static_cast<std::size_t>(line_of(n - 1) / 64 + 1), 0);
  for (const long i : dashpot_nodes_) dash_lines_[line_of(i) / 64] |= 1ull << (line_of(i) % 64);
  const std::uint64_t* lines = dash_lines_.data();
#pragma omp parallel num_threads(nthreads_) reduction(| : bad)
  {
    const NodeUpdate u = nodes;
    NodeUpdate plain = nodes;
    plain.stream = false;
    long i0, i1;
    omp_range(n, i0, i1);
    long from = i0;
    // Each marked line within [i0, i1), in order; a line cut by the range's ends takes only
    // its part (whose own flags say whether it holds a dashpot node).
    const long l0 = i0 < i1 ? line_of(i0) : 0, l1 = i0 < i1 ? line_of(i1 - 1) : -1;
    for (long l = l0; l <= l1;) {
      std::uint64_t w = lines[l / 64] >> (l % 64);
      if (w == 0) {
        l = (l / 64 + 1) * 64;
        continue;
      }
      l += __builtin_ctzll(w);
      if (l > l1) break;
      const long g = std::max(i0, 8 * l - 8 + phase), ge = std::min(i1, 8 * l + phase);
      ++l;
      bool any = ge - g == 8;
      for (long j = g; j < ge && !any; ++j) any = (u.fix[j] & Grid::kDashpotNode) != 0;
      if (any && u.stream && !delayed && ge - g == 8) {
        // A whole line, streamed as the runs around it: its eight nodes' velocities into a
        // buffer, its dashpot nodes' update there (update_dashpot_node without a delayed
        // closure: the trapezoidal update of a node heavier than the floor), then out. The
        // line's plain stores would each first read it from memory.
        bad |= u.run(from, g);
        alignas(64) double b[4][8];
        NodeUpdate t = plain;
        t.m = m + g; t.px += g; t.py += g; t.fx = fx + g; t.fy = fy + g; t.fix += g;
        t.vx = b[0]; t.vy = b[1]; t.ux = b[2]; t.uy = b[3];
        bad |= t.run(0, 8);
        for (long j = g; j < ge;) {
          const long l = j - g;
          if (j + 4 <= ge && four_free_dashpots(u.fix + j) &&
              trapezoidal_dashpots4(j, b[0] + l, b[1] + l, b[2] + l, b[3] + l)) {
            if (track)
              for (long k = l; k < l + 4; ++k) record(g + k, b[0][k], b[1][k], b[2][k], b[3][k], 0);
            j += 4;
            continue;
          }
          if (u.fix[j] & Grid::kDashpotNode) {
            trapezoidal_dashpot(j, b[0][l], b[1][l], b[2][l], b[3][l]);
            if (track) record(j, b[0][l], b[1][l], b[2][l], b[3][l], 0);
          }
          ++j;
        }
        double* const out[4] = {u.vx, u.vy, u.ux, u.uy};
        for (int a = 0; a < 4; ++a) {
          double* to = out[a];
          NodeUpdate::put<true>(to + g, kernels::simd::load(b[a]));
          NodeUpdate::put<true>(to + g + 4, kernels::simd::load(b[a] + 4));
        }
        from = ge;
      } else if (any) {
        bad |= u.run(from, g) | plain.run(g, ge);
        for (long j = g; j < ge;) {
          // Four in a row without a delayed closure: at once (their records then in order).
          if (!delayed && j + 4 <= ge && four_free_dashpots(u.fix + j) &&
              trapezoidal_dashpots4(j, u.vx + j, u.vy + j, u.ux + j, u.uy + j)) {
            if (track)
              for (long l = j; l < j + 4; ++l) record(l, vx[l], vy[l], ux[l], uy[l], 0);
            j += 4;
            continue;
          }
          if (u.fix[j] & Grid::kDashpotNode) dashpot(j);
          ++j;
        }
        from = ge;
      }
    }
    bad |= u.run(from, i1);
    if (u.stream) fence();
  }
  if (bad) fail_nonfinite();
}

// One dashpot node's updated velocity in grid_update: the delayed closure's, or the
// trapezoidal update of its block. Returns how the dashpot solve takes a delayed closure's node
// (0 for any other): kDnSkip, not at all (the closure did not act, or took both components, at
// a corner); kDnHeldX (Y): its x (y) component is the closure's, held in the solve.
int Solver::update_dashpot_node(long i, bool delayed, double gx, double gy) {
  const double floor = mass_floor_, DT = dt;
  const double* m = grid.m.data();
  const uint8_t* fix = grid.fix.data();
  const double* vx = grid.vx.data(); const double* vy = grid.vy.data();
  const double* fx = grid.fx.data(); const double* fy = grid.fy.data();
  double* ux = grid.vnx.data(); double* uy = grid.vny.data();
  if (delayed && delay_rho_[i] > 0) {
    // The delayed closure (delay_strain_velocities): the ring takes this step's start
    // velocity and force less gravity. An edge node on its grid line holds half its layer's
    // weight times h (w N rho h against rho h^2 / 2). A node whose mass is off that by more
    // than kDelayMassTolerance (the layer reaches it only through points moved into the last
    // cell, or the end has drifted off the grid line: the closure's premise is gone), one
    // lighter than dt/2 times its block (the explicit dashpot's limit), one with a block off
    // the axes, or one whose ring does not yet reach back the delay takes the trapezoidal
    // update.
    double* rec = delay_.data() + delay_stride() * delay_slot_[i];
    // A node whose ring missed a step (not reached by the layer then) starts its history anew.
    if (rec[kDelayWritten] != static_cast<double>(steps - 1))
      rec[kDelayRunFrom] = static_cast<double>(steps);
    rec[kDelayWritten] = static_cast<double>(steps);
    const long s = steps % delay_cap_;
    double* ring = rec + kDelayHead + 4 * s;
    const double frx = fx[i] - m[i] * gx, fry = fy[i] - m[i] * gy;
    ring[0] = vx[i];
    ring[1] = vy[i];
    ring[2] = frx;
    ring[3] = fry;
    const double cxx = grid.cxx(i), cyy = grid.cyy(i);
    rec[kDelayCxx] = cxx;
    rec[kDelayCyy] = cyy;
    rec[kDelayRho] = delay_rho_[i];
    rec[kDelayAt] = -1;
    const bool blocks = cxx > 0 && cyy > 0;
    // The closure takes the normal component (delayed_axis); the tangential one keeps the
    // trapezoidal update here, which consistent_dashpots replaces with the particles' mean.
    const bool on_x = delayed_axis(cxx, cyy), on_y = delayed_axis(cyy, cxx);
    const double dx = blocks ? grid.h / (cxx / rec[kDelayRho] * DT) - 0.5 : 0.0;
    const double dy = blocks ? grid.h / (cyy / rec[kDelayRho] * DT) - 0.5 : 0.0;
    const double reach = std::max(on_x ? dx : 0.0, on_y ? dy : 0.0);
    const double history = static_cast<double>(steps) - rec[kDelayRunFrom];  // entries before
    const double half = 0.5 * rec[kDelayRho] * grid.h;  // an edge node's mass on its line
    if (m[i] > floor && grid.cxy(i) == 0 && 0.5 * DT * std::max(cxx, cyy) <= m[i] && blocks &&
        std::abs(m[i] - half) <= kDelayMassTolerance * half && std::floor(reach) + 1 <= history) {
      const double vdx = on_x ? delay_value(rec, 0, dx, 0) : 0.0;
      const double vdy = on_y ? delay_value(rec, 1, dy, 0) : 0.0;
      const double M = rec[kDelayRho] * grid.h;  // a whole node's mass: rho h times its edge length
      double tx = 0, ty = 0;  // the trapezoidal update, for the tangential component
      if (!(on_x && on_y))
        dashpot_velocity(m[i], cxx, 0.0, cyy, vx[i], vy[i], fx[i], fy[i], DT, fix[i], tx, ty);
      ux[i] = !on_x ? tx : (fix[i] & 1) ? 0.0 : vx[i] + DT * gx + DT * (frx - cxx * vdx) / M;
      uy[i] = !on_y ? ty : (fix[i] & 2) ? 0.0 : vy[i] + DT * gy + DT * (fry - cyy * vdy) / M;
      rec[kDelayAt] = static_cast<double>(steps);
      rec[kDelayFx] = frx;
      rec[kDelayFy] = fry;
      rec[kDelayVx] = vdx;
      rec[kDelayVy] = vdy;
      return on_x && on_y ? kDnSkip : on_x ? kDnHeldX : kDnHeldY;
    }
  }
  const int closure = delayed && delay_rho_[i] > 0 ? kDnSkip : 0;
  trapezoidal_dashpot(i, vx[i], vy[i], ux[i], uy[i]);
  return closure;
}

void Solver::trapezoidal_dashpot(long i, double vx, double vy, double& ux, double& uy) const {
  if (grid.m[i] <= mass_floor_) return;
  dashpot_velocity(grid.m[i], grid.cxx(i), grid.cxy(i), grid.cyy(i), vx, vy, grid.fx[i],
                   grid.fy[i], dt, grid.fix[i], ux, uy);
}

// Each lane dashpot_velocity's arithmetic for a free node (the same bits); the four nodes' blocks
// lie in a row of grid.dash (kDash values a node).
bool Solver::trapezoidal_dashpots4(long j, const double* vx, const double* vy, double* ux,
                                   double* uy) const {
  using kernels::simd::V4;
  using kernels::simd::load;
  static_assert(Grid::kDash == 4, "a node's dash values: cxx, cxy, cyy, weight");
  if (!four_free_dashpots(grid.fix.data() + j)) return false;  // each a dashpot node, free
  const V4 m = load(grid.m.data() + j);
  const double floor = mass_floor_;
  if (!(m[0] > floor && m[1] > floor && m[2] > floor && m[3] > floor)) return false;
  const double* c = grid.dash.data() + Grid::kDash * j;
  const V4 c0 = load(c), c1 = load(c + 4), c2 = load(c + 8), c3 = load(c + 12);
  const V4 lo01 = __builtin_shufflevector(c0, c1, 0, 4, 1, 5);  // cxx0 cxx1 cxy0 cxy1
  const V4 lo23 = __builtin_shufflevector(c2, c3, 0, 4, 1, 5);
  const V4 hi01 = __builtin_shufflevector(c0, c1, 2, 6, 3, 7);  // cyy0 cyy1 w0 w1
  const V4 hi23 = __builtin_shufflevector(c2, c3, 2, 6, 3, 7);
  const V4 cxx = __builtin_shufflevector(lo01, lo23, 0, 1, 4, 5);
  const V4 cxy = __builtin_shufflevector(lo01, lo23, 2, 3, 6, 7);
  const V4 cyy = __builtin_shufflevector(hi01, hi23, 0, 1, 4, 5);
  const V4 v_x = load(vx), v_y = load(vy);
  const V4 fx = load(grid.fx.data() + j), fy = load(grid.fy.data() + j);
  V4 ax, ay;
  dashpot_velocity_free(m, cxx, cxy, cyy, v_x, v_y, fx, fy, dt, ax, ay);
  kernels::simd::store(ux, ax);
  kernels::simd::store(uy, ay);
  return true;
}

// MUSL and USF, in particle terms (positions held, one field, FLIP): the nodal velocity is
// v = P v_p with P = M^-1 N^T m_p, the particles take the nodal increment, v_p' = v_p + N dv,
// and the stress update strains them with P v_p' (MUSL) or P v_p (USF). The dashpot's force
// on the particles is then -N M^-1 C vbar, and the step gives up energy to it, for every state,
// only when vbar is the mean of what the particles map to the node before and after the step:
//   vbar = (P v_p + P v_p')/2 = v + 1/2 M^-1 Mc dv,   Mc = N^T m_p N (the consistent mass),
// dv = dt M^-1 (f - C vbar). grid_update's trapezoidal mean v + dv/2 takes M for Mc; at an
// edge node, whose particles lie on one side, Mc_ii / M_i is a quarter at 1 ppc and the rest of
// the row reaches the nodes inside, so that mean over-states the node's change. The difference
// fed MUSL's and USF's odd-even modes where LK edges meet free surfaces: a 20 x 20-cell square
// at 1 ppc and CFL 0.5 grew by 8.5e-5 per step (the step's largest eigenvalue), and every
// eigenvalue is on or inside the unit circle with the consistent mean (docs/physics.md
// section 4). So, at the dashpot nodes of the silent layers with the default edge velocity:
//   (I + kappa_i C_i) vbar_i = v_i + 1/2 (Mc dv0)_i / m_i - 1/2 o_i / m_i,
// dv0 the increment without those nodes' dashpots (dt f / m there; grid_update's v+ - v at
// every other node), kappa_i = dt d_i / (2 m_i^2), d_i = sum m_p N_ip^2 the diagonal of Mc and
// o_i = sum_{j != i} Mc_ij g_j, g_j = dt C_j vbar_j / m_j, solved by fixed-point iteration to
// 1e-13 of the largest vbar.
// A node lighter than dt/2 times its block's largest eigenvalue keeps the trapezoidal update:
// with that bound every other node's share of the row is below 1 - d_i / m_i, so the iteration
// contracts. So does a node whose mass is not its particles' (a hook's share: the hybrid).
// Slots: kCm values per node: (Mc dv0) x, y, d, sum m_p N, vbar x, y, o x, y.
template <class S>
void Solver::consistent_dashpots() {
  constexpr int K = S::kNodes;
  const double DT = dt, floor = mass_floor_;
  const long nnx = grid.nnx;
  // The nodes: a block from such a layer, heavy enough (the same choice on every copy of a
  // shared node: it reads only values summed over the halo, and whether a delayed closure acted,
  // which every rank that holds the node decides from its ring of those values). A node whose
  // mass is not its particles' is dropped and the choice made again (the same on every rank), once the zone
  // was found this step: a node that a particle missing from an older zone left short asks for
  // a new one first.
  if (dn_rec_.size() != kDn * dashpot_nodes_.size())
    throw std::logic_error("consistent_dashpots: grid_update left no record of the dashpot nodes");
  std::vector<long> dropped, short_nodes;
  const long ncx = grid.nx, ncy = grid.ny;
  bool scanned = false, rescan = false;
  double more[3];  // a node short of its particles' mass, a new zone asked, any node listed
  // fn(index) for the cells (or nodes) of rows and columns [n - lo, n + hi] around node i, in a
  // w x ht array.
  auto around = [nnx](long i, long lo, long hi, long w, long ht, auto&& fn) {
    const long ni = i % nnx, nj = i / nnx;
    for (long j = std::max<long>(0, nj - lo); j <= std::min<long>(ht - 1, nj + hi); ++j)
      for (long ii = std::max<long>(0, ni - lo); ii <= std::min<long>(w - 1, ni + hi); ++ii)
        fn(j * w + ii);
  };
  for (;;) {
    // The list is made apart and compared with the last one: along a quiet edge it is the same
    // (its nodes' slots, the zone's cover of them and the cells that reach them are then as
    // they were: no pass over their scattered grid entries).
    cm_next_.clear();
    cm_dk_.clear();
    for (std::size_t k = 0; k < dashpot_nodes_.size(); ++k) {
      const long i = dashpot_nodes_[k];
      const double* r = dn_rec_.data() + kDn * k;
      if (r[kDnWeight] <= 0 || r[kDnM] <= floor) continue;
      if (static_cast<int>(r[kDnFlags]) & kDnSkip) continue;  // see grid_update
      const double cxx = r[kDnCxx], cxy = r[kDnCxy], cyy = r[kDnCyy];
      const double lmax =
          0.5 * (cxx + cyy) + std::sqrt(0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy);
      // No block (a = b = 0: a rank that shares the node lists it only with a block), or one
      // too strong for the node's mass.
      if (!(lmax > 0) || 0.5 * DT * lmax > r[kDnM]) continue;
      if (std::binary_search(dropped.begin(), dropped.end(), i)) continue;
      cm_next_.push_back(i);
      cm_dk_.push_back(static_cast<long>(k));
    }
    const bool same_list = cm_next_ == cm_nodes_;
    if (!same_list) {
      for (const long i : cm_nodes_) cm_slot_[i] = -1;
      cm_nodes_.swap(cm_next_);
      for (std::size_t k = 0; k < cm_nodes_.size(); ++k) cm_slot_[cm_nodes_[k]] = static_cast<int>(k);
    }
    // The particles whose shape functions reach those nodes, from a zone of particles kept
    // between steps: those in the cells whose particles can reach a listed node or one next to
    // it (the nodes it covers), and one more cell around them. The zone is found again by a
    // pass over every particle when a listed node is not covered (a node along the edge enters
    // and leaves the list as the edge's points cross a grid line: its neighbours are covered),
    // the particles were re-ordered, or they may have drifted half a cell since (cm_drift_, the
    // sum over the steps of dt times the fastest velocity of the nodes that move the zone's
    // particles; a particle outside the zone was a cell away from a covered node's cells, less
    // round-off, and crosses zone cells to reach them), and every
    // step when hooks may change that velocity (once).
    bool scan = rescan || (!hooks_.empty() && !scanned) || cm_scan_version_ != order_version_ ||
                cm_scan_size_ != p.size() || !(cm_drift_ < 0.5 * grid.h);
    // (The nodes of an unchanged list are covered: a scan covers every listed node, and only a
    // scan clears the cover.)
    for (std::size_t k = 0; k < cm_nodes_.size() && !scan && !same_list; ++k)
      scan = !(cm_cover_[cm_nodes_[k]] & 1);
    if (scan) {
      for (const long c : cm_cells_) cm_cell_[c] &= 2;
      cm_cells_.clear();
      for (const long i : cm_covered_) cm_cover_[i] = 0;
      for (const long i : cm_moving_) cm_cover_[i] = 0;
      cm_covered_.clear();
      cm_moving_.clear();
      for (const long i : cm_nodes_) {
        around(i, 1, 1, nnx, grid.nny, [&](long c) {
          if (!(cm_cover_[c] & 1)) {
            cm_cover_[c] |= 1;
            cm_covered_.push_back(c);
          }
        });
        around(i, S::kRowsAbove + 2, S::kRowsBelow + 2, ncx, ncy, [&](long c) {
          if (!(cm_cell_[c] & 1)) {
            cm_cell_[c] |= 1;
            cm_cells_.push_back(c);
          }
        });
      }
      // The nodes that move the zone's particles (marked 2): those of its cells' supports.
      for (const long c : cm_cells_)
        around((c / ncx) * nnx + c % ncx, S::kRowsBelow, S::kRowsAbove, nnx, grid.nny, [&](long n) {
          if (!(cm_cover_[n] & 2)) {
            cm_cover_[n] |= 2;
            cm_moving_.push_back(n);
          }
        });
      cm_zone_.clear();
      if (!cm_nodes_.empty()) {
        const std::size_t n = p.size();
        for (std::size_t k = 0; k < n; ++k) {
          const long ci = cell_column(k), cj = cell_row(k);
          if (ci < 0 || cj < 0 || ci >= ncx || cj >= ncy || !(cm_cell_[cj * ncx + ci] & 1)) continue;
          cm_zone_.push_back(static_cast<std::uint32_t>(k));
        }
      }
      cm_scan_version_ = order_version_;
      cm_scan_size_ = p.size();
      cm_drift_ = 0;
      scanned = true;
      rescan = false;
    }
    // dv0 at a node: without the listed nodes' dashpots (a delayed closure's component: its
    // update, whose dashpot is explicit).
    cm_dv_.resize(2 * cm_nodes_.size());
    for (std::size_t k = 0; k < cm_nodes_.size(); ++k) {
      const double* r = dn_rec_.data() + kDn * cm_dk_[k];
      const int fj = static_cast<int>(r[kDnFlags]);
      cm_dv_[2 * k] = (fj & kDnHeldX) ? r[kDnUx] - r[kDnVx]
                      : (fj & 1)      ? 0.0
                                      : DT * r[kDnFx] / r[kDnM];
      cm_dv_[2 * k + 1] = (fj & kDnHeldY) ? r[kDnUy] - r[kDnVy]
                          : (fj & 2)      ? 0.0
                                          : DT * r[kDnFy] / r[kDnM];
    }
    auto dv0 = [&](long j, double& ax, double& ay) {
      if (const int sl = cm_slot_[j]; sl >= 0) {
        ax = cm_dv_[2 * sl];
        ay = cm_dv_[2 * sl + 1];
      } else {
        ax = grid.vnx[j] - grid.vx[j];
        ay = grid.vny[j] - grid.vy[j];
      }
    };
    // The cells whose particles can reach a listed node: a zone particle elsewhere reaches none
    // (a scan keeps these marks).
    if (!same_list) {
      for (const long c : cm_reach_) cm_cell_[c] &= 1;
      cm_reach_.clear();
      for (const long i : cm_nodes_)
        around(i, S::kRowsAbove, S::kRowsBelow, ncx, ncy, [&](long c) {
          if (!(cm_cell_[c] & 2)) {
            cm_cell_[c] |= 2;
            cm_reach_.push_back(c);
          }
        });
    }
    // Each zone particle's shape functions, its nodes' slots and this step's dv0 . N (in
    // parallel, each its own), then the places of those that reach a listed node, in zone order.
    const long nz = static_cast<long>(cm_zone_.size());
    cm_pN_.resize(K * nz);
    cm_ps_.resize(K * nz);
    cm_pm_.resize(nz);
    cm_s_.resize(2 * nz);
    cm_reaches_.resize(nz);
    std::uint8_t* reaches = cm_reaches_.data();
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (nz >= 512)
    for (long e = 0; e < nz; ++e) {
      // The zone lies along the edge, a few particles and nodes in each row, each row on lines
      // of its own: ask for the particles' lines kZone places on, and for the grid lines of the
      // particle half as far on (its position then in cache).
      constexpr long kZone = 16;
      if (e + kZone < nz) {
        const std::uint32_t a = cm_zone_[e + kZone];
        __builtin_prefetch(p.x.data() + a);
        __builtin_prefetch(p.y.data() + a);
        __builtin_prefetch(p.mass.data() + a);
      }
      if (e + kZone / 2 < nz) {
        const std::uint32_t a = cm_zone_[e + kZone / 2];
        const long ci = cell_column(a), cj = cell_row(a);
        if (ci >= 0 && cj >= 0 && ci < ncx && cj < ncy) {
          __builtin_prefetch(cm_cell_.data() + cj * ncx + ci);
          for (long row = 0; row < 2; ++row) {
            const long n = (cj + row) * nnx + ci;
            __builtin_prefetch(cm_slot_.data() + n);
            __builtin_prefetch(grid.vx.data() + n);
            __builtin_prefetch(grid.vy.data() + n);
            __builtin_prefetch(grid.vnx.data() + n);
            __builtin_prefetch(grid.vny.data() + n);
          }
        }
      }
      const std::uint32_t k = cm_zone_[e];
      if (const long ci = cell_column(k), cj = cell_row(k);
          ci < 0 || cj < 0 || ci >= ncx || cj >= ncy || !(cm_cell_[cj * ncx + ci] & 2)) {
        reaches[e] = 0;
        continue;
      }
      S sf;
      if constexpr (S::kSized) sf.size(p.mass[k], inv_rho(p.group[k]), grid.inv_h);
      sf.eval(grid, p.x[k], p.y[k]);
      long nodes[K];
      sf.node_indices(nnx, nodes);
      bool r = false;
      double sx = 0, sy = 0;
      for (int a = 0; a < K; ++a) {
        const int sl = sf.N[a] != 0 ? cm_slot_[nodes[a]] : -1;
        cm_ps_[K * e + a] = sl;
        cm_pN_[K * e + a] = sf.N[a];
        r = r || sl >= 0;
        if (sf.N[a] == 0) continue;
        double ax, ay;
        dv0(nodes[a], ax, ay);
        sx += sf.N[a] * ax;
        sy += sf.N[a] * ay;
      }
      reaches[e] = r;
      cm_pm_[e] = p.mass[k];
      cm_s_[2 * e] = sx;
      cm_s_[2 * e + 1] = sy;
    }
    cm_hits_.clear();
    for (long e = 0; e < nz; ++e)
      if (reaches[e]) cm_hits_.push_back(static_cast<std::uint32_t>(e));
    const std::size_t ns = cm_nodes_.size();
    cm_.assign(kCm * ns, 0.0);
    // The sums at each slot, in particle order: Mc dv0, d and the particles' mass.
    for (const std::uint32_t q : cm_hits_) {
      const double* N = cm_pN_.data() + K * q;
      const int* sls = cm_ps_.data() + K * q;
      const double mp = cm_pm_[q], sx = cm_s_[2 * q], sy = cm_s_[2 * q + 1];
      for (int a = 0; a < K; ++a) {
        const int sl = sls[a];
        if (sl < 0) continue;
        double* c = cm_.data() + kCm * sl;
        c[0] += mp * N[a] * sx;
        c[1] += mp * N[a] * sy;
        c[2] += mp * N[a] * N[a];
        c[3] += mp * N[a];
      }
    }
    cm_sum(0, 4);
    short_nodes.clear();
    for (std::size_t k = 0; k < ns; ++k) {
      const double mi = dn_rec_[kDn * cm_dk_[k] + kDnM];
      if (std::abs(cm_[kCm * k + 3] - mi) > 1e-9 * mi) short_nodes.push_back(cm_nodes_[k]);
    }
    more[0] = short_nodes.empty() ? 0.0 : 1.0;
    more[1] = short_nodes.empty() || scanned ? 0.0 : 1.0;
    more[2] = ns > 0 ? 1.0 : 0.0;
    if (dist_) dist_->max(more, 3);
    if (more[0] == 0) break;
    if (more[1] != 0) {  // every rank finds its zone again before any node is dropped
      rescan = true;
      ++dashpot_solve.rescans;
      continue;
    }
    dropped.insert(dropped.end(), short_nodes.begin(), short_nodes.end());
    std::sort(dropped.begin(), dropped.end());
  }
  const std::size_t ns = cm_nodes_.size();
  // The consistent mass between the slots, row by row (the diagonal left out; in each row the
  // entries in the order their first particle met them, each summed in particle order):
  // (Mc)_ij = sum_p m_p N_ip N_jp. A row holds at most the slots a particle's stencil shares
  // with it, kCmRow of them. The rows' pattern (each entry's slot and place) follows from the
  // hits' slots alone: when those are the last step's, so is the pattern, and the list of each
  // product's place (cm_pair_, in the order the products are summed) is used again.
  const std::size_t nh = cm_hits_.size();
  cm_key_next_.resize(K * nh);
  for (std::size_t t = 0; t < nh; ++t)
    std::copy_n(cm_ps_.data() + K * cm_hits_[t], K, cm_key_next_.data() + K * t);
  if (cm_key_next_ != cm_key_ || cm_cnt_.size() != ns) {
    // A new pattern; its products are summed as they are listed (the order of the pass below).
    cm_key_.clear();  // (no pattern, should the build below throw)
    cm_pair_.clear();
    cm_cnt_.assign(ns, 0);
    cm_col_.resize(kCmRow * ns);
    cm_w_.resize(kCmRow * ns);
    for (std::size_t t = 0; t < nh; ++t) {
      const int* sls = cm_key_next_.data() + K * t;
      const std::uint32_t q = cm_hits_[t];
      const double* N = cm_pN_.data() + K * q;
      for (int a = 0; a < K; ++a) {
        const int i = sls[a];
        if (i < 0) continue;
        int* ci = cm_col_.data() + kCmRow * i;
        for (int b = 0; b < K; ++b) {
          const int j = sls[b];
          if (j < 0 || j == i) continue;
          int e = 0;
          while (e < cm_cnt_[i] && ci[e] != j) ++e;
          if (e == cm_cnt_[i]) {
            if (e == kCmRow) throw std::logic_error("consistent_dashpots: a row of more than 24 slots");
            ci[e] = j;
            cm_w_[kCmRow * i + e] = 0.0;
            ++cm_cnt_[i];
          }
          cm_pair_.push_back({kCmRow * i + e, static_cast<int>(t), a, b});
          cm_w_[kCmRow * i + e] += cm_pm_[q] * N[a] * N[b];
        }
      }
    }
    cm_key_.swap(cm_key_next_);
  } else {
    for (std::size_t i = 0; i < ns; ++i) std::fill_n(cm_w_.data() + kCmRow * i, cm_cnt_[i], 0.0);
    for (const CmPair& c : cm_pair_) {
      const std::uint32_t q = cm_hits_[c.hit];
      const double* N = cm_pN_.data() + K * q;
      cm_w_[c.place] += cm_pm_[q] * N[c.a] * N[c.b];
    }
  }
  // Each slot's equation as an affine map, vbar = b - Q o (Q = P / (2 m), P the inverse of
  // I + kappa C on the free components, b = P (v + 1/2 Mc dv0 / m)), and its g = G vbar
  // (G = dt C / m on the free components); the start is the trapezoidal mean.
  // By columns (kCmNode of nsp values: ns rounded up to whole blocks of four slots, the rest
  // zero), vbar's x and y too; g as (x, y) pairs.
  const std::size_t nsp = (ns + 3) / 4 * 4;
  cm_node_.assign(kCmNode * nsp, 0.0);
  cm_vb_.assign(2 * nsp, 0.0);
  cm_o_.assign(2 * nsp, 0.0);
  cm_g0_.assign(2 * nsp, 0.0);
  double* vbx = cm_vb_.data();
  double* vby = vbx + nsp;
  double* ox = cm_o_.data();
  double* oy = ox + nsp;
  // Each slot its own: in parallel, the same values.
  const long nsl = static_cast<long>(ns);
  const bool sym = symmetric_correction();
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (nsl >= 256)
  for (long k = 0; k < nsl; ++k) {
    const double* r = dn_rec_.data() + kDn * cm_dk_[k];
    double* n = cm_node_.data() + k;  // n[nsp * c]: column c
    const double* c = cm_.data() + kCm * k;
    const int fi = static_cast<int>(r[kDnFlags]);  // a held component: fixed, or the closure's
    const double mi = r[kDnM], free_x = (fi & (1 | kDnHeldX)) ? 0.0 : 1.0,
                 free_y = (fi & (2 | kDnHeldY)) ? 0.0 : 1.0;
    const double cxx = r[kDnCxx], cxy = r[kDnCxy], cyy = r[kDnCyy];
    const double kap = 0.5 * DT * c[2] / (mi * mi);
    const double A = 1 + kap * cxx, B = kap * cxy, D = 1 + kap * cyy;
    double pxx = 0, pxy = 0, pyy = 0;
    if (free_x != 0 && free_y != 0) {
      const double det = A * D - B * B;
      pxx = D / det;
      pxy = -B / det;
      pyy = A / det;
    } else if (free_y != 0) {
      pyy = 1 / D;  // x held
    } else if (free_x != 0) {
      pxx = 1 / A;  // y held
    }
    // (The symmetric form: the corrected start velocity, the one the stress and the boundary
    // work take; the increment's part through R, not R^-1/2 R R^-1/2.)
    const double vx0 = sym ? sym_vx_[cm_nodes_[k]] : r[kDnVx];
    const double vy0 = sym ? sym_vy_[cm_nodes_[k]] : r[kDnVy];
    const double rx = vx0 + 0.5 * c[0] / mi, ry = vy0 + 0.5 * c[1] / mi;
    // A component the delayed closure holds keeps the mean of its start and its closure's
    // velocity (its Q row is zero: pxx = pxy = 0 there).
    n[0] = (fi & kDnHeldX) ? 0.5 * (r[kDnVx] + r[kDnUx]) : pxx * rx + pxy * ry;
    n[nsp] = (fi & kDnHeldY) ? 0.5 * (r[kDnVy] + r[kDnUy]) : pxy * rx + pyy * ry;
    const double q = 0.5 / mi;
    n[2 * nsp] = q * pxx;
    n[3 * nsp] = q * pxy;
    n[4 * nsp] = q * pyy;
    const double gs = DT / mi;
    const double n5 = free_x * gs, n6 = free_y * gs;
    n[5 * nsp] = n5;
    n[6 * nsp] = n6;
    n[7 * nsp] = cxx;
    n[8 * nsp] = cxy;
    n[9 * nsp] = cyy;
    vbx[k] = 0.5 * (r[kDnVx] + r[kDnUx]);
    vby[k] = 0.5 * (r[kDnVy] + r[kDnUy]);
    cm_g0_[2 * k] = n5 * (cxx * vbx[k] + cxy * vby[k]);
    cm_g0_[2 * k + 1] = n6 * (cxy * vbx[k] + cyy * vby[k]);
  }
  // An iteration: each slot's o from g (o's x and y as a pair: one SIMD register, each lane the
  // scalar multiply-adds), then (several ranks: o summed over the halo) every slot's vbar and its
  // new g, four slots at a time, each lane the scalar arithmetic; the new g is written apart
  // from the old. The largest change and vbar are the same whatever the order they are met in.
  using kernels::simd::M4;
  using kernels::simd::V2;
  using kernels::simd::V4;
  using kernels::simd::load;
  using kernels::simd::store;
  auto row_sums = [&](const double* gg) {
    for (std::size_t k = 0; k < ns; ++k) {
      const int* col = cm_col_.data() + kCmRow * k;
      const double* w = cm_w_.data() + kCmRow * k;
      V2 o = {0.0, 0.0};
      for (int e = 0; e < cm_cnt_[k]; ++e) {
        V2 gj;
        std::memcpy(&gj, gg + 2 * col[e], sizeof(V2));
        o += w[e] * gj;
      }
      ox[k] = o[0];
      oy[k] = o[1];
    }
  };
  // std::max(a, b) and std::abs lane by lane: b where a < b, else a; the sign bit cleared.
  auto vmax = [](V4 a, V4 b) {
    const M4 lt = a < b;
    return reinterpret_cast<V4>((reinterpret_cast<M4>(b) & lt) | (reinterpret_cast<M4>(a) & ~lt));
  };
  auto vabs = [](V4 a) {
    const M4 mask = {~(1L << 63), ~(1L << 63), ~(1L << 63), ~(1L << 63)};
    return reinterpret_cast<V4>(reinterpret_cast<M4>(a) & mask);
  };
  auto update = [&](double* gn, double& change, double& scale) {
    const double* n = cm_node_.data();
    V4 ch = {0, 0, 0, 0}, sc = {0, 0, 0, 0};
    for (std::size_t k = 0; k < nsp; k += 4) {
      const V4 o_x = load(ox + k), o_y = load(oy + k);
      const V4 bx = load(n + k) - (load(n + 2 * nsp + k) * o_x + load(n + 3 * nsp + k) * o_y);
      const V4 by = load(n + nsp + k) - (load(n + 3 * nsp + k) * o_x + load(n + 4 * nsp + k) * o_y);
      ch = vmax(ch, vmax(vabs(bx - load(vbx + k)), vabs(by - load(vby + k))));
      sc = vmax(sc, vmax(vabs(bx), vabs(by)));
      store(vbx + k, bx);
      store(vby + k, by);
      const V4 n8 = load(n + 8 * nsp + k);
      const V4 gx = load(n + 5 * nsp + k) * (load(n + 7 * nsp + k) * bx + n8 * by);
      const V4 gy = load(n + 6 * nsp + k) * (n8 * bx + load(n + 9 * nsp + k) * by);
      store(gn + 2 * k, __builtin_shufflevector(gx, gy, 0, 4, 1, 5));
      store(gn + 2 * k + 4, __builtin_shufflevector(gx, gy, 2, 6, 3, 7));
    }
    for (int l = 0; l < 4; ++l) {
      change = std::max(change, ch[l]);
      scale = std::max(scale, sc[l]);
    }
  };
  cm_g_.assign(2 * nsp, 0.0);
  int it = 0;
  for (;; ++it) {
    double change = 0, scale = 0;
    row_sums(cm_g0_.data());
    if (dist_) {
      for (std::size_t k = 0; k < ns; ++k) {
        cm_[kCm * k + 6] = ox[k];
        cm_[kCm * k + 7] = oy[k];
      }
      cm_sum(6, 2);
      for (std::size_t k = 0; k < ns; ++k) {
        ox[k] = cm_[kCm * k + 6];
        oy[k] = cm_[kCm * k + 7];
      }
      update(cm_g0_.data(), change, scale);
      double v[2] = {change, scale};
      dist_->max(v, 2);
      change = v[0];
      scale = v[1];
    } else {
      update(cm_g_.data(), change, scale);
      cm_g0_.swap(cm_g_);
    }
    // (Below the smallest normal double the relative test cannot hold: a wave's leading tail,
    // some 1e-316 m/s, reached an edge and ran the iteration to its limit.)
    if (change <= 1e-13 * scale || change < std::numeric_limits<double>::min()) break;
    if (it + 1 == kCmMaxIterations) {  // the last iterate stands; the run's summary counts it
      ++dashpot_solve.unconverged;
      break;
    }
  }
  if (more[2] != 0) {  // a node listed on some rank
    ++dashpot_solve.steps;
    dashpot_solve.iterations += it + 1;
    dashpot_solve.max_iterations = std::max(dashpot_solve.max_iterations, static_cast<long>(it + 1));
  }
  // Each slot its own: in parallel, the same values.
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (nsl >= 256)
  for (long k = 0; k < nsl; ++k) {
    const long i = cm_nodes_[k];
    double* c = cm_.data() + kCm * k;
    c[4] = vbx[k];
    c[5] = vby[k];
    const double* r = dn_rec_.data() + kDn * cm_dk_[k];
    const int fi = static_cast<int>(r[kDnFlags]);
    const double fx = r[kDnFx] - r[kDnCxx] * c[4] - r[kDnCxy] * c[5];
    const double fy = r[kDnFy] - r[kDnCxy] * c[4] - r[kDnCyy] * c[5];
    const double ux = (fi & kDnHeldX) ? r[kDnUx] : (fi & 1) ? 0.0 : r[kDnVx] + DT * fx / r[kDnM];
    const double uy = (fi & kDnHeldY) ? r[kDnUy] : (fi & 2) ? 0.0 : r[kDnVy] + DT * fy / r[kDnM];
    grid.vnx[i] = ux;
    grid.vny[i] = uy;
  }
  // This step's move of a zone particle, with the velocities as they now are: at most the
  // fastest of the nodes that move them (a particle from outside crosses a cell of the zone
  // before it reaches a listed node).
  double v2 = 0;
  const long nm = static_cast<long>(cm_moving_.size());
  const long* mv = cm_moving_.data();
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (nm >= 1024) reduction(max : v2)
  for (long e = 0; e < nm; ++e)
    v2 = std::max(v2, grid.vnx[mv[e]] * grid.vnx[mv[e]] + grid.vny[mv[e]] * grid.vny[mv[e]]);
  cm_drift_ += DT * std::sqrt(v2);
}

// Work of tractions and energy absorbed by dashpots over the step. The forces act with the
// mid-step nodal velocity (v + v+)/2 (the nodal dashpot is computed from it); their power is
// taken with (v + w)/2, where w is the velocity the particles carry to the grid after the step
// when the caller has it (MUSL's re-mapped field), else v+. With w, the work is exactly what the
// FLIP increments add to the particles' kinetic energy: at a node that holds little mass,
// v+ = v + dt f / m is large while the particles it touches receive a bounded impulse, and
// f (v + v+)/2 would count a spurious f^2 dt / (2 m) of work (film, 0.05 um cells, boundary
// anchor: external work x13 and a -93 % imbalance; with w, < 0.1 %).
template <class S>
void Solver::boundary_work(bool remapped) {
  constexpr int K = S::kNodes;
  const std::vector<double>& ux = remapped ? grid.qx : grid.vnx;
  const std::vector<double>& uy = remapped ? grid.qy : grid.vny;
  // (k: the node's place in dashpot_nodes_.)
  const bool corrected = !mc_dash_v_.empty();
  auto vbar = [&](long i, long k, double& ax, double& ay) {  // the forces' velocity
    if (!cm_slot_.empty() && cm_slot_[i] >= 0) {  // consistent_dashpots
      ax = cm_[kCm * cm_slot_[i] + 4];
      ay = cm_[kCm * cm_slot_[i] + 5];
      return;
    }
    // v+ as the grid update left it (correct_increments changes it afterwards)
    ax = 0.5 * (grid.vx[i] + (corrected ? mc_dash_v_[2 * k] : grid.vnx[i]));
    ay = 0.5 * (grid.vy[i] + (corrected ? mc_dash_v_[2 * k + 1] : grid.vny[i]));
  };
  // MUSL: at the delayed closure's nodes the re-mapped velocity holds the strain velocity the
  // closure made of it (delay_strain_velocities); the power takes the particles' own, which the
  // kinetic energy follows, that value less the change.
  const bool strain_closed = remapped && !delay_slot_.empty() && opt.scheme == Scheme::MUSL;
  // (The symmetric form: both ends of the step corrected, the particles' velocities as the
  // corrected field sees them.)
  const double* sx0 = symmetric_correction() ? sym_vx_.data() : grid.vx.data();
  const double* sy0 = symmetric_correction() ? sym_vy_.data() : grid.vy.data();
  auto wbar = [&](long i, double& ax, double& ay) {  // the power's velocity
    ax = 0.5 * (sx0[i] + ux[i]);
    ay = 0.5 * (sy0[i] + uy[i]);
    if (strain_closed)
      if (const double* rec = delay_record(i)) {  // (the change is zero where it did not act)
        ax -= 0.5 * rec[kDelayDgx];
        ay -= 0.5 * rec[kDelayDgy];
      }
  };
  // A layer's terms: term(q, t) writes entry q's K terms into t (in parallel, each entry its
  // own; none for an entry with skip(q)), then they are added to (or subtracted from) `acc` in
  // entry order: the sums of one pass in order, bit for bit.
  const auto none = [](long) { return false; };
  auto entry_sums = [&](long n, const auto& skip, const auto& term, double& acc, bool subtract) {
    layer_scratch_.resize(K * static_cast<std::size_t>(n));
    double* T = layer_scratch_.data();
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (n >= 256)
    for (long q = 0; q < n; ++q)
      if (!skip(q)) term(q, T + K * q);
    for (long q = 0; q < n; ++q)
      if (!skip(q))
        for (int a = 0; a < K; ++a) {
          if (subtract) acc -= T[K * q + a];
          else acc += T[K * q + a];
        }
  };
  for (const auto& tl : tractions) {
    const double f = tl.fn(t);
    if (f == 0.0) continue;
    entry_sums(static_cast<long>(tl.layer.idx.size()), none, [&](long q, double* T) {
      double tx, ty, ax, ay;
      traction_of(tl, q, f, tx, ty);
      const long* tn = tl.nodes.data() + K * q;  // the weights apply_loads mapped with
      const double* N = tl.N.data() + K * q;
      for (int a = 0; a < K; ++a) {
        wbar(tn[a], ax, ay);
        T[a] = dt * tl.layer.w[q] * N[a] * (tx * ax + ty * ay);
      }
    }, energy.external_work, false);
  }
  // Gravity's work with the same velocity as the tractions' (void nodes have m = 0).
  if (opt.gravity_x != 0 || opt.gravity_y != 0) {
    const double gx = opt.gravity_x, gy = opt.gravity_y;
    // This rank's own nodes: every node without a decomposition, whole rows of slabs, one
    // range of each row of a block.
    const bool all = own_[1] < own_[0];
    const bool rows = all || (own_[0] == 0 && own_[1] == grid.nnx - 1);
    const long j0 = all ? 0 : own_[2], j1 = all ? grid.nny - 1 : own_[3];
    const long n0 = rows ? j0 * grid.nnx : 0;
    const long n = rows ? (j1 + 1) * grid.nnx - n0 : static_cast<long>(grid.nodes());
    const long i0 = rows ? 0 : own_[0], i1 = rows ? grid.nnx - 1 : own_[1];
    const long nnx = grid.nnx;
    const double* m = grid.m.data() + n0;
    const double* v0x = sx0 + n0; const double* v0y = sy0 + n0;
    const double* wx = ux.data() + n0; const double* wy = uy.data() + n0;
    double w = 0;
    if (rows) {
#pragma omp parallel for schedule(static) reduction(+ : w) num_threads(nthreads_)
      for (long i = 0; i < n; ++i)
        w += m[i] * (gx * 0.5 * (v0x[i] + wx[i]) + gy * 0.5 * (v0y[i] + wy[i]));
    } else {
      for (long j = j0; j <= j1; ++j)
        for (long i = j * nnx + i0; i <= j * nnx + i1; ++i)
          w += m[i] * (gx * 0.5 * (v0x[i] + wx[i]) + gy * 0.5 * (v0y[i] + wy[i]));
    }
    if (strain_closed) {  // at the closure's nodes, with the particles' own velocity (above)
      const std::size_t R = delay_stride();
      const std::array<int, 2> o = window_origin();
      for (std::size_t r = 0; r * R < delay_.size(); ++r) {
        const double* rec = delay_.data() + r * R;
        if (rec[kDelayDgx] == 0 && rec[kDelayDgy] == 0) continue;
        const long nd = delay_window_node(rec, o);
        if (nd < 0 || !owns_node(nd)) continue;
        w -= grid.m[nd] * (gx * 0.5 * rec[kDelayDgx] + gy * 0.5 * rec[kDelayDgy]);
      }
    }
    energy.external_work += dt * w;
  }
  // The nodal dashpot blocks C_i (the silent layers' nodal form, the damping layers' mass part,
  // the perfectly matched layers' damping): the force -C_i vbar_i that grid_update applied, its
  // power with wbar_i, node by node in the order the blocks were assembled; this rank's own
  // nodes (a shared node's block is summed over the halo). The per-entry sum of the same terms,
  // sum_q w_q N_i C_q, gives the same work up to round-off.
  if (has_nodal_dashpot_) {
    // Each node's one or two terms (in parallel, each its own), then their sum in order.
    const long nd = static_cast<long>(dashpot_nodes_.size());
    dn_work_.resize(2 * nd);
    dn_terms_.resize(nd);
    double* T = dn_work_.data();
    std::uint8_t* terms = dn_terms_.data();
    const double now = static_cast<double>(steps);
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (nd >= 256)
    for (long k = 0; k < nd; ++k) {
      const long i = dashpot_nodes_[k];
      terms[k] = 0;
      if (!owns_node(i)) continue;
      double ax, ay, bx, by;
      wbar(i, bx, by);
      double* rec = delay_slot_.empty() ? nullptr : delay_record(i);
      if (rec && rec[kDelayAt] == now) {
        // The delayed closure: what it takes out against the conservative update, the force
        // and its work with the strain velocity (delay_strain_velocities):
        // (f + C v_d)/2 . wbar + f_s . (g - g0), f the force less gravity. f_s is the mean of
        // the forces before and after the stress update that g - g0 strains (the work of the
        // stresses it changes, to second order in dt): USF's update comes before this step's
        // forces, so the last step's and this one's; MUSL's after them, so this step's and the
        // next one's, booked then (a node the closure does not take next step keeps f).
        // The tangential component: C vbar . wbar, vbar the particles' mean where
        // consistent_dashpots solved it.
        const double fx = rec[kDelayFx], fy = rec[kDelayFy];
        const double cx = rec[kDelayCxx] * rec[kDelayVx], cy = rec[kDelayCyy] * rec[kDelayVy];
        vbar(i, k, ax, ay);
        T[2 * k] = delayed_axis(rec[kDelayCxx], rec[kDelayCyy])
                       ? 0.5 * (fx + cx) * bx + fx * rec[kDelayDgx]
                       : grid.cxx(i) * ax * bx;
        T[2 * k + 1] = delayed_axis(rec[kDelayCyy], rec[kDelayCxx])
                           ? 0.5 * (fy + cy) * by + fy * rec[kDelayDgy]
                           : grid.cyy(i) * ay * by;
        if (rec[kDelayBookedAt] == now - 1) {
          if (opt.scheme == Scheme::USF) {
            T[2 * k] += 0.5 * (rec[kDelayBookedFx] - fx) * rec[kDelayDgx];
            T[2 * k + 1] += 0.5 * (rec[kDelayBookedFy] - fy) * rec[kDelayDgy];
          } else {
            T[2 * k] += 0.5 * (fx - rec[kDelayBookedFx]) * rec[kDelayBookedDgx];
            T[2 * k + 1] += 0.5 * (fy - rec[kDelayBookedFy]) * rec[kDelayBookedDgy];
          }
        }
        rec[kDelayBookedAt] = now;
        rec[kDelayBookedDgx] = rec[kDelayDgx];
        rec[kDelayBookedDgy] = rec[kDelayDgy];
        rec[kDelayBookedFx] = fx;
        rec[kDelayBookedFy] = fy;
        terms[k] = 2;
        continue;
      }
      vbar(i, k, ax, ay);
      T[2 * k] =
          (grid.cxx(i) * ax + grid.cxy(i) * ay) * bx + (grid.cxy(i) * ax + grid.cyy(i) * ay) * by;
      terms[k] = 1;
    }
    double w = 0;
    for (long k = 0; k < nd; ++k) {
      if (terms[k] > 0) w += T[2 * k];
      if (terms[k] > 1) w += T[2 * k + 1];
    }
    energy.absorbed += dt * w;
  }
  // Silent layers: the springs' displacements advance (USF: in apply_loads); the particle
  // form's dashpot acts on the particle velocity, entry by entry.
  for (auto& sl : silents) {
    const auto& L = sl.layer;
    const bool advance = sl.springs() && opt.scheme != Scheme::USF;
    const bool particle = sl.form == SilentForm::Particle;
    const long n = static_cast<long>(L.idx.size());
    if (!particle) {
      if (!advance) continue;
#pragma omp parallel for schedule(static) num_threads(nthreads_) if (n >= 256)
      for (long q = 0; q < n; ++q)
        advance_spring<K>(sl, q, sl.N.data() + K * q, sl.nodes.data() + K * q, ux, uy, dt);
      continue;
    }
    entry_sums(n, none, [&](long q, double* T) {
      const long* sn = sl.nodes.data() + K * q;  // the weights apply_loads mapped with
      const double* N = sl.N.data() + K * q;
      if (advance) advance_spring<K>(sl, q, N, sn, ux, uy, dt);
      double tx, ty;
      dashpot_of(sl, q, p.vx[L.idx[q]], p.vy[L.idx[q]], tx, ty);
      for (int a = 0; a < K; ++a) {
        double bx, by;
        wbar(sn[a], bx, by);
        T[a] = dt * L.w[q] * N[a] * (tx * bx + ty * by);
      }
    }, energy.absorbed, true);
  }
  // Perfectly matched layers: the power of the explicit loads (their damping is a nodal block,
  // above); then the particles' displacements advance (USF: in pml_loads).
  if (pml.active()) {
    entry_sums(static_cast<long>(pml.layer.idx.size()), none, [&](long q, double* T) {
      const long* pn = pml.nodes.data() + K * q;
      const double* N = pml.N.data() + K * q;
      const double* dNx = pml.dNx.data() + K * q;
      const double* dNy = pml.dNy.data() + K * q;
      const double* f = pml.f.data() + 6 * q;
      // (The loads in registers: T's stores could alias them.)
      const double f0 = f[0], f1 = f[1], f2 = f[2], f3 = f[3], f4 = f[4], f5 = f[5];
      for (int a = 0; a < K; ++a) {
        double bx, by;
        wbar(pn[a], bx, by);
        const double fx = f4 * N[a] - (f0 * dNx[a] + f2 * dNy[a]);
        const double fy = f5 * N[a] - (f1 * dNx[a] + f3 * dNy[a]);
        T[a] = dt * (fx * bx + fy * by);
      }
    }, energy.absorbed, true);
    if (opt.scheme != Scheme::USF) pml_advance<S>(ux, uy);
  }
  // Damping layers: the stiffness-proportional part (their mass part is a nodal block, above).
  for (auto& dl : dampers) {
    const auto& L = dl.layer;
    const long n = static_cast<long>(L.idx.size());
    if (!(dl.beta0 > 0)) continue;
    // The stiffness-proportional part: the work of the viscous force this step applied (with
    // the power's velocity), then the viscous stress beta C : D for the next, all with the
    // gradients the force was mapped with (apply_loads: the positions at the step's start). D is
    // the strain rate of the re-mapped velocity under MUSL and USF (the power's), of the start
    // velocity p / m under USL: never v+, which at a node holding a sliver of a particle
    // magnifies the force and broke the explicit limit (docs/physics.md section 9.2).
    const std::vector<double>& sx = opt.scheme == Scheme::USL ? grid.vx : ux;
    const std::vector<double>& sy = opt.scheme == Scheme::USL ? grid.vy : uy;
    entry_sums(n, [&](long q) { return dl.beta[q] == 0; }, [&](long q, double* T) {
      const std::uint32_t k = L.idx[q];
      const long* gn = dl.gnodes.data() + K * q;
      const double* dNx = dl.dNx.data() + K * q;
      const double* dNy = dl.dNy.data() + K * q;
      double* sv = dl.sv.data() + 3 * q;
      const double V = p.vol[k];
      double lxx = 0, lxy = 0, lyx = 0, lyy = 0;  // du_x/dx, du_x/dy, du_y/dx, du_y/dy
      for (int a = 0; a < K; ++a) {
        double bx, by;
        wbar(gn[a], bx, by);
        T[a] = dt * V * ((sv[0] * dNx[a] + sv[2] * dNy[a]) * bx +
                         (sv[2] * dNx[a] + sv[1] * dNy[a]) * by);
        lxx += sx[gn[a]] * dNx[a];
        lxy += sx[gn[a]] * dNy[a];
        lyx += sy[gn[a]] * dNx[a];
        lyy += sy[gn[a]] * dNy[a];
      }
      const Material& m = materials[p.group[k]];
      const double b = dl.beta[q], tr = lxx + lyy;
      sv[0] = b * (m.lambda * tr + 2 * m.mu * lxx);
      sv[1] = b * (m.lambda * tr + 2 * m.mu * lyy);
      sv[2] = b * m.mu * (lxy + lyx);
    }, energy.absorbed, false);
  }
}

void Solver::begin_moving_pass() {
  std::fill(strip_lo_.begin(), strip_lo_.end(), std::numeric_limits<int>::max());
  std::fill(strip_hi_.begin(), strip_hi_.end(), std::numeric_limits<int>::min());
  std::fill(strip_out_.begin(), strip_out_.end(), 0);
}

void Solver::merge_rows(int s, const RowSpan& r) {
  strip_out_[s] += r.out;
  strip_lo_[s] = std::min(strip_lo_[s], r.lo);
  strip_hi_[s] = std::max(strip_hi_[s], r.hi);
}

// The consistent-mass correction of the increment (docs/physics.md section 1.1). Under MUSL
// and USF the velocity the particles map back to a node after their FLIP update is v + R dv, R
// = M^-1 M_c (M the lumped mass, M_c = N^T m N the particles' consistent mass), so the grid's
// waves move as if each node weighed M R^-1: the scheme's frequencies are the lumped mass's
// times the square root of R's eigenvalue r (1 - (kh)^2 / 6 and below for a wave along an axis).
// The increment taken as sum_{j=0..k} (I - R)^j dv, the first k + 1 terms of R^-1 dv, makes
// that factor 1 - (1 - r)^(k+1). Each term costs one pass over the particles (a gather and a
// scatter); a held component and a void node take none. USL strains the particles with v+
// itself: there v+ keeps the lumped increment (whose time step it needs) and the correction's
// extra increment goes to the particles alone, through the start velocity g2p subtracts
// (shift_start_velocities). A hook set adds to M_c the mass its nodes carry beyond the
// particles' (add_mass_product: the hybrid's FE mass at shared nodes, R = M^-1 (M_c + M_FE)).
template <class S>
void Solver::correct_increments() {
  const std::size_t n = grid.nodes();
  for (auto* v : {&mc_tx_, &mc_ty_, &mc_ax_, &mc_ay_}) v->resize(n);
  const bool usl = opt.scheme == Scheme::USL;
  // The trapezoidal dashpot nodes' force acted with the mean of v and the lumped v+, which the
  // correction is about to change: keep it for the work (a node holding a sliver of a particle
  // beyond a wide shape's edge takes a large corrected increment; booked with it, the column's
  // absorbed work came out 13 % short with GIMP and two terms).
  mc_dash_v_.clear();
  // (With multi-field contact the bodies' fields are corrected, not the grid's own.)
  if (!usl && has_nodal_dashpot_ && !contact.multi()) {
    mc_dash_v_.resize(2 * dashpot_nodes_.size());
    for (std::size_t k = 0; k < dashpot_nodes_.size(); ++k) {
      mc_dash_v_[2 * k] = grid.vnx[dashpot_nodes_[k]];
      mc_dash_v_[2 * k + 1] = grid.vny[dashpot_nodes_[k]];
    }
  }
  if (usl) {  // one block of nodes per field
    mc_ex_.assign(n * fields_.size(), 0.0);
    mc_ey_.assign(n * fields_.size(), 0.0);
  }
  for (std::size_t k = 0; k < fields_.size(); ++k)
    correct_field<S>(fields_[k], usl ? mc_ex_.data() + k * n : nullptr,
                     usl ? mc_ey_.data() + k * n : nullptr);
}

// The nodes of field F: every node of the grid's own field, a body's box of its field.
template <class Fn>
void Solver::field_nodes(const VelocityField& F, Fn&& fn) {
  if (F.body >= 0) {
    kernels::for_box(F.box, grid.nnx, nthreads_, fn);
    return;
  }
  const long n = static_cast<long>(grid.nodes());
#pragma omp parallel for simd schedule(static) num_threads(nthreads_)
  for (long i = 0; i < n; ++i) fn(i);
}

// One field's correction (correct_increments): its increment, its particles' consistent mass,
// the terms into its v+ or, under USL, into (ex, ey).
template <class S>
void Solver::correct_field(const VelocityField& F, double* ex, double* ey) {
  double* tx = mc_tx_.data(); double* ty = mc_ty_.data();
  double* ax = mc_ax_.data(); double* ay = mc_ay_.data();
  const NodalField& f = F.f;
  const double* vx = f.vx; const double* vy = f.vy;
  double* ux = f.vnx; double* uy = f.vny;
  const double* m = f.m;
  const uint8_t* fix = grid.fix.data();
  const double floor = mass_floor_;
  field_nodes(F, [=](long i) {
    const bool heavy = m[i] > floor;
    tx[i] = heavy && !(fix[i] & 1) ? ux[i] - vx[i] : 0.0;
    ty[i] = heavy && !(fix[i] & 2) ? uy[i] - vy[i] : 0.0;
    ax[i] = 0;  // each term's product; the update below clears it again once read
    ay[i] = 0;
  });
  if (!ex) {  // where the terms go: USL's extra increment, or v+
    ex = ux;
    ey = uy;
  }
  series_terms<S>(F, ex, ey, symmetric_correction());
}

// The terms of the series on the field's nodes, from the term t = (mc_tx_, mc_ty_) each node
// holds (its zeroth) into (ex, ey): t <- (I - R) t, then e += c_j t, with c_j = 1 (R^-1), or the
// coefficients of (1 - x)^-1/2 (`half`: R^-1/2; multiplying by 1 changes no bit of the sum).
template <class S>
void Solver::series_terms(const VelocityField& F, double* ex, double* ey, bool half) {
  double* tx = mc_tx_.data(); double* ty = mc_ty_.data();
  double* ax = mc_ax_.data(); double* ay = mc_ay_.data();
  const double* m = F.f.m;
  const uint8_t* fix = grid.fix.data();
  const double floor = mass_floor_;
  double c = 1;
  for (int term = 0; term < opt.mass_correction; ++term) {
    if (half) c *= (2.0 * term + 1) / (2.0 * term + 2);
    scatter(F.ranges, [&](uint32_t b, uint32_t e, int g, int) {
      kernels::consistent_mass_product<S>(grid, p, b, e, inv_rho(g), tx, ty, ax, ay);
    });
    if (dist_) {
      double* const sums[2] = {ax, ay};
      dist_->sum_halo(sums, 2, nullptr);
    }
    call([&](StepHooks& h) { h.add_mass_product(*this, tx, ty, ax, ay); });
    if (light_nodes.active()) light_nodes.fold_product(m, fix, floor, tx, ty, ax, ay);
    field_nodes(F, [=](long i) {
      const bool heavy = m[i] > floor;
      tx[i] = heavy && !(fix[i] & 1) ? tx[i] - ax[i] / m[i] : 0.0;
      ty[i] = heavy && !(fix[i] & 2) ? ty[i] - ay[i] / m[i] : 0.0;
      ex[i] += c * tx[i];
      ey[i] += c * ty[i];
      ax[i] = 0;
      ay[i] = 0;
    });
  }
}

// The symmetric form of the correction (docs/physics.md section 1.1): the series of R^-1/2 on u,
// in place, over the grid's own field (one field: no multi-field contact, no hybrid).
template <class S>
void Solver::symmetric_velocity(double* ux, double* uy) {
  const VelocityField& F = fields_[0];
  const std::size_t n = grid.nodes();
  for (auto* v : {&mc_tx_, &mc_ty_, &mc_ax_, &mc_ay_}) v->resize(n);
  double* tx = mc_tx_.data(); double* ty = mc_ty_.data();
  double* ax = mc_ax_.data(); double* ay = mc_ay_.data();
  const double* m = F.f.m;
  const uint8_t* fix = grid.fix.data();
  const double floor = mass_floor_;
  field_nodes(F, [=](long i) {
    const bool heavy = m[i] > floor;
    tx[i] = heavy && !(fix[i] & 1) ? ux[i] : 0.0;
    ty[i] = heavy && !(fix[i] & 2) ? uy[i] : 0.0;
    ax[i] = 0;
    ay[i] = 0;
  });
  series_terms<S>(F, ux, uy, true);
}

// The start velocity's symmetric correction, at the step's start positions: the velocity the
// boundary work takes at the start of the step (with the re-mapped one's, corrected too, at its
// end), and USF's strain velocity.
template <class S>
void Solver::symmetric_start_velocity() {
  sym_vx_.assign(grid.vx.begin(), grid.vx.end());
  sym_vy_.assign(grid.vy.begin(), grid.vy.end());
  symmetric_velocity<S>(sym_vx_.data(), sym_vy_.data());
}

void Solver::correct_body_increments() {
  switch (opt.shape) {
    case ShapeKind::Bilinear: return correct_increments<Bilinear>();
    case ShapeKind::UGimp: return correct_increments<UGimp>();
    case ShapeKind::BSpline2: return correct_increments<BSpline2>();
  }
}

// USL with the mass correction, just before g2p: the start velocity of each field less the
// correction's extra increment, so that the particles' FLIP increment v+ - v is the corrected
// one while v+ (the strain's and the positions' velocity) keeps the lumped increment.
void Solver::shift_start_velocities() {
  const std::size_t n = grid.nodes();
  for (std::size_t k = 0; k < fields_.size(); ++k) {
    double* vx = fields_[k].f.vx; double* vy = fields_[k].f.vy;
    const double* ex = mc_ex_.data() + k * n; const double* ey = mc_ey_.data() + k * n;
    field_nodes(fields_[k], [=](long i) {
      vx[i] -= ex[i];
      vy[i] -= ey[i];
    });
  }
}

// Particle velocities from every field (FLIP/PIC blend); MUSL re-maps the particle momenta to
// the field at the same positions; USF moves the particles here.
template <class S>
void Solver::g2p(bool remap, bool move) {
  if (move) begin_moving_pass();
  const double flip = opt.flip, DT = dt;
  for (VelocityField& F : fields_) {
    const NodalField& f = F.f;
    if (remap && F.body >= 0) kernels::for_box(F.box, grid.nnx, nthreads_, [&](long i) {
      f.qx[i] = 0; f.qy[i] = 0;
    });
    std::vector<double> ke(nstrips_, 0.0), v2(nstrips_, 0.0);
    auto body = [&](uint32_t b, uint32_t e, int g, int s) {
      RowSpan r;
      const double ir = inv_rho(g);
      if (remap && move) kernels::g2p<S, true, true>(grid, p, b, e, f, ir, flip, DT, r);
      else if (remap) kernels::g2p<S, true, false>(grid, p, b, e, f, ir, flip, DT, r);
      else if (move) kernels::g2p<S, false, true>(grid, p, b, e, f, ir, flip, DT, r);
      else kernels::g2p<S, false, false>(grid, p, b, e, f, ir, flip, DT, r);
      if (move) merge_rows(s, r);
      ke[s] += r.kinetic;
      v2[s] = std::max(v2[s], r.speed2);
    };
    if (remap) scatter(F.ranges, body);
    else parallel(F.ranges, body);
    for (int s = 0; s < nstrips_; ++s) {
      step_kinetic_ += ke[s];
      step_speed2_ = std::max(step_speed2_, v2[s]);
    }
  }
}

// Stress update of every field's particles from the field's start velocity (USF), its re-mapped
// velocity (MUSL) or its updated velocity (USL); with move, positions advance with the updated
// nodal velocity. The dissipation is booked field by field.
template <class S>
void Solver::update_stress(bool remapped_field, bool start_field, bool move) {
  if (move) begin_moving_pass();
  for (VelocityField& F : fields_) {
    const NodalField& f = F.f;
    const bool sym = start_field && symmetric_correction();
    const double* gx = sym ? sym_vx_.data() : start_field ? f.vx : (remapped_field ? f.qx : f.vnx);
    const double* gy = sym ? sym_vy_.data() : start_field ? f.vy : (remapped_field ? f.qy : f.vny);
    std::vector<double> diss(nstrips_, 0.0);
    parallel(F.ranges, [&](uint32_t b, uint32_t e, int g, int s) {
      if (b == e) return;
      RowSpan r;
      const Material& mat = materials[g];
      auto run = [&](auto model_c) {
        constexpr Model M = decltype(model_c)::value;
        return move ? kernels::update_stress<S, M, true>(grid, p, b, e, mat, gx, gy, f.vnx,
                                                        f.vny, dt, r)
                    : kernels::update_stress<S, M, false>(grid, p, b, e, mat, gx, gy, f.vnx,
                                                         f.vny, dt, r);
      };
      double d = 0;
      switch (mat.model) {
        case Model::Elastic: d = run(std::integral_constant<Model, Model::Elastic>()); break;
        case Model::VonMises: d = run(std::integral_constant<Model, Model::VonMises>()); break;
        case Model::J2Film: d = run(std::integral_constant<Model, Model::J2Film>()); break;
      }
      diss[s] += d;
      if (move) merge_rows(s, r);
    });
    for (double d : diss) energy.dissipated += d;
  }
}

// The passes that move particles count, per strip, the particles outside the grid's columns and
// track the rows; no extra pass over the particles is needed unless one has left.
// The first node whose updated velocity is not finite, named with the step, the time and the
// node's position; the run stops there.
void Solver::fail_nonfinite() const {
  for (long i = 0; i < static_cast<long>(grid.nodes()); ++i) {
    if (std::isfinite(grid.vnx[i]) && std::isfinite(grid.vny[i])) continue;
    const long ii = i % grid.nnx, jj = i / grid.nnx;
    std::ostringstream o;
    o << "non-finite velocity at step " << steps + 1 << " (t = " << t + dt << " s) at grid node ("
      << ii << ", " << jj << "), position (" << grid.x0 + ii * grid.h << ", " << grid.y0 + jj * grid.h
      << "): mass " << grid.m[i] << ", force (" << grid.fx[i] << ", " << grid.fy[i]
      << "); the run is unstable (reduce time.cfl or time.dt) or a load or material value is not "
         "finite";
    throw std::runtime_error(o.str());
  }
  throw std::runtime_error("non-finite velocity at step " + std::to_string(steps + 1) +
                           ": the run is unstable");
}

void Solver::check_outside() {
  bool bad = false;
  for (int s = 0; s < nstrips_; ++s)
    if (strip_out_[s] > 0 ||
        (strip_lo_[s] <= strip_hi_[s] && (strip_lo_[s] < 0 || strip_hi_[s] >= grid.ny)))
      bad = true;
  if (!bad) {
    strips_ok_ = !strips_conflict();
    return;
  }
  const long k = first_particle_outside();
  std::ostringstream o;
  o << "particle " << (k >= 0 ? p.id[k] : 0) << " left the grid at step " << steps << " (t = " << t
    << " s)";
  if (k >= 0) o << " at (" << p.x[k] << ", " << p.y[k] << ")";
  o << "; enlarge grid.size or check the loads";
  throw std::runtime_error(o.str());
}

std::vector<std::uint8_t> Solver::layer_flags() const {
  std::vector<std::uint8_t> f(p.size(), 0);
  auto mark = [&](const BoundaryLayer& L, std::uint8_t bit) {
    for (const uint32_t k : L.idx) f[k] |= bit;
  };
  for (const auto& sl : silents) mark(sl.layer, sl.delta > 0 ? 1 | 4 : 1);
  for (const auto& tl : tractions) mark(tl.layer, 2);
  for (const auto& dl : dampers) mark(dl.layer, 8);
  mark(pml.layer, 16);
  return f;
}

Solver::NodalProjection Solver::nodal_projection() const {
  NodalProjection out;
  switch (opt.shape) {
    case ShapeKind::Bilinear: project<Bilinear>(out); break;
    case ShapeKind::UGimp: project<UGimp>(out); break;
    case ShapeKind::BSpline2: project<BSpline2>(out); break;
  }
  return out;
}

template <class S>
void Solver::project(NodalProjection& o) const {
  const std::size_t n = grid.nodes();
  for (auto* v : {&o.mass, &o.vx, &o.vy, &o.sxx, &o.syy, &o.szz, &o.sxy}) v->assign(n, 0.0);
  S sf;
  long nodes[S::kNodes];
  for (std::size_t k = 0; k < p.size(); ++k) {
    if constexpr (S::kSized) sf.size(p.mass[k], 1.0 / materials[p.group[k]].rho, grid.inv_h);
    sf.eval(grid, p.x[k], p.y[k]);
    sf.node_indices(grid.nnx, nodes);
    for (int a = 0; a < S::kNodes; ++a) {
      const double w = sf.N[a] * p.mass[k];
      const auto i = static_cast<std::size_t>(nodes[a]);
      o.mass[i] += w;
      o.vx[i] += w * p.vx[k];
      o.vy[i] += w * p.vy[k];
      o.sxx[i] += w * p.sxx[k];
      o.syy[i] += w * p.syy[k];
      o.szz[i] += w * p.szz[k];
      o.sxy[i] += w * p.sxy[k];
    }
  }
  if (dist_) {  // the shared nodes' sums over the ranks, before the division
    double* f[7] = {o.mass.data(), o.vx.data(), o.vy.data(), o.sxx.data(),
                    o.syy.data(),  o.szz.data(), o.sxy.data()};
    dist_->sum_halo(f, 7, nullptr);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!(o.mass[i] > 0)) {
      o.mass[i] = o.vx[i] = o.vy[i] = o.sxx[i] = o.syy[i] = o.szz[i] = o.sxy[i] = 0;
      continue;
    }
    const double inv = 1.0 / o.mass[i];
    o.vx[i] *= inv; o.vy[i] *= inv;
    o.sxx[i] *= inv; o.syy[i] *= inv; o.szz[i] *= inv; o.sxy[i] *= inv;
  }
}

// The time step: see the sequence at the top of solver.hpp.
void Solver::step() {
  switch (opt.shape) {
    case ShapeKind::Bilinear: return step_with<Bilinear>();
    case ShapeKind::UGimp: return step_with<UGimp>();
    case ShapeKind::BSpline2: return step_with<BSpline2>();
  }
}

template <class S>
void Solver::step_with() {
  const double start = store_mode() < 0 ? omp_get_wtime() : 0.0;
  if (!strips_ok_) sort_particles();
  if (body_of_group_.empty()) refresh_fields();  // the grid's arrays (pointers only)
  const Scheme sc = opt.scheme;
  reset_grid();
  p2g<S>(sc == Scheme::USF ? kMomentum : kMomentum | kForce);
  // Split over ranks: the shared nodes' masses and momenta are summed before anything reads them
  // (the boundary layers' weights read the nodal mass); their forces once the loads are in.
  if (dist_) sum_halo(true, false);
  if (light_nodes.active() && light_nodes.candidates(grid, mass_floor_))
    light_nodes.classify_and_fold(grid, layer_nodes<S>());
  call([&](StepHooks& h) { h.after_momentum(*this); });
  if (sc == Scheme::USF) {
    start_velocities();
    // Kelvin-Voigt springs advance with the centre-of-mass start velocity (apply_loads); with
    // body fields the grid's own arrays hold that field, whose velocity grid_update computes
    // only later: compute it now (the same values grid_update will find).
    if (!body_of_group_.empty() && has_springs_)
      kernels::nodal_velocity(grid, NodeBox{0, grid.nnx - 1, 0, grid.nny - 1}, grid.m.data(),
                              grid.fix.data(), grid.px.data(), grid.py.data(), grid.vx.data(),
                              grid.vy.data(), mass_floor_, nthreads_);
    if (light_nodes.active()) {
      light_nodes.extend(grid.vx.data());
      light_nodes.extend(grid.vy.data());
    }
    if (symmetric_correction()) symmetric_start_velocity<S>();
    update_stress<S>(false, true, false);
    p2g<S>(kForce);
  }
  apply_loads<S>();
  if (light_nodes.active())
    light_nodes.fold_forces(grid, gravity_in_update() ? 0.0 : opt.gravity_x,
                            gravity_in_update() ? 0.0 : opt.gravity_y);
  call([&](StepHooks& h) { h.after_forces(*this); });
  grid_update();
  if (light_nodes.active()) extend_updated(true);
  // (MUSL: the start velocity's symmetric correction, for the dashpots' solve and the boundary
  // work; USF made it before its stress update.)
  if (symmetric_correction() && sc == Scheme::MUSL) symmetric_start_velocity<S>();
  if (consistent_) {
    consistent_dashpots<S>();
    if (light_nodes.active()) extend_updated(false);
  }
  call([&](StepHooks& h) { h.after_grid_update(*this); });
  // After every dashpot's update; multi-field contact corrects its bodies' fields itself,
  // before its contact correction (correct_body_increments).
  if (opt.mass_correction > 0 && !contact.multi()) correct_increments<S>();
  // (The symmetric form books every power with the corrected re-mapped velocity.)
  bool remapped_power =
      sc == Scheme::MUSL || (sc == Scheme::USF && (usf_remapped_power() || symmetric_correction()));
  call([&](StepHooks& h) { remapped_power = remapped_power && h.remapped_power(); });
  if (!remapped_power) boundary_work<S>(false);
  call([&](StepHooks& h) { h.before_g2p(*this); });
  if (pml.active()) pml_pic<S>();
  switch (sc) {
    case Scheme::MUSL:
      g2p<S>(true, false);
      if (pml.active()) pml_damping<S>(true);
      remapped_velocities(true);
      if (symmetric_correction()) symmetric_velocity<S>(grid.qx.data(), grid.qy.data());
      sym_field_ = symmetric_correction();
      if (remapped_power) boundary_work<S>(true);
      update_stress<S>(true, false, true);
      break;
    case Scheme::USL:
      if (opt.mass_correction > 0) shift_start_velocities();
      g2p<S>(false, false);
      update_stress<S>(false, false, true);
      break;
    case Scheme::USF:
      // The particles move here; the loads' power is taken with the velocity they carry back,
      // their momenta re-mapped as MUSL's (unless a hook keeps v+).
      g2p<S>(remapped_power, true);
      if (pml.active()) pml_damping<S>(remapped_power);
      if (remapped_power) {
        remapped_velocities(false);
        if (symmetric_correction()) symmetric_velocity<S>(grid.qx.data(), grid.qy.data());
        sym_field_ = symmetric_correction();
        boundary_work<S>(true);
      }
      if (usf_edges()) keep_edge_velocities();
      break;
  }
  t += dt;
  ++steps;
  check_health();  // first: a blow-up, not the grid's size, is why particles fly off
  check_outside();
  if (dist_ && dist_->migrate(*this)) sort_particles();
  call([&](StepHooks& h) { h.end_of_step(*this); });
  if (store_mode() < 0) time_stores(omp_get_wtime() - start);
}

// The nodes the silent and Kelvin-Voigt layers' and the damping bands' entries weigh this step
// (apply_loads gives them dashpot blocks, and the light nodes' extension leaves them alone).
template <class S>
const std::vector<char>& Solver::layer_nodes() {
  layer_mask_.assign(grid.nodes(), 0);
  const auto none = [](long) { return false; };
  auto mark = [&](const BoundaryLayer& L, Anchor anchor) {
    layer_weights<S>(L, anchor, mask_nodes_, mask_N_, none);
    for (std::size_t e = 0; e < mask_nodes_.size(); ++e)
      if (mask_N_[e] != 0) layer_mask_[mask_nodes_[e]] = 1;
  };
  for (const auto& sl : silents) mark(sl.layer, sl.anchor);
  for (const auto& dl : dampers) mark(dl.layer, Anchor::Particle);
  return layer_mask_;
}

std::size_t Solver::light_nodes_at_start(double ratio) {
  const std::size_t n = grid.nodes();
  if (opt.shape != ShapeKind::Bilinear || contact.multi() || p.size() == 0 || dist_ ||
      grid.m.size() != n || grid.px.size() != n || grid.py.size() != n)
    return 0;
  auto clear = [&] {
    std::fill(grid.m.begin(), grid.m.end(), 0.0);
    std::fill(grid.px.begin(), grid.px.end(), 0.0);
    std::fill(grid.py.begin(), grid.py.end(), 0.0);
  };
  clear();
  Bilinear sf;
  for (std::size_t k = 0; k < p.size(); ++k) {  // the lumped masses, m_i = sum_p m_p N_i(x_p)
    sf.eval(grid, p.x[k], p.y[k]);
    if (sf.ci < 0 || sf.cj < 0 || sf.ci >= grid.nx || sf.cj >= grid.ny) continue;
    for (int a = 0; a < Bilinear::kNodes; ++a)
      grid.m[(sf.cj + sf.dj[a]) * grid.nnx + sf.ci + sf.di[a]] += p.mass[k] * sf.N[a];
  }
  LightNodes found;
  found.ratio = ratio;
  std::size_t count = 0;
  if (found.candidates(grid, mass_floor_)) {
    found.classify_and_fold(grid, layer_nodes<Bilinear>());
    count = found.count();
  }
  clear();
  return count;
}

// The light nodes' velocities extended from the heavy nodes' (light_nodes.hpp): the start
// velocity too when `start`.
void Solver::extend_updated(bool start) {
  if (start) {
    light_nodes.extend(grid.vx.data());
    light_nodes.extend(grid.vy.data());
  }
  light_nodes.extend(grid.vnx.data());
  light_nodes.extend(grid.vny.data());
}

// Health checks at the end of a step, from reductions the step's own passes made (no extra pass
// unless one fails), in the order a blow-up shows them: no particle faster than a cell per step
// (the transfer assumes a particle stays within its stencil); no particle volume inverted (J < 0,
// seen by the internal-force p2g, which loads the volumes: a volume the stress update of step n
// inverts stops step n + 1); no particle stretched so far (J large) that its wave speed
// c_d sqrt(J) puts dt above the stability limit (the same p2g; see stretch_limit); the
// particles' kinetic energy (from g2p) within opt.energy_bound times the
// energy put in (initial + |external work|, with a floor of 1e-12 sum(m c_d^2) for a run with
// nothing put in). Nodal values would not do: a node holding a sliver of mass at a body's edge
// takes a large velocity the particles hardly see.
void Solver::check_health() {
  long collapsed = collapsed_, stretched = stretched_;
  double ke = step_kinetic_, v2 = step_speed2_;
  double put_in = energy.initial + std::abs(energy.external_work);
  if (dist_) {  // the checks of the whole body: every rank takes the same decisions
    double s[5] = {static_cast<double>(collapsed), static_cast<double>(stretched), ke,
                   energy.initial, energy.external_work};
    dist_->sum(s, 5);
    dist_->max(&v2, 1);
    collapsed = static_cast<long>(s[0]);
    stretched = static_cast<long>(s[1]);
    ke = s[2];
    put_in = s[3] + std::abs(s[4]);
  }
  collapsed_ = 0;
  stretched_ = 0;
  step_kinetic_ = 0;
  step_speed2_ = 0;
  auto where = [&](std::ostringstream& o) { o << "at step " << steps << " (t = " << t << " s)"; };
  auto usl_hint = [&](std::ostringstream& o) {
    if (opt.scheme == Scheme::USL) o << "; " << kUslSliverHint;
  };
  auto particle = [&](std::ostringstream& o, std::size_t k) {
    o << "particle " << p.id[k] << " of body " << p.body[k] << " at (" << p.x[k] << ", " << p.y[k]
      << ")";
  };
  if (v2 * dt * dt > grid.h * grid.h) {
    std::size_t k = 0;
    for (std::size_t q = 1; q < p.size(); ++q)
      if (p.vx[q] * p.vx[q] + p.vy[q] * p.vy[q] > p.vx[k] * p.vx[k] + p.vy[k] * p.vy[k]) k = q;
    const double v = std::sqrt(v2);
    std::ostringstream o;
    o << "a particle moves more than a cell per step ";
    where(o);
    o << ": ";
    particle(o, k);
    o << " at |v| = " << v << " m/s, v dt = " << v * dt << " m > h = " << grid.h
      << " m; the run is unstable (reduce time.cfl or time.dt";
    usl_hint(o);
    o << ")";
    throw std::runtime_error(o.str());
  }
  if (collapsed > 0) {
    std::size_t k = p.size();
    long n = 0;
    for (std::size_t q = 0; q < p.size(); ++q)
      if (std::signbit(p.vol[q]) && n++ == 0) k = q;
    std::ostringstream o;
    o << "particle volume inverted ";
    where(o);
    if (k < p.size()) {
      o << ": ";
      particle(o, k);
      o << " has J = V/V0 = " << p.vol[k] / (p.mass[k] * inv_rho(p.group[k]));
    }
    o << " (" << n << " particle(s) with J < 0); the run is unstable or the deformation "
         "too large for the grid (reduce time.cfl or time.dt, refine the grid";
    usl_hint(o);
    o << ")";
    throw std::runtime_error(o.str());
  }
  if (stretched > 0) {
    // The particle most over its limit; its J and the wave speed and stability limit it has.
    std::size_t k = p.size();
    double worst = 1;
    for (std::size_t q = 0; q < p.size(); ++q) {
      const double r = p.vol[q] / (stretch_limit(p.group[q]) * p.mass[q]);
      if (r > worst) worst = r, k = q;
    }
    std::ostringstream o;
    o << "time step above the stability limit ";
    where(o);
    if (k < p.size()) {
      const Material& m = materials[p.group[k]];
      const double J = p.vol[k] / (p.mass[k] * inv_rho(p.group[k]));
      o << ": ";
      particle(o, k);
      o << " has expanded to J = V/V0 = " << J << ", so its wave speed c_d sqrt(J) is "
        << m.cd * std::sqrt(J) << " m/s and the limit h / (c_d sqrt(J)) is "
        << grid.h / (m.cd * std::sqrt(J)) << " s < dt / sqrt(1.1) = " << dt / std::sqrt(1.1)
        << " s (J more than 10 % past 1 / CFL^2)";
    }
    o << " (reduce time.cfl or time.dt)";
    throw std::runtime_error(o.str());
  }
  if (opt.energy_bound > 0) {
    if (ke > opt.energy_bound * put_in + energy_floor_) {
      std::ostringstream o;
      o << "kinetic energy " << ke << " J exceeds " << opt.energy_bound
        << " times the energy put in (" << put_in << " J: initial " << energy.initial
        << ", external work " << energy.external_work << ") ";
      where(o);
      o << "; the run is unstable (reduce time.cfl or time.dt";
      usl_hint(o);
      if (pml.active()) o << "; " << kPmlGrowthHint;
      o << ")";
      throw std::runtime_error(o.str());
    }
  }
}

// ------------------------------------------------------------------------------------------
// Diagnostics
// ------------------------------------------------------------------------------------------

void Solver::update_energies() {
  double ke = 0, el = 0;
  const int G = static_cast<int>(std::max<std::size_t>(1, materials.size()));
  for (int s = 0; s < nstrips_; ++s)
    for (int g = 0; g < G && !ranges_.empty(); ++g) {
      const Material& m = materials[g];
      for (uint32_t k = ranges_[s * G + g][0]; k < ranges_[s * G + g][1]; ++k) {
        ke += 0.5 * p.mass[k] * (p.vx[k] * p.vx[k] + p.vy[k] * p.vy[k]);
        el += p.vol[k] * elastic_energy_density(m, p.sxx[k], p.syy[k], p.szz[k], p.sxy[k]);
      }
    }
  // The energy stored in Kelvin-Voigt springs, 1/2 u.K u per unit length.
  for (const auto& sl : silents) {
    if (!sl.springs()) continue;
    for (std::size_t q = 0; q < sl.layer.idx.size(); ++q) {
      double tx, ty;
      spring_of(sl, q, sl.ux[q], sl.uy[q], tx, ty);
      el -= 0.5 * sl.layer.w[q] * (tx * sl.ux[q] + ty * sl.uy[q]);
    }
  }
  energy.kinetic = ke;
  energy.elastic = el;
}

std::vector<ProbeSample> Solver::sample(const std::vector<std::array<double, 2>>& pts) const {
  return sample(pts, std::vector<int>());
}

std::vector<ProbeSample> Solver::sample(const std::vector<std::array<double, 2>>& pts,
                                        const std::vector<int>& bodies) const {
  const std::size_t np = pts.size();
  std::vector<ProbeSample> out(np);
  if (np == 0) return out;
  // Per probe: the 4 nodes of its cell; accumulate m, m*field for each.
  struct Acc { double m[4] = {0, 0, 0, 0}, f[4][6] = {}; int ci, cj; Bilinear sf; };
  std::vector<Acc> acc(np);
  // The probe's cell and weights from the whole grid's origin, the same on every rank: from a
  // window's own origin a point on a grid line can fall in the next cell on one rank, and the
  // ranks' sums of the cell's four nodes would then mix two cells.
  const std::array<int, 2> o = window_origin();
  const double X0 = dist_ ? whole_x0_ : grid.x0, Y0 = dist_ ? whole_y0_ : grid.y0;
  for (std::size_t q = 0; q < np; ++q) {
    acc[q].sf.eval(pts[q][0], pts[q][1], X0, Y0, grid.inv_h);
    acc[q].ci = acc[q].sf.ci - o[0];
    acc[q].cj = acc[q].sf.cj - o[1];
  }
  // Many probes (curve probes): the probes near each cell (their cell within one of it) as a
  // sorted (cell, probe) list, so that a particle visits only the probes it can reach; with
  // few probes every particle checks them all. Either way each probe accumulates its particles
  // in the same order.
  const bool indexed = np > 8;
  std::vector<std::pair<long, uint32_t>> near;  // (cell key, probe), sorted
  if (indexed) {
    near.reserve(9 * np);
    const long W = static_cast<long>(grid.nx) + 3;  // keys of cells -1 .. nx + 1
    for (std::size_t q = 0; q < np; ++q)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di)
          near.push_back({(static_cast<long>(acc[q].cj) + dj + 1) * W + (acc[q].ci + di + 1),
                          static_cast<uint32_t>(q)});
    std::sort(near.begin(), near.end());
  }
  // A particle reaches a probe when its cell is within one of the probe's: floor(g) in
  // [c - 1, c + 1], i.e. g in [c - 1, c + 2) for its grid coordinate g (as Bilinear::eval
  // computes it). Few probes: the particles are tested in blocks, a loop without branches that
  // vectorises, and only those that reach a probe go on to the shape (a history row every step
  // made this loop a sixth of a small run).
  std::vector<std::array<double, 4>> reach;  // per probe: gx from, gx to, gy from, gy to
  if (!indexed)
    for (std::size_t q = 0; q < np; ++q)
      reach.push_back({acc[q].ci - 1.0, acc[q].ci + 2.0, acc[q].cj - 1.0, acc[q].cj + 2.0});
  constexpr std::size_t kBlock = 256;
  std::uint8_t hit[kBlock];
  const double* px = p.x.data();
  const double* py = p.y.data();
  Bilinear sf;
  for (std::size_t k0 = 0; k0 < p.size(); k0 += kBlock) {
    const std::size_t nb = std::min(kBlock, p.size() - k0);
    if (!indexed) {
      std::fill(hit, hit + nb, std::uint8_t(0));
      for (const auto& r : reach)
        for (std::size_t i = 0; i < nb; ++i) {
          const double gx = (px[k0 + i] - grid.x0) * grid.inv_h;
          const double gy = (py[k0 + i] - grid.y0) * grid.inv_h;
          hit[i] |= static_cast<std::uint8_t>(int(gx >= r[0]) & int(gx < r[1]) & int(gy >= r[2]) & int(gy < r[3]));
        }
    }
    for (std::size_t k = k0; k < k0 + nb; ++k) {
      if (!indexed && !hit[k - k0]) continue;
      sf.eval(p.x[k], p.y[k], grid.x0, grid.y0, grid.inv_h);
      std::size_t e = 0, e1 = np;
      if (indexed) {
        const long key = (static_cast<long>(sf.cj) + 1) * (static_cast<long>(grid.nx) + 3) + sf.ci + 1;
        e = static_cast<std::size_t>(
            std::lower_bound(near.begin(), near.end(), std::make_pair(key, uint32_t(0))) - near.begin());
        e1 = e;
        while (e1 < near.size() && near[e1].first == key) ++e1;
      }
      for (; e < e1; ++e) {
        const std::size_t q = indexed ? near[e].second : e;
        Acc& A = acc[q];
        if (!indexed && (std::abs(sf.ci - A.ci) > 1 || std::abs(sf.cj - A.cj) > 1)) continue;
        if (!bodies.empty() && bodies[q] >= 0 && p.body[k] != bodies[q]) continue;
        const double vals[6] = {p.sxx[k], p.syy[k], p.szz[k], p.sxy[k], p.vx[k], p.vy[k]};
        for (int a = 0; a < 4; ++a) {
          const int li = sf.ci + sf.di[a] - A.ci, lj = sf.cj + sf.dj[a] - A.cj;
          if (li < 0 || li > 1 || lj < 0 || lj > 1) continue;
          const int slot = lj == 0 ? li : 3 - li;  // node numbering of Bilinear
          const double w = p.mass[k] * sf.N[a];
          A.m[slot] += w;
          for (int c = 0; c < 6; ++c) A.f[slot][c] += w * vals[c];
        }
      }
    }
  }
  if (dist_) {  // the particles near a probe may lie on several ranks: add their sums
    std::vector<double> sums(28 * np);
    for (std::size_t q = 0; q < np; ++q) {
      std::copy_n(acc[q].m, 4, &sums[28 * q]);
      std::copy_n(&acc[q].f[0][0], 24, &sums[28 * q + 4]);
    }
    dist_->sum(sums.data(), static_cast<int>(sums.size()));
    for (std::size_t q = 0; q < np; ++q) {
      std::copy_n(&sums[28 * q], 4, acc[q].m);
      std::copy_n(&sums[28 * q + 4], 24, &acc[q].f[0][0]);
    }
  }
  // The symmetric form of the mass correction: the particles carry R^1/2 of the velocity field
  // its stresses follow; the probes read that field, the last step's corrected re-mapped
  // velocity (docs/physics.md section 1.1).
  for (std::size_t q = 0; q < np; ++q) {
    const Acc& A = acc[q];
    double v[6] = {0, 0, 0, 0, 0, 0}, wsum = 0;
    for (int a = 0; a < 4; ++a) {
      if (A.m[a] <= 0) continue;
      wsum += A.sf.N[a];
      for (int c = 0; c < 6; ++c) v[c] += A.sf.N[a] * A.f[a][c] / A.m[a];
    }
    ProbeSample& s = out[q];
    if (wsum <= 0) continue;
    s.valid = true;
    s.sxx = v[0] / wsum; s.syy = v[1] / wsum; s.szz = v[2] / wsum; s.sxy = v[3] / wsum;
    s.vx = v[4] / wsum; s.vy = v[5] / wsum;
    // (A probe of one body's particles, under multi-field contact, reads them: the symmetric
    // form has one field.)
    if (sym_field_ && (bodies.empty() || bodies[q] < 0)) {  // the corrected field, same weights
      double ux = 0, uy = 0;
      for (int a = 0; a < 4; ++a) {
        if (A.m[a] <= 0) continue;
        const long nd = static_cast<long>(A.cj + A.sf.dj[a]) * grid.nnx + A.ci + A.sf.di[a];
        ux += A.sf.N[a] * grid.qx[nd];
        uy += A.sf.N[a] * grid.qy[nd];
      }
      s.vx = ux / wsum;
      s.vy = uy / wsum;
    }
    s.j2 = j2_of(s.sxx, s.syy, s.szz, s.sxy);
  }
  return out;
}

ProbeSample Solver::sample(double x, double y) const { return sample({{x, y}})[0]; }

ProbeSample Solver::region_mean(double x0, double y0, double x1, double y1, int body) const {
  double m = 0, v = 0, px = 0, py = 0, sxx = 0, syy = 0, szz = 0, sxy = 0, j2 = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!(p.x[k] >= x0 && p.x[k] <= x1 && p.y[k] >= y0 && p.y[k] <= y1)) continue;
    if (body >= 0 && p.body[k] != body) continue;
    const double mk = p.mass[k], vk = p.vol[k];
    m += mk;
    v += vk;
    px += mk * p.vx[k];
    py += mk * p.vy[k];
    sxx += vk * p.sxx[k];
    syy += vk * p.syy[k];
    szz += vk * p.szz[k];
    sxy += vk * p.sxy[k];
    j2 += vk * j2_of(p.sxx[k], p.syy[k], p.szz[k], p.sxy[k]);
  }
  const bool has_force = body >= 0 && static_cast<std::size_t>(body) < contact.force.size();
  double fc[2] = {has_force ? contact.force[body][0] : 0.0, has_force ? contact.force[body][1] : 0.0};
  if (dist_) {  // each rank's own contact nodes' part of the force
    double s[11] = {m, v, px, py, sxx, syy, szz, sxy, j2, fc[0], fc[1]};
    dist_->sum(s, 11);
    m = s[0], v = s[1], px = s[2], py = s[3], sxx = s[4], syy = s[5], szz = s[6], sxy = s[7];
    j2 = s[8], fc[0] = s[9], fc[1] = s[10];
  }
  ProbeSample out;
  if (!(m > 0 && v > 0)) return out;
  out.valid = true;
  if (has_force) {
    out.fcx = fc[0];
    out.fcy = fc[1];
  }
  out.px = px;
  out.py = py;
  out.mass = m;
  out.vx = px / m;
  out.vy = py / m;
  out.sxx = sxx / v;
  out.syy = syy / v;
  out.szz = szz / v;
  out.sxy = sxy / v;
  out.j2 = j2 / v;
  return out;
}

}  // namespace smpm
