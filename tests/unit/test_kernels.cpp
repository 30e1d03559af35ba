// Bilinear shape functions (exact identities, to round-off) and the grid check of moving particles.
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

// The transfer identities (mass and momentum to the grid and back, internal forces summing to
// zero, tractions summing to t L for 1, 4 and 9 ppc) are ShapeTransfer.* in test_shapes.cpp,
// for every shape and scheme, bilinear included.

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

// Solver::nodal_projection (the MPM grid's snapshots, output.grid): for every shape, the nodal
// masses sum to the particles' mass and the nodal momenta to theirs (partition of unity, to
// round-off), a uniform stress comes back exactly at every node with mass, and nodes out of
// reach of every particle hold zeros.
TEST(Transfer, NodalProjectionConservesMassAndMomentum) {
  for (ShapeKind shape : {ShapeKind::Bilinear, ShapeKind::UGimp, ShapeKind::BSpline2}) {
    ColumnSpec spec;
    spec.cells = 20;
    spec.ppc_side = 2;
    spec.offset = 0.3e-3;  // partly filled cells at both ends
    spec.shape = shape;
    auto s = make_column(spec);
    double m = 0, px = 0, py = 0;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (std::size_t k = 0; k < s->p.size(); ++k) {
      s->p.vx[k] = u(rng);
      s->p.vy[k] = u(rng);
      s->p.sxx[k] = -3e8; s->p.syy[k] = 1e8; s->p.szz[k] = -0.5e8; s->p.sxy[k] = 2e8;
      m += s->p.mass[k];
      px += s->p.mass[k] * s->p.vx[k];
      py += s->p.mass[k] * s->p.vy[k];
    }
    const Solver::NodalProjection P = s->nodal_projection();
    ASSERT_EQ(P.mass.size(), s->grid.nodes());
    double M = 0, PX = 0, PY = 0, worst = 0;
    std::size_t empty = 0;
    for (std::size_t i = 0; i < P.mass.size(); ++i) {
      M += P.mass[i];
      PX += P.mass[i] * P.vx[i];
      PY += P.mass[i] * P.vy[i];
      if (P.mass[i] == 0) {
        ++empty;
        EXPECT_EQ(P.sxx[i], 0.0);
        EXPECT_EQ(P.vx[i], 0.0);
        continue;
      }
      worst = std::max({worst, std::abs(P.sxx[i] + 3e8), std::abs(P.syy[i] - 1e8),
                        std::abs(P.szz[i] + 0.5e8), std::abs(P.sxy[i] - 2e8)});
    }
    const char* name = shape_name(shape);
    EXPECT_NEAR(M, m, 1e-13 * m) << name;
    EXPECT_NEAR(PX, px, 1e-12 * m) << name;
    EXPECT_NEAR(PY, py, 1e-12 * m) << name;
    EXPECT_LT(worst, 1e-6) << name << ": a uniform stress of 1e8 Pa comes back to round-off";
    EXPECT_GT(empty, 0u) << name << ": the grid's cells beyond the column hold no mass";
  }
}
