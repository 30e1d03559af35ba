// Contact of bodies: 1D plate impact, aluminium flyer on a steel target, rollers on the
// long sides (uniaxial strain), elastic. Closed forms (docs/physics.md §4, P-wave impedances
// Z = rho c_d computed from E, nu, rho):
//   contact stress     sigma = v0 Z1 Z2 / (Z1 + Z2)        (12.26 MPa per m/s)
//   contact duration   T_c = 2 d1 / c_d1                     (flyer thickness d1)
//   rebound velocity   v0 (Z1 - Z2) / (Z1 + Z2)              (multi-velocity contact only)
// Both contact modes: stress, duration, momentum, no interpenetration. Only the multi-field mode
// separates.
#include <gtest/gtest.h>

#include <cstdio>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <tuple>

#include "silentmpm/solver.hpp"
#include "test_contact_common.hpp"

using namespace smpm;
using namespace smpm::contact_testing;

namespace {

// Flyer [-d1, 0] x [0, H] (body 0) moving at v0 onto the target [0, d2] x [0, H] (body 1).
std::unique_ptr<Solver> make_impact(const Impact& c) {
  auto s = std::make_unique<Solver>();
  s->materials.push_back(aluminium());
  s->materials.push_back(steel());
  const double d1 = c.flyer_cells * c.h, d2 = c.target_cells * c.h, H = c.height * c.h;
  s->grid.init(-d1 - (10 + c.offset) * c.h, 0.0, c.h,
               c.flyer_cells + c.target_cells + 20 + (c.offset > 0 ? 1 : 0), c.height);
  s->seed_rectangle(-d1, 0, 0, H, c.ppc_side, 0, 0, c.v0, 0);
  s->seed_rectangle(0, 0, d2, H, c.ppc_side, 1, 1, 0, 0);
  s->constraints.push_back({"bottom", s->nodes_in_box(-1, 0, 1, 0), 2});
  s->constraints.push_back({"top", s->nodes_in_box(-1, H, 1, H), 2});
  s->contact.type = c.type;
  s->contact.friction = c.friction;
  s->opt.scheme = c.scheme;
  s->opt.threads = c.threads;
  s->opt.mass_correction = c.mass_correction;
  s->opt.shape = c.shape;
  s->dt = c.cfl * c.h / std::max(s->materials[0].cd, s->materials[1].cd);
  s->finalize();
  return s;
}

struct Trace {
  std::vector<double> t, force, s_flyer, s_target, gap;
  double p0 = 0, max_momentum_error = 0;
  double min_gap = std::numeric_limits<double>::infinity();
  double flyer_v = 0;  // mass-weighted mean velocity of the flyer at the end
};

double momentum_x(const Solver& s) {
  double q = 0;
  for (std::size_t k = 0; k < s.p.size(); ++k) q += s.p.mass[k] * s.p.vx[k];
  return q;
}

// Right-most flyer particle to left-most target particle (initially one particle spacing).
double gap(const Solver& s) {
  double xf = -1e30, xt = 1e30;
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    if (s.p.body[k] == 0) xf = std::max(xf, s.p.x[k]);
    else xt = std::min(xt, s.p.x[k]);
  }
  return xt - xf;
}

Trace run(Solver& s, const Impact& c, double t_end) {
  Trace tr;
  tr.p0 = momentum_x(s);
  const double d1 = c.flyer_cells * c.h, H = c.height * c.h;
  while (s.t < t_end - 0.5 * s.dt) {
    s.step();
    tr.t.push_back(s.t);
    tr.force.push_back(s.contact.multi() ? -s.contact.force[0][0] / H : 0.0);
    // Probes at mid-height: the flyer's centre, and 10.5 cells into the target.
    tr.s_flyer.push_back(s.sample(-0.5 * d1, 0.5 * H).sxx);
    tr.s_target.push_back(s.sample(10.5 * c.h, 0.5 * H).sxx);
    const double g = gap(s);
    tr.gap.push_back(g);
    tr.min_gap = std::min(tr.min_gap, g);
    tr.max_momentum_error =
        std::max(tr.max_momentum_error, std::abs(momentum_x(s) - tr.p0) / std::abs(tr.p0));
  }
  double m = 0, q = 0;
  for (std::size_t k = 0; k < s.p.size(); ++k)
    if (s.p.body[k] == 0) { m += s.p.mass[k]; q += s.p.mass[k] * s.p.vx[k]; }
  tr.flyer_v = q / m;
  return tr;
}

