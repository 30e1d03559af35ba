// The uGIMP and quadratic B-spline shapes (docs/physics.md section 8): partition of unity, linear
// reproduction with its gradient, non-negative weights, the edge treatment, the closed forms of
// the 1D weights; and the transfer identities of the kernels for every shape (mass and momentum
// to the grid, internal forces summing to zero, tractions summing to t L).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "common.hpp"
#include "silentmpm/shape.hpp"

using namespace smpm;
using namespace smpm::testing;

namespace {

// Checks the identities of shape S at n random points of a 7 x 5 grid, edge cells included
// (a third of the points within half a cell of an edge), with sized shapes at half-width lp.
template <class S>
void check_identities(double lp_cells) {
  Grid g;
  g.init(-1.0, 2.0, 0.25, 7, 5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 3000; ++trial) {
    double gx = 7 * u(rng), gy = 5 * u(rng);
    if (trial % 3 == 1) gx = trial % 2 ? 0.5 * u(rng) : 7 - 0.5 * u(rng);
    if (trial % 3 == 2) gy = trial % 2 ? 0.5 * u(rng) : 5 - 0.5 * u(rng);
    if (trial == 0) gx = 0, gy = 0;
    const double x = g.x0 + gx * g.h, y = g.y0 + gy * g.h;
    S s;
    if constexpr (S::kSized) s.size(std::pow(2 * lp_cells * g.h, 2), 1.0, g.inv_h);
    if (trial == 0) s.eval_clamped(g, x, y);
    else s.eval(g, x, y);
    long nodes[S::kNodes];
    s.node_indices(g.nnx, nodes);
    double sum = 0, sx = 0, sy = 0, f = 0, fx = 0, fy = 0;
    for (int a = 0; a < S::kNodes; ++a) {
      ASSERT_GE(nodes[a], 0);
      ASSERT_LT(nodes[a], static_cast<long>(g.nodes()));
      EXPECT_GE(s.N[a], -1e-15);
      const double xn = g.node_x(nodes[a] % g.nnx), yn = g.node_y(nodes[a] / g.nnx);
      const double fn = 3 + 2 * xn - 5 * yn;
      sum += s.N[a]; sx += s.dNx[a]; sy += s.dNy[a];
      f += s.N[a] * fn; fx += s.dNx[a] * fn; fy += s.dNy[a] * fn;
    }
    EXPECT_NEAR(sum, 1.0, 1e-14) << gx << " " << gy;
    EXPECT_NEAR(sx, 0.0, 1e-12);
    EXPECT_NEAR(sy, 0.0, 1e-12);
    EXPECT_NEAR(f, 3 + 2 * x - 5 * y, 1e-12) << gx << " " << gy;
    EXPECT_NEAR(fx, 2.0, 1e-10) << gx << " " << gy;
    EXPECT_NEAR(fy, -5.0, 1e-10) << gx << " " << gy;
  }
}

}  // namespace

TEST(Shapes, BSplineIdentitiesUpToTheEdges) { check_identities<BSpline2>(0); }
TEST(Shapes, GimpIdentitiesUpToTheEdges) {
  for (double lp : {0.5, 0.25, 1.0 / 6}) check_identities<UGimp>(lp);
}

// The uGIMP weight is the hat function averaged over the particle [xi - lp, xi + lp] (its
// definition): compared with a 4000-point midpoint rule, and its derivative with a central
// difference.
TEST(Shapes, GimpWeightIsTheAveragedHat) {
  auto hat = [](double z) { return std::max(0.0, 1.0 - std::abs(z)); };
  for (double lp : {0.5, 0.25, 1.0 / 6})
    for (double xi = -1.6; xi <= 1.6; xi += 0.01) {
      double avg = 0;
      const int n = 4000;
      for (int k = 0; k < n; ++k) avg += hat(xi - lp + (k + 0.5) * 2 * lp / n);
      avg /= n;
      double w, d, wp, dp, wm, dm;
      shape_detail::ugimp_1d(xi, lp, w, d);
      shape_detail::ugimp_1d(xi + 1e-6, lp, wp, dp);
      shape_detail::ugimp_1d(xi - 1e-6, lp, wm, dm);
      EXPECT_NEAR(w, avg, 1e-6) << lp << " " << xi;
      EXPECT_NEAR(d, (wp - wm) / 2e-6, 1e-5) << lp << " " << xi;
    }
}

