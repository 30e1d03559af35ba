// Multi-velocity-field contact (Bardenhagen, Brackbill & Sulsky 2000); see contact.hpp for the
// algorithm, the choice of normal and the energy accounting.
//
// The step reuses the solver's own stages. Per-body nodal fields live here, one array per body
// and field; to run a solver stage (g2p, stress update) for body b, the solver's nodal arrays and
// particle ranges are swapped with body b's (O(1) vector swaps), the stage runs over b's
// particles only (material groups are split per body in setup(), so b's particles are whole
// ranges), and everything is swapped back. The single-field step is not touched.
#include "silentmpm/contact.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "silentmpm/shape.hpp"
#include "silentmpm/solver.hpp"

namespace smpm {

namespace {
// The heaviest body's gradient gives the normal unless it is shorter than this fraction of the
// difference of the gradients.
constexpr double kWeakGradient = 0.25;
// Bodies closer than this fraction of a cell (gap between their particle domains) are in contact.
constexpr double kGapTolerance = 0.01;

}  // namespace

namespace {
using Box = std::array<int, 4>;  // node range i0..i1, j0..j1 (inclusive)

bool empty(const Box& b) { return b[0] > b[1] || b[2] > b[3]; }
bool inside(const Box& b, int i, int j) { return i >= b[0] && i <= b[1] && j >= b[2] && j <= b[3]; }

// fn(node index) over the nodes of a box, rows in parallel.
template <class Fn>
void for_box(const Box& bx, int nnx, int nt, Fn&& fn) {
  if (empty(bx)) return;
#pragma omp parallel for schedule(static) num_threads(nt)
  for (int j = bx[2]; j <= bx[3]; ++j) {
    const long r = static_cast<long>(j) * nnx;
    for (int i = bx[0]; i <= bx[1]; ++i) fn(r + i);
  }
}
}  // namespace

const char* contact_type_name(ContactType t) {
  return t == ContactType::Multi ? "multi" : "single";
}

void Contact::setup(Solver& s) {
  // Split material groups so that each group holds one body: the first body met in a group keeps
  // the group, every further body of that group gets a copy of the material.
  const std::size_t G0 = s.materials.size();
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
      it = split.emplace(std::make_pair(g, b), static_cast<int>(s.materials.size() - 1)).first;
    }
    s.p.group[k] = static_cast<uint16_t>(it->second);
  }
  nb_ = bmax + 1;
  body_of_group_.assign(s.materials.size(), 0);
  for (std::size_t g = 0; g < G0; ++g) body_of_group_[g] = std::max(owner[g], 0);
  for (const auto& [gb, g] : split) body_of_group_[g] = gb.second;
  const std::size_t n = s.grid.nodes();
  for (Field* f : {&m_, &px_, &py_, &fx_, &fy_, &gx_, &gy_, &vx_, &vy_, &vnx_, &vny_, &qx_, &qy_,
                   &xm_, &ym_, &sm_})
    f->assign(nb_, std::vector<double>(n, 0.0));
  force.assign(nb_, {0.0, 0.0});
  box_.assign(nb_, {0, -1, 0, -1});
  ranges_.assign(nb_, {});
  dissipated = 0;
}

// Per body: the solver's ranges with every group of another body emptied.
void Contact::body_ranges(Solver& s) {
  const int G = static_cast<int>(std::max<std::size_t>(1, s.materials.size()));
  for (int b = 0; b < nb_; ++b) {
    ranges_[b] = s.ranges_;
    for (int st = 0; st < s.nstrips_; ++st)
      for (int g = 0; g < G; ++g)
        if (body_of_group_[g] != b) ranges_[b][st * G + g] = {0, 0};
  }
}

void Contact::swap_in(Solver& s, int b) {
  Grid& g = s.grid;
  std::swap(g.m, m_[b]);
  std::swap(g.vx, vx_[b]);
  std::swap(g.vy, vy_[b]);
  std::swap(g.vnx, vnx_[b]);
  std::swap(g.vny, vny_[b]);
  std::swap(g.qx, qx_[b]);
  std::swap(g.qy, qy_[b]);
  std::swap(s.ranges_, ranges_[b]);
}

