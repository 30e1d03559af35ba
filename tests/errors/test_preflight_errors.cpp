// Pre-flight limits of gmsh inputs: a device or a pipe given as a geometry or mesh file, and an
// FE mesh size that would make more cells than a run could hold, are refused before anything is
// read or meshed (both used to hang: /dev/zero was read without end, 1e12 cells were meshed).
#include <gtest/gtest.h>

#include <chrono>

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

}  // namespace
}  // namespace smpm
