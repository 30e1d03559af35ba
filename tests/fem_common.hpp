#pragma once
// Helpers for the FEM tests: rectangular gmsh meshes written on the fly, and FEM models.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "silentmpm/fem.hpp"

namespace smpm::fem_testing {

namespace fs = std::filesystem;

inline fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / "smpm_fem_tests";
  fs::create_directories(d);
  return d;
}

// A .geo of the rectangle [0, lx] x [0, ly] with the project's group convention (surface 1,
// curves 11 left, 12 right, 13 bottom, 14 top) and square transfinite quads of size h
// (DefineConstant "Parameters/h"). Returns its path.
inline std::string rectangle_geo(const std::string& name, double lx, double ly, double h) {
  const fs::path p = temp_dir() / (name + ".geo");
  std::ofstream f(p);
  char buf[2048];
  std::snprintf(buf, sizeof buf,
                "DefineConstant[ h = {%.17g, Name \"Parameters/h\"} ];\n"
                "Point(1) = {0, 0, 0}; Point(2) = {%.17g, 0, 0};\n"
                "Point(3) = {%.17g, %.17g, 0}; Point(4) = {0, %.17g, 0};\n"
                "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
                "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
                "Transfinite Curve{1, 3} = Round(%.17g / h) + 1;\n"
                "Transfinite Curve{2, 4} = Round(%.17g / h) + 1;\n"
                "Transfinite Surface{1}; Recombine Surface{1};\n"
                "Physical Surface(\"body\", 1) = {1};\n"
                "Physical Curve(\"left\", 11) = {4}; Physical Curve(\"right\", 12) = {2};\n"
                "Physical Curve(\"bottom\", 13) = {1}; Physical Curve(\"top\", 14) = {3};\n",
                h, lx, lx, ly, ly, lx, ly);
  f << buf;
  return p.string();
}

inline Material elastic(const std::string& name, double E, double nu, double rho) {
  Material m;
  m.name = name;
  m.E = E;
  m.nu = nu;
  m.rho = rho;
  m.derive();
  return m;
}

inline Material tungsten() { return elastic("tungsten", 411e9, 0.28, 15000); }

inline fem::Boundary bc(fem::Boundary::Kind k, int curve, const std::string& name) {
  fem::Boundary b;
  b.kind = k;
  b.curves = {curve};
  b.name = name;
  return b;
}

inline TimeFunction sin2_bell(double duration) {
  TimeFunction f;
  f.kind = TimeFunction::Kind::Sin2Pulse;
  f.duration = duration;
  f.ramp = 0.5 * duration;
  return f;
}

}  // namespace smpm::fem_testing