// Run fn() for each body with that body swapped in; fn moves particles, so the strip row and
// outside counts of the passes are merged.
template <class Fn>
void Contact::per_body_moving(Solver& s, Fn&& fn) {
  const int S = s.nstrips_;
  std::vector<int> lo(S, std::numeric_limits<int>::max()), hi(S, std::numeric_limits<int>::min()),
      out(S, 0);
  for (int b = 0; b < nb_; ++b) {
    swap_in(s, b);
    fn();
    swap_in(s, b);
    for (int st = 0; st < S; ++st) {
      lo[st] = std::min(lo[st], s.strip_lo_[st]);
      hi[st] = std::max(hi[st], s.strip_hi_[st]);
      out[st] += s.strip_out_[st];
    }
  }
  s.strip_lo_ = lo;
  s.strip_hi_ = hi;
  s.strip_out_ = out;
}

// Per-body masses, momenta, mass gradients and internal forces; their sums go to the solver's
// (centre of mass) fields. Same strip colouring as the solver's scatters: no two threads write
// one node.
void Contact::p2g(Solver& s, bool momentum, bool with_force) {
  const int nt = s.nthreads_;
  const int nnx0 = s.grid.nnx;
  // The momentum pass clears what the last step wrote (every field, forces included) and finds
  // the new boxes; a force-only pass (USF) accumulates into the same step's boxes.
  if (momentum)
    for (int b = 0; b < nb_; ++b) {
      double* a[10] = {m_[b].data(), px_[b].data(), py_[b].data(), gx_[b].data(),
                       gy_[b].data(), xm_[b].data(), ym_[b].data(), sm_[b].data(),
                       fx_[b].data(), fy_[b].data()};
      for_box(box_[b], nnx0, nt, [&](long i) {
        for (double* v : a) v[i] = 0;
      });
    }
  std::vector<Box> sbox(static_cast<std::size_t>(s.nstrips_) * nb_, Box{1 << 30, -1, 1 << 30, -1});
  const Grid& grid = s.grid;
  const double x0 = grid.x0, y0 = grid.y0, ih = grid.inv_h;
  const int nnx = grid.nnx;
  const Particles& p = s.p;
  const int G = static_cast<int>(std::max<std::size_t>(1, s.materials.size()));
  auto strip = [&](int st) {
    Bilinear sf;
    for (int g = 0; g < G; ++g) {
      const uint32_t kb = s.ranges_[st * G + g][0], ke = s.ranges_[st * G + g][1];
      if (kb == ke) continue;
      const int b = body_of_group_[g];
      double* gm = m_[b].data(); double* gpx = px_[b].data(); double* gpy = py_[b].data();
      double* ggx = gx_[b].data(); double* ggy = gy_[b].data();
      double* gxm = xm_[b].data(); double* gym = ym_[b].data(); double* gsm = sm_[b].data();
      double* gfx = fx_[b].data(); double* gfy = fy_[b].data();
      Box& bx = sbox[static_cast<std::size_t>(st) * nb_ + b];
      for (uint32_t k = kb; k < ke; ++k) {
        sf.eval(p.x[k], p.y[k], x0, y0, ih);
        const long n0 = static_cast<long>(sf.cj) * nnx + sf.ci;
        const long nodes[4] = {n0, n0 + 1, n0 + nnx + 1, n0 + nnx};
        if (momentum) {
          bx[0] = std::min(bx[0], sf.ci);
          bx[1] = std::max(bx[1], sf.ci + 1);
          bx[2] = std::min(bx[2], sf.cj);
          bx[3] = std::max(bx[3], sf.cj + 1);
          const double mk = p.mass[k], mvx = mk * p.vx[k], mvy = mk * p.vy[k];
          for (int c = 0; c < 4; ++c) {
            gm[nodes[c]] += mk * sf.N[c];
            gpx[nodes[c]] += mvx * sf.N[c];
            gpy[nodes[c]] += mvy * sf.N[c];
            ggx[nodes[c]] += mk * sf.dNx[c];
            ggy[nodes[c]] += mk * sf.dNy[c];
            gxm[nodes[c]] += mk * sf.N[c] * p.x[k];
            gym[nodes[c]] += mk * sf.N[c] * p.y[k];
            gsm[nodes[c]] += mk * sf.N[c] * std::sqrt(p.vol[k]);
          }
        }
        if (with_force) {
          const double v = p.vol[k], sxx = p.sxx[k], syy = p.syy[k], sxy = p.sxy[k];
          for (int c = 0; c < 4; ++c) {
            gfx[nodes[c]] -= v * (sxx * sf.dNx[c] + sxy * sf.dNy[c]);
            gfy[nodes[c]] -= v * (sxy * sf.dNx[c] + syy * sf.dNy[c]);
          }
        }
      }
    }
  };
  if (!s.strips_ok_ || nt == 1) {
    for (int st = 0; st < s.nstrips_; ++st) strip(st);
  } else {
    for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(static, 1) num_threads(nt)
      for (int st = colour; st < s.nstrips_; st += 2) strip(st);
    }
  }
  if (momentum)
    for (int b = 0; b < nb_; ++b) {
      Box u{1 << 30, -1, 1 << 30, -1};
      for (int st = 0; st < s.nstrips_; ++st) {
        const Box& q = sbox[static_cast<std::size_t>(st) * nb_ + b];
        u = {std::min(u[0], q[0]), std::max(u[1], q[1]), std::min(u[2], q[2]), std::max(u[3], q[3])};
      }
      box_[b] = u;
    }
  // Centre-of-mass fields: the solver's arrays were cleared by reset_grid; add each body's box.
  Grid& gw = s.grid;
  for (int b = 0; b < nb_; ++b) {
    const double* m = m_[b].data(); const double* qx = px_[b].data(); const double* qy = py_[b].data();
    const double* fx = fx_[b].data(); const double* fy = fy_[b].data();
    for_box(box_[b], nnx0, nt, [&](long i) {
      if (momentum) { gw.m[i] += m[i]; gw.px[i] += qx[i]; gw.py[i] += qy[i]; }
      if (with_force) { gw.fx[i] += fx[i]; gw.fy[i] += fy[i]; }
    });
  }
}