// Away from the edges the quadratic B-spline is C1: value and gradient continuous where the
// support shifts (half-cell lines) and across cell lines; the interior weights are the spline's
// (3/4 at a node, 1/8 at its neighbours).
TEST(Shapes, BSplineIsSmoothInside) {
  Grid g;
  g.init(0.0, 0.0, 1.0, 8, 8);
  auto field = [&](double x, double y, double& f, double& fx) {
    BSpline2 s;
    s.eval(g, x, y);
    long nodes[9];
    s.node_indices(g.nnx, nodes);
    f = fx = 0;
    for (int a = 0; a < 9; ++a) {
      const double xn = g.node_x(nodes[a] % g.nnx), yn = g.node_y(nodes[a] / g.nnx);
      const double fn = std::sin(xn) * std::cos(0.7 * yn);  // any nodal field
      f += s.N[a] * fn;
      fx += s.dNx[a] * fn;
    }
  };
  for (double xs : {2.5, 3.0, 3.5, 4.0, 5.5}) {
    double f1, g1, f2, g2;
    field(xs - 1e-9, 3.3, f1, g1);
    field(xs + 1e-9, 3.3, f2, g2);
    EXPECT_NEAR(f1, f2, 1e-8) << xs;
    EXPECT_NEAR(g1, g2, 1e-7) << xs;
  }
  BSpline2 s;
  s.eval(g, 4.0, 4.0);
  EXPECT_NEAR(s.N[4], 0.75 * 0.75, 1e-15);
  EXPECT_NEAR(s.N[3], 0.125 * 0.75, 1e-15);
  EXPECT_NEAR(s.N[0], 0.125 * 0.125, 1e-15);
}

// At the grid's edges the folded basis interpolates: a point on the edge takes the edge node's
// value alone (so a fixed or roller node holds the field there).
TEST(Shapes, EdgeNodeInterpolatesOnTheEdge) {
  Grid g;
  g.init(0.0, 0.0, 1.0, 6, 6);
  for (double x : {0.0, 6.0}) {
    BSpline2 s;
    s.eval_clamped(g, x, 2.0);
    long nodes[9];
    s.node_indices(g.nnx, nodes);
    double at_edge = 0, total = 0;
    for (int a = 0; a < 9; ++a) {
      total += s.N[a];
      if (g.node_x(nodes[a] % g.nnx) == x) at_edge += s.N[a];
    }
    EXPECT_NEAR(at_edge, 1.0, 1e-15) << x;
    EXPECT_NEAR(total, 1.0, 1e-15);
  }
}

// ---- the kernels for every shape ------------------------------------------------------------

class ShapeTransfer : public ::testing::TestWithParam<ShapeKind> {};

constexpr Scheme kSchemes[] = {Scheme::USF, Scheme::USL, Scheme::MUSL};

// With no stress and no load, one step maps particles to the grid and back: the grid carries
// exactly the particle mass and momentum, and the particles keep their total momentum.
TEST_P(ShapeTransfer, MassAndMomentum) {
  for (Scheme scheme : kSchemes) {
  SCOPED_TRACE(scheme_name(scheme));
  Solver s;
  s.materials.push_back(tungsten());
  s.grid.init(0, 0, 1e-3, 20, 20);
  s.seed_rectangle(2.3e-3, 3.1e-3, 15.7e-3, 16.2e-3, 2, 0, 0, 0, 0);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 5.0);
  for (std::size_t k = 0; k < s.p.size(); ++k) { s.p.vx[k] = n(rng); s.p.vy[k] = n(rng); }
  s.opt.shape = GetParam();
  s.opt.scheme = scheme;
  s.opt.flip = 0.7;
  s.dt = 1e-9;
  s.finalize();
  double M = 0, PX = 0, PY = 0;
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    M += s.p.mass[k]; PX += s.p.mass[k] * s.p.vx[k]; PY += s.p.mass[k] * s.p.vy[k];
  }
  s.step();
  const double gm = std::accumulate(s.grid.m.begin(), s.grid.m.end(), 0.0);
  const double gpx = std::accumulate(s.grid.px.begin(), s.grid.px.end(), 0.0);
  const double gpy = std::accumulate(s.grid.py.begin(), s.grid.py.end(), 0.0);
  double px = 0, py = 0;
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    px += s.p.mass[k] * s.p.vx[k]; py += s.p.mass[k] * s.p.vy[k];
  }
  const double pscale = std::abs(PX) + std::abs(PY) + M;
  EXPECT_NEAR(gm, M, 1e-13 * M);
  EXPECT_NEAR(gpx, PX, 1e-12 * pscale);
  EXPECT_NEAR(gpy, PY, 1e-12 * pscale);
  EXPECT_NEAR(px, PX, 1e-11 * pscale);
  EXPECT_NEAR(py, PY, 1e-11 * pscale);
  }
}