double mean_over(const std::vector<double>& t, const std::vector<double>& v, double a, double b) {
  double s = 0;
  int n = 0;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] >= a && t[i] <= b) { s += v[i]; ++n; }
  return n ? s / n : std::numeric_limits<double>::quiet_NaN();
}

// First and last time a history is above half its plateau value: the contact duration as the
// width at half height of the stress pulse.
std::pair<double, double> half_width(const std::vector<double>& t, const std::vector<double>& v,
                                     double level) {
  double t0 = -1, t1 = -1;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (v[i] >= 0.5 * level) {
      if (t0 < 0) t0 = t[i];
      t1 = t[i];
    }
  return {t0, t1};
}

// One multi-field impact run to 2.8 contact times and what the closed forms are checked on.
struct Measured {
  Oracle o;
  Trace tr;
  double pc = 0;       // mean contact pressure over the middle of the contact
  double sf = 0;       // mean stress at the flyer's centre while it is loaded
  double ta = 0, tb = 0;  // first and last time the pressure is above half the closed form's
  double imb = 0;      // energy imbalance over the initial energy at the end
};

Measured measure(const Impact& c) {
  Measured m;
  m.o = oracle(c);
  auto s = make_impact(c);
  m.tr = run(*s, c, 2.8 * m.o.tc);
  m.pc = mean_over(m.tr.t, m.tr.force, 0.2 * m.o.tc, 0.8 * m.o.tc);
  m.sf = mean_over(m.tr.t, m.tr.s_flyer, 0.35 * m.o.tc, 0.65 * m.o.tc);
  std::tie(m.ta, m.tb) = half_width(m.tr.t, m.tr.force, m.o.sigma);
  s->update_energies();
  m.imb = s->energy.imbalance() / s->energy.initial;
  return m;
}

}  // namespace

// Multi-velocity-field contact: contact stress (from the contact force and from the stress in
// both plates), duration, rebound, momentum, no interpenetration.
TEST(ContactImpact, MultiFieldRebounds) {
  Impact c;
  const Oracle o = oracle(c);
  auto s = make_impact(c);
  const double t_end = 2.8 * o.tc;
  const Trace tr = run(*s, c, t_end);
  // Contact pressure from the contact impulses, mean over the middle of the contact.
  const double pc = mean_over(tr.t, tr.force, 0.2 * o.tc, 0.8 * o.tc);
  EXPECT_NEAR(pc, o.sigma, 0.03 * o.sigma);
  // Stress in the flyer (centre: loaded from d1/(2 c1) to 3 d1/(2 c1)) and in the target.
  const double d1 = c.flyer_cells * c.h, xt = 10.5 * c.h;
  const double sf = mean_over(tr.t, tr.s_flyer, 0.35 * o.tc, 0.65 * o.tc);
  EXPECT_NEAR(-sf, o.sigma, 0.03 * o.sigma) << "flyer";
  const double st = mean_over(tr.t, tr.s_target, xt / o.c2 + 0.2 * o.tc, xt / o.c2 + 0.8 * o.tc);
  EXPECT_NEAR(-st, o.sigma, 0.03 * o.sigma) << "target";
  (void)d1;
  // Duration: width at half height of the contact pressure.
  const auto [ta, tb] = half_width(tr.t, tr.force, o.sigma);
  EXPECT_NEAR(tb - ta, o.tc, 0.05 * o.tc);
  // After the release the contact stays open: no force in the last third.
  EXPECT_LT(std::abs(mean_over(tr.t, tr.force, 1.8 * o.tc, t_end)), 1e-3 * o.sigma);
  // Rebound of the flyer (mean velocity; it rings but its momentum is fixed once free).
  EXPECT_NEAR(tr.flyer_v, o.rebound, 0.05 * std::abs(o.rebound));
  // The gap opens at about the rebound speed (the target face is at rest once the pulse left).
  const double g0 = c.h, opened = tr.gap.back() - g0;
  const double expect = -o.rebound * (t_end - o.tc);
  EXPECT_GT(opened, 0.5 * expect);
  EXPECT_LT(opened, 1.5 * expect);
  EXPECT_LT(tr.max_momentum_error, 1e-10);
  EXPECT_GT(tr.min_gap, 0.0);  // no particle of one body passes one of the other
  // Frictionless contact does no work: kinetic + elastic energy is conserved to 1 %.
  s->update_energies();
  EXPECT_LT(std::abs(s->contact.dissipated), 1e-9 * s->energy.initial);
  EXPECT_LT(std::abs(s->energy.imbalance()), 0.01 * s->energy.initial);
  std::printf("multi: contact pressure %.4g (closed form %.4g), flyer %.4g, target %.4g MPa; "
              "duration %.4g us (2d/c %.4g); rebound %.4g m/s (closed form %.4g); gap opened "
              "%.3g m (expected about %.3g); momentum error %.2g; energy: dissipated by contact "
              "%.3g J/m, imbalance %.3g of the initial %.4g J/m\n",
              pc / 1e6, o.sigma / 1e6, -sf / 1e6, -st / 1e6, (tb - ta) * 1e6, o.tc * 1e6,
              tr.flyer_v, o.rebound, opened, expect, tr.max_momentum_error,
              s->contact.dissipated, (s->update_energies(), s->energy.imbalance()),
              s->energy.initial);
}

