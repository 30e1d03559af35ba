// Probes along a physical curve (probes[i].curve; geometry_probes.cpp): the points are evenly
// spaced by arc length and lie exactly on an inclined straight edge and on a circle (not on the
// inscribed polygon of its mesh); a uniform stress and velocity state is read back at every point
// (solver samples and history.csv); the point table (probes.csv) and summary.json list them.
// The bad inputs: tests/errors/test_geometry_probe_errors.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "silentmpm/case.hpp"
#include "silentmpm/driver.hpp"
#include "silentmpm/history.hpp"
#include "test_geometry_common.hpp"
#include "test_geometry_probes_common.hpp"

#ifndef SMPM_SOURCE_DIR
#define SMPM_SOURCE_DIR "."
#endif

namespace {

using namespace smpm::geotest;

// The ring of studies/geometry (meshes/ring.geo: hole r = a = 0.01 (curve 15), rim r = R = 0.05
// (curve 16), both counter-clockwise from the +x axis), 1 mm cells.
std::string ring_case(const std::string& probes) {
  return R"({
  "grid": { "origin": [-0.052, -0.052], "size": [0.104, 0.104], "cell": 0.001 },
  "time": { "end": 1e-7, "cfl": 0.3 },
  "materials": { "al": { "model": "elastic", "young": 70e9, "poisson": 0.33, "density": 2700 } },
  "geometry": { "file": ")" + std::string(SMPM_SOURCE_DIR) + R"(/meshes/ring.geo", "size": 0.001,
                "parameters": { "a": 0.01, "R": 0.05 } },
  "bodies": [ { "name": "ring", "material": "al", "surface": 1 } ],
  "probes": [ )" + probes + R"( ],
  "output": { "snapshots": 0, "progress": false }
})";
}

smpm::Case load(const std::string& name, const std::string& json) {
  return smpm::load_case(write_file(name, json).string());
}

// The probes of `c` named <along>_*, in order.
std::vector<smpm::ProbeSpec> points_of(const smpm::Case& c, const std::string& along) {
  std::vector<smpm::ProbeSpec> v;
  for (const auto& p : c.probes)
    if (p.along == along) v.push_back(p);
  return v;
}

TEST(GeometryProbes, InclinedEdgeExactPositionsAndSpacing) {
  write_file("probes_inclined.geo", inclined_geo(kAngle));
  const smpm::Case c = load(
      "probes_inclined.json",
      inclined_case("probes_inclined.geo",
                    R"({ "name": "edge", "curve": 12, "count": 11 },
                       { "name": "back", "curve": "inclined", "count": 5, "reverse": true },
                       { "name": "every", "curve": 12, "spacing": 0.003, "fields": ["sxx", "vy"] })"));
  const double xb = kIncXb, xt = kIncXb - kIncH * std::tan(kAngle), H = kIncH;
  const double L = H / std::cos(kAngle);
  const double tol = 1e-12 * L;
  // count 11: s_k = k L / 10, from (xb, 0) (the curve's direction) to (xt, H).
  const auto e = points_of(c, "edge");
  ASSERT_EQ(e.size(), 11u);
  for (std::size_t k = 0; k < e.size(); ++k) {
    const double f = k / 10.0;
    EXPECT_EQ(e[k].name, "edge_" + std::string(k < 10 ? "0" : "") + std::to_string(k));
    EXPECT_NEAR(e[k].x, xb + f * (xt - xb), tol) << k;
    EXPECT_NEAR(e[k].y, f * H, tol) << k;
    EXPECT_NEAR(e[k].s, f * L, tol) << k;
    EXPECT_EQ(e[k].fields.size(), 7u);  // all point-probe quantities by default
  }
  // reverse: from (xt, H) to (xb, 0).
  const auto b = points_of(c, "back");
  ASSERT_EQ(b.size(), 5u);
  for (std::size_t k = 0; k < b.size(); ++k) {
    const double f = 1 - k / 4.0;
    EXPECT_NEAR(b[k].x, xb + f * (xt - xb), tol) << k;
    EXPECT_NEAR(b[k].y, f * H, tol) << k;
  }
  // spacing 3 mm: floor(L / 3 mm) + 1 = 8 points at s = 0, 3, ..., 21 mm (L = 23.09 mm).
  const auto s = points_of(c, "every");
  ASSERT_EQ(s.size(), static_cast<std::size_t>(std::floor(L / 0.003)) + 1);
  ASSERT_EQ(s.size(), 8u);
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double f = 0.003 * k / L;
    EXPECT_NEAR(s[k].s, 0.003 * k, tol);
    EXPECT_NEAR(s[k].x, xb + f * (xt - xb), tol) << k;
    EXPECT_NEAR(s[k].y, f * H, tol) << k;
    EXPECT_EQ(s[k].fields, (std::vector<std::string>{"sxx", "vy"}));
  }
}

