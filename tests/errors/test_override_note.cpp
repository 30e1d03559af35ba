// A bad value set by a command-line override says so, "(value set by override '...')", in every
// section of a case file: MPM keys (tests/errors/test_case.cpp), FEM keys, and the keys a hybrid
// case reads itself (its top level, its FEM probes) or hands to the MPM parser with its probes
// renumbered.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "silentmpm/case.hpp"

namespace {

const std::string kFemCase =
    std::string(SMPM_SOURCE_DIR) + "/studies/pulse/cases/compressive_fem_dashpot.json";
const std::string kHybridCase =
    std::string(SMPM_SOURCE_DIR) + "/studies/hybrid/cases/pulse_hybrid_dashpot.json";

// The CaseError message of loading `file` with `overrides` ("" if it loads).
std::string error_of(const std::string& file, const std::vector<std::string>& overrides) {
  try {
    smpm::load_case(file, overrides);
  } catch (const smpm::CaseError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(OverrideNote, FemKey) {
  EXPECT_EQ(error_of(kFemCase, {"output.snapshots=0", "fem.boundaries.1.a=-1"}),
            kFemCase + ": fem.boundaries[1].a: must be >= 0, got -1 (value set by override "
                       "'fem.boundaries.1.a=-1')");
  // The override covers the keys below the path it sets.
  const std::string mesh = std::string(SMPM_SOURCE_DIR) + "/meshes/pulse_plate.geo";
  EXPECT_EQ(error_of(kFemCase, {"fem.boundaries.1={\"type\": \"dashpot\", \"curve\": \"nope\"}"}),
            kFemCase + ": fem.boundaries[1].curve: no physical curve \"nope\" in " + mesh +
                "; it has: 11 \"left\", 12 \"right\", 13 \"bottom\", 14 \"top\" (value set by "
                "override 'fem.boundaries.1={\"type\": \"dashpot\", \"curve\": \"nope\"}')");
  // An error at a key no override set (time, above time.cfl) has no note.
  EXPECT_EQ(error_of(kFemCase, {"time.cfl=0.5"}),
            kFemCase + ": time: give either dt or cfl, not both");
  EXPECT_EQ(error_of(kFemCase, {"time.end=1"}), "");
}

TEST(OverrideNote, HybridKey) {
  // Probe A lies in the FEM region: read by the hybrid parser.
  EXPECT_EQ(error_of(kHybridCase, {"probes.0.fields=[\"sxx\", \"bogus\"]"}),
            kHybridCase + ": probes[0].fields[1]: must be one of sxx, syy, szz, sxy, J2, vx, vy, "
                          "div, curl, got \"bogus\" (value set by override "
                          "'probes.0.fields=[\"sxx\", \"bogus\"]')");
  EXPECT_EQ(error_of(kHybridCase, {"fem_region=1"}),
            kHybridCase + ": fem_region: unknown key in a hybrid (MPM + FEM) case; allowed: title, "
                          "grid, time, scheme, materials, bodies, boundaries, probes, geometry, "
                          "output, contact, fem, gravity (value set by override 'fem_region=1')");
  // A probe in the particles is MPM probe 0 of the MPM region; its error and its note name it
  // at its index in the document.
  EXPECT_EQ(error_of(kHybridCase, {"probes.0.fields=[\"sxx\"]",
                                   "probes.1={\"name\": \"B\", \"at\": [0.005, 0.1], "
                                   "\"fields\": [\"div\"]}"}),
            kHybridCase + ": probes[1].fields[0]: must be one of \"sxx\", \"syy\", \"szz\", "
                          "\"sxy\", \"J2\", \"vx\", \"vy\", got \"div\" (value set by override "
                          "'probes.1={\"name\": \"B\", \"at\": [0.005, 0.1], "
                          "\"fields\": [\"div\"]}')");
  // The FEM region of a hybrid (read by the FEM parser).
  EXPECT_EQ(error_of(kHybridCase, {"fem.degree=3"}),
            kHybridCase +
                ": fem.degree: must be 1 or 2, got 3 (value set by override 'fem.degree=3')");
}