// The paper's single velocity field: same stress and duration, the bodies stay together.
TEST(ContactImpact, SingleFieldSticks) {
  Impact c;
  c.type = ContactType::Single;
  const Oracle o = oracle(c);
  auto s = make_impact(c);
  const double t_end = 2.8 * o.tc;
  const Trace tr = run(*s, c, t_end);
  const double xt = 10.5 * c.h;
  const double sf = mean_over(tr.t, tr.s_flyer, 0.35 * o.tc, 0.65 * o.tc);
  EXPECT_NEAR(-sf, o.sigma, 0.03 * o.sigma) << "flyer";
  const double st = mean_over(tr.t, tr.s_target, xt / o.c2 + 0.2 * o.tc, xt / o.c2 + 0.8 * o.tc);
  EXPECT_NEAR(-st, o.sigma, 0.03 * o.sigma) << "target";
  // Duration from the compressive pulse that the contact sends into the target.
  std::vector<double> comp(tr.s_target.size());
  for (std::size_t i = 0; i < comp.size(); ++i) comp[i] = -tr.s_target[i];
  const auto [ta, tb] = half_width(tr.t, comp, o.sigma);
  EXPECT_NEAR(tb - ta, o.tc, 0.05 * o.tc);
  // No separation: the gap stays one particle spacing (up to elastic strain), the flyer does not
  // rebound.
  EXPECT_NEAR(tr.gap.back(), c.h, 0.01 * c.h);
  EXPECT_GT(tr.flyer_v - o.rebound, 0.5 * std::abs(o.rebound));
  EXPECT_LT(tr.max_momentum_error, 1e-10);
  EXPECT_GT(tr.min_gap, 0.0);
  std::printf("single: flyer %.4g, target %.4g MPa (closed form %.4g); duration %.4g us (2d/c "
              "%.4g); flyer velocity %.4g m/s; gap %.5g h; momentum error %.2g\n",
              -sf / 1e6, -st / 1e6, o.sigma / 1e6, (tb - ta) * 1e6, o.tc * 1e6, tr.flyer_v,
              tr.gap.back() / c.h, tr.max_momentum_error);
}

