// The 1D column with rollers (docs/physics.md §4): arrival time, plateau, and what the right end
// reflects (free, LK silent layer in both its forms).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "common.hpp"
#include "absorbing_oracles.hpp"

using namespace smpm;
using namespace smpm::testing;

namespace {

struct Trace {
  std::vector<double> t, sxx, sxy, vx, vy;
};

// Run to t_end recording the probe at x.
Trace run_probe(Solver& s, double x, double y, double t_end) {
  Trace tr;
  while (s.t < t_end - 0.5 * s.dt) {
    s.step();
    const auto p = s.sample(x, y);
    tr.t.push_back(s.t); tr.sxx.push_back(p.sxx); tr.sxy.push_back(p.sxy);
    tr.vx.push_back(p.vx); tr.vy.push_back(p.vy);
  }
  return tr;
}


}  // namespace

// Step load: the front reaches x at x / c (within one cell), the plateau is the applied traction
// and the particle velocity traction / (rho c), within 2 %. P: normal compression, c = c_d;
// S: tangential traction, c = c_s (rollers hold v_x on the long sides).
void check_arrival_and_plateau(bool shear) {
  ColumnSpec c;
  c.cells = shear ? 80 : 120;
  c.shear = shear;
  c.end = End::Silent;
  const Material m = tungsten();
  const double cw = shear ? m.cs : m.cd;
  c.fn.kind = TimeFunction::Kind::Step;
  c.fn.ramp = 12 * c.h / cw;  // sin^2 rise over 12 cells, to limit Gibbs ringing
  auto s = make_column(c);
  const double xp = 40.5 * c.h;
  const double t_end = (c.cells * c.h) / cw * 0.95 + c.fn.ramp;
  const Trace tr = run_probe(*s, xp, 2 * c.h, t_end);
  const auto& stress = shear ? tr.sxy : tr.sxx;
  const auto& vel = shear ? tr.vy : tr.vx;
  // Arrival: half-amplitude crossing, minus half the rise.
  double t_half = -1;
  for (std::size_t i = 0; i < tr.t.size(); ++i)
    if (std::abs(stress[i]) >= 0.5 * c.amplitude) { t_half = tr.t[i]; break; }
  ASSERT_GT(t_half, 0);
  const double t_arr = xp / cw;
  EXPECT_NEAR(t_half - 0.5 * c.fn.ramp, t_arr, c.h / cw);
  // Plateau: mean from 10 cells of travel after the front to the end.
  double ss = 0, sv = 0;
  int n = 0;
  for (std::size_t i = 0; i < tr.t.size(); ++i)
    if (tr.t[i] > t_arr + c.fn.ramp + 10 * c.h / cw) { ss += stress[i]; sv += vel[i]; ++n; }
  ASSERT_GT(n, 50);
  // Compression gives sigma_xx = -sigma0; the tangential traction on the left end (s = (0, -1))
  // gives |sigma_xy| = tau.
  EXPECT_NEAR(std::abs(ss / n), c.amplitude, 0.02 * c.amplitude);
  if (!shear) {
    EXPECT_LT(ss / n, 0.0);
  }
  const double v0 = c.amplitude / (m.rho * cw);
  EXPECT_NEAR(std::abs(sv / n), v0, 0.02 * v0);
}

TEST(Column, ArrivalAndPlateauP) { check_arrival_and_plateau(false); }
TEST(Column, ArrivalAndPlateauS) { check_arrival_and_plateau(true); }

// Energy reflected by the right end, by extended-domain differencing (docs/physics.md §4.1): run A
// has the boundary under test at x = L; run B is the same column three times as long (same
// particles, same dt), so nothing comes back from its end in the window. At a time when the
// incident pulse has left A and its reflection is inside, the energy of the field A - B on the
// particles of A is the reflected energy. Pulse: sin^2 bell whose full width at half maximum is
// `fwhm_cells` (its support is twice that).
double reflected_energy_ratio(ColumnSpec c, int fwhm_cells, double imbalance_bound = 0.01) {
  const Material m = tungsten();
  const double cw = c.shear ? m.cs : m.cd;
  const double dur = 2.0 * fwhm_cells * c.h / cw;
  c.fn = sin2_pulse(dur, 0.5 * dur);
  auto A = make_column(c);
  ColumnSpec cb = c;
  cb.cells = 3 * c.cells;
  cb.end = End::Free;
  cb.damp_cells = 0;
  cb.pml_cells = 0;
  auto B = make_column(cb);
  const double tstar = dur + 1.8 * c.cells * c.h / cw;
  while (A->t < tstar - 0.5 * A->dt) A->step();
  while (B->t < tstar - 0.5 * B->dt) B->step();
  // Particles are seeded row by row; match them by lattice position.
  const long na = static_cast<long>(c.cells) * c.ppc_side, nb = static_cast<long>(cb.cells) * c.ppc_side;
  std::vector<long> of_b(B->p.size());
  for (std::size_t k = 0; k < B->p.size(); ++k) of_b[B->p.id[k]] = static_cast<long>(k);
  double er = 0;
  for (std::size_t k = 0; k < A->p.size(); ++k) {
    const long id = A->p.id[k], j = id / na, i = id % na;
    // A perfectly matched layer's field is not a physical one: the difference is taken in front.
    if (i >= na - static_cast<long>(c.pml_cells) * c.ppc_side) continue;
    const long kb = of_b[j * nb + i];
    const double dvx = A->p.vx[k] - B->p.vx[kb], dvy = A->p.vy[k] - B->p.vy[kb];
    er += 0.5 * A->p.mass[k] * (dvx * dvx + dvy * dvy) +
          A->p.vol[k] * elastic_energy_density(m, A->p.sxx[k] - B->p.sxx[kb],
                                               A->p.syy[k] - B->p.syy[kb],
                                               A->p.szz[k] - B->p.szz[kb],
                                               A->p.sxy[k] - B->p.sxy[kb]);
  }
  EXPECT_NEAR(A->energy.external_work, B->energy.external_work, 1e-9 * B->energy.external_work);
  if ((c.end == End::Silent || c.end == End::KelvinVoigt || c.damp_cells > 0 || c.pml_cells > 0) &&
      c.ppc_side == 1) {
    // Energy balance with the dashpots: kinetic + elastic + absorbed = external work. (At 4 and 9
    // particles per cell the FLIP particle kinetic energy exceeds the grid's by about 1 %.)
    // A perfectly matched layer's work is booked with the forces' mid-step velocity, as the
    // other loads are, but its forces are of the order of the stresses: under USL (the power
    // taken with v+, not with what the particles receive) the account then closes to 4-7 %.
    A->update_energies();
    const double imb = std::abs(A->energy.imbalance()) / A->energy.external_work;
    if (c.pml_cells > 0) std::printf("  energy imbalance %.3f\n", imb);
    EXPECT_LE(imb, c.pml_cells > 0 ? 0.08 : imbalance_bound) << "energy imbalance";
  }
  return er / A->energy.external_work;
}

struct ReflectCase {
  bool shear;
  End end;
  SilentForm form;
  Anchor anchor;
  int ppc_side;
  double bound;  // reflected / incident <= bound (silent) or >= bound (free)
  const char* label;
  ShapeKind shape = ShapeKind::Bilinear;
  int cells_beyond = 4;  // grid cells beyond the silent end
};

class ColumnReflection : public ::testing::TestWithParam<ReflectCase> {};

TEST_P(ColumnReflection, ReflectedEnergy) {
  const ReflectCase rc = GetParam();
  ColumnSpec c;
  c.cells = 100;
  c.shear = rc.shear;
  c.end = rc.end;
  c.form = rc.form;
  c.anchor = rc.anchor;
  c.ppc_side = rc.ppc_side;
  c.shape = rc.shape;
  c.cells_beyond = rc.cells_beyond;
  const double ratio = reflected_energy_ratio(c, 8);
  std::printf("  [%s] reflected energy / incident = %.3e\n", rc.label, ratio);
  if (rc.end == End::Free) EXPECT_GE(ratio, rc.bound);
  else EXPECT_LE(ratio, rc.bound);
}

INSTANTIATE_TEST_SUITE_P(
    Ends, ColumnReflection,
    ::testing::Values(
        // Default: semi-implicit nodal dashpot at the boundary points, on the particles' mean
        // velocity (measured 6.0e-4 P, 6.1e-4 S at 1 ppc; 1.5e-4 P at 4 ppc, 1.3e-4 S at 9 ppc;
        // with the lumped trapezoidal mean 9.1e-4, 7.1e-4, 3.1e-4, 1.9e-4).
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 1, 1e-3, "P default 1ppc"},
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 2, 1e-3, "P default 4ppc"},
        ReflectCase{true, End::Silent, SilentForm::Nodal, Anchor::Boundary, 1, 1e-3, "S default 1ppc"},
        ReflectCase{true, End::Silent, SilentForm::Nodal, Anchor::Boundary, 3, 1e-3, "S default 9ppc"},
        // The paper's Eq. 20-21 as written (lagged particle velocity, mapped at the particle):
        // measured 1.5e-3 (P) and 2.1e-3 (S) at 1 ppc.
        ReflectCase{false, End::Silent, SilentForm::Particle, Anchor::Particle, 1, 3e-3, "P paper form"},
        ReflectCase{true, End::Silent, SilentForm::Particle, Anchor::Particle, 1, 3e-3, "S paper form"},
        ReflectCase{false, End::Free, SilentForm::Nodal, Anchor::Boundary, 1, 0.95, "P free end"},
        ReflectCase{true, End::Free, SilentForm::Nodal, Anchor::Boundary, 1, 0.95, "S free end"},
        // The wider shapes (docs/physics.md section 8) with the default silent layer, the column
        // ending 4 cells inside the grid (measured: B-spline P 8.2e-4 / 4.4e-3 at 1 / 4 ppc,
        // S 9.0e-4; uGIMP P 1.8e-4 / 1.0e-4 at 4 / 9 ppc, S 1.8e-4) and on the grid's edge, where
        // the folded basis interpolates (B-spline P 1.6e-3 / 1.2e-3, uGIMP P 1.4e-4 at 4 ppc);
        // the paper's form with B-splines 1.5e-3. (With whole shares on the node beyond the end
        // once it held a sliver of mass, docs/physics.md section 8.5: B-spline P 4.5e-3 at 1 ppc,
        // uGIMP P 1.03e-3 / 4.0e-4.)
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 1, 1.6e-3, "P bspline 1ppc", ShapeKind::BSpline2},
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 2, 6e-3, "P bspline 4ppc", ShapeKind::BSpline2},
        ReflectCase{true, End::Silent, SilentForm::Nodal, Anchor::Boundary, 1, 1.6e-3, "S bspline 1ppc", ShapeKind::BSpline2},
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 2, 4e-4, "P gimp 4ppc", ShapeKind::UGimp},
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 3, 2.5e-4, "P gimp 9ppc", ShapeKind::UGimp},
        ReflectCase{true, End::Silent, SilentForm::Nodal, Anchor::Boundary, 2, 3e-4, "S gimp 4ppc", ShapeKind::UGimp},
        ReflectCase{false, End::Free, SilentForm::Nodal, Anchor::Boundary, 1, 0.95, "P bspline free end", ShapeKind::BSpline2},
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 1, 2.3e-3, "P bspline 1ppc edge", ShapeKind::BSpline2, 0},
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 2, 1.7e-3, "P bspline 4ppc edge", ShapeKind::BSpline2, 0},
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 2, 4e-4, "P gimp 4ppc edge", ShapeKind::UGimp, 0},
        ReflectCase{false, End::Silent, SilentForm::Nodal, Anchor::Boundary, 1, 1.2e-3, "P bilinear 1ppc edge", ShapeKind::Bilinear, 0},
        ReflectCase{false, End::Silent, SilentForm::Particle, Anchor::Particle, 1, 2e-3, "P bspline paper form", ShapeKind::BSpline2}),
    [](const auto& info) {
      std::string s = info.param.label;
      for (char& ch : s) if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return s;
    });

