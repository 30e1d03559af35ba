#pragma once
// Helpers of the geometry tests: a scratch directory, .geo texts, point-in-element.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "common.hpp"
#include "silentmpm/case.hpp"
#include "silentmpm/geometry.hpp"

#ifndef SMPM_CLI
#define SMPM_CLI ""
#endif

namespace smpm::geotest {

namespace fs = std::filesystem;
using smpm::testing::tungsten;

inline fs::path scratch() {
  struct Scratch {
    fs::path dir = fs::temp_directory_path() /
                   ("smpm_test_geometry_" + std::to_string(static_cast<long>(::getpid())));
    Scratch() { fs::create_directories(dir); }
    ~Scratch() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  };
  static const Scratch s;
  return s.dir;
}

inline fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path p = scratch() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

inline std::string read_text(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// Loading the case file fails with one line that starts with the file's path and contains every
// string of `expect`.
inline void expect_case_error(const fs::path& file, const std::vector<std::string>& expect,
                              const std::string& name) {
  try {
    smpm::load_case(file.string());
    ADD_FAILURE() << name << ": no error";
  } catch (const smpm::CaseError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(file.string() + ": ", 0), 0u) << m;  // starts with the case file
    for (const auto& s : expect) EXPECT_NE(m.find(s), std::string::npos) << "missing \"" << s << "\" in: " << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << "one line: " << m;
  }
}

// `silentmpm check FILE` exits non-zero with every string of `expect` on stderr (skipped when the
// CLI is not built).
inline void expect_cli_error(const fs::path& file, const std::vector<std::string>& expect,
                             const std::string& name) {
  const std::string cli = SMPM_CLI;
  if (cli.empty() || !fs::exists(cli)) GTEST_SKIP() << "CLI binary not built";
  const fs::path err = scratch() / ("cli_err_" + name + ".txt");
  const std::string cmd = "\"" + cli + "\" check \"" + file.string() + "\" >/dev/null 2>\"" + err.string() + "\"";
  EXPECT_NE(std::system(cmd.c_str()), 0) << name;
  const std::string m = read_text(err);
  for (const auto& s : expect) EXPECT_NE(m.find(s), std::string::npos) << "missing \"" << s << "\" in: " << m;
}

inline std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

inline bool point_in_element(const Geometry& g, const std::array<int, 4>& e, double px,
                             double py) {
  auto tri = [&](int a, int b, int c) {
    const double o = (g.x[b] - g.x[a]) * (g.y[c] - g.y[a]) - (g.y[b] - g.y[a]) * (g.x[c] - g.x[a]);
    auto side = [&](int i, int j) {
      return ((g.x[j] - g.x[i]) * (py - g.y[i]) - (g.y[j] - g.y[i]) * (px - g.x[i])) * o >= 0;
    };
    return side(a, b) && side(b, c) && side(c, a);
  };
  return tri(e[0], e[1], e[2]) || (e[3] >= 0 && tri(e[0], e[2], e[3]));
}

// A plate of height kIncH whose right edge (physical curve 12) has the outward normal
// (cos angle, sin angle); left 11, bottom 13, top 14.
constexpr double kIncH = 0.02, kIncXb = 0.025;
inline std::string inclined_geo(double angle) {
  return "DefineConstant[ h = 0.001 ];\n"
         "H = " + num(kIncH) + "; xb = " + num(kIncXb) + "; xt = " +
         num(kIncXb - kIncH * std::tan(angle)) + ";\n" + R"(
Point(1) = {0, 0, 0, h}; Point(2) = {xb, 0, 0, h}; Point(3) = {xt, H, 0, h}; Point(4) = {0, H, 0, h};
Line(1) = {4, 1}; Line(2) = {2, 3}; Line(3) = {1, 2}; Line(4) = {3, 4};
Curve Loop(1) = {3, 2, 4, 1}; Plane Surface(1) = {1};
Physical Surface("plate", 1) = {1};
Physical Curve("left", 11) = {1}; Physical Curve("inclined", 12) = {2};
Physical Curve("bottom", 13) = {3}; Physical Curve("top", 14) = {4};
)";
}

}  // namespace smpm::geotest