// Nodes where two or more bodies have mass: for each body b, the part of its box that overlaps
// a later body's box; a node is listed by the first body that has mass there.
void Contact::find_contact_nodes(Solver& s) {
  cnodes_.clear();
  const double floor = s.mass_floor_;
  const int nnx = s.grid.nnx;
  for (int b = 0; b < nb_; ++b) {
    if (empty(box_[b])) continue;
    Box u{1 << 30, -1, 1 << 30, -1};
    for (int c = b + 1; c < nb_; ++c)
      if (!empty(box_[c]))
        u = {std::min(u[0], box_[c][0]), std::max(u[1], box_[c][1]), std::min(u[2], box_[c][2]),
             std::max(u[3], box_[c][3])};
    const Box r{std::max(box_[b][0], u[0]), std::min(box_[b][1], u[1]),
                std::max(box_[b][2], u[2]), std::min(box_[b][3], u[3])};
    if (empty(r)) continue;
    for (int j = r[2]; j <= r[3]; ++j)
      for (int i = r[0]; i <= r[1]; ++i) {
        const long n = static_cast<long>(j) * nnx + i;
        if (m_[b][n] <= floor) continue;
        bool earlier = false;
        for (int c = 0; c < b && !earlier; ++c) earlier = inside(box_[c], i, j) && m_[c][n] > floor;
        if (earlier) continue;
        bool other = false;
        for (int c = b + 1; c < nb_ && !other; ++c) other = inside(box_[c], i, j) && m_[c][n] > floor;
        if (other) cnodes_.push_back(static_cast<uint32_t>(n));
      }
  }
  contact_nodes = static_cast<long>(cnodes_.size());
}

// v_b = p_b / m_b with the constraints (on a node with one body this is the centre-of-mass value).
void Contact::split_start(Solver& s, Field& vx, Field& vy, const Field& px, const Field& py) {
  const double floor = s.mass_floor_;
  const uint8_t* fix = s.grid.fix.data();
  for (int b = 0; b < nb_; ++b) {
    const double* m = m_[b].data();
    const double* qx = px[b].data(); const double* qy = py[b].data();
    double* ux = vx[b].data(); double* uy = vy[b].data();
    for_box(box_[b], s.grid.nnx, s.nthreads_, [&](long i) {
      if (m[i] > floor) {
        ux[i] = (fix[i] & 1) ? 0.0 : qx[i] / m[i];
        uy[i] = (fix[i] & 2) ? 0.0 : qy[i] / m[i];
      } else {
        ux[i] = 0; uy[i] = 0;
      }
    });
  }
}

