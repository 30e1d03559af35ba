// Probes restricted to one body (the film's W-Si interface, studies/film) on a tiny two-body grid.
// (The film through the whole solver: tests/physics/test_film_study.cpp.)
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "silentmpm/solver.hpp"

using namespace smpm;

// A probe restricted to one body interpolates only that body's particles: at a point half a cell
// below the interface of two bodies with different uniform stresses it reads the lower body's
// stress exactly, while the unrestricted probe mixes the two (mass-weighted at shared nodes).
TEST(FilmProbe, BodyRestrictedSamplingAtAnInterface) {
  Solver s;
  Material a, b;
  a.name = "a"; a.E = 411e9; a.nu = 0.28; a.rho = 15000; a.derive();
  b.name = "b"; b.E = 107e9; b.nu = 0.42; b.rho = 3200; b.derive();
  s.materials = {a, b};
  s.grid.init(-1, -1, 0.5, 12, 12);
  s.seed_rectangle(0, 2, 4, 4, 1, 0, 0, 0, 0);  // body 0 on top
  s.seed_rectangle(0, 0, 4, 2, 1, 1, 1, 0, 0);  // body 1 below
  for (std::size_t k = 0; k < s.p.size(); ++k) s.p.sxx[k] = s.p.body[k] == 0 ? -1.3e9 : 0.2e9;
  s.dt = 1e-9;
  s.finalize();
  const std::vector<std::array<double, 2>> pts = {{1.75, 1.75}, {1.75, 1.75}};
  const auto r = s.sample(pts, {1, -1});
  ASSERT_TRUE(r[0].valid && r[1].valid);
  EXPECT_NEAR(r[0].sxx, 0.2e9, 1e-6);
  EXPECT_LT(r[1].sxx, 0.0);  // the denser top body dominates the shared interface nodes
}