// Stability of the dashpot forms (docs/physics.md §1). A pulse runs into the silent end of a short
// column for 20 pulse lengths; a stable absorbing end leaves < 5 % of the input energy. The
// column starts inside its first cell (offset) so the boundary cells are partly filled.
//  * the paper's form (lagged particle velocity, mapped at the particle) is stable up to the
//    bulk limit CFL = 1, because each node's dashpot share never exceeds m_i c / h;
//  * the semi-implicit nodal form is stable everywhere;
//  * a lagged dashpot mapped at the boundary point (where nodes can be nearly massless) is not:
//    that is why the nodal form is the default.
double energy_left_after(SilentForm form, Anchor anchor, double offset_cells, int ppc, double cfl,
                         bool updated_edge = false, Scheme scheme = Scheme::MUSL) {
  ColumnSpec c;
  c.scheme = scheme;
  c.cells = 40;
  c.end = End::Silent;
  c.form = form;
  c.anchor = anchor;
  c.offset = offset_cells * c.h;
  c.cfl = cfl;
  c.ppc_side = ppc;
  c.updated_edge = updated_edge;
  const double dur = 16 * c.h / 5918.5;
  c.fn = sin2_pulse(dur, 0.5 * dur);
  auto s = make_column(c);
  try {
    while (s->t < 20 * dur) s->step();
  } catch (const std::exception&) {
    return 1e300;  // blew up (particles left the grid)
  }
  s->update_energies();
  const double e = s->energy.kinetic + s->energy.elastic;
  return std::isfinite(e) ? e / s->energy.external_work : 1e300;
}

// A silent end of 1 101 nodes takes the parallel paths of the dashpot nodes (their update and
// record in the grid update's blocks, the solve's final update, the absorbed work): on 2 threads
// the run agrees with 1 thread to round-off (the particles' strips sum in another order), so the
// nodes' own work does not race. Plain and delayed edges, MUSL and USF.
TEST(SilentStability, LongEdgeOnTwoThreadsAgreesToRoundOff) {
  for (const bool delayed : {false, true})
    for (const Scheme sc : {Scheme::MUSL, Scheme::USF}) {
      double absorbed[2], left[2], work[2];
      for (int t = 0; t < 2; ++t) {
        ColumnSpec c;
        c.cells = 12;
        c.height = 1100;
        c.scheme = sc;
        c.delayed_edge = delayed;
        c.threads = t + 1;
        c.fn = sin2_pulse(8 * c.h / 5918.5, 2 * c.h / 5918.5);
        auto s = make_column(c);
        for (int i = 0; i < 150; ++i) s->step();
        s->update_energies();
        absorbed[t] = s->energy.absorbed;
        left[t] = s->energy.kinetic + s->energy.elastic;
        work[t] = s->energy.external_work;
        EXPECT_EQ(s->dashpot_solve.unconverged, 0);
      }
      const char* what = delayed ? "delayed" : "plain";
      ASSERT_GT(absorbed[0], 0.9 * work[0]) << what;  // the pulse has gone through the edge
      EXPECT_NEAR(absorbed[1], absorbed[0], 1e-12 * work[0]) << what;
      EXPECT_NEAR(left[1], left[0], 1e-12 * work[0]) << what;
    }
}

TEST(SilentStability, PaperFormStableUpToBulkLimit) {
  for (int ppc : {1, 2})
    for (double off : {0.0, 0.3, 0.45})
      for (double cfl : {0.1, 0.3, 0.5, 0.7, 0.9, 1.0})
        EXPECT_LT(energy_left_after(SilentForm::Particle, Anchor::Particle, off, ppc, cfl), 0.05)
            << "ppc_side " << ppc << " offset " << off << " CFL " << cfl;
}

// The dashpot solve's convergence test is relative (1e-13 of the largest vbar); below the
// smallest normal double it cannot hold, as a wave's leading tail of some 1e-316 m/s reaching
// an edge showed (the column example with B-splines: one step ran the iteration to its limit of
// 200 and the run printed a note). A column moving at 1e-312 m/s towards its silent end: every
// step converges within 40 iterations (before, two of the 50 ran to 200).
TEST(SilentStability, DashpotSolveConvergesAtDenormalVelocities) {
  for (const ShapeKind shape : {ShapeKind::Bilinear, ShapeKind::BSpline2}) {
    ColumnSpec c;
    c.cells = 20;
    c.shape = shape;
    c.amplitude = 0;
    auto s = make_column(c);
    for (std::size_t k = 0; k < s->p.size(); ++k) s->p.vx[k] = 1e-312;
    for (int n = 0; n < 50; ++n) s->step();
    EXPECT_EQ(s->dashpot_solve.steps, 50);
    EXPECT_EQ(s->dashpot_solve.unconverged, 0);
    EXPECT_LE(s->dashpot_solve.max_iterations, 40);
  }
}

TEST(SilentStability, NodalFormStable) {
  for (int ppc : {1, 2})
    for (double off : {0.0, 0.3, 0.45})
      for (double cfl : {0.1, 0.3, 0.5, 0.7, 0.9, 1.0})
        EXPECT_LT(energy_left_after(SilentForm::Nodal, Anchor::Boundary, off, ppc, cfl), 0.05)
            << "ppc_side " << ppc << " offset " << off << " CFL " << cfl;
}

// The same under MUSL with the updated velocity at the dashpots' nodes (`edge_velocity`
// "updated"): it strains the particles next to the edge as USL does, and a node of a nearly
// empty cell keeps the re-mapped value (docs/physics.md section 4). Stable up to CFL 0.85 for
// every filling of the last cell tried (offsets 0.05-0.95 h, 1 and 4 ppc); at CFL 0.9-0.95 a
// 1-ppc column whose particles lie within 0.05-0.1 h of the grid lines blows up, where the
// re-mapped velocity stays stable up to 1. (USL itself blows up from CFL 0.4 there.)
TEST(SilentStability, UpdatedEdgeVelocityStableUpToCfl085) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USF})
    for (int ppc : {1, 2})
      for (double off : {0.0, 0.3, 0.45, 0.75})
        for (double cfl : {0.1, 0.3, 0.5, 0.7, 0.85})
          EXPECT_LT(energy_left_after(SilentForm::Nodal, Anchor::Boundary, off, ppc, cfl, true, sc),
                    0.05)
              << scheme_name(sc) << " ppc_side " << ppc << " offset " << off << " CFL " << cfl;
}

TEST(SilentStability, LaggedDashpotOnLightBoundaryNodeFails) {
  // Documented failure mode, kept as a regression guard for the choice of the default.
  EXPECT_GT(energy_left_after(SilentForm::Particle, Anchor::Boundary, 0.3, 2, 0.3), 0.5);
}

// ---- Kelvin-Voigt (spring-dashpot) end, docs/physics.md section 9.1 ----

namespace {

// Mean x displacement of the right end's layer particles since `x_start` (by particle id).
double end_displacement(const Solver& s, const std::vector<double>& x_start) {
  const SilentBoundary& sl = s.silents.at(0);
  double u = 0;
  for (uint32_t k : sl.layer.idx) u += s.p.x[k] - x_start[s.p.id[k]];
  return u / static_cast<double>(sl.layer.idx.size());
}

std::vector<double> start_positions(const Solver& s) {
  std::vector<double> x(s.p.size());
  for (std::size_t k = 0; k < s.p.size(); ++k) x[s.p.id[k]] = s.p.x[k];
  return x;
}

struct Settled {
  double u_end = 0;     // mean displacement of the end's layer particles
  double u_spring = 0;  // mean displacement of their anchors, as the springs see it
  double mean_sxx = 0, imbalance = 0;
};

// A 40-cell column under a sustained compression sigma (sin^2 rise over 12 cells) on its left
// end, run for 30 transit times.
Settled settle(End end, double delta_cells, double cfl = 0.3) {
  ColumnSpec c;
  c.cells = 40;
  c.end = end;
  c.delta = delta_cells * c.h;
  c.cfl = cfl;
  const Material m = tungsten();
  c.fn.kind = TimeFunction::Kind::Step;
  c.fn.ramp = 12 * c.h / m.cd;
  auto s = make_column(c);
  const auto x0 = start_positions(*s);
  const double t_end = 30 * c.cells * c.h / m.cd;
  while (s->t < t_end - 0.5 * s->dt) s->step();
  s->update_energies();
  Settled r;
  r.u_end = end_displacement(*s, x0);
  for (std::size_t k = 0; k < s->p.size(); ++k) r.mean_sxx += s->p.sxx[k];
  r.mean_sxx /= static_cast<double>(s->p.size());
  const SilentBoundary& sl = s->silents.at(0);
  for (double u : sl.ux) r.u_spring += u / static_cast<double>(sl.ux.size());
  r.imbalance = s->energy.imbalance() / s->energy.external_work;
  return r;
}

}  // namespace

// Under a sustained load the Kelvin-Voigt end comes to rest at u = sigma delta / (alpha rho c_d^2)
// (alpha = 1) and the column carries sigma; the LK end keeps moving at sigma / (rho c_d).
// delta = the column's length and four times it (the end then moves 3 % of a cell: its boundary
// points leave the body's last cell, whose load shares must stay on the body).
TEST(KelvinVoigt, SettlesUnderSustainedLoad) {
  const Material m = tungsten();
  const double sigma = 100e6, h = 1e-3, M = m.rho * m.cd * m.cd;
  for (double dc : {40.0, 160.0}) {
    const Settled r = settle(End::KelvinVoigt, dc);
    const double u = sigma * dc * h / M;
    std::printf("  [delta %g cells] spring displacement %.6e m (closed form %.6e), particles "
                "%.6e, mean sxx %.6e, imbalance %.2e\n",
                dc, r.u_spring, u, r.u_end, r.mean_sxx, r.imbalance);
    EXPECT_NEAR(r.u_spring, u, 0.005 * u) << "delta " << dc << " cells";
    // The last particles sit half a cell inside: u + (sigma / M) h / 2.
    EXPECT_NEAR(r.u_end, u + 0.5 * sigma * h / M, 0.01 * u) << "delta " << dc << " cells";
    EXPECT_NEAR(r.mean_sxx, -sigma, 0.005 * sigma) << "delta " << dc << " cells";
    EXPECT_LE(std::abs(r.imbalance), 0.005) << "delta " << dc << " cells";
  }
  // LK: at 30 transits the end has moved about 29 times sigma L / M.
  const Settled lk = settle(End::Silent, 0);
  const double u_l = sigma * 40 * h / M;
  std::printf("  [LK] end displacement %.6e m = %.1f sigma L / M\n", lk.u_end, lk.u_end / u_l);
  EXPECT_GT(lk.u_end, 20 * u_l);
}