// Updated per-body velocities: the centre-of-mass value where one body is present; at contact
// nodes the centre-of-mass value plus the body's own deviation, then the contact correction.
void Contact::split_updated(Solver& s) {
  const double floor = s.mass_floor_, dt = s.dt;
  const Grid& g = s.grid;
  for (int b = 0; b < nb_; ++b) {
    const double* m = m_[b].data();
    double* ux = vnx_[b].data(); double* uy = vny_[b].data();
    for_box(box_[b], g.nnx, s.nthreads_, [&](long i) {
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
  for (auto& f : force) f = {0.0, 0.0};
  correct(s, vnx_, vny_, true);
}

// Contact correction of the fields (vx, vy) at the contact nodes. With count, the impulses are
// recorded as contact forces and their work on the corrected velocities as dissipated energy.
void Contact::correct(Solver& s, Field& vx, Field& vy, bool count) {
  const double floor = s.mass_floor_, mu = friction;
  const Grid& g = s.grid;
  double work = 0;
  long active = 0;
  const double tol = kGapTolerance * g.h;
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
    // Which bodies touch h here: the gap along n between the nodal centroids of the two bodies'
    // particles, less half of each one's particle size, must be closed. (Sharing a node only
    // means the bodies are less than about a cell apart.)
    const double mh = m_[hb][i];
    const double xh = xm_[hb][i] / mh, yh = ym_[hb][i] / mh, sh = sm_[hb][i] / mh;
    int touching = 0;
    double M = 0, cx = 0, cy = 0;
    for (int b = 0; b < nb_; ++b) {
      const double mb = m_[b][i];
      in[b] = 0;
      if (mb <= floor) continue;
      if (b != hb) {
        const double gap = (xm_[b][i] / mb - xh) * Nx + (ym_[b][i] / mb - yh) * Ny -
                           0.5 * (sm_[b][i] / mb + sh);
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
      if (count) {
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

void Contact::step(Solver& s) {
  body_ranges(s);
  s.reset_grid();
  if (s.opt.scheme == Scheme::USF) {
    // Stress first, from each body's own start-of-step field (qx_ as scratch; not corrected,
    // as for MUSL below).
    p2g(s, true, false);
    find_contact_nodes(s);
    split_start(s, qx_, qy_, px_, py_);
    for (int b = 0; b < nb_; ++b) {
      swap_in(s, b);
      s.update_stress_and_position(s.grid.qx, s.grid.qy, false);
      swap_in(s, b);
    }
    p2g(s, false, true);
  } else {
    p2g(s, true, true);
    find_contact_nodes(s);
  }
  s.apply_loads();
  s.grid_update();
  s.boundary_work();
  split_start(s, vx_, vy_, px_, py_);
  split_updated(s);
  switch (s.opt.scheme) {
    case Scheme::USF:
      per_body_moving(s, [&] { s.g2p_velocity(false, true); });
      break;
    case Scheme::USL:
      for (int b = 0; b < nb_; ++b) {
        swap_in(s, b);
        s.g2p_velocity(false, false);
        swap_in(s, b);
      }
      per_body_moving(s, [&] { s.update_stress_and_position(s.grid.vnx, s.grid.vny, true); });
      break;
    case Scheme::MUSL: {
      for (int b = 0; b < nb_; ++b) {
        double* qx = qx_[b].data(); double* qy = qy_[b].data();
        for_box(box_[b], s.grid.nnx, s.nthreads_, [&](long i) { qx[i] = 0; qy[i] = 0; });
        swap_in(s, b);
        s.g2p_velocity(true, false);
        swap_in(s, b);
      }
      // Re-mapped momenta -> velocities of each body. Not contact-corrected: the strain rate
      // must come from the velocities the body's particles actually carry (a corrected field
      // here fed the light body's edge particles a spurious strain rate through grad N and
      // gained energy, 27 % in the impact study, before the gap check was added).
      split_start(s, qx_, qy_, qx_, qy_);
      per_body_moving(s, [&] { s.update_stress_and_position(s.grid.qx, s.grid.qy, true); });
      break;
    }
  }
}

}  // namespace smpm
