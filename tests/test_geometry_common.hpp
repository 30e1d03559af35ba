#pragma once
// Helpers of the geometry tests: a scratch directory, .geo texts, point-in-element.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "common.hpp"
#include "silentmpm/geometry.hpp"

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