// The stiffest spring a case accepts (delta = one cell) at CFL 0.9: no growth over 30 transit
// times (kinetic + elastic, springs included, stays within the work put in) and the energy
// account closes within 3 %.
TEST(KelvinVoigt, StiffestSpringStableAtHighCfl) {
  const Settled r = settle(End::KelvinVoigt, 1.0, 0.9);
  std::printf("  [delta 1 cell, CFL 0.9] imbalance %.2e\n", r.imbalance);
  EXPECT_TRUE(std::isfinite(r.u_end));
  EXPECT_LE(std::abs(r.imbalance), 0.03);
}

// Reflected energy of a sin^2 pulse against the closed form (absorbing_oracles.hpp).
TEST(KelvinVoigt, ReflectionMatchesClosedForm) {
  const Material m = tungsten();
  for (double dc : {4.0, 16.0}) {
    ColumnSpec c;
    c.cells = 100;
    c.end = End::KelvinVoigt;
    c.delta = dc * c.h;
    const double ratio = reflected_energy_ratio(c, 8);
    const double dur = 2.0 * 8 * c.h / m.cd;
    const double pred = kv_reflected_energy_fraction(sin2_pulse(dur, 0.5 * dur), dur, c.delta, m.cd);
    std::printf("  [delta %g cells] reflected energy / incident = %.4e (closed form %.4e)\n", dc,
                ratio, pred);
    EXPECT_NEAR(ratio, pred, 0.1 * pred + 1e-3) << "delta " << dc << " cells";
  }
}

// Gravity along the column towards a Kelvin-Voigt end (no other load): the column comes to rest
// carrying its weight, sigma_xx = -rho g x, and the end at u = rho g L delta / (rho c_d^2); the
// work of gravity closes the energy account. On an LK end the column keeps sinking at g L / c_d.
// (The spring ends 0.34 % above the weight in MUSL and USF, exact in USL or with the particle
// anchor: the sudden load leaves a node-to-node checkerboard of grid forces, +-280 N against a
// 48 kN weight, that particles at cell centres do not see and MUSL's re-map never damps; the
// end node carries part of it.) The delayed closure's end sinks as LK's (its ring holds the
// steady velocity, its block the same dashpot): 2.659e-5 m against LK's 2.654e-5 and the
// estimate 2.649e-5. A delayed end under a load it cannot carry drifts off its grid line; past 5 %
// of a cell it takes the trapezoidal update (docs/physics.md section 4).
TEST(KelvinVoigt, ColumnUnderGravity) {
  const Material m = tungsten();
  const double g = 2e4, h = 1e-3, L = 40 * h, M = m.rho * m.cd * m.cd;  // rho g L = 12 MPa
  for (int variant = 0; variant < 3; ++variant) {
    const End end = variant == 0 ? End::KelvinVoigt : End::Silent;
    ColumnSpec c;
    c.cells = 40;
    c.end = end;
    c.delta = L;
    c.amplitude = 0;
    c.gravity = g;
    c.delayed_edge = variant == 2;
    auto s = make_column(c);
    const auto x0 = start_positions(*s);
    while (s->t < 30 * L / m.cd) s->step();
    s->update_energies();
    const double u = end_displacement(*s, x0);
    const double imb = s->energy.imbalance() / s->energy.external_work;
    if (end == End::KelvinVoigt) {
      double us = 0;
      for (double v : s->silents[0].ux) us += v / static_cast<double>(s->silents[0].ux.size());
      const double exact = m.rho * g * L * L / M;
      // sigma_xx at the particles of the column's middle cell against -rho g x.
      double worst = 0;
      for (std::size_t k = 0; k < s->p.size(); ++k)
        worst = std::max(worst, std::abs(s->p.sxx[k] + m.rho * g * s->p.x[k]) / (m.rho * g * L));
      std::printf("  [KV] spring displacement %.6e m (closed form %.6e), worst |sxx + rho g x| / "
                  "(rho g L) %.2e, imbalance %.2e\n", us, exact, worst, imb);
      EXPECT_NEAR(us, exact, 0.005 * exact);
      EXPECT_LE(worst, 0.03);
      EXPECT_LE(std::abs(imb), 0.005);
    } else {
      // Terminal velocity g L / c_d: after 30 transits the end has sunk by about 29 L/c_d * g L/c_d.
      const double sink = 29 * (L / m.cd) * (g * L / m.cd);
      std::printf("  [LK%s] end displacement %.6e m (terminal-velocity estimate %.6e)\n",
                  c.delayed_edge ? ", delayed" : "", u, sink);
      EXPECT_NEAR(u, sink, 0.1 * sink);
    }
  }
}

// ---- Graded damping layer, docs/physics.md section 9.2 ----

// A mass-proportional layer of 10 and 20 cells (alpha0 from r0 = 1e-3, power 2) before a fixed
// end, and 10 cells before an LK end: the reflected energy of the 16-cell sin^2 pulse against the
// continuum solution of the layer (absorbing_oracles.hpp), within 10 %; thicker reflects less.
TEST(DampingLayer, ReflectionMatchesContinuum) {
  const Material m = tungsten();
  double last = 1;
  for (const auto& end_cells : {std::pair{End::Fixed, 10}, {End::Fixed, 20}, {End::Silent, 10}}) {
    const End end = end_cells.first;  // named copies: the lambda below captures end
    const int dc = end_cells.second;
    ColumnSpec c;
    c.cells = 100;
    c.end = end;
    c.damp_cells = dc;
    const double ratio = reflected_energy_ratio(c, 8);
    const double dur = 2.0 * 8 * c.h / m.cd, L = dc * c.h;
    const double a0 = -3 * m.cd * std::log(c.damp_r0) / L;
    const double pred = reflected_energy_fraction(sin2_pulse(dur, 0.5 * dur), dur, [&](double w) {
      return damping_layer_r2(w, L, a0, 2, m.cd, end == End::Silent);
    });
    std::printf("  [%d cells, %s end] reflected energy / incident = %.4e (continuum %.4e)\n", dc,
                end == End::Silent ? "LK" : "fixed", ratio, pred);
    EXPECT_NEAR(ratio, pred, 0.1 * pred) << dc << " cells";
    if (end == End::Fixed) {
      EXPECT_LT(ratio, last);
      last = ratio;
    }
  }
}

// The stiffness-proportional part (beta0 = h / c_d, graded as alpha), alone (r0 = 0.9999: alpha0
// 1e-4 of its default) and with the mass part, fixed end, 10 cells, MUSL, 1 ppc: the reflected
// energy within 10 % of the continuum's with the same graded beta, the energy balance within
// 1 % (reflected_energy_ratio), and the critical step lowered as documented, with the largest
// beta at a particle (two bands over the same particles: their sum).
TEST(DampingLayer, StiffnessProportionalMatchesContinuum) {
  const Material m = tungsten();
  for (const double r0 : {0.9999, 1e-3}) {
    ColumnSpec c;
    c.cells = 100;
    c.end = End::Fixed;
    c.damp_cells = 10;
    c.damp_r0 = r0;
    c.damp_beta = c.h / m.cd;
    const auto s = make_column(c);
    // The outermost particles lie h/2 inside the edge: beta = beta0 (1 - 0.5 / 10)^2 there.
    const double bmax = c.damp_beta * 0.95 * 0.95, dt_plain = c.h / m.cd;
    for (const double twice : {1.0, 2.0}) {
      if (twice > 1) {  // the same band twice: beta adds up
        s->dampers.push_back(s->dampers[0]);
        s->finalize();
      }
      const double xi = twice * bmax / dt_plain;
      EXPECT_NEAR(s->critical_dt(), dt_plain * (std::sqrt(1 + xi * xi) - xi), 1e-12 * dt_plain);
    }
    const double ratio = reflected_energy_ratio(c, 8);
    const double dur = 2.0 * 8 * c.h / m.cd, L = 10 * c.h;
    const double a0 = -3 * m.cd * std::log(r0) / L;
    const double pred = reflected_energy_fraction(sin2_pulse(dur, 0.5 * dur), dur, [&](double w) {
      return damping_layer_r2(w, L, a0, 2, m.cd, false, c.damp_beta);
    });
    std::printf("  r0 %g, beta0 h/c_d: reflected energy / incident = %.4e (continuum %.4e)\n", r0,
                ratio, pred);
    EXPECT_NEAR(ratio, pred, 0.1 * pred) << "r0 " << r0;
  }
}

// The stiffness part is explicit; its limit assumes a full cell's mass at every node. Its
// viscous stress takes the re-mapped velocity (MUSL, USF) or the start velocity (USL), never
// v+, which at a node holding a sliver of a particle magnified the force: with v+, a 1-ppc band
// (beta0 = h / c_d, 10 cells, fixed end) whose last particle lay 0.25 h past a grid line blew up
// under USF and USL at CFL 0.3, and under both at CFL 0.6 on a grid line. Now every offset runs
// at CFL 0.3 and 0.6 under every scheme, and at 0.9 under MUSL and USF (USL's own limit at 1 ppc
// is lower: it stops at CFL 0.75 without the band's stiffness part too); the band absorbs
// 0.52-0.61 of the work, the account closes within 1e-3 (MUSL, USF; measured 9e-5-6.5e-4) and
// 2 % (USL, which books with v+; measured 0.4-1.3 %).
TEST(DampingLayer, StiffnessPartStableAtLightNodes) {
  const Material m = tungsten();
  for (const Scheme sc : {Scheme::MUSL, Scheme::USF, Scheme::USL})
    for (const double cfl : {0.3, 0.6, 0.9}) {
      if (sc == Scheme::USL && cfl > 0.6) continue;
      for (const double shift : {0.0, 0.25, 0.75}) {
        ColumnSpec c;
        c.scheme = sc;
        c.cfl = cfl;
        c.end = End::Fixed;
        c.damp_cells = 10;
        c.damp_beta = c.h / m.cd;
        c.amplitude = 1e4;
        c.offset = shift * c.h;
        const double dur = 2.0 * 16 * c.h / m.cd;
        c.fn = sin2_pulse(dur, 0.5 * dur);
        auto s = make_column(c);
        char what_c[64];
        std::snprintf(what_c, sizeof what_c, "%s, CFL %.1f, %.2f h off", scheme_name(sc), cfl,
                      shift);
        const std::string what = what_c;
        try {
          while (s->t < dur + 2.5 * c.cells * c.h / m.cd) s->step();
        } catch (const std::exception& e) {
          ADD_FAILURE() << what << ": " << e.what();
          continue;
        }
        s->update_energies();
        const double imb = s->energy.imbalance() / s->energy.external_work;
        std::printf("  [%s] absorbed %.4f of the work, imbalance %.2e\n", what.c_str(),
                    s->energy.absorbed / s->energy.external_work, imb);
        EXPECT_GE(s->energy.absorbed, 0.4 * s->energy.external_work) << what;
        EXPECT_LE(std::abs(imb), sc == Scheme::USL ? 0.02 : 1e-3) << what;
      }
    }
}

