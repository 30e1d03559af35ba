// Oblique incidence on the FEM LK dashpot boundary (docs/physics.md §4.1): a plane P pulse at 15 and
// 30 degrees, reflected P and SV amplitudes measured by extended-domain differencing (same mesh,
// identical dt), against the closed form: within 10 % or 2e-3 absolute. The set-up is the one of
// studies/oblique (studies/oblique/oblique.hpp), at nu = 0.25 and a Gaussian pulse 24 cells wide (FWHM).
#include <gtest/gtest.h>

#include "../../studies/oblique/oblique.hpp"

using namespace smpm;

namespace {

void check_angle(double deg) {
  oblique::Setup s;
  s.angle_deg = deg;
  s.threads = 1;
  const oblique::Result r = oblique::measure(s);
  std::printf("  P at %.0f deg: |R_PP| %.5f (exact %.5f), |R_PS| %.5f (exact %.5f); %zu + %zu dofs, %.1f s\n",
              deg, r.r_same, r.exact_same, r.r_conv, r.exact_conv, r.dofs_a, r.dofs_b, r.seconds);
  EXPECT_LE(std::abs(r.r_same - r.exact_same), std::max(0.1 * r.exact_same, 2e-3)) << "R_PP";
  EXPECT_LE(std::abs(r.r_conv - r.exact_conv), std::max(0.1 * r.exact_conv, 2e-3)) << "R_PS";
}

}  // namespace

TEST(FemOblique, PAt15Degrees) { check_angle(15); }
TEST(FemOblique, PAt30Degrees) { check_angle(30); }
