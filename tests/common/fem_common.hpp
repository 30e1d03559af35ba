#pragma once
// Helpers for the FEM tests: rectangular gmsh meshes written on the fly, and FEM models.
#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "silentmpm/geo_box.hpp"
#include "silentmpm/fem.hpp"

namespace smpm::fem_testing {

namespace fs = std::filesystem;

inline fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("smpm_fem_tests_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

// A .geo of the rectangle [0, lx] x [0, ly] with the project's group convention (surface 1,
// curves 11 left, 12 right, 13 bottom, 14 top) and square transfinite quads of size h
// (DefineConstant "Parameters/h"). Returns its path.
inline std::string rectangle_geo(const std::string& name, double lx, double ly, double h) {
  const fs::path p = temp_dir() / (name + ".geo");
  std::ofstream f(p);
  f << smpm::fem::box_geo_text(0, 0, lx, ly, h);
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

// A steel rectangle of nx x ny square cells of 1 mm (the groups of rectangle_geo), Q`degree`,
// one thread, no boundary conditions.
inline fem::Spec steel_rectangle(const std::string& name, int nx, int ny, int degree) {
  fem::Spec s;
  const double h = 1e-3;
  s.mesh = fem::load_mesh(rectangle_geo(name, nx * h, ny * h, h), h);
  s.degree = degree;
  s.materials = {elastic("steel", 2e11, 0.25, 7800)};
  s.region_material = {{1, 0}};
  s.threads = 1;
  return s;
}

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