// ---- Perfectly matched layer on particles, docs/physics.md section 9.3 ----

// USL, CFL 0.3, free end behind the layer, 8-cell sin^2 pulses; the reflected energy in front of
// the layer. Measured (layer particles taking (depth/width)^5 of the grid's velocity): 10 cells
// 2.9e-5 (P) and 6.1e-5 (S) at 1 ppc, 1.0e-5 and 3.8e-5 at 4 ppc; 20 cells 2.9e-6 and 3.0e-6 at
// 1 ppc (with the power 2.5 used before: 8.0e-6, 2.8e-5, 9.0e-6, 4.1e-5, 2.4e-6, 2.2e-6; the
// larger power trades a little normal-incidence reflection for much smaller converted waves at
// oblique incidence; the FE column: 6.7e-5 and 2.7e-4, 9.6e-7).
// The reflection tests' column: 100 cells, a layer of `cells` at its free end.
static ColumnSpec pml_column(Scheme scheme, int ppc_side, int cells, bool shear) {
  ColumnSpec c;
  c.cells = 100;
  c.ppc_side = ppc_side;
  c.end = End::Free;
  c.scheme = scheme;
  c.shear = shear;
  c.pml_cells = cells;
  return c;
}

TEST(Pml, ColumnReflectionUsl) {
  for (const int ppc : {1, 2})
    for (const int cells : {10, 20})
      for (const bool shear : {false, true}) {
        if (ppc == 2 && cells == 20) continue;
        const double ratio = reflected_energy_ratio(pml_column(Scheme::USL, ppc, cells, shear), 8);
        std::printf("  [USL, %d ppc, %d cells, %s] reflected energy %.3e\n", ppc * ppc, cells,
                    shear ? "S" : "P", ratio);
        EXPECT_LE(ratio, cells == 10 ? 1e-4 : 1e-5) << cells << " cells, " << (shear ? "S" : "P");
      }
}

// 10^5 steps after an 8-cell sin^2 pulse has left the column: the energy (kinetic plus elastic)
// sampled every 500 steps from 10^4 steps on.
struct LongRun {
  double e1, emax, elast;  // at 10^4 steps, largest from there, at the end: fractions of e0
  double e0_of_input;      // e0, the energy when the pulse had left, over the input
  double imbalance = 0;    // the energy account at the end, over the external work
  double late_max = 0, late_min = 1e300;  // largest and smallest from 5 * 10^4 steps on
  double drift = 0;        // at the end, the column's mean velocity along the pulse's (m/s)
};

static LongRun long_run(ColumnSpec c) {
  const Material m = tungsten();
  const double cw = c.shear ? m.cs : m.cd;
  const double dur = 2.0 * 8 * c.h / cw;
  c.fn = sin2_pulse(dur, 0.5 * dur);
  auto A = make_column(c);
  while (A->t < dur + 1.8 * c.cells * c.h / cw) A->step();
  A->update_energies();
  const double e0 = A->energy.kinetic + A->energy.elastic;
  LongRun r{0, 0, 0, e0 / A->energy.external_work};
  for (long n = 1; n <= 100000; ++n) {
    A->step();
    if (n % 500 == 0 && n >= 10000) {
      A->update_energies();
      const double e = (A->energy.kinetic + A->energy.elastic) / e0;
      if (n == 10000) r.e1 = e;
      r.emax = std::max(r.emax, e);
      r.elast = e;
      if (n >= 50000) {
        r.late_max = std::max(r.late_max, e);
        r.late_min = std::min(r.late_min, e);
      }
    }
  }
  A->update_energies();
  r.imbalance = A->energy.imbalance() / A->energy.external_work;
  double mv = 0, mass = 0;
  for (std::size_t k = 0; k < A->p.size(); ++k) {
    mv += A->p.mass[k] * (c.shear ? A->p.vy[k] : A->p.vx[k]);
    mass += A->p.mass[k];
  }
  r.drift = mv / mass;
  return r;
}

// MUSL and USF at 4 and 9 ppc (docs/physics.md section 9.3: the layer's damping acts on its
// particles), as the USL test above: CFL 0.3, free end behind, 8-cell sin^2 pulses, 10 cells.
// Measured: MUSL 3.4e-6 (P) and 1.2e-5 (S) at 4 ppc, 3.7e-6 and 1.7e-5 at 9 ppc; USF 3.4e-6 and
// 1.2e-5, 3.6e-6 and 1.6e-5 (USL: 1.0e-5 and 3.8e-5 at 4).
TEST(Pml, ColumnReflectionMuslUsf) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USF})
    for (const int ppc : {2, 3})
      for (const bool shear : {false, true}) {
        const double ratio = reflected_energy_ratio(pml_column(sc, ppc, 10, shear), 8);
        std::printf("  [%s, %d ppc, %s] reflected energy %.3e\n", scheme_name(sc), ppc * ppc,
                    shear ? "S" : "P", ratio);
        EXPECT_LE(ratio, 3e-5) << scheme_name(sc) << ", " << ppc * ppc << " ppc, "
                               << (shear ? "S" : "P");
      }
}

// Late-time stability: after the pulse has gone, 10^5 more steps at CFL 0.5 (the case whose FLIP
// layer grew within 3 500 steps; under MUSL and USF at 1 ppc this one still grows after 5 * 10^4,
// so cases take those schemes at 4 and 9 ppc only). The energy left is what the pulse's net impulse
// leaves and what the layer still holds. Measured from 10^4 steps on: P decays; S, after a first
// decay of 1.5 %, rises linearly by 1.4e-3 of it over the next 9 * 10^4 steps. That energy is not a
// wave: the layer (alpha = 0) stops the S pulse's net impulse and holds the column still (mean
// velocity 3e-7 m/s, against 0.163 m/s without the layer), so what is left is the static shear
// strain in the layer; the layer's memories decay at the rate alpha + d, and at alpha = 0 those
// where d is small hardly forget and integrate that strain: the rise is the layer's response at
// zero frequency (with alpha > 0 there is none: the next test). Bounds on the rise from 10^4 steps
// on: P 1e-6, S 3e-3 of the energy when the pulse has left.
// The long runs' column: 100 cells, a 10-cell layer at its end, USL at CFL 0.5.
static ColumnSpec pml_long_column(bool shear, double alpha, End end = End::Free) {
  ColumnSpec c;
  c.cells = 100;
  c.end = end;
  c.scheme = Scheme::USL;
  c.shear = shear;
  c.cfl = 0.5;
  c.pml_cells = 10;
  c.pml_alpha = alpha;
  return c;
}

TEST(Pml, NoGrowthOver100000StepsUsl) {
  for (const bool shear : {false, true}) {
    const LongRun r = long_run(pml_long_column(shear, 0));
    std::printf("  [%s] energy left %.3e of the input; after 1e4 steps %.6f of it, largest later "
                "%.6f; the column's mean velocity %.2e m/s\n", shear ? "S" : "P", r.e0_of_input,
                r.e1, r.emax, r.drift);
    EXPECT_LE(r.emax - r.e1, shear ? 3e-3 : 1e-6) << (shear ? "S" : "P");
    // The layer holds the column still: what is left is the strain it keeps.
    if (shear) {
      EXPECT_LT(std::abs(r.drift), 1e-5);
    }
  }
}

// The same long runs with the frequency-shifted layer, alpha = 2e4 1/s (below the pulses' band:
// the column reflects 3.2e-5 (P) and 5.9e-5 (S) of the energy, as with alpha = 0): the net
// impulse passes the layer and the column drifts (within its cells over these
// steps; P 0.0081 m/s, S 0.0146 m/s). The energy left, the drift's and what the layer holds,
// settles within 2.5 * 10^4 (P, rising by 8e-4 of itself from 10^4 steps) and 4.5 * 10^4 steps
// (S, falling by a third) and then stays constant: from 5 * 10^4 steps on it varies by less than
// 1e-6 of itself (measured: to the seventh digit, P 7.953677e-4 and S 6.109539e-4 of the energy
// when the pulse had left). With alpha = 0 the S column's rises by 8e-4 of itself over the
// same steps (the test above). With LK behind the layer, below, nothing is left.
TEST(Pml, ShiftedLayerNoGrowthOver100000StepsUsl) {
  for (const bool shear : {false, true}) {
    const LongRun r = long_run(pml_long_column(shear, 2e4));
    std::printf("  [%s] energy left %.3e of the input; after 1e4 steps %.6e of it, from 5e4 steps "
                "on %.7e to %.7e; the column's mean velocity %.2e m/s\n", shear ? "S" : "P",
                r.e0_of_input, r.e1, r.late_min, r.late_max, r.drift);
    EXPECT_LE(r.late_max - r.late_min, 1e-6 * r.late_max) << (shear ? "S" : "P");
    EXPECT_LE(r.late_max, 1.01 * r.e1) << (shear ? "S" : "P");
    if (shear) {
      EXPECT_GT(std::abs(r.drift), 1e-3);  // the impulse passed: the column drifts
    }
  }
  // With LK dashpots behind the layer (the recommended layout) they take that drift out: the
  // energy left falls to 8.5e-9 of what it held after the pulse and stays there (S; 8.549e-9 at
  // 5 * 10^4 steps, 8.540e-9 at the end).
  const LongRun r = long_run(pml_long_column(true, 2e4, End::Silent));
  std::printf("  [S, LK behind] energy left after 1e4 steps %.3e, at 1.1e5 %.3e\n", r.e1, r.elast);
  EXPECT_LE(r.late_max, 1e-7);  // from 5 * 10^4 steps on
}