TEST(GeometryProbes, CircleExactPositionsByArcLength) {
  const smpm::Case c = load("probes_ring.json",
                            ring_case(R"({ "name": "rim", "curve": 16, "count": 24 },
                                         { "name": "hole", "curve": "hole", "spacing": 0.01 })"));
  const double R = 0.05, a = 0.01;
  // Closed curve, count 24: 24 points at theta_k = 2 pi k / 24 from (R, 0), counter-clockwise.
  const auto rim = points_of(c, "rim");
  ASSERT_EQ(rim.size(), 24u);
  double worst = 0;
  for (std::size_t k = 0; k < rim.size(); ++k) {
    const double th = 2 * M_PI * k / 24;
    worst = std::max(worst, std::hypot(rim[k].x - R * std::cos(th), rim[k].y - R * std::sin(th)));
    EXPECT_NEAR(rim[k].s, R * th, 1e-10 * R) << k;
  }
  std::printf("  rim: largest distance from R (cos, sin)(2 pi k / 24): %.3g m (R = %g m)\n", worst, R);
  EXPECT_LT(worst, 1e-10 * R);
  // The mesh's chords (1 mm on R = 50 mm) would put a midpoint s^2 / 8R = 2.5e-6 m inside the
  // circle and shorten the perimeter by 1.6e-5 relative: the exact positions are not the polygon's.
  // spacing 10 mm on the hole (perimeter 2 pi a = 62.8 mm): 7 points at theta = 0, 1, ..., 6 rad.
  const auto hole = points_of(c, "hole");
  ASSERT_EQ(hole.size(), 7u);
  for (std::size_t k = 0; k < hole.size(); ++k) {
    EXPECT_NEAR(hole[k].x, a * std::cos(static_cast<double>(k)), 1e-10 * a) << k;
    EXPECT_NEAR(hole[k].y, a * std::sin(static_cast<double>(k)), 1e-10 * a) << k;
    EXPECT_NEAR(hole[k].s, 0.01 * k, 1e-12) << k;
  }
}

// A physical curve made of two gmsh curves whose end points coincide but are distinct points
// (meshes/convergence.geo: "bottom" = the bottoms of the two plates, which share no point) is
// one chain: 5 points from x = -L to L.
TEST(GeometryProbes, CoincidentEndsJoinTheChain) {
  const smpm::Case c = load("probes_plates.json", R"({
  "grid": { "origin": [-0.12, -0.02], "size": [0.24, 0.14], "cell": 0.01 },
  "time": { "end": 1e-6, "cfl": 0.3 },
  "materials": { "w": { "model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000 } },
  "geometry": { "file": ")" + std::string(SMPM_SOURCE_DIR) + R"(/meshes/convergence.geo", "size": 0.01 },
  "bodies": [ { "name": "al", "material": "w", "surface": "aluminium" },
              { "name": "st", "material": "w", "surface": "steel" } ],
  "probes": [ { "name": "b", "curve": "bottom", "count": 5 } ] })");
  const auto b = points_of(c, "b");
  ASSERT_EQ(b.size(), 5u);
  // Line 3 of the file runs from (-L, 0) to (0, 0): the chain starts at x = -L.
  for (std::size_t k = 0; k < b.size(); ++k) {
    EXPECT_NEAR(b[k].x, -0.1 + 0.05 * k, 1e-14) << k;
    EXPECT_NEAR(b[k].y, 0.0, 1e-14) << k;
    EXPECT_NEAR(b[k].s, 0.05 * k, 1e-14) << k;
  }
}

// A uniform state (stress and velocity of every particle) is read back at every point of the
// curve probes, boundary points included: by the solver's sampling to round-off, and through
// run_case in history.csv to its 10 printed digits; probes.csv and summary.json list the points.
TEST(GeometryProbes, UniformStateReadBackAtEveryPoint) {
  smpm::Case c = load("probes_uniform.json",
                      ring_case(R"({ "name": "P", "at": [0.03, 0.0] },
                                   { "name": "rim", "curve": 16, "count": 16, "body": "ring" },
                                   { "name": "hole", "curve": 15, "count": 9, "fields": ["sxy", "vx"] })"));
  ASSERT_EQ(c.probes.size(), 1u + 16u + 9u);
  smpm::Solver& s = *c.solver;
  const double sxx = -123.456e6, syy = 78.9e6, szz = -11.5e6, sxy = 42.25e6, vx = 3.5, vy = -1.25;
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    s.p.sxx[k] = sxx; s.p.syy[k] = syy; s.p.szz[k] = szz; s.p.sxy[k] = sxy;
    s.p.vx[k] = vx; s.p.vy[k] = vy;
  }
  // The state is set behind the energy account's back (its initial energy stays 0): the
  // energy health check would stop the run it steps below.
  s.opt.energy_bound = 0;
  std::vector<std::array<double, 2>> pts;
  std::vector<int> bodies;
  for (const auto& p : c.probes) pts.push_back({p.x, p.y}), bodies.push_back(p.body);
  const auto samples = s.sample(pts, bodies);
  for (std::size_t q = 0; q < samples.size(); ++q) {
    ASSERT_TRUE(samples[q].valid) << c.probes[q].name;
    EXPECT_NEAR(samples[q].sxx, sxx, 1e-13 * std::fabs(sxx)) << c.probes[q].name;
    EXPECT_NEAR(samples[q].syy, syy, 1e-13 * std::fabs(syy)) << c.probes[q].name;
    EXPECT_NEAR(samples[q].szz, szz, 1e-13 * std::fabs(szz)) << c.probes[q].name;
    EXPECT_NEAR(samples[q].sxy, sxy, 1e-13 * std::fabs(sxy)) << c.probes[q].name;
    EXPECT_NEAR(samples[q].vx, vx, 1e-13 * std::fabs(vx)) << c.probes[q].name;
    EXPECT_NEAR(samples[q].vy, vy, 1e-13 * std::fabs(vy)) << c.probes[q].name;
  }
  // Through the driver: the first row of history.csv is the state before the first step.
  const fs::path out = scratch() / "probes_uniform_out";
  smpm::run_case(c, out.string());
  const smpm::History h = smpm::read_history((out / "history.csv").string());
  std::vector<std::string> expect_cols = {"P.sxx", "P.syy", "P.szz", "P.sxy", "P.J2", "P.vx", "P.vy"};
  for (int k = 0; k < 16; ++k)
    for (const char* f : {"sxx", "syy", "szz", "sxy", "J2", "vx", "vy"})
      expect_cols.push_back("rim_" + std::string(k < 10 ? "0" : "") + std::to_string(k) + "." + f);
  for (int k = 0; k < 9; ++k)
    for (const char* f : {"sxy", "vx"}) expect_cols.push_back("hole_0" + std::to_string(k) + "." + f);
  ASSERT_GE(h.columns.size(), expect_cols.size());
  for (std::size_t i = 0; i < expect_cols.size(); ++i) EXPECT_EQ(h.columns[i], expect_cols[i]);
  auto first = [&](const std::string& col) {
    for (std::size_t i = 0; i < h.columns.size(); ++i)
      if (h.columns[i] == col) return h.data[i].at(0);
    ADD_FAILURE() << "no column " << col;
    return std::nan("");
  };
  for (int k = 0; k < 16; ++k) {
    const std::string n = "rim_" + std::string(k < 10 ? "0" : "") + std::to_string(k);
    EXPECT_NEAR(first(n + ".sxx"), sxx, 1e-9 * std::fabs(sxx)) << n;
    EXPECT_NEAR(first(n + ".syy"), syy, 1e-9 * std::fabs(syy)) << n;
    EXPECT_NEAR(first(n + ".sxy"), sxy, 1e-9 * std::fabs(sxy)) << n;
    EXPECT_NEAR(first(n + ".vy"), vy, 1e-9 * std::fabs(vy)) << n;
  }
  for (int k = 0; k < 9; ++k) {
    const std::string n = "hole_0" + std::to_string(k);
    EXPECT_NEAR(first(n + ".sxy"), sxy, 1e-9 * std::fabs(sxy)) << n;
    EXPECT_NEAR(first(n + ".vx"), vx, 1e-9 * std::fabs(vx)) << n;
  }
  // probes.csv: one row per probe, the positions to 17 digits, the arc length of curve points.
  std::ifstream f(out / "probes.csv");
  std::string line;
  std::getline(f, line);
  EXPECT_EQ(line, "name,x,y,along,s");
  std::size_t rows = 0;
  while (std::getline(f, line)) {
    std::stringstream ss(line);
    std::string name, x, y, along, sarc;
    std::getline(ss, name, ','); std::getline(ss, x, ','); std::getline(ss, y, ',');
    std::getline(ss, along, ','); std::getline(ss, sarc, ',');
    ASSERT_LT(rows, c.probes.size());
    const auto& p = c.probes[rows++];
    EXPECT_EQ(name, p.name);
    EXPECT_EQ(std::stod(x), p.x);
    EXPECT_EQ(std::stod(y), p.y);
    EXPECT_EQ(along, p.along);
    if (!p.along.empty()) {
      EXPECT_EQ(std::stod(sarc), p.s);
    }
  }
  EXPECT_EQ(rows, c.probes.size());
  std::ifstream js(out / "summary.json");
  const auto sum = nlohmann::json::parse(js);
  ASSERT_EQ(sum["curve_probes"].size(), 2u);
  EXPECT_EQ(sum["curve_probes"][0]["name"], "rim");
  EXPECT_EQ(sum["curve_probes"][0]["points"], 16);
  EXPECT_EQ(sum["curve_probes"][0]["last"], "rim_15");
  EXPECT_NEAR(sum["curve_probes"][0]["spacing"].get<double>(), 2 * M_PI * 0.05 / 16, 1e-12);
  EXPECT_EQ(sum["curve_probes"][1]["points"], 9);
  EXPECT_EQ(sum["bodies"][0]["particles"], s.p.size());
}

// Many probes are sampled through a cell index (Solver::sample with more than 8 points): the
// same numbers, bit for bit, as sampling each point alone, for a non-uniform state.
TEST(GeometryProbes, IndexedSamplingMatchesOnePointAtATime) {
  smpm::Case c = load("probes_indexed.json",
                      ring_case(R"({ "name": "rim", "curve": 16, "count": 40 },
                                   { "name": "hole", "curve": 15, "count": 12, "body": "ring" },
                                   { "name": "P", "at": [0.03, 0.001] })"));
  smpm::Solver& s = *c.solver;
  for (std::size_t k = 0; k < s.p.size(); ++k) {
    s.p.sxx[k] = 1e9 * s.p.x[k] + 3e8 * s.p.y[k] * s.p.y[k] / 0.05;
    s.p.syy[k] = -2e9 * s.p.x[k] * s.p.y[k] / 0.05;
    s.p.sxy[k] = 5e6 * std::sin(100 * s.p.x[k]);
    s.p.vx[k] = std::cos(80 * s.p.y[k]);
  }
  std::vector<std::array<double, 2>> pts;
  std::vector<int> bodies;
  for (const auto& p : c.probes) pts.push_back({p.x, p.y}), bodies.push_back(p.body);
  ASSERT_GT(pts.size(), 8u);
  const auto all = s.sample(pts, bodies);
  for (std::size_t q = 0; q < pts.size(); ++q) {
    const auto one = s.sample({pts[q]}, {bodies[q]})[0];
    EXPECT_EQ(all[q].valid, one.valid) << c.probes[q].name;
    EXPECT_EQ(all[q].sxx, one.sxx) << c.probes[q].name;
    EXPECT_EQ(all[q].syy, one.syy) << c.probes[q].name;
    EXPECT_EQ(all[q].sxy, one.sxy) << c.probes[q].name;
    EXPECT_EQ(all[q].vx, one.vx) << c.probes[q].name;
  }
  // And the rim reads the radial-ish field it should: sxx = 1e9 x + ... at x = R cos(theta).
  EXPECT_NEAR(all[0].sxx, 1e9 * 0.05, 0.02 * 1e9 * 0.05);
}

}  // namespace