namespace {

// Coulomb friction: an aluminium block (L x H = 20 x 10 cells, body 1) on a steel base (40 x 10
// cells, body 0, bottom fixed), pushed down by p0 and sideways by tau0 on its top, both ramped
// up together (sin^2 over 20 us, quasi-static for the block: 6 shear transit times). While it
// slides, the base holds it back with mu N = mu p0 L, so its momentum is
//   P(T) = (tau0 - mu p0) L  integral_0^T f dt = (tau0 - mu p0) L (T - t_ramp / 2);
// with tau0 < mu p0 it sticks.
struct Sliding {
  double P = 0, P_free = 0;       // block momentum at T, and tau0 L integral f (no friction)
  double min_gap = 1e30;          // lowest block particle minus highest base particle
  double dissipated = 0, external = 0, imbalance = 0;
};

Sliding slide(double mu, double tau0, double p0) {
  const double h = 1e-3, L = 20 * h, H = 10 * h;
  auto s = std::make_unique<Solver>();
  s->materials.push_back(steel());
  s->materials.push_back(aluminium());
  s->grid.init(-5 * h, 0.0, h, 50, 25);
  s->seed_rectangle(0, 0, 40 * h, H, 1, 0, 0, 0, 0);
  s->seed_rectangle(10 * h, H, 10 * h + L, 2 * H, 1, 1, 1, 0, 0);
  s->constraints.push_back({"bottom", s->nodes_in_box(-1, 0, 1, 0), 3});
  TractionLoad tl;
  tl.layer = s->select_layer("top", 1, 10 * h + L, 2 * H, 10 * h, 2 * H, 0, 1, h);
  tl.vx = tau0;
  tl.vy = -p0;
  const double t_ramp = 20e-6, T = 40e-6;
  tl.fn.kind = TimeFunction::Kind::Step;
  tl.fn.ramp = t_ramp;
  s->tractions.push_back(tl);
  s->contact.type = ContactType::Multi;
  s->contact.friction = mu;
  s->opt.threads = 1;
  s->dt = 0.3 * h / s->materials[1].cd;
  s->finalize();
  Sliding r;
  while (s->t < T - 0.5 * s->dt) {
    s->step();
    double top_base = -1e30, low_block = 1e30;
    for (std::size_t k = 0; k < s->p.size(); ++k) {
      if (s->p.body[k] == 0) top_base = std::max(top_base, s->p.y[k]);
      else low_block = std::min(low_block, s->p.y[k]);
    }
    r.min_gap = std::min(r.min_gap, low_block - top_base);
  }
  for (std::size_t k = 0; k < s->p.size(); ++k)
    if (s->p.body[k] == 1) r.P += s->p.mass[k] * s->p.vx[k];
  r.P_free = tau0 * L * (s->t - 0.5 * t_ramp);
  s->update_energies();
  r.dissipated = s->contact.dissipated;
  r.external = s->energy.external_work;
  r.imbalance = s->energy.imbalance();
  return r;
}

}  // namespace

TEST(ContactFriction, SlidingBlockCoulomb) {
  const double tau0 = 30e6, p0 = 50e6, mu = 0.3;
  const Sliding f = slide(mu, tau0, p0);
  const double expect = (tau0 - mu * p0) / tau0 * f.P_free;
  EXPECT_NEAR(f.P, expect, 0.05 * expect);
  EXPECT_GT(f.min_gap, 0.0);
  // Friction heat is counted: kinetic + elastic + friction = work of the top traction, 2 %.
  EXPECT_GT(f.dissipated, 0.0);
  EXPECT_LT(std::abs(f.imbalance), 0.02 * f.external);
  // Frictionless: the block slides with the full tangential impulse; nothing is dissipated.
  const Sliding g = slide(0.0, tau0, p0);
  EXPECT_NEAR(g.P, g.P_free, 0.03 * g.P_free);
  EXPECT_LT(std::abs(g.dissipated), 1e-9 * g.external);
  // Below the friction limit it sticks.
  const Sliding st = slide(mu, 10e6, p0);
  EXPECT_LT(std::abs(st.P), 0.05 * st.P_free);
  std::printf("friction: momentum %.4g (closed form %.4g), frictionless %.4g (%.4g), stick %.3g "
              "(free sliding would give %.4g) N s/m; friction heat %.4g J/m of %.4g J/m work, "
              "imbalance %.3g J/m; min gap %.3g mm\n",
              f.P, expect, g.P, g.P_free, st.P, st.P_free, f.dissipated, f.external, f.imbalance,
              f.min_gap * 1e3);
}