// The long runs under MUSL, 4 ppc, a 60-cell column: with a free end behind the layer (alpha = 0)
// the strain the layer keeps rises as under USL (P 1.0007 to 1.0008, S 0.9951 to 0.9968 of the
// energy left after the pulse); with LK behind and alpha = 2e4 1/s what is left decays (P 3.3e-5
// at 5e4 steps to 1.5e-5, S 3.4e-5 to 1.9e-5). The energy account, the particles' damping
// booked as absorbed, closes to 1.5e-3 to 3.0e-3 of the work (USL's nodal blocks: 4-7 %).
static void pml_long_runs_4ppc(Scheme scheme) {
  for (const bool lk : {false, true})
    for (const bool shear : {false, true}) {
      ColumnSpec c = pml_long_column(shear, lk ? 2e4 : 0, lk ? End::Silent : End::Free);
      c.cells = 60;
      c.ppc_side = 2;
      c.scheme = scheme;
      const LongRun r = long_run(c);
      std::printf("  [%s, %s, %s] after 1e4 steps %.4e of the energy left, largest later %.4e, "
                  "from 5e4 steps on at most %.4e, at 1.1e5 %.4e; imbalance %.2e of the work\n",
                  scheme_name(scheme), lk ? "LK behind, alpha 2e4" : "free end", shear ? "S" : "P",
                  r.e1, r.emax, r.late_max, r.elast, r.imbalance);
      if (lk) {
        EXPECT_LE(r.late_max, 1e-4) << (shear ? "S" : "P");
        EXPECT_LE(r.elast, 0.9 * r.late_max) << (shear ? "S" : "P");
      } else {
        EXPECT_LE(r.emax - r.e1, 3e-3) << (shear ? "S" : "P");
      }
      EXPECT_LE(std::abs(r.imbalance), 0.01) << (shear ? "S" : "P");
    }
}

TEST(Pml, NoGrowthOver100000StepsMusl) { pml_long_runs_4ppc(Scheme::MUSL); }

// USF, which strains the particles with their mapped velocities as MUSL does (at the next step's
// start), damps them the same way. Measured: free end P 1.0006 to 1.0007, S 0.9949 to 0.9966 of
// the energy left after the pulse; LK behind, P 3.3e-5 at 5e4 steps to 1.6e-5, S 3.3e-5 to
// 2.3e-5; the account 1.5e-3 to 2.9e-3 of the work.
TEST(Pml, NoGrowthOver100000StepsUsf) { pml_long_runs_4ppc(Scheme::USF); }

// MUSL and USF at 1 ppc: the schemes' odd-even branch (a particle strained by its two
// neighbours' velocities) carries slow waves whose group velocity opposes their phase velocity,
// and a stretching amplifies such waves (docs/physics.md section 9.3). A 10-cell layer with the
// frequency shift pml_one_ppc_alpha (2.4e5 1/s here), LK behind: 10^5 steps after the pulse the
// energy left decays (measured: P 4.8e-4 of what the pulse left at 10^4 steps, at most 4.0e-4
// from 5 * 10^4 on, 3.2e-4 at the end; S 2.7e-4, 1.4e-4, 7.4e-5; both schemes alike), and the
// column reflects (CFL 0.3, 8-cell pulses) 8.1e-5 (P) and 2.1e-4 (S) of the energy under both
// (unshifted, before the growth: 4.9e-5 and 2.5e-5). Without the shift the S column stops on the
// energy check after 3.2 * 10^4 steps.
TEST(Pml, OnePpcMuslUsfNeedTheShift) {
  const Material m = tungsten();
  for (const Scheme sc : {Scheme::USF, Scheme::MUSL})
    for (const bool shear : {false, true}) {
      const char* what = shear ? "S" : "P";
      ColumnSpec c = pml_long_column(shear, 0, End::Silent);
      c.cells = 60;
      c.scheme = sc;
      c.pml_alpha = pml_one_ppc_alpha(m.cd, 1e-3, 2, 10 * c.h, c.h);
      const LongRun r = long_run(c);
      std::printf("  [%s, %s, alpha %.3g] energy left after 1e4 steps %.3e, from 5e4 on at most "
                  "%.3e, at 1.1e5 %.3e; imbalance %.2e of the work\n", scheme_name(sc), what,
                  c.pml_alpha, r.e1, r.late_max, r.elast, r.imbalance);
      EXPECT_LE(r.late_max, 1e-3) << scheme_name(sc) << " " << what;
      EXPECT_LE(r.elast, 0.9 * r.late_max) << scheme_name(sc) << " " << what;
      EXPECT_LE(std::abs(r.imbalance), 0.01) << scheme_name(sc) << " " << what;
      ColumnSpec f = pml_column(sc, 1, 10, shear);
      f.end = End::Silent;
      f.pml_alpha = c.pml_alpha;
      const double ratio = reflected_energy_ratio(f, 8);
      std::printf("  [%s, %s] reflected energy %.3e\n", scheme_name(sc), what, ratio);
      EXPECT_LE(ratio, 3e-4) << scheme_name(sc) << " " << what;
    }
  // The same S column without the shift grows.
  ColumnSpec c = pml_long_column(true, 0, End::Silent);
  c.cells = 60;
  c.scheme = Scheme::USF;
  bool grew = false;
  try {
    const LongRun r = long_run(c);
    grew = r.emax > 10;
  } catch (const std::runtime_error& e) {
    grew = std::string(e.what()).find("unstable") != std::string::npos;
  }
  EXPECT_TRUE(grew) << "USF, S, 1 ppc, alpha 0";
}

// Long runs of the Kelvin-Voigt end and of the damping band (LK end behind it): after the pulse,
// 10^5 steps at CFL 0.5 under each scheme, P and S. The energy left in the column (kinetic plus
// elastic, the springs' included), as a fraction of what it held when the pulse had left, is
// sampled every 500 steps from 10^4 steps on. Bounded: its largest value within 10 % of the
// value at 10^4 steps, and the last no larger than that (a layer that feeds energy back, as the
// particle PML's FLIP memory did, grows by orders of magnitude within a few 10^4 steps).
// Measured: KV 8-16 % left at 10^4 steps, decaying to 1e-7-2e-4 (the springs ring out through
// the dashpots); band, USL: 2e-15 (P) and 3e-8 (S) left; MUSL and USF: 5e-3 left at 10^4 steps,
// decaying to 3e-4-8e-4, except USF P, which swaps energy up by 6 % of it once (5.03e-3 to
// 5.34e-3) before it decays: the residue is a cell-scale mode at 1 ppc that the particles
// carry and the grid barely sees, which the band damps only slowly; the scheme's own energy
// error at that level, not the layer's.
static void expect_bounded(const ColumnSpec& c) {
  const LongRun r = long_run(c);
  const char* what = c.shear ? "S" : "P";
  std::printf("  [%s %s] energy left at 1e4 steps %.3e, largest later %.3e, at 1.1e5 %.3e\n",
              scheme_name(c.scheme), what, r.e1, r.emax, r.elast);
  EXPECT_LE(r.emax, 1.1 * r.e1 + 1e-14) << scheme_name(c.scheme) << " " << what;
  EXPECT_LE(r.elast, r.e1 + 1e-14) << scheme_name(c.scheme) << " " << what;
}

TEST(KelvinVoigt, NoGrowthOver100000Steps) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USL, Scheme::USF})
    for (const bool shear : {false, true}) {
      ColumnSpec c;
      c.cells = 60;
      c.end = End::KelvinVoigt;
      c.delta = 4 * c.h;
      c.scheme = sc;
      c.shear = shear;
      c.cfl = 0.5;
      expect_bounded(c);
    }
}

TEST(DampingLayer, NoGrowthOver100000Steps) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USL, Scheme::USF})
    for (const bool shear : {false, true}) {
      ColumnSpec c;
      c.cells = 60;
      c.end = End::Silent;
      c.damp_cells = 10;
      c.damp_r0 = 0.5;
      c.scheme = sc;
      c.shear = shear;
      c.cfl = 0.5;
      expect_bounded(c);
    }
}

// ---- Health check: a NaN or Inf stops the run within the step it reaches the grid ----
TEST(HealthCheck, NonFiniteStopsWithinOneStep) {
  for (int what = 0; what < 3; ++what) {
    ColumnSpec c;
    c.cells = 40;
    c.fn = sin2_pulse(16 * c.h / 5918.5, 8 * c.h / 5918.5);
    auto s = make_column(c);
    for (int i = 0; i < 20; ++i) s->step();
    const std::size_t k = s->p.size() / 2;
    if (what == 0) s->p.sxx[k] = std::nan("");
    if (what == 1) s->p.vx[k] = std::numeric_limits<double>::infinity();
    if (what == 2) s->p.mass[k] = std::nan("");
    const long before = s->steps;
    try {
      s->step();
      FAIL() << "no error (case " << what << ")";
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("non-finite velocity at step " + std::to_string(before + 1)),
                std::string::npos) << m;
      EXPECT_NE(m.find("at grid node ("), std::string::npos) << m;
    }
  }
}

// ---- Health checks: a blow-up, a runaway node and a collapsed particle stop the run in the step
// they happen, with a message naming the step, the cause and the particle ----
TEST(HealthCheck, BlowUpStopsWithinOneStep) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USL, Scheme::USF}) {
    ColumnSpec c;
    c.cells = 40;
    c.scheme = sc;
    c.fn = sin2_pulse(16 * c.h / 5918.5, 8 * c.h / 5918.5);
    auto s = make_column(c);
    for (int i = 0; i < 20; ++i) s->step();
    // An energy runaway: one particle 200 times faster than the pulse's particle velocity (its
    // kinetic energy alone is ~20 times what the load has put in), still far below a cell a step.
    const std::size_t k = s->p.size() / 2;
    double vmax = 0;
    for (double v : s->p.vx) vmax = std::max(vmax, std::abs(v));
    s->p.vx[k] = 200 * vmax;
    const long before = s->steps;
    try {
      s->step();
      FAIL() << "no error (" << scheme_name(sc) << ")";
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("kinetic energy"), std::string::npos) << m;
      EXPECT_NE(m.find("at step " + std::to_string(before + 1)), std::string::npos) << m;
    }
  }
}

TEST(HealthCheck, RunawayNodeAndCollapsedParticleStop) {
  ColumnSpec c;
  c.cells = 40;
  c.fn = sin2_pulse(16 * c.h / 5918.5, 8 * c.h / 5918.5);
  {
    auto s = make_column(c);
    for (int i = 0; i < 5; ++i) s->step();
    s->opt.energy_bound = 0;  // the speed check alone
    s->p.vx[s->p.size() / 2] = 2 * s->grid.h / s->dt * s->p.size();
    try {
      s->step();
      FAIL() << "no error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("a particle moves more than a cell per step at step 6"),
                std::string::npos) << e.what();
    }
  }
  {
    auto s = make_column(c);
    for (int i = 0; i < 5; ++i) s->step();
    const std::size_t k = s->p.size() / 3;
    s->p.vol[k] = -s->p.vol[k];  // an inverted particle
    try {
      s->step();
      FAIL() << "no error";
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("particle volume inverted at step 6"), std::string::npos) << m;
      EXPECT_NE(m.find("particle " + std::to_string(s->p.id[k]) + " of body 0"), std::string::npos)
          << m;
      EXPECT_NE(m.find("J = V/V0 = -"), std::string::npos) << m;
    }
  }
}

