// Multi-velocity-field contact (Bardenhagen, Brackbill & Sulsky 2000); see contact.hpp for the
// algorithm, the choice of normal and the energy accounting.
//
// The per-body nodal arrays live here, one array per body and field. The solver's step runs its
// kernels on them as one velocity field per body (material groups are split per body in
// setup(), so a body's particles are whole ranges) and sums them into the grid's arrays; this
// file adds the contact nodes and the corrections at the step's hooks.
#include "silentmpm/contact.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "silentmpm/kernels.hpp"
#include "silentmpm/solver.hpp"

namespace smpm {

namespace {
// The heaviest body's gradient gives the normal unless it is shorter than this fraction of the
// difference of the gradients.
constexpr double kWeakGradient = 0.25;
// Bodies closer than this fraction of a cell (gap between their particle domains) are in contact.
constexpr double kGapTolerance = 0.01;
// The gap check's model of a body near a node: a flat surface, the body's particles in layers
// of thickness l parallel to it, their centres at depths (j + 1/2) l behind it. For a node d
// outside the surface (d < 0: inside the body) the particles' nodal centroid then lies
// offset(d) behind the node along the body's outward normal: the mean of the layers' distances
// u_j = d + (j + 1/2) l from the node weighted by the case's 1D shape S(u_j / h) (the tensor
// products' other factor is the same for every layer of a flat surface). At a node on the
// surface (d = 0) the bilinear weights give l / 2 while one layer lies within h (1 ppc), 3h/8
// at two layers per cell side, 19h/54 at three (h / 3 + l^2 / (6 h) at n per side, l = h / n);
// the quadratic B-spline gives 27h/64 and 67h/162 at two and three. offset(d) grows with d, with
// a slope of 0.63-1 at the surface (1 only at one particle per cell), so the measured offset
// gives d back by bisection; the gap between two bodies at a node is the sum of their d.
double weight_1d(ShapeKind k, double xi, double lp) {
  const double r = std::abs(xi);
  switch (k) {
    case ShapeKind::Bilinear:
      return r < 1 ? 1 - r : 0.0;
    case ShapeKind::BSpline2:
      if (r <= 0.5) return 0.75 - r * r;
      return r < 1.5 ? 0.5 * (1.5 - r) * (1.5 - r) : 0.0;
    case ShapeKind::UGimp: {
      double w, d;
      shape_detail::ugimp_1d(xi, lp, w, d);
      return w;
    }
  }
  return 0.0;
}

// The support's half-width in cells.
double support_1d(ShapeKind k, double lp) {
  return k == ShapeKind::Bilinear ? 1.0 : k == ShapeKind::BSpline2 ? 1.5 : 1.0 + lp;
}

// offset(d) of the model above (cells: d, l in units of h); +infinity where no layer reaches.
double centroid_offset(ShapeKind k, double d, double l, double lp) {
  const double R = support_1d(k, lp);
  double sw = 0, swu = 0;
  for (double u = d + 0.5 * l; u < R; u += l) {
    const double w = weight_1d(k, u, lp);
    sw += w;
    swu += w * u;
  }
  return sw > 0 ? swu / sw : std::numeric_limits<double>::infinity();
}

// The node's distance outside the body's surface (units of h) for a measured offset o of the
// body's nodal centroid behind it (units of h), particles of size l (units of h).
double node_outside(ShapeKind k, double o, double l) {
  if (!(l > 0)) return o;
  // Layers finer than 64 per cell: the continuum's offset already, in fewer terms.
  l = std::max(l, 1.0 / 64);
  const double lp = std::min(0.5, 0.5 * l);
  const double R = support_1d(k, lp);
  double lo = -R, hi = R - 0.5 * l;  // the first layer at the support's end
  if (o <= centroid_offset(k, lo, l, lp)) return lo;
  for (int it = 0; it < 60 && hi - lo > 1e-12; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (centroid_offset(k, mid, l, lp) < o) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

namespace {
using Box = NodeBox;  // node range i0..i1, j0..j1 (inclusive)

bool inside(const Box& b, int i, int j) { return i >= b[0] && i <= b[1] && j >= b[2] && j <= b[3]; }
}  // namespace

const char* contact_type_name(ContactType t) {
  return t == ContactType::Multi ? "multi" : "single";
}

void Contact::setup(Solver& s) {
  // Split material groups so that each group holds one body: the first body met in a group keeps
  // the group, every further body of that group gets a copy of the material.
  const std::size_t G0 = s.materials.size();
  groups_before_ = static_cast<int>(G0);
  copied_from_.clear();
  std::vector<int> owner(G0, -1);
  std::map<std::pair<int, int>, int> split;  // (group, body) -> new group
  int bmax = -1;
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    const int g = s.p.group[k], b = s.p.body[k];
    bmax = std::max(bmax, b);
    if (owner[g] < 0) owner[g] = b;
    if (owner[g] == b) continue;
    auto it = split.find({g, b});
    if (it == split.end()) {
      s.materials.push_back(s.materials[g]);
      copied_from_.push_back(g);
      it = split.emplace(std::make_pair(g, b), static_cast<int>(s.materials.size() - 1)).first;
    }
    s.p.group[k] = static_cast<uint16_t>(it->second);
  }
  nb_ = bmax + 1;
  body_of_group_.assign(s.materials.size(), 0);
  for (std::size_t g = 0; g < G0; ++g) body_of_group_[g] = std::max(owner[g], 0);
  for (const auto& [gb, g] : split) body_of_group_[g] = gb.second;
  force.assign(nb_, {0.0, 0.0});
  dissipated = 0;
  resize(s);
}

std::vector<int> Contact::split_layout() const {
  std::vector<int> v = {nb_, groups_before_, static_cast<int>(copied_from_.size())};
  v.insert(v.end(), copied_from_.begin(), copied_from_.end());
  v.insert(v.end(), body_of_group_.begin(), body_of_group_.end());
  return v;
}

void Contact::adopt_split(Solver& s, const std::vector<int>& layout) {
  const auto bad = [](const char* why) {
    throw std::logic_error(std::string("contact: rank 0's split cannot be taken: ") + why);
  };
  if (layout.size() < 3) bad("too short");
  const int nb = layout[0], G0 = layout[1], added = layout[2];
  if (nb < 0 || G0 < 0 || added < 0 || layout.size() != 3u + added + (G0 + added))
    bad("inconsistent sizes");
  if (s.p.size() != 0 || static_cast<int>(s.materials.size()) != G0)
    bad("this solver holds particles or other material groups");
  for (int k = 0; k < added; ++k) {
    const int from = layout[3 + k];
    if (from < 0 || from >= G0) bad("a copy of a group that does not exist");
    s.materials.push_back(s.materials[from]);
  }
  for (std::size_t k = 3 + added; k < layout.size(); ++k)
    if (layout[k] < 0 || layout[k] >= std::max(nb, 1)) bad("a group of a body that does not exist");
  groups_before_ = G0;
  copied_from_.assign(layout.begin() + 3, layout.begin() + 3 + added);
  body_of_group_.assign(layout.begin() + 3 + added, layout.end());
  nb_ = nb;
  force.assign(nb_, {0.0, 0.0});
  dissipated = 0;
  resize(s);
}

void Contact::resize(Solver& s) {
  const std::size_t n = s.grid.nodes();
  for (Field* f : {&m_, &px_, &py_, &fx_, &fy_, &gx_, &gy_, &vx_, &vy_, &vnx_, &vny_, &qx_, &qy_,
                   &xm_, &ym_, &sm_})
    f->assign(nb_, std::vector<double>(n, 0.0));
  std::vector<NodalField> f(nb_);
  for (int b = 0; b < nb_; ++b)
    f[b] = NodalField{m_[b].data(),  px_[b].data(),  py_[b].data(),  fx_[b].data(),
                      fy_[b].data(), vx_[b].data(),  vy_[b].data(),  vnx_[b].data(),
                      vny_[b].data(), qx_[b].data(), qy_[b].data(), gx_[b].data(),
                      gy_[b].data(), xm_[b].data(),  ym_[b].data(),  sm_[b].data()};
  s.use_body_fields(f, body_of_group_);
}

// Nodes where two or more bodies have mass: for each body b, the part of its box that overlaps
// a later body's box; a node is listed by the first body that has mass there.
void Contact::find_contact_nodes(Solver& s) {
  cnodes_.clear();
  const double floor = s.mass_floor();
  const int nnx = s.grid.nnx;
  std::vector<Box> bx(nb_);
  for (int b = 0; b < nb_; ++b) bx[b] = s.fields()[b].box;
  for (int b = 0; b < nb_; ++b) {
    if (box_empty(bx[b])) continue;
    Box u{1 << 30, -1, 1 << 30, -1};
    for (int c = b + 1; c < nb_; ++c)
      if (!box_empty(bx[c]))
        u = {std::min(u[0], bx[c][0]), std::max(u[1], bx[c][1]), std::min(u[2], bx[c][2]),
             std::max(u[3], bx[c][3])};
    const Box r{std::max(bx[b][0], u[0]), std::min(bx[b][1], u[1]),
                std::max(bx[b][2], u[2]), std::min(bx[b][3], u[3])};
    if (box_empty(r)) continue;
    for (int j = r[2]; j <= r[3]; ++j)
      for (int i = r[0]; i <= r[1]; ++i) {
        const long n = static_cast<long>(j) * nnx + i;
        if (m_[b][n] <= floor) continue;
        bool earlier = false;
        for (int c = 0; c < b && !earlier; ++c) earlier = inside(bx[c], i, j) && m_[c][n] > floor;
        if (earlier) continue;
        bool other = false;
        for (int c = b + 1; c < nb_ && !other; ++c) other = inside(bx[c], i, j) && m_[c][n] > floor;
        if (other) cnodes_.push_back(static_cast<uint32_t>(n));
      }
  }
  contact_nodes = static_cast<long>(cnodes_.size());
}

// v_b = p_b / m_b with the constraints (on a node with one body this is the centre-of-mass value).
void Contact::split_start(Solver& s) {
  for (int b = 0; b < nb_; ++b)
    kernels::nodal_velocity(s.grid, s.fields()[b].box, m_[b].data(), s.grid.fix.data(),
                            px_[b].data(), py_[b].data(), vx_[b].data(), vy_[b].data(),
                            s.mass_floor(), s.thread_count());
}

// Updated per-body velocities: the centre-of-mass value where one body is present; at contact
// nodes the centre-of-mass value plus the body's own deviation, then the contact correction.
void Contact::split_updated(Solver& s) {
  const double floor = s.mass_floor(), dt = s.dt;
  const Grid& g = s.grid;
  for (int b = 0; b < nb_; ++b) {
    const double* m = m_[b].data();
    double* ux = vnx_[b].data(); double* uy = vny_[b].data();
    kernels::for_box(s.fields()[b].box, g.nnx, s.thread_count(), [&](long i) {
      const bool has = m[i] > floor;
      ux[i] = has ? g.vnx[i] : 0.0;
      uy[i] = has ? g.vny[i] : 0.0;
    });
  }
  for (uint32_t i : cnodes_) {
    double fx = 0, fy = 0;
    for (int b = 0; b < nb_; ++b) { fx += fx_[b][i]; fy += fy_[b][i]; }
    const double M = g.m[i];
    const double cx = (g.px[i] + dt * fx) / M, cy = (g.py[i] + dt * fy) / M;
    for (int b = 0; b < nb_; ++b) {
      const double mb = m_[b][i];
      if (mb <= floor) continue;
      const double dx = (px_[b][i] + dt * fx_[b][i]) / mb - cx;
      const double dy = (py_[b][i] + dt * fy_[b][i]) / mb - cy;
      vnx_[b][i] = (g.fix[i] & 1) ? 0.0 : g.vnx[i] + dx;
      vny_[b][i] = (g.fix[i] & 2) ? 0.0 : g.vny[i] + dy;
    }
  }
}

// Contact correction of the fields (vx, vy) at the contact nodes. With count, the impulses are
// recorded as contact forces and their work on the corrected velocities as dissipated energy.
void Contact::correct(Solver& s, Field& vx, Field& vy, bool count) {
  const double floor = s.mass_floor(), mu = friction;
  const Grid& g = s.grid;
  double work = 0;
  long active = 0;
  const double tol = kGapTolerance * g.h;
  const ShapeKind shape = s.opt.shape;
  std::vector<char> in(nb_, 0);
  for (uint32_t i : cnodes_) {
    // The heaviest body h at the node, and the sum of the mass gradients.
    int hb = -1;
    double Gx = 0, Gy = 0;
    for (int b = 0; b < nb_; ++b) {
      if (m_[b][i] <= floor) continue;
      Gx += gx_[b][i];
      Gy += gy_[b][i];
      if (hb < 0 || m_[b][i] > m_[hb][i]) hb = b;
    }
    // One normal for the node: the outward normal of h (its mass gradient), unless that gradient
    // is weak against the difference g_h - g_others (a node inside body h); the other bodies
    // take the opposite direction.
    double Nx = gx_[hb][i], Ny = gy_[hb][i];
    const double Dx = 2 * Nx - Gx, Dy = 2 * Ny - Gy;
    if (std::hypot(Nx, Ny) < kWeakGradient * std::hypot(Dx, Dy)) Nx = Dx, Ny = Dy;
    const double NN = std::hypot(Nx, Ny);
    if (!(NN > 0)) continue;
    Nx /= NN; Ny /= NN;
    // Which bodies touch h here: how far the node lies outside h's surface along n plus how far
    // it lies outside the other body's along -n (each from that body's nodal centroid, through
    // node_outside) is the gap, which must be closed. (Sharing a node only means the bodies are
    // less than about a cell apart.)
    const double mh = m_[hb][i];
    const double xh = xm_[hb][i] / mh, yh = ym_[hb][i] / mh;
    const double xi = g.x0 + static_cast<double>(i % g.nnx) * g.h;
    const double yi = g.y0 + static_cast<double>(i / g.nnx) * g.h;
    const double dh = node_outside(shape, ((xi - xh) * Nx + (yi - yh) * Ny) * g.inv_h,
                                   sm_[hb][i] / mh * g.inv_h);
    int touching = 0;
    double M = 0, cx = 0, cy = 0;
    for (int b = 0; b < nb_; ++b) {
      const double mb = m_[b][i];
      in[b] = 0;
      if (mb <= floor) continue;
      if (b != hb) {
        const double ob = (xm_[b][i] / mb - xi) * Nx + (ym_[b][i] / mb - yi) * Ny;
        const double gap = (node_outside(shape, ob * g.inv_h, sm_[b][i] / mb * g.inv_h) + dh) * g.h;
        if (gap > tol) continue;
        ++touching;
      }
      in[b] = 1;
      M += mb;
      cx += mb * vx[b][i];
      cy += mb * vy[b][i];
    }
    if (touching == 0) continue;
    cx /= M; cy /= M;
    bool any = false;
    for (int b = 0; b < nb_; ++b) {
      if (!in[b]) continue;
      const double mb = m_[b][i];
      double nx = b == hb ? Nx : -Nx, ny = b == hb ? Ny : -Ny;
      if (g.fix[i] & 1) nx = 0;
      if (g.fix[i] & 2) ny = 0;
      const double nn = std::hypot(nx, ny);
      if (!(nn > 0)) continue;
      nx /= nn; ny /= nn;
      const double dx = vx[b][i] - cx, dy = vy[b][i] - cy;
      const double dn = dx * nx + dy * ny;
      if (dn <= 0) continue;  // separating or sliding apart: no contact force
      any = true;
      double ex = -dn * nx, ey = -dn * ny;
      const double tx = dx - dn * nx, ty = dy - dn * ny;
      const double tt = std::hypot(tx, ty);
      if (tt > 0 && mu > 0) {
        const double r = std::min(mu * dn, tt) / tt;  // stick if mu dn >= |dv_t|, else slide
        ex -= r * tx;
        ey -= r * ty;
      }
      if (g.fix[i] & 1) ex = 0;
      if (g.fix[i] & 2) ey = 0;
      if (count && s.owns_node(i)) {  // a node that ranks share is counted by its owner
        // Work of the impulse on the corrected velocity: zero for the normal part (the pair
        // moves together along n afterwards), impulse times remaining slip for friction.
        const double ax = vx[b][i] + ex, ay = vy[b][i] + ey;
        work += mb * (ex * ax + ey * ay);
        force[b][0] += mb * ex / s.dt;
        force[b][1] += mb * ey / s.dt;
      }
      vx[b][i] += ex;
      vy[b][i] += ey;
    }
    active += any;
  }
  if (count) {
    active_nodes = active;
    dissipated -= work;
    s.energy.dissipated -= work;
  }
}

void Contact::after_momentum(Solver& s) { find_contact_nodes(s); }

void Contact::after_grid_update(Solver& s) {
  split_start(s);
  split_updated(s);
  // The mass correction of each body's increment (docs/physics.md section 1.1), before the
  // contact correction, so that under MUSL and USF the corrected velocities keep the contact
  // conditions (under USL the particles' extra increment beyond v+ is their body's own).
  if (s.opt.mass_correction > 0) s.correct_body_increments();
  for (auto& f : force) f = {0.0, 0.0};
  correct(s, vnx_, vny_, true);
}

}  // namespace smpm