// The multi-field contact with the other update schemes: the flyer still rebounds at
// v0 (Z1 - Z2)/(Z1 + Z2) within 5 %, momentum to 1e-10, no interpenetration.
TEST(ContactImpact, MultiFieldOtherSchemes) {
  for (Scheme sc : {Scheme::USL, Scheme::USF}) {
    Impact c;
    c.scheme = sc;
    const Oracle o = oracle(c);
    auto s = make_impact(c);
    const Trace tr = run(*s, c, 2.0 * o.tc);
    EXPECT_NEAR(tr.flyer_v, o.rebound, 0.05 * std::abs(o.rebound)) << scheme_name(sc);
    EXPECT_LT(tr.max_momentum_error, 1e-10) << scheme_name(sc);
    EXPECT_GT(tr.min_gap, 0.0) << scheme_name(sc);
  }
}

// The 1D impact with 4 and 9 particles per cell, MUSL and USL, and with two terms of the
// consistent-mass correction of each body's field (docs/physics.md section 1.1; applied after
// the bodies' own updates and before their contact correction): the closed forms as at 1 ppc
// (contact pressure and the flyer's stress within 3 %, duration and rebound within 5 %),
// momentum to 1e-10, no interpenetration, the energy account within 3 % of the impact energy.
// Measured: pressure and stress within 0.2 %, duration 0.993-0.999 of 2d/c, rebound 0.978-0.982
// of the closed form, energy -0.6 to -2.6 % (USL's own damping). With the gap check's s / 2 in
// place of r(s) (contact.hpp) the 4-ppc impact gave 0.77 of the pressure and 0.49 of the rebound
// and lost 39 % of the energy; at 9 ppc no pressure at all in the middle of the contact.
TEST(ContactImpact, MultiFieldAtFourAndNinePpcWithTheMassCorrection) {
  for (Scheme sc : {Scheme::MUSL, Scheme::USL})
    for (int side : {2, 3})
      for (int k : {0, 2}) {
        Impact c;
        c.scheme = sc;
        c.ppc_side = side;
        c.mass_correction = k;
        const Measured m = measure(c);
        const Oracle& o = m.o;
        const Trace& tr = m.tr;
        const double pc = m.pc, sf = m.sf, ta = m.ta, tb = m.tb, imb = m.imb;
        std::printf("%s, %d ppc, %d terms: pressure %.4f, flyer %.4f of the closed form; duration "
                    "%.4f of 2d/c; rebound %.4f of the closed form; momentum %.1e; energy %.2e\n",
                    scheme_name(sc), side * side, k, pc / o.sigma, -sf / o.sigma, (tb - ta) / o.tc,
                    tr.flyer_v / o.rebound, tr.max_momentum_error, imb);
        const std::string what = std::string(scheme_name(sc)) + ", " +
                                 std::to_string(side * side) + " ppc, " + std::to_string(k) + " terms";
        EXPECT_NEAR(pc, o.sigma, 0.03 * o.sigma) << what;
        EXPECT_NEAR(-sf, o.sigma, 0.03 * o.sigma) << what;
        EXPECT_NEAR(tb - ta, o.tc, 0.05 * o.tc) << what;
        EXPECT_NEAR(tr.flyer_v, o.rebound, 0.05 * std::abs(o.rebound)) << what;
        EXPECT_LT(tr.max_momentum_error, 1e-10) << what;
        EXPECT_GT(tr.min_gap, 0.0) << what;
        EXPECT_LT(std::abs(imb), 0.03) << what;
      }
}

