// Closed-form LK reflection coefficients (docs/physics.md §4.1): the nu = 0.25 table to 1e-4, and
// energy conservation on a free surface.
#include <gtest/gtest.h>

#include <cmath>

#include "silentmpm/lk_reflection.hpp"

using smpm::lk_reflection;

namespace {
constexpr double kDeg = M_PI / 180.0;
}

TEST(LKReflection, TableNu025) {
  // angle, |R_PP|, |R_PS|, E_P, |R_SP|, |R_SS|, E_S
  const double table[][7] = {
      {0, 0, 0, 0, 0, 0, 0},
      {15, 0.0077, 0.0132, 0.0002, 0.0000, 0.0545, 0.0030},
      {30, 0.0160, 0.0090, 0.0003, 0.1340, 0.1340, 0.0359},
      {45, 0.0138, 0.0709, 0.0039, 0.4204, 0.1694, 0.0287},
      {60, 0.1340, 0.1340, 0.0359, 0.4082, 0.3365, 0.1132},
      {70, 0.2963, 0.1440, 0.1172, 0.3372, 0.4941, 0.2442},
      {80, 0.5617, 0.1049, 0.3455, 0.2046, 0.7070, 0.4999}};
  for (const auto& row : table) {
    const auto r = lk_reflection(0.25, 1, 1, row[0] * kDeg);
    const double tol = 1e-4;
    EXPECT_NEAR(std::abs(r.rpp), row[1], tol) << row[0];
    EXPECT_NEAR(std::abs(r.rps), row[2], tol) << row[0];
    EXPECT_NEAR(r.epp + r.eps, row[3], tol) << row[0];
    EXPECT_NEAR(std::abs(r.rsp), row[4], tol) << row[0];
    EXPECT_NEAR(std::abs(r.rss), row[5], tol) << row[0];
    EXPECT_NEAR(r.ess + r.esp, row[6], tol) << row[0];
  }
}

TEST(LKReflection, FreeSurfaceConservesEnergy) {
  for (double nu : {0.1, 0.25, 0.28, 0.42})
    for (double deg = 0; deg < 89.5; deg += 2.5) {
      const auto r = lk_reflection(nu, 0, 0, deg * kDeg);
      EXPECT_NEAR(r.epp + r.eps, 1.0, 1e-12) << nu << " " << deg;
      EXPECT_NEAR(r.ess + r.esp, 1.0, 1e-12) << nu << " " << deg;
    }
}

TEST(LKReflection, VanishesAtNormalIncidenceAndWhereTheoryPredicts) {
  const auto r = lk_reflection(0.3, 1, 1, 0.0);
  EXPECT_LT(std::abs(r.rpp) + std::abs(r.rps) + std::abs(r.rss) + std::abs(r.rsp), 1e-14);
  // R_PS = 0 where cos 2 phi = a b / (2 kappa): for nu = 0.25, a = b = 1.
  const double k = std::sqrt(0.5 / 1.5);
  const double phi = 0.5 * std::acos(1.0 / (2 * k));
  const double theta = std::asin(std::sin(phi) / k);
  EXPECT_LT(std::abs(lk_reflection(0.25, 1, 1, theta).rps), 1e-12);
}
