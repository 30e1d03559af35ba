// The "contact" case key: a two-body case built from JSON runs the contact mode it names (the 1D
// plate impact rebounds only with "multi"). Wrong contact input fails with the key path:
// tests/errors/test_contact_case_errors.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"
#include "test_contact_common.hpp"

using namespace smpm;
using namespace smpm::contact_testing;

namespace {

double flyer_velocity_at_end(Case& c) {
  Solver& s = *c.solver;
  while (s.t < c.t_end - 0.5 * s.dt) s.step();
  double m = 0, q = 0;
  for (std::size_t k = 0; k < s.p.size(); ++k)
    if (s.p.body[k] == 0) { m += s.p.mass[k]; q += s.p.mass[k] * s.p.vx[k]; }
  return q / m;
}

}  // namespace

// Through the case file: "multi" rebounds at v0 (Z1 - Z2)/(Z1 + Z2) (-4.65 m/s, 5 %), the
// default single field does not (its flyer velocity stays far from the rebound value).
TEST(ContactCase, ModeFromCaseFile) {
  const double z1 = 2700 * std::sqrt(70e9 * 0.67 / (1.33 * 0.34) / 2700);
  const double z2 = 7800 * std::sqrt(200e9 * 0.70 / (1.30 * 0.40) / 7800);
  const double rebound = 10.0 * (z1 - z2) / (z1 + z2);
  Case multi = build_case(impact_case(), "impact.json");
  ASSERT_TRUE(multi.solver->contact.multi());
  EXPECT_NEAR(flyer_velocity_at_end(multi), rebound, 0.05 * std::abs(rebound));
  auto doc = impact_case();
  doc.erase("contact");
  Case single = build_case(doc, "impact.json");
  ASSERT_FALSE(single.solver->contact.multi());
  EXPECT_GT(flyer_velocity_at_end(single) - rebound, 0.5 * std::abs(rebound));
}