// The stability limit as particles stretch: with constant moduli and the current density
// rho0 / J the wave speed is c_d sqrt(J), so dt = cfl h / c_d stays stable while J <= 1 / cfl^2
// (docs/physics.md, section 1); the check allows 10 % over it. A particle stretched to
// 1.01 x 1.1 / cfl^2 stops the next step naming it, its J and the limit; one at 0.99 x 1.1 /
// cfl^2 passes.
TEST(HealthCheck, StretchedParticleStopsAtTheStabilityLimit) {
  ColumnSpec c;
  c.cells = 40;
  c.fn = sin2_pulse(16 * c.h / 5918.5, 8 * c.h / 5918.5);
  const double j_limit = 1.1 / (c.cfl * c.cfl);
  for (const double factor : {0.99, 1.01}) {
    auto s = make_column(c);
    for (int i = 0; i < 5; ++i) s->step();
    const std::size_t k = s->p.size() / 2;
    const double v0 = s->p.mass[k] / s->materials[s->p.group[k]].rho;
    s->p.vol[k] = factor * j_limit * v0;
    if (factor < 1) {
      EXPECT_NO_THROW(s->step()) << "J = " << factor << " / cfl^2";
      continue;
    }
    try {
      s->step();
      FAIL() << "no error at J = " << factor << " / cfl^2";
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("time step above the stability limit at step 6"), std::string::npos) << m;
      EXPECT_NE(m.find("particle " + std::to_string(s->p.id[k]) + " of body 0"), std::string::npos)
          << m;
      char j[64];
      std::snprintf(j, sizeof j, "J = V/V0 = %g,", factor * j_limit);
      EXPECT_NE(m.find(j), std::string::npos) << m;
    }
  }
}


// The snapshot's "layer" field: Solver::layer_flags marks exactly the particles of each boundary
// condition, by their current place after re-sorting (bits: 1 silent, 2 traction, 4 springs,
// 8 damping layer, 16 perfectly matched layer).
TEST(Column, LayerFlagsMarkTheLayers) {
  for (const End end : {End::Silent, End::KelvinVoigt}) {
    ColumnSpec c;
    c.cells = 40;
    c.end = end;
    c.delta = 1e-2;
    c.damp_cells = 3;
    c.scheme = Scheme::USL;
    c.pml_cells = 5;
    c.fn = sin2_pulse(1e-6, 0.5e-6);
    auto s = make_column(c);
    for (int n = 0; n < 20; ++n) s->step();
    const auto f = s->layer_flags();
    ASSERT_EQ(f.size(), s->p.size());
    auto count = [&](std::uint8_t bit) {
      return static_cast<std::size_t>(std::count_if(f.begin(), f.end(), [&](std::uint8_t v) { return (v & bit) != 0; }));
    };
    EXPECT_EQ(count(1), s->silents[0].layer.ids.size());
    EXPECT_EQ(count(2), s->tractions[0].layer.ids.size());
    EXPECT_EQ(count(4), end == End::KelvinVoigt ? s->silents[0].layer.ids.size() : 0u);
    EXPECT_EQ(count(8), s->dampers[0].layer.ids.size());
    EXPECT_EQ(count(16), s->pml.layer.ids.size());
    EXPECT_GT(count(16), 0u);
    for (std::size_t q = 0; q < s->pml.layer.idx.size(); ++q)
      EXPECT_EQ(s->pml.layer.ids[q], s->p.id[s->pml.layer.idx[q]]);
    for (std::size_t k = 0; k < f.size(); ++k)  // the traction acts on the left end only
      if (f[k] & 2) {
        EXPECT_LT(s->p.x[k], 2 * c.h) << k;
      }
  }
}

// The silent end of a 100-cell column under 16-cell pulses: the reflected amplitude, printed.
double pulse16_reflection(Scheme sc, int ppc, bool shear, int mass_correction = 0,
                          bool symmetric = false) {
  ColumnSpec c;
  c.cells = 100;
  c.end = End::Silent;
  c.scheme = sc;
  c.ppc_side = ppc;
  c.shear = shear;
  c.mass_correction = mass_correction;
  c.symmetric = symmetric;
  const double amp = std::sqrt(reflected_energy_ratio(c, 16, 0.015));
  std::printf("  [%s %d ppc %s%s] reflected amplitude %.5f\n", scheme_name(sc), ppc * ppc,
              shear ? "S" : "P",
              mass_correction ? (symmetric ? ", mass correction (symmetric)" : ", mass correction")
                              : "",
              amp);
  return amp;
}

// LK at normal incidence on 16-cell (FWHM) pulses, every scheme, 1, 4 and 9 ppc: the reflected
// amplitude, the square root of the reflected energy fraction (97-99 % of that energy is in
// front of the last fifth of the column, i.e. it travels back: a reflection, not a residue at
// the end). Measured, P / S:
//   USL   0.19 / 0.11 % (1 ppc), 0.10 / 0.17 % (4), 0.11 / 0.17 % (9)
//   MUSL  0.74 / 0.58 % (1 ppc), 0.26 / 0.26 % (4), 0.24 / 0.25 % (9); USF within 1 % of MUSL.
// USL meets 0.3 % everywhere, MUSL and USF from 4 ppc on; at 1 ppc they strain each particle
// with its two neighbours' velocities, whose odd-even pattern the end excites (docs/physics.md
// section 4). With the trapezoidal mean of the lumped mass at the dashpot nodes instead of the
// particles' own (Solver::consistent_dashpots), MUSL and USF gave 1.12 / 0.75 %, 0.39 / 0.33 %
// and 0.35 / 0.31 %. The 1-ppc MUSL energy account closes to 1.1 % here (1 % on 8-cell pulses).
TEST(SilentLayer, NormalIncidence16CellPulsesEveryScheme) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USL, Scheme::USF})
    for (const int ppc : {1, 2, 3})
      for (const bool shear : {false, true}) {
        const double amp = pulse16_reflection(sc, ppc, shear);
        const double bound = sc == Scheme::USL || ppc > 1 ? 3e-3 : 8e-3;
        EXPECT_LE(amp, bound) << scheme_name(sc) << " " << ppc * ppc << " ppc " << (shear ? "S" : "P");
      }
}

// The consistent-mass correction (one term; docs/physics.md section 1.1) at 4 and 9 ppc under
// MUSL and USF: the silent end's reflection of 16-cell pulses falls from 0.24-0.26 % (the table
// of NormalIncidence16CellPulsesEveryScheme) to 0.11-0.14 % (P and S). Bound 0.16 %, below
// every uncorrected figure.
TEST(SilentLayer, MassCorrectionHalvesTheReflectionFrom4Ppc) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USF})
    for (const int ppc : {2, 3})
      for (const bool shear : {false, true}) {
        const double amp = pulse16_reflection(sc, ppc, shear, 1);
        EXPECT_LE(amp, 1.6e-3) << scheme_name(sc) << " " << ppc * ppc << " ppc " << (shear ? "S" : "P");
      }
}

// The correction's symmetric form (scheme.mass_correction_form "symmetric"; docs/physics.md
// section 1.1), one and two terms, 4 and 9 ppc, MUSL and USF. Its dashpots' solve takes the
// corrected start velocity, the one the stresses and the boundary work take. Measured, P / S:
// one term 0.103 / 0.127 % (4 ppc), 0.098 / 0.122 % (9); two terms 0.083 / 0.110 % and 0.083 /
// 0.110 %; USF within 1 % of MUSL (the increment form: 0.11 / 0.14 % with one term, 0.088 / 0.113
// % with two). With the lumped start velocity in that solve the end reflected 0.85-1.1 %. Bound
// 0.14 %.
TEST(SilentLayer, SymmetricMassCorrectionReflectsLessThanWithout) {
  for (const int terms : {1, 2})
    for (const Scheme sc : {Scheme::MUSL, Scheme::USF})
      for (const int ppc : {2, 3})
        for (const bool shear : {false, true}) {
          const double amp = pulse16_reflection(sc, ppc, shear, terms, true);
          EXPECT_LE(amp, 1.4e-3) << scheme_name(sc) << " " << terms << " terms " << ppc * ppc
                                 << " ppc " << (shear ? "S" : "P");
        }
}

// The absorbed work with the consistent-mass correction and the wide shapes (docs/physics.md
// section 1.1). A compressive pulse moves the end outward, and a GIMP or B-spline particle then
// puts a sliver of its mass on the node column beyond it, which the end's anchors also weigh: a
// light dashpot node that keeps the trapezoidal update. Its force acted with the mean of v and
// the lumped v+; booked with the corrected v+ (the sliver's increment, multiplied by the series)
// the account missed 13 % of the work with GIMP and 0.78 % with B-splines. Measured, 16-cell P
// pulse, 4 ppc, two terms, the pulse absorbed: |imbalance| / work 4.7-7.1e-6 (GIMP) and
// 1.5-1.7e-4 (B-spline), MUSL and USF. Bound 1e-3.
TEST(SilentLayer, MassCorrectionBooksTheWorkOfLightEndNodes) {
  for (const ShapeKind shape : {ShapeKind::UGimp, ShapeKind::BSpline2})
    for (const Scheme sc : {Scheme::MUSL, Scheme::USF}) {
      ColumnSpec c;
      c.cells = 40;
      c.ppc_side = 2;
      c.shape = shape;
      c.scheme = sc;
      c.mass_correction = 2;
      const double cd = tungsten().cd;
      const double dur = 32 * c.h / cd;
      c.fn = sin2_pulse(dur, 0.5 * dur);
      auto s = make_column(c);
      int light = 0;  // steps with a dashpot node beyond the end that holds mass
      const long beyond = c.cells + 3;  // the node column past the end's (x0 = -2 h)
      while (s->t < dur + 1.5 * c.cells * c.h / cd) {
        s->step();
        const double m = s->grid.m[s->grid.nnx * 1 + beyond];
        light += m > 0 && (s->grid.fix[s->grid.nnx * 1 + beyond] & Grid::kDashpotNode);
      }
      s->update_energies();
      const double rel = std::abs(s->energy.imbalance()) / s->energy.external_work;
      std::printf("%s, %s: |imbalance| / work %.2e, %d steps with a light node beyond the end\n",
                  shape == ShapeKind::UGimp ? "GIMP" : "B-spline", scheme_name(sc), rel, light);
      EXPECT_GT(light, 100);  // the case the booking must handle occurs
      EXPECT_GT(s->energy.absorbed, 0.95 * s->energy.external_work);
      EXPECT_LT(rel, 1e-3) << scheme_name(sc);
    }
}