// The gap check off the grid lines and with the wide shapes (contact.hpp: each body's nodal
// centroid gives the node's distance from its surface through the case's own 1D weights). The
// 1D impact at 4 ppc (9 ppc: 0.25 off), MUSL, three cells across, the contact face on a grid
// line or 0.25 and 0.5 of a cell off it, bilinear, GIMP and B-spline shapes: contact pressure and duration within
// 1 %, rebound within 3 % of the closed forms, the energy account within 1.5 % of the impact
// energy, no interpenetration. Measured: pressure 0.997-1.001, duration 0.996-0.999, rebound
// 0.978-1.002, energy -0.95 to +0.28 %. With one reach per body (the distance from the surface
// to the centroid at a node on the surface, bilinear weights) bilinear 4 ppc 0.25 of a cell off
// rebounded at 1.21 of the closed form and gained 15 %; B-splines on the grid line lasted 1.06-
// 1.07 of 2d/c, rebounded at 1.03-1.04 and gained 1.6 %, GIMP 0.5 off gained 4 %.
TEST(ContactImpact, GapCheckOffTheGridLinesAndWithWideShapes) {
  for (ShapeKind sk : {ShapeKind::Bilinear, ShapeKind::UGimp, ShapeKind::BSpline2})
    for (int side : {2, 3})
      for (double off : {0.0, 0.25, 0.5}) {
        if (sk == ShapeKind::Bilinear && off == 0.0) continue;  // MultiFieldAtFourAndNinePpc...
        if (side == 3 && off != 0.25) continue;                 // 9 ppc: one offset
        Impact c;
        c.height = 3;
        c.ppc_side = side;
        c.shape = sk;
        c.offset = off;
        const Measured m = measure(c);
        const std::string what = std::string(shape_name(sk)) + ", " + std::to_string(side * side) +
                                 " ppc, " + std::to_string(off) + " of a cell off";
        std::printf("%s: pressure %.4f, duration %.4f, rebound %.4f of the closed forms; energy "
                    "%+.2e\n", what.c_str(), m.pc / m.o.sigma, (m.tb - m.ta) / m.o.tc,
                    m.tr.flyer_v / m.o.rebound, m.imb);
        EXPECT_NEAR(m.pc, m.o.sigma, 0.01 * m.o.sigma) << what;
        EXPECT_NEAR(m.tb - m.ta, m.o.tc, 0.01 * m.o.tc) << what;
        EXPECT_NEAR(m.tr.flyer_v, m.o.rebound, 0.03 * std::abs(m.o.rebound)) << what;
        EXPECT_GT(m.tr.min_gap, 0.0) << what;
        EXPECT_LT(std::abs(m.imb), 0.015) << what;
      }
}

namespace {

// A 12 x 12 mm aluminium block at 10 m/s (body 0) striking the left face of a 30 x 40 mm steel
// plate (body 1) off-centre, 1 mm cells, free edges, 2 threads.
std::unique_ptr<Solver> make_oblique(ContactType type, double y0, int threads, double x1 = 0,
                                     int side = 1, Scheme scheme = Scheme::MUSL,
                                     int mass_correction = 0, double offset = 0) {
  auto s = std::make_unique<Solver>();
  s->materials.push_back(aluminium());
  s->materials.push_back(steel());
  const double h = 1e-3;
  // offset: the grid moved left and down by that fraction of a cell (faces off its lines)
  s->grid.init(-0.02 - offset * h, -0.005 - offset * h, h, offset > 0 ? 61 : 60,
               offset > 0 ? 51 : 50);
  s->seed_rectangle(x1 - 0.012, y0, x1, y0 + 0.012, side, 0, 0, 10.0, 0);
  s->seed_rectangle(0.0, 0.0, 0.03, 0.04, side, 1, 1, 0, 0);
  s->contact.type = type;
  s->opt.threads = threads;
  s->opt.scheme = scheme;
  s->opt.mass_correction = mass_correction;
  s->dt = 0.3 * h / s->materials[0].cd;
  s->finalize();
  return s;
}

}  // namespace

