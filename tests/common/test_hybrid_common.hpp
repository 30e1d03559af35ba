#pragma once
// Helpers for the MPM-FEM hybrid tests: a tungsten strip [0, L] x [0, H] whose part x < xi is
// particles and x > xi finite elements (a gmsh rectangle with curves 11 left = interface,
// 12 right, 13 bottom, 14 top), or all particles, or all finite elements.
#include <unistd.h>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "silentmpm/geo_box.hpp"
#include "common.hpp"
#include "silentmpm/fem.hpp"
#include "silentmpm/hybrid.hpp"

namespace smpm::hybrid_testing {

namespace fs = std::filesystem;

// .geo of [x0, x1] x [y0, y1], square transfinite quads of size h.
inline std::string box_geo(const std::string& name, double x0, double y0, double x1, double y1,
                           double h) {
  const fs::path d = fs::temp_directory_path() / ("smpm_hybrid_tests_" + std::to_string(::getpid()));
  fs::create_directories(d);
  const fs::path p = d / (name + ".geo");
  std::ofstream f(p);
  f << smpm::fem::box_geo_text(x0, y0, x1, y1, h);
  return p.string();
}

inline fem::Boundary fe_bc(fem::Boundary::Kind k, int curve, const std::string& name) {
  fem::Boundary b;
  b.kind = k;
  b.curves = {curve};
  b.name = name;
  return b;
}

enum class Right { Free, Dashpot };

struct Strip {
  int cells = 200;        // total length in cells
  int mpm_cells = 60;     // particles on [0, mpm_cells h] (cells = mpm_cells: all MPM; 0: all FE)
  int height = 2;         // cells across
  int ppc_side = 1;
  double h = 1e-3;
  double cfl = 0.3;
  bool rollers = true;    // top and bottom hold v_y (a 1D column); false: free plate
  Right right = Right::Free;
  double amplitude = 100e6;  // compressive normal traction on the left end
  TimeFunction fn;
  Scheme scheme = Scheme::MUSL;
  double v0 = 0;          // initial x velocity of the particles
  bool load = true;       // the traction on the left end
  double gravity_x = 0, gravity_y = 0;  // both regions' (m/s^2)
  int mass_correction = 0;  // the MPM region's scheme.mass_correction
  bool fe_side_dashpots = false;  // without rollers: LK dashpots on the elements' top and bottom
  Seeding seeding = Seeding::Uniform;
};

struct HybRun {
  std::unique_ptr<Solver> mpm;
  std::unique_ptr<fem::Solver> fe;
  std::unique_ptr<Hybrid> hyb;
  double dt = 0;
  void step() {
    if (hyb) hyb->step();
    else if (mpm) mpm->step();
    else fe->step();
  }
  double time() const { return mpm ? mpm->t : fe->t; }
};

inline std::unique_ptr<fem::Solver> strip_fe(const Strip& c, double x0, bool loaded_left) {
  fem::Spec s;
  const double L = c.cells * c.h, H = c.height * c.h;
  s.mesh = fem::load_mesh(box_geo("strip_" + std::to_string(c.cells) + "_" +
                                      std::to_string(c.mpm_cells) + "_" +
                                      std::to_string(c.height),
                                  x0, 0, L, H, c.h),
                          c.h);
  s.degree = 1;
  s.materials = {testing::tungsten()};
  s.region_material = {{1, 0}};
  s.threads = 1;
  s.gravity_x = c.gravity_x;
  s.gravity_y = c.gravity_y;
  if (c.rollers) {
    auto b13 = fe_bc(fem::Boundary::Kind::Roller, 13, "bottom");
    auto b14 = fe_bc(fem::Boundary::Kind::Roller, 14, "top");
    b13.component = b14.component = 1;
    s.boundaries = {b13, b14};
  }
  if (loaded_left) {
    auto load = fe_bc(fem::Boundary::Kind::Traction, 11, "load");
    load.normal = -c.amplitude;
    load.fn = c.fn;
    s.boundaries.push_back(load);
  }
  if (c.right == Right::Dashpot) s.boundaries.push_back(fe_bc(fem::Boundary::Kind::Dashpot, 12, "right"));
  if (c.fe_side_dashpots && !c.rollers) {
    s.boundaries.push_back(fe_bc(fem::Boundary::Kind::Dashpot, 13, "bottom"));
    s.boundaries.push_back(fe_bc(fem::Boundary::Kind::Dashpot, 14, "top"));
  }
  return std::make_unique<fem::Solver>(s);
}

// A free strip (no rollers, no load) of 40 cells, the first 20 of particles on a 2 x 2 lattice,
// `height` cells high: the momentum tests' (with v0 or gravity set).
inline Strip free_strip(int height) {
  Strip c;
  c.cells = 40;
  c.mpm_cells = 20;
  c.height = height;
  c.rollers = false;
  c.load = false;
  c.ppc_side = 2;
  return c;
}

inline HybRun make_strip(const Strip& c) {
  HybRun m;
  const double h = c.h, L = c.cells * h, H = c.height * h, xi = c.mpm_cells * h;
  const double dt = c.cfl * h / testing::tungsten().cd;
  m.dt = dt;
  if (c.mpm_cells > 0) {
    auto s = std::make_unique<Solver>();
    s->materials.push_back(testing::tungsten());
    const int nx = (c.mpm_cells < c.cells ? c.mpm_cells : c.cells) + 4;
    s->grid.init(-2 * h, 0.0, h, nx, c.height);
    s->seed_rectangle(0, 0, xi, H, c.ppc_side, 0, 0, c.v0, 0, c.seeding);
    if (c.rollers) {
      s->constraints.push_back({"bottom", s->nodes_in_box(-1, 0, 1, 0), 2});
      s->constraints.push_back({"top", s->nodes_in_box(-1, H, 1, H), 2});
    }
    if (c.load) {
      TractionLoad tl;
      tl.layer = s->select_layer("left", 0, 0, H, 0, 0, -1, 0, h);
      tl.normal = -c.amplitude;
      tl.fn = c.fn;
      s->tractions.push_back(tl);
    }
    if (c.mpm_cells == c.cells && c.right == Right::Dashpot) {
      SilentBoundary sb;
      sb.layer = s->select_layer("right", 0, L, 0, L, H, 1, 0, h);
      s->silents.push_back(sb);
    }
    s->opt.scheme = c.scheme;
    s->opt.mass_correction = c.mass_correction;
    s->opt.threads = 1;
    s->opt.gravity_x = c.gravity_x;
    s->opt.gravity_y = c.gravity_y;
    s->dt = dt;
    s->finalize();
    m.mpm = std::move(s);
  }
  if (c.mpm_cells < c.cells) {
    m.fe = strip_fe(c, xi, c.mpm_cells == 0 && c.load);
    if (m.mpm) {
      m.hyb = std::make_unique<Hybrid>(*m.mpm, *m.fe);
      m.hyb->set_dt(dt);
    } else {
      m.fe->set_dt(dt);
    }
  }
  return m;
}

// The uniform-strain patch: uniaxial strain eps across the interface of a strip (c's sizes are
// set here: 30 cells, 12 of particles on a 2 x 2 lattice, 4 high, rollers on top and bottom).
// The particles carry sigma = C eps, the FE nodes u_x = eps x, and the traction sigma_xx acts on
// both ends (MPM left, FE right): every node is in equilibrium.
inline HybRun make_uniform_strain_patch(Strip& c, double eps) {
  const Material mat = smpm::testing::tungsten();
  const double sxx = mat.lambda * eps + 2 * mat.mu * eps, syy = mat.lambda * eps;
  c.cells = 30;
  c.mpm_cells = 12;
  if (c.height < 4) c.height = 4;
  c.ppc_side = 2;
  c.load = false;
  HybRun m = make_strip(c);
  const double L = c.cells * c.h, H = c.height * c.h;
  // Rebuild with the loads: particles' stress, MPM traction on the left, FE traction on the right.
  {
    Solver& s = *m.mpm;
    for (std::size_t k = 0; k < s.p.size(); ++k) {
      s.p.sxx[k] = sxx; s.p.syy[k] = syy; s.p.szz[k] = syy; s.p.sxy[k] = 0;
    }
    TractionLoad tl;
    tl.layer = s.select_layer("left", 0, 0, H, 0, 0, -1, 0, c.h);
    tl.normal = sxx;  // t = sigma n, n = (-1, 0): t . n = sigma_xx
    s.tractions.push_back(tl);
    s.finalize();
  }
  {
    fem::Spec spec;
    spec.mesh = fem::load_mesh(box_geo("patch", c.mpm_cells * c.h, 0, L, H, c.h), c.h);
    spec.materials = {mat};
    spec.region_material = {{1, 0}};
    spec.threads = 1;
    auto b13 = fe_bc(fem::Boundary::Kind::Roller, 13, "bottom");
    auto b14 = fe_bc(fem::Boundary::Kind::Roller, 14, "top");
    b13.component = b14.component = 1;
    auto right = fe_bc(fem::Boundary::Kind::Traction, 12, "right");
    right.normal = sxx;
    spec.boundaries = {b13, b14, right};
    m.hyb.reset();
    m.fe = std::make_unique<fem::Solver>(spec);
    for (std::size_t i = 0; i < m.fe->nodes(); ++i) m.fe->displacement()[2 * i] = eps * m.fe->node_x()[i];
    m.hyb = std::make_unique<Hybrid>(*m.mpm, *m.fe);
    m.hyb->set_dt(m.dt);
  }
  return m;
}

// sigma_xx history at (x, y): from the particles where x lies in the MPM part, else from the FE.
struct Probe {
  HybRun& m;
  double x, y, xi;
  int fe_index = -1;
  Probe(HybRun& m_, double x_, double y_, double xi_) : m(m_), x(x_), y(y_), xi(xi_) {
    if (!(m.mpm && x < xi)) fe_index = m.fe->add_probe(x, y);
  }
  double sxx() const {
    if (fe_index < 0) return m.mpm->sample(x, y).sxx;
    return m.fe->sample()[fe_index].sxx;
  }
};

// The probe's sigma_xx after every step up to t_end.
inline std::vector<double> record(HybRun& m, const Strip& c, double x, double y, double t_end) {
  Probe p(m, x, y, c.mpm_cells * c.h);
  std::vector<double> out;
  while (m.time() < t_end - 0.5 * m.dt) {
    m.step();
    out.push_back(p.sxx());
  }
  return out;
}

inline TimeFunction bell(double duration) {
  TimeFunction f;
  f.kind = TimeFunction::Kind::Sin2Pulse;
  f.duration = duration;
  f.ramp = 0.5 * duration;
  return f;
}

}  // namespace smpm::hybrid_testing
