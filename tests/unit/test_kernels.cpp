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