// 2D: no particle of the block passes the steel's left face (its left-most particle column) in
// either mode while the block is over the plate; momentum is conserved to 1e-10.
TEST(ContactImpact, ObliqueNoInterpenetration) {
  for (int side : {1, 2})  // 1 and 4 ppc
  for (ContactType type : {ContactType::Single, ContactType::Multi}) {
    auto s = make_oblique(type, 0.024, 1, 0, side);
    double p0 = 0, q0 = 0;
    for (std::size_t k = 0; k < s->p.size(); ++k) { p0 += s->p.mass[k] * s->p.vx[k]; }
    double min_gap = 1e30, merr = 0;
    for (int n = 0; n < 400; ++n) {
      s->step();
      double xf = -1e30, xt = 1e30, q = 0, qy = 0;
      for (std::size_t k = 0; k < s->p.size(); ++k) {
        q += s->p.mass[k] * s->p.vx[k];
        qy += s->p.mass[k] * s->p.vy[k];
        if (s->p.body[k] == 0) xf = std::max(xf, s->p.x[k]);
        else if (s->p.y[k] > 0.024 && s->p.y[k] < 0.036) xt = std::min(xt, s->p.x[k]);
      }
      min_gap = std::min(min_gap, xt - xf);
      merr = std::max({merr, std::abs(q - p0) / p0, std::abs(qy - q0) / p0});
    }
    EXPECT_GT(min_gap, 0.0) << contact_type_name(type) << ", " << side * side << " ppc";
    EXPECT_LT(merr, 1e-10) << contact_type_name(type) << ", " << side * side << " ppc";
    s->update_energies();
    // Energy: no gain (1 %); the multi-field contact loses 6.1 % here at 1 ppc (12 x 12 cell
    // block) and 2.0 % at 4 ppc, 0.4-0.5 % in the impact study (40 x 60 cells), 0.55 % in the 1D
    // test.
    EXPECT_LT(s->energy.imbalance(), 0.01 * s->energy.initial)
        << contact_type_name(type) << ", " << side * side << " ppc";
    EXPECT_GT(s->energy.imbalance(), -0.08 * s->energy.initial)
        << contact_type_name(type) << ", " << side * side << " ppc";
    std::printf("oblique %s, %d ppc: min gap %.3g mm, momentum error %.2g, energy imbalance %.3g "
                "of %.3g J/m\n", contact_type_name(type), side * side, min_gap * 1e3, merr,
                s->energy.imbalance(), s->energy.initial);
  }
}

// The oblique impact with multi-field contact at 4 ppc, its faces 0.3 and 0.6 of a cell off the
// grid lines (the gap check of contact.hpp): no interpenetration, momentum to 1e-10, the block
// rebounds at the on-grid run's speed within 5 % and the energy account within -3 % and +2 %.
// Measured: -1.6 and +1.5 %, rebound -5.31 and -5.24 m/s (on the lines -2.1 %, -5.15 m/s). With
// one reach per body (bilinear depth at a node on the surface) 0.6 off gained 39 % and the block
// left at -8.6 m/s.
TEST(ContactImpact, ObliqueOffTheGridLines) {
  auto rebound = [](const Solver& s) {
    double m = 0, q = 0;
    for (std::size_t k = 0; k < s.p.size(); ++k)
      if (s.p.body[k] == 0) m += s.p.mass[k], q += s.p.mass[k] * s.p.vx[k];
    return q / m;
  };
  auto on = make_oblique(ContactType::Multi, 0.024, 1, 0, 2);
  for (int n = 0; n < 400; ++n) on->step();
  const double v_on = rebound(*on);
  for (double off : {0.3, 0.6}) {
    auto s = make_oblique(ContactType::Multi, 0.024, 1, 0, 2, Scheme::MUSL, 0, off);
    double p0 = 0;
    for (std::size_t k = 0; k < s->p.size(); ++k) p0 += s->p.mass[k] * s->p.vx[k];
    double min_gap = 1e30;
    for (int n = 0; n < 400; ++n) {
      s->step();
      double xf = -1e30, xt = 1e30;
      for (std::size_t k = 0; k < s->p.size(); ++k) {
        if (s->p.body[k] == 0) xf = std::max(xf, s->p.x[k]);
        else if (s->p.y[k] > 0.024 && s->p.y[k] < 0.036) xt = std::min(xt, s->p.x[k]);
      }
      min_gap = std::min(min_gap, xt - xf);
    }
    double q = 0;
    for (std::size_t k = 0; k < s->p.size(); ++k) q += s->p.mass[k] * s->p.vx[k];
    s->update_energies();
    const double imb = s->energy.imbalance() / s->energy.initial, v = rebound(*s);
    std::printf("oblique multi, 4 ppc, %.1f of a cell off: min gap %.3g mm, rebound %.3f m/s (on "
                "the lines %.3f), energy %+.2e\n", off, min_gap * 1e3, v, v_on, imb);
    EXPECT_GT(min_gap, 0.0) << off;
    EXPECT_LT(std::abs(q - p0) / p0, 1e-10) << off;
    EXPECT_NEAR(v, v_on, 0.05 * std::abs(v_on)) << off;
    EXPECT_LT(imb, 0.02) << off;
    EXPECT_GT(imb, -0.03) << off;
  }
}

