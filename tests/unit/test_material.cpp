// von Mises return mapping against closed forms. (The energy balance of an elastic run with a
// silent boundary: tests/physics/test_energy_balance.cpp.)
#include <gtest/gtest.h>

#include <cmath>

#include "common.hpp"

using namespace smpm;
using namespace smpm::testing;

// Uniaxial strain (exx driven, eyy = ezz = 0): elastic sxx = M e, syy = szz = lambda e, so
// q = 2 mu |e| and yield at e_y = sigma_y / (2 mu), sxx_y = M sigma_y / (2 mu). On the plastic
// plateau the deviator is frozen: sxx = K e + (2/3) sigma_y, syy = K e - (1/3) sigma_y.
TEST(ReturnMapping, UniaxialStrainYieldAndPlateau) {
  const Material m = tungsten(Model::VonMises, 1.0e9);
  const double ey = m.sigma_y / (2 * m.mu);
  double sxx = 0, syy = 0, szz = 0, sxy = 0, ep = 0, work = 0, diss = 0;
  const int n = 4000;
  const double de = 5 * ey / n;
  double first_yield = -1;
  for (int i = 1; i <= n; ++i) {
    const double sxx0 = sxx, syy0 = syy, szz0 = szz;
    diss += stress_update<Model::VonMises>(m, de, 0, 0, sxx, syy, szz, sxy, ep);
    work += 0.5 * (sxx0 + sxx) * de;
    (void)syy0; (void)szz0;
    const double e = i * de;
    if (e <= ey * (1 - 1e-9)) {
      EXPECT_NEAR(sxx, m.M * e, 1e-9 * m.M * e);
      EXPECT_NEAR(syy, m.lambda * e, 1e-9 * m.M * e);
      EXPECT_EQ(ep, 0.0);
    } else {
      if (first_yield < 0) first_yield = e;
      EXPECT_NEAR(sxx, m.K * e + 2.0 / 3.0 * m.sigma_y, 1e-9 * sxx);
      EXPECT_NEAR(syy, m.K * e - 1.0 / 3.0 * m.sigma_y, 1e-9 * sxx);
      EXPECT_NEAR(szz, syy, 1e-9 * sxx);
      EXPECT_NEAR(std::sqrt(3 * j2_of(sxx, syy, szz, sxy)), m.sigma_y, 1e-9 * m.sigma_y);
    }
  }
  EXPECT_NEAR(first_yield, ey, 1.01 * de);
  // Yield stress value of the closed form: sxx_y = M sigma_y / (2 mu) = 1.6363 GPa for tungsten.
  EXPECT_NEAR(m.M * m.sigma_y / (2 * m.mu), 1.6363e9, 1e6);
  // Plastic strain: the deviatoric plastic strain rate equals the total past yield,
  // so ep = (2/3) (e - e_y) for uniaxial strain.
  EXPECT_NEAR(ep, 2.0 / 3.0 * (5 * ey - ey), 1e-3 * ep);
  // Work = stored + dissipated (trapezoidal work of a piecewise linear path).
  const double stored = elastic_energy_density(m, sxx, syy, szz, sxy);
  EXPECT_NEAR(work, stored + diss, 1e-3 * work);
}
