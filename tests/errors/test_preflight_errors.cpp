// Pre-flight limits of gmsh inputs: a device or a pipe given as a geometry or mesh file, and an
// FE mesh size that would make more cells than a run could hold, are refused before anything is
// read or meshed (both used to hang: /dev/zero was read without end, 1e12 cells were meshed).
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>

#include "silentmpm/case.hpp"
#include "test_restart_common.hpp"

namespace smpm {
namespace {

using namespace restart_testing;

void expect_fast_error(const json& c, const std::string& name, const std::string& expect) {
  const std::string file = write_case("preflight_" + name, c);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    load_case(file);
    FAIL() << name << ": no error";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << name << ": " << e.what();
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(s, 20.0) << name << ": the error took " << s << " s";
}

TEST(Preflight, DevicesAndHugeMeshesAreRefusedBeforeMeshing) {
  json fem = hybrid_case_testing::plate_case("fem");
  fem["fem"]["size"] = 1e-7;
  expect_fast_error(fem, "fem_size", "a mesh of size 1e-07 would have about 1.8e+11 cells");
  json fem_dev = hybrid_case_testing::plate_case("fem");
  fem_dev["fem"]["mesh"] = "/dev/zero";
  fem_dev["fem"].erase("size");
  expect_fast_error(fem_dev, "fem_device", "/dev/zero: is not a regular file");
  json mpm = small_plate(1, 10);
  mpm["geometry"] = {{"file", "/dev/zero"}};
  expect_fast_error(mpm, "geometry_device", "geometry.file: /dev/zero: is not a regular file");
}

// A grid and particles that would not fit in memory: refused before anything is allocated, with
// the estimate (the grid is sized from this machine's memory; beyond what the case limits of
// 2e8 cells and particles can ask for, the test is skipped).
TEST(Preflight, RunLargerThanMemoryIsRefusedBeforeAllocating) {
  const double phys = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * ::sysconf(_SC_PAGE_SIZE);
  const double per_cell = 15 * 8.0 + 4 * 161.0;  // grid node + 4 particles with the film block
  const double cells = 0.9 * phys / per_cell;
  if (cells > 1.9e8) GTEST_SKIP() << "this machine has more memory than a case may ask for";
  const long n = static_cast<long>(std::ceil(std::sqrt(cells)));
  json c = small_plate(4, 10);
  const double h = 1e-3;
  c["grid"] = {{"origin", {0.0, 0.0}}, {"size", {n * h, n * h}}, {"cell", h}};
  c["bodies"][0]["box"] = {0.0, 0.0, n * h, n * h};
  c["boundaries"] = json::array();
  c["probes"] = json::array();
  expect_fast_error(c, "memory", "the run would need about");
}

}  // namespace
}  // namespace smpm