// Bodies that never come within a cell of each other: the multi-field step is the single-field
// step (same particle states to round-off), so the per-body fields change nothing away from
// contact.
// Bodies that never share a node: the multi-field run is the single-field one to round-off,
// under MUSL and USL, without and with two terms of the mass correction (which the multi-field
// run applies to each body's field over its box, the single-field one to the grid's).
TEST(ContactImpact, MultiEqualsSingleAwayFromContact) {
  for (Scheme sc : {Scheme::MUSL, Scheme::USL})
    for (int mc : {0, 2}) {
      auto a = make_oblique(ContactType::Single, 0.024, 1, -0.003, 1, sc, mc);
      auto b = make_oblique(ContactType::Multi, 0.024, 1, -0.003, 1, sc, mc);
      // The block starts 3 cells away and moves away; the plate is hit by nothing, so give it
      // a velocity to have something to compute.
      for (auto* s : {a.get(), b.get()})
        for (std::size_t k = 0; k < s->p.size(); ++k)
          s->p.vx[k] = s->p.body[k] == 0 ? -10.0 : 5.0 * std::sin(200.0 * s->p.y[k]);
      double dmax = 0, moved = 0;
      for (int n = 0; n < 200; ++n) {
        a->step();
        b->step();
      }
      ASSERT_EQ(a->p.size(), b->p.size());
      std::vector<std::size_t> at(a->p.size());
      for (std::size_t k = 0; k < b->p.size(); ++k) at[b->p.id[k]] = k;
      for (std::size_t k = 0; k < a->p.size(); ++k) {
        const std::size_t j = at[a->p.id[k]];  // the same particle in the multi-field run
        dmax = std::max({dmax, std::abs(a->p.x[k] - b->p.x[j]), std::abs(a->p.vx[k] - b->p.vx[j]),
                         std::abs(a->p.sxx[k] - b->p.sxx[j]) * 1e-9});
        moved = std::max(moved, std::abs(a->p.sxx[k]) * 1e-9);
      }
      EXPECT_LT(dmax, 1e-12) << scheme_name(sc) << ", " << mc << " terms";
      EXPECT_GT(moved, 1e-6) << scheme_name(sc) << ", " << mc << " terms";
    }
}

// The correction changes the run: two terms against none, the same single-field plate.
TEST(ContactImpact, MassCorrectionChangesTheMultiFieldRun) {
  auto a = make_oblique(ContactType::Multi, 0.024, 1, -0.003, 1, Scheme::MUSL, 0);
  auto b = make_oblique(ContactType::Multi, 0.024, 1, -0.003, 1, Scheme::MUSL, 2);
  for (auto* s : {a.get(), b.get()})
    for (std::size_t k = 0; k < s->p.size(); ++k)
      s->p.vx[k] = s->p.body[k] == 0 ? -10.0 : 5.0 * std::sin(200.0 * s->p.y[k]);
  for (int n = 0; n < 200; ++n) {
    a->step();
    b->step();
  }
  double d = 0, ref = 0;
  for (std::size_t k = 0; k < a->p.size(); ++k) {
    d = std::max(d, std::abs(a->p.vx[k] - b->p.vx[k]));
    ref = std::max(ref, std::abs(a->p.vx[k]));
  }
  EXPECT_GT(d, 1e-3 * ref);  // the per-body correction acted (the equality above is not vacuous)
}
