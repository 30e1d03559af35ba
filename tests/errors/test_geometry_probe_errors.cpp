// Probes along a physical curve (probes[i].curve; geometry_probes.cpp): each bad input gives one
// clear error naming the case file, the key path, the gmsh file and the group, with a non-zero
// exit of the CLI. (The probes of good inputs: tests/unit/test_geometry_probes.cpp.)
#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <vector>

#include "silentmpm/case.hpp"
#include "test_geometry_common.hpp"
#include "test_geometry_probes_common.hpp"

namespace {

using namespace smpm::geotest;

// The inclined plate plus a separate lid (surface 2, not a body of the cases below) whose bottom
// edge is curve 15; curve 16: three free lines meeting at one point; curve 17: two separate
// lines (the plate's bottom and top).
std::string odd_geo() {
  return inclined_geo(kAngle) + R"(
Point(11) = {0, 0.022, 0, h}; Point(12) = {0.005, 0.022, 0, h};
Point(13) = {0.005, 0.023, 0, h}; Point(14) = {0, 0.023, 0, h};
Line(11) = {11, 12}; Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
Curve Loop(2) = {11, 12, 13, 14}; Plane Surface(2) = {2};
Point(21) = {0.010, 0.0235, 0, h}; Point(22) = {0.014, 0.0235, 0, h};
Point(23) = {0.012, 0.0215, 0, h}; Point(24) = {0.012, 0.0235, 0, h};
Line(21) = {21, 24}; Line(22) = {24, 22}; Line(23) = {24, 23};
Physical Surface("lid", 2) = {2};
Physical Curve("lid_bottom", 15) = {11};
Physical Curve("branched", 16) = {21, 22, 23};
Physical Curve("apart", 17) = {3, 4};
)";
}

struct Bad {
  std::string name, probes;
  std::vector<std::string> expect;  // substrings of the message
};

std::vector<Bad> bad_probes() {
  return {
      {"missing_curve", R"({ "name": "t", "curve": 99, "count": 5 })",
       {"probes[0].curve", "probes_odd.geo", "no physical curve 99", "12 \"inclined\""}},
      {"missing_curve_name", R"({ "name": "t", "curve": "rim", "count": 5 })",
       {"probes[0].curve", "probes_odd.geo", "no physical curve named \"rim\""}},
      {"count_one", R"({ "name": "t", "curve": 12, "count": 1 })",
       {"probes[0].count", "must be >= 2", "got 1"}},
      {"count_not_integer", R"({ "name": "t", "curve": 12, "count": 2.5 })", {"probes[0].count"}},
      {"count_and_spacing", R"({ "name": "t", "curve": 12, "count": 3, "spacing": 0.001 })",
       {"probes[0]", "either count or spacing"}},
      {"neither", R"({ "name": "t", "curve": 12 })", {"probes[0]", "needs count", "or spacing"}},
      {"spacing_zero", R"({ "name": "t", "curve": 12, "spacing": 0 })", {"probes[0].spacing", "must be > 0"}},
      {"spacing_too_long", R"({ "name": "t", "curve": 12, "spacing": 0.05 })",
       {"probes[0].spacing", "probes_odd.geo", "physical curve 12 \"inclined\"", "fewer than 2 points"}},
      {"outside_body", R"({ "name": "t", "curve": "lid_bottom", "count": 3, "body": "plate" })",
       {"probes[0].curve", "probes_odd.geo", "physical curve 15 \"lid_bottom\"", "t_00",
        "outside body \"plate\""}},
      {"outside_every_body", R"({ "name": "P", "at": [0, 0] }, { "name": "t", "curve": 15, "count": 3 })",
       {"probes[1].curve", "probes_odd.geo", "physical curve 15 \"lid_bottom\"", "outside every body"}},
      {"branched", R"({ "name": "t", "curve": 16, "count": 3 })",
       {"probes[0].curve", "probes_odd.geo", "physical curve 16 \"branched\"", "branches at"}},
      {"disconnected", R"({ "name": "t", "curve": "apart", "count": 3 })",
       {"probes[0].curve", "probes_odd.geo", "physical curve 17 \"apart\"", "not one connected curve"}},
      {"at_and_curve", R"({ "name": "t", "at": [0, 0], "curve": 12, "count": 3 })",
       {"probes[0].at", "either at (a point) or curve"}},
      {"unknown_key", R"({ "name": "t", "curve": 12, "count": 3, "spcing": 1 })",
       {"probes[0].spcing", "unknown key", "spacing"}},
      {"name_clash", R"({ "name": "t_01", "at": [0.001, 0.001] }, { "name": "t", "curve": 12, "count": 3 })",
       {"probes[1].name", "\"t_01\" is used twice"}},
  };
}

void PrintTo(const Bad& b, std::ostream* os) { *os << b.name; }

fs::path write_bad(const Bad& b) {
  write_file("probes_odd.geo", odd_geo());
  return write_file("probes_bad_" + b.name + ".json", inclined_case("probes_odd.geo", b.probes));
}

class GeometryProbeErrors : public ::testing::TestWithParam<Bad> {};

TEST_P(GeometryProbeErrors, LibraryMessage) {
  const Bad& b = GetParam();
  expect_case_error(write_bad(b), b.expect, b.name);
}

TEST_P(GeometryProbeErrors, CliExitAndMessage) {
  const Bad& b = GetParam();
  expect_cli_error(write_bad(b), b.expect, b.name);
}

std::string bad_name(const ::testing::TestParamInfo<Bad>& info) { return info.param.name; }
INSTANTIATE_TEST_SUITE_P(Bad, GeometryProbeErrors, ::testing::ValuesIn(bad_probes()), bad_name);

// No geometry key: the probe names the missing key.
TEST(GeometryProbes, CurveWithoutGeometryIsAnError) {
  const fs::path file = write_file("probes_nogeo.json", R"({
  "grid": { "size": [0.03, 0.02], "cell": 0.001 }, "time": { "end": 1e-6, "cfl": 0.3 },
  "materials": { "w": { "model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000 } },
  "bodies": [ { "name": "plate", "material": "w", "box": [0, 0, 0.02, 0.01] } ],
  "probes": [ { "name": "t", "curve": 12, "count": 3 } ] })");
  try {
    smpm::load_case(file.string());
    FAIL() << "no error";
  } catch (const smpm::CaseError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("probes[0].curve"), std::string::npos) << m;
    EXPECT_NE(m.find("needs the top-level key \"geometry\""), std::string::npos) << m;
  }
}

}  // namespace