// A load's share on a node that holds a sliver of mass (docs/physics.md section 8.5). A GIMP
// particle's boundary point reaches the node column beyond the loaded end, which the end's
// slight outward motion fills with a sliver of the particles' domains; a whole share there
// accelerated that node without bound and put energy into particle velocities the grid does
// not see. The S column at 4 ppc, 8-cell pulse, after the pulse has left through the silent
// end (measured): with two terms of the mass correction kinetic / elastic energy 1.28 and the
// account open by 1.9e-5 of the work (whole shares: 11.2 and 2.0e-3); without the correction
// 0.97 (1.38). Bounds 1.5, 2e-4 and 1.2.
TEST(Shapes, LoadShareOnASliverNodeFollowsItsMass) {
  for (const int mc : {0, 2}) {
    ColumnSpec c;
    c.cells = 40;
    c.height = 8;
    c.shear = true;
    c.ppc_side = 2;
    c.shape = ShapeKind::UGimp;
    c.mass_correction = mc;
    const double cs = tungsten().cs;
    const double dur = 16 * c.h / cs;
    c.fn = sin2_pulse(dur, 0.5 * dur);
    auto s = make_column(c);
    while (s->t < dur + 1.5 * c.cells * c.h / cs) s->step();
    s->update_energies();
    const double ratio = s->energy.kinetic / s->energy.elastic;
    const double imb = std::abs(s->energy.imbalance()) / s->energy.external_work;
    std::printf("%d terms: kinetic / elastic %.3f, |imbalance| / work %.2e\n", mc, ratio, imb);
    EXPECT_GT(s->energy.absorbed, 0.99 * s->energy.external_work);
    EXPECT_LT(ratio, mc ? 1.5 : 1.2) << mc << " terms";
    if (mc) {
      EXPECT_LT(imb, 2e-4);
    }
  }
}

// The consistent-mass correction under USL (docs/physics.md section 1.1), which strains with the
// lumped increment while the particles take the corrected one: one term takes the silent end's
// reflection of 16-cell pulses to 0.14 / 0.082 % at 1 ppc (P / S; 0.19 / 0.11 % without), 0.092 /
// 0.118 % at 4 ppc (0.10 / 0.17 %) and 0.099 / 0.121 % at 9 ppc (0.11 / 0.17 %). Bound 0.15 %.
TEST(SilentLayer, MassCorrectionUnderUsl) {
  for (const int ppc : {1, 2, 3})
    for (const bool shear : {false, true}) {
      const double amp = pulse16_reflection(Scheme::USL, ppc, shear, 1);
      EXPECT_LE(amp, 1.5e-3) << ppc * ppc << " ppc " << (shear ? "S" : "P");
    }
}

// Energy of the particles' odd-even (sawtooth) velocity pattern along the column's first row of
// particles (1 ppc), as a fraction of the work put in: twice the kinetic energy of half the
// second difference v_p - (v_{p-1} + v_{p+1}) / 2 (a smooth 16-cell pulse puts ~3e-5 there).
double sawtooth_energy_fraction(const Solver& s, int cells) {
  std::vector<long> of(s.p.size());
  for (std::size_t k = 0; k < s.p.size(); ++k) of[s.p.id[k]] = static_cast<long>(k);
  double e = 0;
  for (int i = 1; i + 1 < cells; ++i) {
    const long k = of[i], km = of[i - 1], kp = of[i + 1];
    const double d = 0.5 * (s.p.vx[k] - 0.5 * (s.p.vx[km] + s.p.vx[kp]));
    e += s.p.mass[k] * d * d;
  }
  return e / (s.energy.external_work / 4);  // one row of the four
}

// Why MUSL and USF at 1 ppc stay above 0.3 % at normal incidence (docs/physics.md section 4).
// At 1 ppc both strain a particle with the difference of its neighbours' velocities over two
// cells, so the odd-even velocity pattern is nearly free of stress, and any end excites it.
// Measured, P, 16-cell pulses, small amplitude (1e4 Pa, the pulse moves the end 1e-10 h):
//   * on a grid line the silent end reflects 0.57 % (16 cells) and 0.14 % (32): second order
//     (with the lumped trapezoidal mean at the dashpot nodes 1.03 and 0.45 %, first order);
//     at the usual 100 MPa the 32-cell pulse moves the end by ~0.8 % of a cell, which is
//     enough for 1.28 % (why the reflection seemed to grow with the pulse width);
//   * a free end returns 3.3e-3 of the input energy in the odd-even pattern under MUSL (amplitude
//     5.7 %), 2.8e-5 under USL (the smooth pulse's own share); the silent end on a grid line 6e-6;
//   * with the end 0.03 h off the grid line the silent end reflects 7.1 % under MUSL, 0.27 %
//     under USL: the pattern's frequency grows with the offset and meets the pulse's there.
// Bounds: the ratios and levels above with a margin each.
// An end on a node line carries its dashpots on its own node column only. Its anchors' bilinear
// weights put nothing on the column beyond (void; its shares go to the end's nodes) nor, while
// the end is at rest or moves out, on the column inside: nodes with a zero block take the plain
// update and are no dashpot nodes (they were half the edge's, each updated by the block's
// formula, recorded and booked every step). Checked every step while a compressive pulse
// reaches the end and moves it outward, under MUSL (the dashpot solve) and USL.
TEST(SilentLayer, EndOnANodeLineCarriesDashpotsOnItsNodesOnly) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USL}) {
    ColumnSpec c;
    c.cells = 30;
    c.scheme = sc;
    c.fn = sin2_pulse(1e-6, 0.5e-6);
    auto s = make_column(c);
    const long end = c.cells + 2, nnx = s->grid.nnx;  // the end's node column (x0 = -2 h)
    long steps_moved = 0;
    for (int n = 0; n < 400; ++n) {
      s->step();
      long on_end = 0, elsewhere = 0;
      for (long i = 0; i < static_cast<long>(s->grid.nodes()); ++i) {
        if (!(s->grid.fix[i] & Grid::kDashpotNode)) continue;
        if (i % nnx == end && s->grid.cxx(i) > 0) ++on_end;
        else ++elsewhere;
      }
      ASSERT_EQ(on_end, c.height + 1) << "step " << n;
      ASSERT_EQ(elsewhere, 0) << "step " << n;
      // The end's particles have moved out (by more than 1e-6 of a cell) at least once.
      const auto& L = s->silents[0].layer;
      if (s->p.x[L.idx[0]] - s->p.x0[L.idx[0]] > 1e-6 * c.h) ++steps_moved;
    }
    EXPECT_GT(steps_moved, 100);
  }
}

TEST(SilentLayer, MuslOnePpcEndsExciteTheOddEvenMode) {
  auto refl = [](Scheme sc, int w, double amplitude, double offset) {
    ColumnSpec c;
    c.cells = 100 * w / 16;
    c.scheme = sc;
    c.amplitude = amplitude;
    c.offset = offset * c.h;
    return std::sqrt(reflected_energy_ratio(c, w, 0.5));
  };
  const double a16 = refl(Scheme::MUSL, 16, 1e4, 0), a32 = refl(Scheme::MUSL, 32, 1e4, 0);
  const double big32 = refl(Scheme::MUSL, 32, 100e6, 0);
  std::printf("  [MUSL 1 ppc, 1e4 Pa] reflected amplitude %.4f (16 cells), %.4f (32); 100 MPa "
              "%.4f (32)\n", a16, a32, big32);
  EXPECT_LE(a16, 0.007);
  EXPECT_GE(a32 / a16, 0.15);
  EXPECT_LE(a32 / a16, 0.35);
  EXPECT_GE(big32, 2.5 * a32);
  const double off_musl = refl(Scheme::MUSL, 16, 1e4, 0.03), off_usl = refl(Scheme::USL, 16, 1e4, 0.03);
  std::printf("  [end 0.03 h off a grid line] MUSL %.4f, USL %.4f\n", off_musl, off_usl);
  EXPECT_GE(off_musl, 0.04);
  EXPECT_LE(off_usl, 0.005);
  const Material m = tungsten();
  const double dur = 2.0 * 16 * 1e-3 / m.cd;
  double saw[3];
  int n = 0;
  for (const auto& [sc, end] : {std::pair{Scheme::MUSL, End::Free}, std::pair{Scheme::USL, End::Free},
                                std::pair{Scheme::MUSL, End::Silent}}) {
    ColumnSpec c;
    c.scheme = sc;
    c.end = end;
    c.amplitude = 1e4;
    c.fn = sin2_pulse(dur, 0.5 * dur);
    auto s = make_column(c);
    while (s->t < dur + 1.5 * c.cells * c.h / m.cd) s->step();
    saw[n++] = sawtooth_energy_fraction(*s, c.cells);
  }
  std::printf("  [odd-even energy after the end] MUSL free %.2e, USL free %.2e, MUSL silent %.2e\n",
              saw[0], saw[1], saw[2]);
  EXPECT_GE(saw[0], 1.5e-3);
  EXPECT_LE(saw[1], 1e-4);
  EXPECT_LE(saw[2], 1e-4);
}

// USF takes the power of the loads with the velocity the particles carry back (their momenta
// re-mapped, as MUSL does; docs/physics.md section 4). With v+, a load on a light node -- the
// boundary-anchored traction or dashpot of an edge off the grid lines -- was booked 7-15 % off:
// a free end 0.25 h off kept 0.858 of the work booked, a silent end 0.75 h off absorbed 0.876.
// Measured now, 1 ppc, 16-cell P pulse, 1e4 Pa: the free end keeps 1.0096 (USL 0.985), the
// silent end's account closes to 1e-4. Bounds: 2 % and 0.5 %. A 10-cell damping band with a
// stiffness part (beta0 = h / c_d) in front of a fixed end, on a grid line and 0.25 h off: its
// force and viscous stress take the gradients of the step's start, so it books with the
// re-mapped velocity too; measured 2e-5 and 4e-5 (with v+: 0.8 % and 15 %). Bound 1e-3.
// A USF column with 1 ppc, the end `shift` cells off a grid line, under a 16-cell P pulse of
// 1e4 Pa, run for `crossings` column lengths after it: its energies.
static Energies usf_column_after_pulse(ColumnSpec c, double shift, double crossings) {
  const Material m = tungsten();
  c.scheme = Scheme::USF;
  c.amplitude = 1e4;
  c.offset = shift * c.h;
  const double dur = 2.0 * 16 * c.h / m.cd;
  c.fn = sin2_pulse(dur, 0.5 * dur);
  auto s = make_column(c);
  while (s->t < dur + crossings * c.cells * c.h / m.cd) s->step();
  s->update_energies();
  return s->energy;
}