// Internal forces sum to zero whatever the stresses (sum_i grad N_i = 0), on two threads too
// (the strip colouring with the wider stencil).
TEST_P(ShapeTransfer, InternalForcesSumToZero) {
  for (Scheme scheme : kSchemes)
  for (int threads : {1, 2}) {
    SCOPED_TRACE(scheme_name(scheme));
    Solver s;
    s.materials.push_back(tungsten());
    s.grid.init(0, 0, 1e-3, 12, 40);
    s.seed_rectangle(1.4e-3, 1.2e-3, 9.9e-3, 37.3e-3, 3, 0, 0, 0, 0);
    std::mt19937 rng(5);
    std::normal_distribution<double> n(0.0, 1e8);
    for (std::size_t k = 0; k < s.p.size(); ++k) {
      s.p.sxx[k] = n(rng); s.p.syy[k] = n(rng); s.p.sxy[k] = n(rng);
    }
    s.opt.shape = GetParam();
    s.opt.scheme = scheme;
    s.opt.threads = threads;
    s.dt = 1e-10;
    s.finalize();
    s.step();
    double fx = 0, fy = 0, fabs = 0;
    for (std::size_t i = 0; i < s.grid.nodes(); ++i) {
      fx += s.grid.fx[i]; fy += s.grid.fy[i]; fabs += std::abs(s.grid.fx[i]);
    }
    ASSERT_GT(fabs, 0);
    EXPECT_NEAR(fx, 0, 1e-12 * fabs);
    EXPECT_NEAR(fy, 0, 1e-12 * fabs);
  }
}

// A uniform traction t on the four edges of a body whose edges are off the grid lines maps to
// nodal forces summing to t L exactly, for 1, 4 and 9 particles per cell.
TEST_P(ShapeTransfer, TractionSumEqualsTractionTimesLength) {
  for (Scheme scheme : kSchemes)
  for (int n : {1, 2, 3}) {
    SCOPED_TRACE(scheme_name(scheme));
    Solver s;
    s.materials.push_back(tungsten());
    s.grid.init(0, 0, 1e-3, 30, 30);
    const double x0 = 3.37e-3, y0 = 4.21e-3, x1 = 21.9e-3, y1 = 17.45e-3;
    s.seed_rectangle(x0, y0, x1, y1, n, 0, 0, 0, 0);
    struct Edge { double ax, ay, bx, by, nx, ny; };
    const Edge edges[4] = {{x0, y1, x0, y0, -1, 0}, {x1, y0, x1, y1, 1, 0},
                           {x0, y0, x1, y0, 0, -1}, {x1, y1, x0, y1, 0, 1}};
    double TX = 0, TY = 0;
    int k = 0;
    for (const auto& e : edges) {
      TractionLoad tl;
      tl.layer = s.select_layer("e", 0, e.ax, e.ay, e.bx, e.by, e.nx, e.ny, 1e-3);
      ASSERT_FALSE(tl.layer.idx.empty());
      tl.vx = 1e6 * (k + 1);
      tl.vy = -3e5 * (k + 2);
      tl.anchor = k % 2 ? Anchor::Particle : Anchor::Boundary;
      const double L = std::hypot(e.bx - e.ax, e.by - e.ay);
      TX += tl.vx * L; TY += tl.vy * L;
      s.tractions.push_back(tl);
      ++k;
    }
    s.opt.shape = GetParam();
    s.opt.scheme = scheme;
    s.dt = 1e-12;
    s.finalize();
    s.step();
    double fx = 0, fy = 0;
    for (std::size_t i = 0; i < s.grid.nodes(); ++i) { fx += s.grid.fx[i]; fy += s.grid.fy[i]; }
    EXPECT_NEAR(fx, TX, 1e-12 * std::abs(TX)) << n;
    EXPECT_NEAR(fy, TY, 1e-12 * std::abs(TY)) << n;
  }
}

INSTANTIATE_TEST_SUITE_P(Shapes, ShapeTransfer,
                         ::testing::Values(ShapeKind::Bilinear, ShapeKind::UGimp, ShapeKind::BSpline2),
                         [](const auto& info) { return std::string(shape_name(info.param)); });

// At one particle per cell (half-width h/2) uGIMP is the quadratic B-spline, weight for weight.
TEST(Shapes, GimpAtOnePpcIsTheBSpline) {
  Grid g;
  g.init(0.0, 0.0, 0.5, 6, 6);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0.0, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double x = u(rng), y = u(rng);
    UGimp a;
    a.size(0.25, 1.0, g.inv_h);  // V_p = h^2: lp = h/2
    a.eval(g, x, y);
    BSpline2 b;
    b.eval(g, x, y);
    for (int k = 0; k < 9; ++k) {
      EXPECT_NEAR(a.N[k], b.N[k], 1e-15);
      EXPECT_NEAR(a.dNx[k], b.dNx[k], 1e-13);
      EXPECT_NEAR(a.dNy[k], b.dNy[k], 1e-13);
    }
  }
}
