// The "contact" case key: a two-body case built from JSON runs the contact mode it names (the 1D
// plate impact rebounds only with "multi"), and wrong contact input fails with the key path.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"

using namespace smpm;

namespace {

// Aluminium flyer (40 mm) at 10 m/s onto a steel target (120 mm), 1 mm cells, rollers.
nlohmann::json impact_case() {
  return nlohmann::json::parse(R"({
    "grid": { "origin": [-0.05, 0], "size": [0.18, 0.002], "cell": 0.001 },
    "time": { "end": 2.6e-5, "cfl": 0.3 },
    "materials": {
      "aluminium": { "model": "elastic", "young": 70e9, "poisson": 0.33, "density": 2700 },
      "steel": { "model": "elastic", "young": 200e9, "poisson": 0.30, "density": 7800 }
    },
    "bodies": [
      { "name": "flyer", "material": "aluminium", "box": [-0.04, 0, 0, 0.002], "velocity": [10, 0] },
      { "name": "target", "material": "steel", "box": [0, 0, 0.12, 0.002] }
    ],
    "boundaries": [
      { "type": "roller", "component": "y", "grid_side": "bottom" },
      { "type": "roller", "component": "y", "grid_side": "top" }
    ],
    "scheme": { "threads": 1 },
    "contact": { "type": "multi", "friction": 0 },
    "output": { "snapshots": 0, "progress": false }
  })");
}

double flyer_velocity_at_end(Case& c) {
  Solver& s = *c.solver;
  while (s.t < c.t_end - 0.5 * s.dt) s.step();
  double m = 0, q = 0;
  for (std::size_t k = 0; k < s.p.size(); ++k)
    if (s.p.body[k] == 0) { m += s.p.mass[k]; q += s.p.mass[k] * s.p.vx[k]; }
  return q / m;
}

std::string error_of(const nlohmann::json& doc) {
  try {
    build_case(doc, "impact.json");
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
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

TEST(ContactCase, Errors) {
  auto d = impact_case();
  d["contact"]["type"] = "mult";
  EXPECT_EQ(error_of(d),
            "impact.json: contact.type: must be one of \"single\", \"multi\", got \"mult\" (did "
            "you mean \"multi\"?)");
  d = impact_case();
  d["contact"] = {{"type", "single"}, {"friction", 0.2}};
  EXPECT_NE(error_of(d).find("impact.json: contact.friction: friction needs \"type\": \"multi\""),
            std::string::npos);
  d = impact_case();
  d["contact"]["friction"] = -0.1;
  EXPECT_EQ(error_of(d), "impact.json: contact.friction: must be >= 0, got -0.1");
  d = impact_case();
  d["contact"]["frction"] = 0.1;
  EXPECT_NE(error_of(d).find("impact.json: contact.frction: unknown key (did you mean "
                             "\"friction\"?)"),
            std::string::npos);
  d = impact_case();
  d["contact"] = "multi";
  EXPECT_EQ(error_of(d), "impact.json: contact: expected an object, got a string");
}
