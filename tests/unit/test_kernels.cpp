// Shape functions, transfers and traction mapping: exact identities, checked to round-off.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "common.hpp"
#include "silentmpm/shape.hpp"

using namespace smpm;
using namespace smpm::testing;

TEST(Shape, PartitionOfUnityAndGradients) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double h = 0.25, x0 = -1.0, y0 = 2.0;
  for (int trial = 0; trial < 1000; ++trial) {
    const double x = x0 + 10 * h * u(rng), y = y0 + 10 * h * u(rng);
    Bilinear s;
    s.eval(x, y, x0, y0, 1 / h);
    double sum = 0, gx = 0, gy = 0;
    for (int a = 0; a < 4; ++a) {
      EXPECT_GE(s.N[a], 0.0);
      sum += s.N[a]; gx += s.dNx[a]; gy += s.dNy[a];
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
    EXPECT_NEAR(gx, 0.0, 1e-12);
    EXPECT_NEAR(gy, 0.0, 1e-12);
    // A linear field f = 3 + 2x - 5y is reproduced exactly, with its gradient.
    double f = 0, fx = 0, fy = 0;
    for (int a = 0; a < 4; ++a) {
      const double xn = x0 + (s.ci + s.di[a]) * h, yn = y0 + (s.cj + s.dj[a]) * h;
      const double fn = 3 + 2 * xn - 5 * yn;
      f += s.N[a] * fn; fx += s.dNx[a] * fn; fy += s.dNy[a] * fn;
    }
    EXPECT_NEAR(f, 3 + 2 * x - 5 * y, 1e-12);
    EXPECT_NEAR(fx, 2.0, 1e-10);
    EXPECT_NEAR(fy, -5.0, 1e-10);
  }
}

// With no stress and no load, one step maps particles to the grid and back: the grid carries
// exactly the particle mass and momentum, and the particles keep their total momentum.
class TransferConservation : public ::testing::TestWithParam<Scheme> {};

TEST_P(TransferConservation, MassAndMomentum) {
  Solver s;
  s.materials.push_back(tungsten());
  s.grid.init(0, 0, 1e-3, 20, 20);
  s.seed_rectangle(2.3e-3, 3.1e-3, 15.7e-3, 16.2e-3, 2, 0, 0, 0, 0);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 5.0);
  for (std::size_t k = 0; k < s.p.size(); ++k) { s.p.vx[k] = n(rng); s.p.vy[k] = n(rng); }
  s.opt.scheme = GetParam();
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
  // Internal forces of a stress-free body vanish; a moving body has a non-zero stress after the
  // step, but its internal forces still sum to zero.
  EXPECT_NEAR(px, PX, 1e-11 * pscale);
  EXPECT_NEAR(py, PY, 1e-11 * pscale);
}

INSTANTIATE_TEST_SUITE_P(Schemes, TransferConservation,
                         ::testing::Values(Scheme::USF, Scheme::USL, Scheme::MUSL));

// Internal forces sum to zero whatever the stresses (Eq. 18 with sum_i grad N_i = 0).
TEST(Transfer, InternalForcesSumToZero) {
  Solver s;
  s.materials.push_back(tungsten());
  s.grid.init(0, 0, 1e-3, 12, 12);
  s.seed_rectangle(1.4e-3, 1.2e-3, 9.9e-3, 10.3e-3, 3, 0, 0, 0, 0);
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1e8);
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    s.p.sxx[k] = n(rng); s.p.syy[k] = n(rng); s.p.sxy[k] = n(rng);
  }
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

// A uniform traction t on an edge of length L maps to nodal forces summing to t L exactly,
// for 1, 4 and 9 particles per cell, on a body whose edges do not fall on grid lines.
class TractionSum : public ::testing::TestWithParam<int> {};

TEST_P(TractionSum, EqualsTractionTimesLength) {
  const int n = GetParam();
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
    const double L = std::hypot(e.bx - e.ax, e.by - e.ay);
    TX += tl.vx * L; TY += tl.vy * L;
    s.tractions.push_back(tl);
    ++k;
  }
  s.dt = 1e-12;
  s.finalize();
  s.step();  // stress-free body at rest: the grid force is the external force alone
  double fx = 0, fy = 0;
  for (std::size_t i = 0; i < s.grid.nodes(); ++i) { fx += s.grid.fx[i]; fy += s.grid.fy[i]; }
  EXPECT_NEAR(fx, TX, 1e-12 * std::abs(TX));
  EXPECT_NEAR(fy, TY, 1e-12 * std::abs(TY));
}

INSTANTIATE_TEST_SUITE_P(ParticlesPerCell, TractionSum, ::testing::Values(1, 2, 3));

// A particle that leaves the grid stops the run with an error naming the step, in x and in y.
TEST(Transfer, ParticleLeavingTheGridIsAnError) {
  for (int dir = 0; dir < 2; ++dir) {
    Solver s;
    s.materials.push_back(tungsten());
    s.grid.init(0, 0, 1e-3, 10, 10);
    const double v = 2000.0;  // m/s: crosses the 1 mm margin within 1 us
    s.seed_rectangle(1e-3, 1e-3, 9e-3, 9e-3, 1, 0, 0, dir == 0 ? v : 0, dir == 1 ? v : 0);
    s.dt = 0.2 * s.critical_dt();
    s.finalize();
    bool thrown = false;
    try {
      for (int i = 0; i < 10000; ++i) s.step();
    } catch (const std::runtime_error& e) {
      thrown = std::string(e.what()).find("left the grid at step") != std::string::npos;
    }
    EXPECT_TRUE(thrown) << "direction " << dir;
  }
}
