// Hybrid cases (both "bodies" and "fem"): errors name the key, through build_case / run_case and
// the CLI (check prints the hybrid line, a bad case exits 1 with one error line). (The hybrid
// plate against the all-MPM and all-FEM plates: tests/cross/test_hybrid_case.cpp.)
#include <gtest/gtest.h>

#include <unistd.h>
#include <string>
#include <cstdlib>
#include <fstream>
#include <utility>
#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"
#include "silentmpm/driver.hpp"
#include "test_hybrid_case_common.hpp"
#include "test_hybrid_common.hpp"

#ifndef SMPM_CLI
#define SMPM_CLI ""
#endif

using namespace smpm;
using nlohmann::json;
namespace fs = std::filesystem;
using namespace smpm::hybrid_case_testing;

namespace {

std::string case_error(const json& c) {
  try {
    build_case(c, "h.json");
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(HybridCase, ErrorsNameTheKey) {
  json c = plate_case("hybrid");
  c["fem"]["size"] = 0.5 * h;  // FE spacing h/2 at the interface
  EXPECT_NE(case_error(c).find("h.json: fem: hybrid: FE node"), std::string::npos) << case_error(c);
  c = plate_case("hybrid");
  c["scheme"]["mass_correction"] = 2;  // at 4 particles per cell: accepted
  EXPECT_EQ(case_error(c), "");
  c["bodies"][0]["particles_per_cell"] = 1;  // the interface would reflect more, not less
  EXPECT_NE(case_error(c).find("h.json: scheme.mass_correction: needs 2 or more particles per "
                               "cell side next to the interface, but the MPM cell"),
            std::string::npos) << case_error(c);
  c = plate_case("hybrid");
  c["time"]["dt"] = 2 * h / cd;
  EXPECT_NE(case_error(c).find("time.dt"), std::string::npos) << case_error(c);
  c = plate_case("hybrid");
  c["probes"][1]["body"] = "plate";
  EXPECT_NE(case_error(c).find("h.json: probes[1].body: the point lies in the FEM region"),
            std::string::npos) << case_error(c);
  c = plate_case("hybrid");
  c["probes"][1]["fields"] = {"sxx", "bogus"};
  EXPECT_NE(case_error(c).find("h.json: probes[1].fields[1]: must be one of"), std::string::npos)
      << case_error(c);
  c = plate_case("hybrid");
  c["probes"][0]["fields"] = {"div"};  // A is in the particles: no div there
  EXPECT_NE(case_error(c).find("h.json: probes[0].fields"), std::string::npos) << case_error(c);
  // A probe along a curve is an MPM probe: its errors come from the MPM parser, reported at the
  // probe's index in the document (probes[2], the first MPM probe after A and the FE probe B).
  c = plate_case("hybrid");
  c["probes"].push_back({{"name", "C"}, {"curve", 12}, {"count", 3}});
  EXPECT_NE(case_error(c).find("h.json: probes[2].curve: needs the top-level key \"geometry\""),
            std::string::npos) << case_error(c);
  // The MPM region's keys are read before the FE mesh: a mistake in a body is reported even
  // when the FE mesh file does not exist (the control: that file alone is the error).
  c = plate_case("hybrid");
  c["fem"]["mesh"] = (dir() / "no_such_mesh.geo").string();
  EXPECT_NE(case_error(c).find("h.json: fem.mesh"), std::string::npos) << case_error(c);
  c["bodies"][0]["colour"] = "red";
  EXPECT_NE(case_error(c).find("h.json: bodies[0].colour: unknown key"), std::string::npos)
      << case_error(c);
  c = plate_case("hybrid");
  c["extra"] = 1;
  EXPECT_NE(case_error(c).find("h.json: extra: unknown key in a hybrid"), std::string::npos)
      << case_error(c);
  c = plate_case("hybrid");
  c["fem"]["boundaries"].push_back({{"type", "traction"}, {"curve", "top"}, {"normal", -1e6}});
  // the FE top curve ends on the interface node (20h, 30h): the run stops at the first step
  Case bad = build_case(c, "h.json");
  EXPECT_THROW(run_case(bad, (dir() / "out_bad").string()), HybridError);
}

// The CLI: check prints the hybrid line, a bad case exits 1 with one error line.
TEST(HybridCase, Cli) {
  if (std::string(SMPM_CLI).empty() || !fs::exists(SMPM_CLI)) GTEST_SKIP() << "CLI not built";
  const std::string good = write_case("cli_good", plate_case("hybrid"));
  json b = plate_case("hybrid");
  b["fem"]["size"] = 2 * h;
  const std::string bad = write_case("cli_bad", b);
  const fs::path out = dir() / "cli_out.txt";
  auto run = [&](const std::string& args) {
    const std::string cmd = "\"" + std::string(SMPM_CLI) + "\" " + args + " >\"" + out.string() + "\" 2>&1";
    const int rc = std::system(cmd.c_str());
    std::ifstream f(out);
    std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    return std::make_pair(WEXITSTATUS(rc), text);
  };
  auto [rc1, t1] = run("check \"" + good + "\"");
  EXPECT_EQ(rc1, 0) << t1;
  EXPECT_NE(t1.find("hybrid: 35 nodes shared with the FEM mesh, 31 of them on the interface"),
            std::string::npos) << t1;
  auto [rc2, t2] = run("check \"" + bad + "\"");
  EXPECT_EQ(rc2, 1) << t2;
  EXPECT_NE(t2.find("fem: hybrid: the FE cell with a node at"), std::string::npos) << t2;
  EXPECT_NE(t2.find("is not one grid cell"), std::string::npos) << t2;
}