TEST(SilentLayer, UsfEnergyAccountClosesOffTheGridLines) {
  for (const End end : {End::Free, End::Silent})
    for (const double shift : {0.0, 0.25, 0.75}) {
      ColumnSpec c;
      c.end = end;
      const Energies e = usf_column_after_pulse(c, shift, 1.8);
      const double imb = e.imbalance() / e.external_work;
      std::printf("  [USF, %s end %.2f h off a grid line] imbalance %.4f of the work\n",
                  end == End::Free ? "free" : "silent", shift, imb);
      EXPECT_LE(std::abs(imb), end == End::Free ? 0.02 : 0.005) << shift;
    }
  for (const double shift : {0.0, 0.25}) {
    ColumnSpec c;
    c.end = End::Fixed;
    c.damp_cells = 10;
    c.damp_beta = c.h / tungsten().cd;
    const Energies e = usf_column_after_pulse(c, shift, 2.5);
    const double imb = e.imbalance() / e.external_work;
    std::printf("  [USF, damping band with a stiffness part, %.2f h off] imbalance %.2e of the "
                "work, absorbed %.4f\n", shift, imb, e.absorbed / e.external_work);
    EXPECT_LE(std::abs(imb), 1e-3) << "band " << shift;
    EXPECT_GE(e.absorbed, 0.4 * e.external_work) << "the band took part";
  }
}

// A column whose end lies `shift` cells off a grid line (1 ppc, P), with the scheme and edge
// velocity of `c`: the reflected amplitude of a 16- and a 32-cell pulse (columns of 100 and 200
// cells), which must fall at first order in kh: at most 2 % at 16 cells, the 32-cell one 0.4-0.6
// of it. `imbalance` bounds the energy account (reflected_energy_ratio).
void expect_first_order_off_grid(ColumnSpec c, double shift, const char* what,
                                 double imbalance = 0.02) {
  double amp[2];
  c.offset = shift * c.h;
  for (int k = 0; k < 2; ++k) {
    c.cells = 100 << k;
    amp[k] = std::sqrt(reflected_energy_ratio(c, 16 << k, imbalance));
  }
  std::printf("  [%s, edge %.2f h off a grid line] reflected amplitude %.4f (16 cells), %.4f (32)\n",
              what, shift, amp[0], amp[1]);
  EXPECT_LE(amp[0], 0.02) << what << " " << shift;
  EXPECT_GE(amp[1] / amp[0], 0.4) << what << " " << shift;
  EXPECT_LE(amp[1] / amp[0], 0.6) << what << " " << shift;
}

// A silent edge off the grid lines (the column shifted by 0.25 h and 0.75 h, so the last cell
// is partly filled), USL, 1 ppc, P: the end node then carries more of the last particle's mass
// than a matched half cell, and the edge reflects at first order in kh. Measured 1.42 / 0.72 %
// (0.25 h) and 1.68 / 0.84 % (0.75 h) for 16- / 32-cell pulses, against 0.19 / 0.08 % on a grid
// line (docs/physics.md section 4). Bounds: at most 2 % at 16 cells, and the 32-cell pulse's
// reflection 0.4-0.6 of the 16-cell one's.
TEST(SilentLayer, EdgeOffTheGridLinesReflectsAtFirstOrderUsl) {
  ColumnSpec c;
  c.scheme = Scheme::USL;
  for (const double shift : {0.25, 0.75}) expect_first_order_off_grid(c, shift, "USL");
}

// MUSL with the updated velocity at the dashpots' nodes (`edge_velocity` "updated";
// docs/physics.md section 4), P pulses. An edge off the grid lines reflects as under USL, at
// first order in kh: measured 1.42 / 0.72 % (0.25 h) and 1.71 / 0.86 % (0.75 h) for 16- /
// 32-cell pulses; the re-mapped velocity gives 2.33 % at 0.75 h (7.6 % with the lumped
// trapezoidal mean at the dashpot nodes). On a grid line at 4 ppc: 0.13 % (P) and 0.18 % (S),
// against 0.26 / 0.26 % re-mapped.
TEST(SilentLayer, UpdatedEdgeVelocityMusl) {
  ColumnSpec u;
  u.updated_edge = true;
  for (const double shift : {0.25, 0.75}) expect_first_order_off_grid(u, shift, "MUSL updated");
  {  // the re-mapped velocity 0.75 h off
    ColumnSpec c;
    c.offset = 0.75 * c.h;
    const double remapped = std::sqrt(reflected_energy_ratio(c, 16, 0.02));
    u.offset = c.offset;
    const double updated = std::sqrt(reflected_energy_ratio(u, 16, 0.02));
    std::printf("  [MUSL, edge 0.75 h off] reflected amplitude %.4f re-mapped, %.4f updated\n",
                remapped, updated);
    EXPECT_LE(remapped, 0.03) << "the re-mapped velocity with the particles' mean";
    EXPECT_LE(updated, 0.8 * remapped) << "the updated velocity reflects less";
  }
  for (const bool shear : {false, true}) {
    ColumnSpec c;
    c.ppc_side = 2;
    c.shear = shear;
    c.updated_edge = true;
    const double amp = std::sqrt(reflected_energy_ratio(c, 16, 0.02));
    std::printf("  [MUSL updated, 4 ppc, on a grid line, %s] reflected amplitude %.4f\n",
                shear ? "S" : "P", amp);
    EXPECT_LE(amp, 3e-3) << (shear ? "S" : "P");
  }
}

// USF with the updated velocity at the dashpots' nodes (`edge_velocity` "updated"): USF strains
// the particles with the start-of-step nodal velocity, so at those nodes it takes the last step's
// v+ (docs/physics.md section 4). On a grid line at 4 and 9 ppc, measured 0.13 % (P) and 0.18 %
// (S) against 0.26 / 0.26 % (4 ppc) and 0.24 / 0.25 % (9 ppc) with the default; off the grid
// line at 1 ppc, first order as under MUSL. Bounds: 0.25 % on the grid line, below 0.6 of the
// default for P; the 1-ppc edge as the MUSL test's.
TEST(SilentLayer, UpdatedEdgeVelocityUsf) {
  for (const int ppc : {2, 3})
    for (const bool shear : {false, true}) {
      ColumnSpec c;
      c.scheme = Scheme::USF;
      c.ppc_side = ppc;
      c.shear = shear;
      c.updated_edge = true;
      const double amp = std::sqrt(reflected_energy_ratio(c, 16, 0.02));
      c.updated_edge = false;
      const double dflt = std::sqrt(reflected_energy_ratio(c, 16, 0.02));
      std::printf("  [USF, %d ppc, on a grid line, %s] reflected amplitude %.4f updated, %.4f "
                  "default\n", ppc * ppc, shear ? "S" : "P", amp, dflt);
      EXPECT_LE(amp, 2.5e-3) << ppc * ppc << " ppc " << (shear ? "S" : "P");
      if (!shear) {
        EXPECT_LE(amp, 0.6 * dflt) << ppc * ppc << " ppc";
      }
    }
  ColumnSpec u;
  u.scheme = Scheme::USF;
  u.updated_edge = true;
  for (const double shift : {0.25, 0.75}) expect_first_order_off_grid(u, shift, "USF updated");
}

// A column of `cells` cells at 1 ppc with the delayed closure at its silent end.
static ColumnSpec delayed_column(Scheme sc, double cfl, bool shear, int cells) {
  ColumnSpec c;
  c.cells = cells;
  c.end = End::Silent;
  c.scheme = sc;
  c.shear = shear;
  c.cfl = cfl;
  c.delayed_edge = true;
  return c;
}

// The delayed closure at 1 ppc (docs/physics.md section 4, "edge_velocity": "delayed"): the edge
// node's dashpot acts on its normal component with its start velocity of h/c_d - dt/2 earlier,
// on the node weighed as a whole one, and its normal strain velocity is the mean of the
// re-mapped one and the force of as long ago over the dashpot's coefficient; the tangential
// component keeps LK's dashpot on the particles' mean, solved with the other dashpot nodes
// (delayed, it made a two-dimensional body unstable: SilentStability.DelayedClosureSquareDecays).
// 16-cell pulses on a grid line, MUSL and USF, P and S. Measured at 1e4 Pa (the end moves
// 1e-10 h): P 0.070-0.079 % at CFL 0.3 and 0.5 (the default 1.03-1.54 %), S 0.57-0.58 %, the
// default's (0.75-0.98 % with the lumped trapezoidal mean there); at 100 MPa the P pulse moves
// the end by 0.4 % of a cell off its grid line, and P returns 0.54 % (default 1.12 %). Bounds:
// P 0.1 % at small amplitude and 0.6 % at 100 MPa, S 0.65 %.
TEST(SilentLayer, DelayedClosureOnePpc) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USF})
    for (const double cfl : {0.3, 0.5})
      for (const double amplitude : {1e4, 100e6})
        for (const bool shear : {false, true}) {
          if (amplitude > 1e4 && (cfl != 0.3 || sc != Scheme::MUSL)) continue;
          ColumnSpec c = delayed_column(sc, cfl, shear, 100);
          c.amplitude = amplitude;
          const double amp = std::sqrt(reflected_energy_ratio(c, 16, 0.01));
          std::printf("  [%s CFL %.1f %.0e Pa %s] reflected amplitude %.5f\n", scheme_name(sc), cfl,
                      amplitude, shear ? "S" : "P", amp);
          const double bound = shear ? 6.5e-3 : amplitude > 1e4 ? 6e-3 : 1e-3;
          EXPECT_LE(amp, bound) << scheme_name(sc) << " CFL " << cfl << " " << amplitude << " Pa "
                                << (shear ? "S" : "P");
        }
}

// The delayed closure over 10^5 steps after an 8-cell pulse has left a 60-cell column (MUSL and
// USF, P and S, CFL 0.3 and 0.9): the energy left (the column's drift and what the end still
// rings with) sampled every 500 steps from 10^4 steps on. Measured: it decays (to 0.03-0.35 of
// its value at 10^4 steps), except MUSL P at CFL 0.9, which swaps up to 2.4 times its value at
// 10^4 steps once before it decays to 0.03 of it. With the tangential strain velocity closed
// as the normal one the run grew within 2 000 steps, and with neither within 4-9 * 10^4.
// The energy account: within 1.5e-4 of the work (2.0e-3 under MUSL at CFL 0.9 while the
// closure's strain-velocity work took the step's own force and MUSL's power its changed
// velocity; docs/physics.md section 4).
// Bounds: the largest value within 3 times that at 10^4 steps, the last below it, the account
// within 1e-3.
TEST(SilentStability, DelayedClosureNoGrowthOver100000Steps) {
  for (const Scheme sc : {Scheme::MUSL, Scheme::USF})
    for (const double cfl : {0.3, 0.9})
      for (const bool shear : {false, true}) {
        const LongRun r = long_run(delayed_column(sc, cfl, shear, 60));
        std::printf("  [%s CFL %.1f %s] at 1e4 steps %.3e, largest later %.3e, at 1.1e5 %.3e; "
                    "imbalance %.1e\n", scheme_name(sc), cfl, shear ? "S" : "P", r.e1, r.emax,
                    r.elast, r.imbalance);
        const std::string what = std::string(scheme_name(sc)) + " CFL " + std::to_string(cfl) +
                                 (shear ? " S" : " P");
        EXPECT_LE(r.emax, 3 * r.e1) << what;
        EXPECT_LE(r.elast, r.e1) << what;
        EXPECT_LE(std::abs(r.imbalance), 1e-3) << what;
      }
}
