// gmsh geometries: lattice seeding of physical surfaces (area, mass, particles per cell),
// boundary layers from physical curves (normals, boundary-length weights, traction sum t L),
// node sets from curves, and the case keys geometry / surface / curve.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <omp.h>
#include <unistd.h>

#include "silentmpm/case.hpp"
#include "silentmpm/geometry.hpp"
#include "silentmpm/solver.hpp"
#include "test_geometry_common.hpp"

#ifndef SMPM_SOURCE_DIR
#define SMPM_SOURCE_DIR "."
#endif

namespace {

using namespace smpm;
using namespace smpm::geotest;

constexpr double kH = 1e-3;  // grid cell

// A solver with a grid [-4h, 4h + 30h]^2 and one tungsten material.
std::unique_ptr<Solver> make_solver() {
  auto s = std::make_unique<Solver>();
  s->materials.push_back(tungsten());
  s->grid.init(-4 * kH, -4 * kH, kH, 38, 38);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Seeding.

const char* kRectangle = R"(
DefineConstant[ h = 0.001 ];
Point(1) = {0, 0, 0, h}; Point(2) = {0.02, 0, 0, h};
Point(3) = {0.02, 0.01, 0, h}; Point(4) = {0, 0.01, 0, h};
Line(1) = {4, 1}; Line(2) = {2, 3}; Line(3) = {1, 2}; Line(4) = {3, 4};
Curve Loop(1) = {3, 2, 4, 1}; Plane Surface(1) = {1};
Physical Surface("plate", 1) = {1};
Physical Curve("left", 11) = {1}; Physical Curve("right", 12) = {2};
Physical Curve("bottom", 13) = {3}; Physical Curve("top", 14) = {4};
)";

// Disk of radius R about (xc, yc), off the grid lines.
const double kXc = 0.0131, kYc = 0.0127, kR = 0.0093;
std::string disk_geo() {
  return "DefineConstant[ h = 0.001 ];\n"
         "xc = " + num(kXc) + "; yc = " + num(kYc) + "; R = " + num(kR) + ";\n"
         R"(
Point(1) = {xc, yc, 0, h}; Point(2) = {xc + R, yc, 0, h}; Point(3) = {xc, yc + R, 0, h};
Point(4) = {xc - R, yc, 0, h}; Point(5) = {xc, yc - R, 0, h};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4}; Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Physical Surface("disk", 1) = {1};
Physical Curve("rim", 15) = {1, 2, 3, 4};
)";
}

// L-shape: [a, a + 2c] x [a, a + 2c] minus the upper right quarter, corners off the grid lines.
const double kA = 0.00037, kC = 0.0113;
std::string l_geo() {
  return "DefineConstant[ h = 0.001 ];\n"
         "a = " + num(kA) + "; c = " + num(kC) + ";\n"
         R"(
Point(1) = {a, a, 0, h}; Point(2) = {a + 2*c, a, 0, h}; Point(3) = {a + 2*c, a + c, 0, h};
Point(4) = {a + c, a + c, 0, h}; Point(5) = {a + c, a + 2*c, 0, h}; Point(6) = {a, a + 2*c, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6};
Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Plane Surface(1) = {1};
Physical Surface("L", 1) = {1};
Physical Curve("inner", 15) = {3, 4};
)";
}

struct SeedResult {
  std::size_t n = 0;
  double volume = 0, mass = 0;
};

SeedResult seed(Solver& s, const Geometry& g, int n_side) {
  s.p.resize(0);
  SeedResult r;
  r.n = seed_surface(s, g, g.surfaces[0], n_side, 0, 0, 0, 0);
  for (std::size_t k = 0; k < s.p.size(); ++k) r.volume += s.p.vol[k], r.mass += s.p.mass[k];
  return r;
}

TEST(GeometrySeeding, RectangleExact) {
  auto s = make_solver();
  const Geometry g = load_geometry(write_file("rect.geo", kRectangle).string(), 0.5 * kH);
  ASSERT_EQ(g.surfaces.size(), 1u);
  EXPECT_NEAR(g.area(g.surfaces[0]), 2e-4, 1e-16);
  for (int n : {1, 2, 3}) {
    const SeedResult r = seed(*s, g, n);
    // The rectangle lies on grid lines: 20 x 10 cells, n^2 particles in each.
    EXPECT_EQ(r.n, static_cast<std::size_t>(200 * n * n)) << "n = " << n;
    EXPECT_NEAR(r.volume, 2e-4, 1e-15) << "n = " << n;
    EXPECT_NEAR(r.mass, 2e-4 * s->materials[0].rho, 1e-15 * s->materials[0].rho);
    // Same sub-cell positions as Solver::seed_rectangle.
    Solver ref;
    ref.materials = s->materials;
    ref.grid = s->grid;
    ref.seed_rectangle(0, 0, 0.02, 0.01, n, 0, 0, 0, 0);
    ASSERT_EQ(ref.p.size(), s->p.size());
    double dmax = 0;
    for (std::size_t k = 0; k < ref.p.size(); ++k)
      dmax = std::max({dmax, std::fabs(ref.p.x[k] - s->p.x[k]), std::fabs(ref.p.y[k] - s->p.y[k])});
    EXPECT_LT(dmax, 1e-15) << "n = " << n;
  }
}

// Gauss seeding (docs/physics.md section 1.1): each cell's n x n Gauss-Legendre points, the
// weights' shares of the cell; the box and the gmsh rectangle give the same particles. Each cell
// integrates x^(2n-1) y^(2n-1) exactly (the rule's degree), and its particles' volumes sum to
// the cell's.
TEST(GeometrySeeding, GaussPointsOfEachCell) {
  auto s = make_solver();
  const Geometry g = load_geometry(write_file("rect_gauss.geo", kRectangle).string(), 0.5 * kH);
  for (int n : {1, 2, 3}) {
    s->p.resize(0);
    const std::size_t added = seed_surface(*s, g, g.surfaces[0], n, 0, 0, 0, 0, Seeding::Gauss);
    EXPECT_EQ(added, static_cast<std::size_t>(200 * n * n)) << "n = " << n;
    Solver ref;
    ref.materials = s->materials;
    ref.grid = s->grid;
    ref.seed_rectangle(0, 0, 0.02, 0.01, n, 0, 0, 0, 0, Seeding::Gauss);
    ASSERT_EQ(ref.p.size(), s->p.size());
    // Per cell: the volume and the moment of x^(2n-1) y^(2n-1) about the cell's corner.
    const double h = s->grid.h;
    std::vector<double> vol(200, 0.0), mom(200, 0.0);
    double dmax = 0;
    for (std::size_t k = 0; k < ref.p.size(); ++k) {
      dmax = std::max({dmax, std::fabs(ref.p.x[k] - s->p.x[k]), std::fabs(ref.p.y[k] - s->p.y[k]),
                       std::fabs(ref.p.vol[k] - s->p.vol[k])});
      const double cx = std::floor(ref.p.x[k] / h), cy = std::floor(ref.p.y[k] / h);
      const auto c = static_cast<std::size_t>(cy * 20 + cx);
      const double u = ref.p.x[k] / h - cx, v = ref.p.y[k] / h - cy;
      vol[c] += ref.p.vol[k];
      mom[c] += ref.p.vol[k] * std::pow(u, 2 * n - 1) * std::pow(v, 2 * n - 1);
    }
    EXPECT_LT(dmax, 1e-15) << "n = " << n;
    for (std::size_t c = 0; c < 200; ++c) {
      EXPECT_NEAR(vol[c], h * h, 1e-12 * h * h) << "n = " << n << ", cell " << c;
      EXPECT_NEAR(mom[c], h * h / (4.0 * n * n), 1e-12 * h * h) << "n = " << n << ", cell " << c;
    }
  }
}

// Seeded area against the exact one: the error is a boundary effect, bounded by half a lattice
// spacing times the perimeter; in practice far below it.
void check_area(const Geometry& g, double exact_area, double perimeter, const char* what) {
  auto s = make_solver();
  for (int n : {1, 2, 3}) {
    const double sp = kH / n;
    const SeedResult r = seed(*s, g, n);
    const double err = std::fabs(r.volume - exact_area);
    const double bound = 0.5 * perimeter * sp;
    EXPECT_LT(err, bound) << what << ", n = " << n;
    EXPECT_NEAR(r.mass, r.volume * s->materials[0].rho, 1e-12 * r.mass);
    EXPECT_NEAR(r.volume, r.n * sp * sp, 1e-12 * r.volume);
    std::printf("[ geometry ] %s, %d ppc: %zu particles, area error %.3e (%.2f%% of the bound "
                "perimeter x spacing / 2)\n",
                what, n * n, r.n, (r.volume - exact_area) / exact_area, 100 * err / bound);
    // Particles per cell: every cell whose four corners are inside holds n^2 particles.
    std::map<long, int> per_cell;
    for (std::size_t k = 0; k < s->p.size(); ++k) {
      const long ci = static_cast<long>(std::floor((s->p.x[k] - s->grid.x0) / kH));
      const long cj = static_cast<long>(std::floor((s->p.y[k] - s->grid.y0) / kH));
      ++per_cell[cj * 1000 + ci];
    }
    int full = 0;
    for (const auto& [key, count] : per_cell) {
      const long ci = key % 1000, cj = key / 1000;
      bool inside = true;
      for (int c = 0; c < 4; ++c) {
        const double x = s->grid.x0 + (ci + c % 2) * kH, y = s->grid.y0 + (cj + c / 2) * kH;
        bool in = false;
        for (const auto& e : g.surfaces[0].elems) in = in || point_in_element(g, e, x, y);
        inside = inside && in;
      }
      if (!inside) continue;
      ++full;
      EXPECT_EQ(count, n * n) << what << ": cell " << ci << ", " << cj;
    }
    EXPECT_GT(full, 50) << what;
  }
}

// gmsh's start-up sets OpenMP's thread count to its own option (1): reading a geometry must
// leave the process's count as it was, or every case with a geometry would step on one core.
TEST(GeometrySeeding, ReadingKeepsTheThreadCount) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(3);
  const Geometry g = load_geometry(write_file("rect_threads.geo", kRectangle).string(), 0.5 * kH);
  EXPECT_GT(g.x.size(), 0u);
  EXPECT_EQ(omp_get_max_threads(), 3);
  omp_set_num_threads(before);
}

TEST(GeometrySeeding, DiskAreaAndPpc) {
  const Geometry g = load_geometry(write_file("disk.geo", disk_geo()).string(), 0.25 * kH);
  // The meshed polygon is inscribed in the circle: its own area is within (2 pi R) sagitta.
  const double exact = M_PI * kR * kR;
  EXPECT_NEAR(g.area(g.surfaces[0]), exact, 2 * M_PI * kR * (0.25 * kH) * (0.25 * kH) / (8 * kR));
  check_area(g, exact, 2 * M_PI * kR, "disk");
}

TEST(GeometrySeeding, LShapeAreaAndPpc) {
  const Geometry g = load_geometry(write_file("l.geo", l_geo()).string(), kH);
  const double exact = 3 * kC * kC;
  EXPECT_NEAR(g.area(g.surfaces[0]), exact, 1e-12 * exact);
  check_area(g, exact, 8 * kC, "L-shape");
}

// ---------------------------------------------------------------------------------------------
// Normals and weights.

TEST(GeometryLayer, CircleNormalsRadial) {
  auto s = make_solver();
  const Geometry g = load_geometry(write_file("disk_n.geo", disk_geo()).string(), 0.5 * kH);
  for (int n : {1, 2, 3}) {
    s->p.resize(0);
    seed_surface(*s, g, g.surfaces[0], n, 0, 0, 0, 0);
    BodyRegion region;
    region.surface = &g.surfaces[0];
    const BoundaryLayer L = select_curve_layer(*s, g, g.curves[0], region, 0, kH, "rim");
    ASSERT_GT(L.ids.size(), 40u);
    double worst = 0, wsum = 0;
    for (std::size_t q = 0; q < L.ids.size(); ++q) {
      const std::size_t k = L.idx[q];
      const double rx = s->p.x[k] - kXc, ry = s->p.y[k] - kYc, r = std::hypot(rx, ry);
      const double c = std::clamp((rx * L.nx[q] + ry * L.ny[q]) / r, -1.0, 1.0);
      worst = std::max(worst, std::acos(c) * 180 / M_PI);
      // Depth: the particle's distance to the (discretised) circle.
      EXPECT_NEAR(L.d[q], kR - r, 0.02 * kH);
      EXPECT_LT(kR - r, kH + 0.02 * kH);
      wsum += L.w[q];
    }
    std::printf("[ geometry ] circle, %d ppc: %zu layer particles, worst normal %.3f deg from "
                "radial\n", n * n, L.ids.size(), worst);
    EXPECT_LT(worst, 2.0);
    EXPECT_NEAR(wsum, L.length, 1e-12 * L.length);
    EXPECT_NEAR(L.length, 2 * M_PI * kR, 1e-3 * 2 * M_PI * kR);
  }
}

TEST(GeometryLayer, InclinedEdgeNormalsAndTractionSum) {
  const double angle = 30 * M_PI / 180;
  const Geometry g = load_geometry(write_file("incl.geo", inclined_geo(angle)).string(), kH);
  const Geometry::Curve& edge = g.curves[g.find_curve(12)];
  const double nx = std::cos(angle), ny = std::sin(angle);
  const double exact_length = kIncH / std::cos(angle);
  EXPECT_NEAR(g.length(edge), exact_length, 1e-12 * exact_length);
  for (int n : {1, 2, 3}) {
    auto s = make_solver();
    seed_surface(*s, g, g.surfaces[0], n, 0, 0, 0, 0);
    BodyRegion region;
    region.surface = &g.surfaces[0];
    TractionLoad t;
    // Length weights (1D Voronoi cells of the projections) also sum to the edge length.
    const BoundaryLayer by_length =
        select_curve_layer(*s, g, edge, region, 0, kH, "edge", LayerWeights::Length);
    double lsum = 0;
    for (double w : by_length.w) lsum += w;
    EXPECT_NEAR(lsum, exact_length, 1e-12 * exact_length);
    t.layer = select_curve_layer(*s, g, edge, region, 0, kH, "edge");
    ASSERT_GT(t.layer.ids.size(), 10u);
    double worst = 0, off = 0;
    for (std::size_t q = 0; q < t.layer.ids.size(); ++q) {
      worst = std::max(worst, std::acos(std::clamp(t.layer.nx[q] * nx + t.layer.ny[q] * ny,
                                                   -1.0, 1.0)) * 180 / M_PI);
      off = std::max({off, std::abs(t.layer.nx[q] - nx), std::abs(t.layer.ny[q] - ny)});
    }
    EXPECT_LT(worst, 0.5) << "n = " << n;
    // A straight segment: exact, to round-off of the components (measured 1.2e-15 and 1.3e-15,
    // from the mesh's rounded points); an angle through acos cannot say so: one ulp off a dot
    // product of 1 is 1.2e-6 degrees.
    EXPECT_LE(off, 1e-14) << "n = " << n;
    // A uniform traction vector and a normal + tangential one: nodal forces sum to t L.
    t.vx = 3.0e6;
    t.vy = -2.0e6;
    t.normal = 5.0e6;
    t.tangential = 1.5e6;
    s->tractions.push_back(t);
    s->dt = 0.1 * kH / s->materials[0].cd;
    s->opt.threads = 1;
    s->finalize();
    s->step();  // zero stress at the start: the nodal force is the traction alone
    double fx = 0, fy = 0;
    for (std::size_t i = 0; i < s->grid.nodes(); ++i) fx += s->grid.fx[i], fy += s->grid.fy[i];
    const double tx = 3.0e6 + 5.0e6 * nx - 1.5e6 * ny, ty = -2.0e6 + 5.0e6 * ny + 1.5e6 * nx;
    EXPECT_NEAR(fx, tx * exact_length, 1e-12 * std::hypot(tx, ty) * exact_length) << "n = " << n;
    EXPECT_NEAR(fy, ty * exact_length, 1e-12 * std::hypot(tx, ty) * exact_length) << "n = " << n;
  }
}

// The L-shape's re-entrant corner: the two inner edges keep their own normals (a corner), and
// particles near the corner are not dropped.
TEST(GeometryLayer, CornerKeepsSideNormals) {
  auto s = make_solver();
  const Geometry g = load_geometry(write_file("l_n.geo", l_geo()).string(), kH);
  seed_surface(*s, g, g.surfaces[0], 1, 0, 0, 0, 0);
  BodyRegion region;
  region.surface = &g.surfaces[0];
  const BoundaryLayer L = select_curve_layer(*s, g, g.curves[0], region, 0, kH, "inner");
  int up = 0, right = 0, wedge = 0;
  for (std::size_t q = 0; q < L.ids.size(); ++q) {
    const std::size_t k = L.idx[q];
    if (s->p.x[k] > kA + kC) {  // under the horizontal inner edge: normal +y
      EXPECT_NEAR(L.ny[q], 1.0, 1e-12);
      ++up;
    } else if (s->p.y[k] > kA + kC) {  // left of the vertical inner edge: normal +x
      EXPECT_NEAR(L.nx[q], 1.0, 1e-12);
      ++right;
    } else {  // in the wedge of the corner: the normal of one of the two sides
      EXPECT_NEAR(std::max(L.nx[q], L.ny[q]), 1.0, 1e-12);
      ++wedge;
    }
  }
  EXPECT_LE(wedge, 1);
  // One particle row along each inner edge (11 cells of the lattice each, plus the corner one).
  EXPECT_GE(up, 11);
  EXPECT_GE(right, 11);
  double wsum = 0;
  for (double w : L.w) wsum += w;
  EXPECT_NEAR(wsum, 2 * kC, 1e-12 * kC);
}

// Numbers given to one load (size, parameters) must not leak into the next one in the process.
TEST(GeometryLoad, NoStateLeaksBetweenLoads) {
  const std::string l = write_file("leak_l.geo", l_geo()).string();
  const Geometry first = load_geometry(l, 0);  // the file's own h = 1 mm
  load_geometry(write_file("leak_disk.geo", disk_geo()).string(), 0.004);
  const Geometry again = load_geometry(l, 0);
  EXPECT_EQ(first.x.size(), again.x.size());
  const Geometry coarse = load_geometry(l, 0.004);
  EXPECT_LT(coarse.x.size(), first.x.size() / 4);
}

TEST(GeometryNodes, CurveOnGridLineAndInclined) {
  auto s = make_solver();
  const Geometry g = load_geometry(write_file("rect_n.geo", kRectangle).string(), kH);
  // Bottom edge y = 0 from x = 0 to 0.02: the 21 nodes of that grid line.
  const auto nodes = nodes_near_curve(*s, g, g.curves[g.find_curve(13)], 0.5 * kH);
  ASSERT_EQ(nodes.size(), 21u);
  for (uint32_t n : nodes) {
    const int i = n % s->grid.nnx, j = n / s->grid.nnx;
    EXPECT_NEAR(s->grid.node_y(j), 0.0, 1e-15);
    EXPECT_GE(s->grid.node_x(i), -1e-15);
    EXPECT_LE(s->grid.node_x(i), 0.02 + 1e-15);
  }
}

// ---------------------------------------------------------------------------------------------
// Through a case file.

TEST(GeometryCase, BodiesAndBoundariesFromGmsh) {
  write_file("case_rect.geo", kRectangle);
  const std::string json = R"({
    "grid": { "origin": [-0.004, -0.004], "size": [0.03, 0.02], "cell": 0.001 },
    "time": { "end": 1e-6, "cfl": 0.3 },
    "materials": { "w": { "model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000 } },
    "geometry": { "file": "case_rect.geo" },
    "bodies": [ { "name": "plate", "material": "w", "surface": "plate", "particles_per_cell": 4 } ],
    "boundaries": [
      { "type": "traction", "body": "plate", "curve": 11, "normal": -1e6 },
      { "type": "silent", "body": "plate", "curve": "right" },
      { "type": "roller", "component": "y", "curve": 13 }
    ]
  })";
  const Case c = load_case(write_file("case_rect.json", json).string());
  const Solver& s = *c.solver;
  EXPECT_EQ(s.p.size(), 800u);
  ASSERT_EQ(s.tractions.size(), 1u);
  ASSERT_EQ(s.silents.size(), 1u);
  ASSERT_EQ(s.constraints.size(), 1u);
  EXPECT_EQ(s.constraints[0].nodes.size(), 21u);
  // Same layers as the box form of the case (body + side).
  EXPECT_EQ(s.tractions[0].layer.ids.size(), 40u);  // 2 x 20 particles within one cell
  EXPECT_EQ(s.silents[0].layer.ids.size(), 40u);
  for (std::size_t q = 0; q < s.silents[0].layer.ids.size(); ++q) {
    EXPECT_NEAR(s.silents[0].layer.nx[q], 1.0, 1e-14);
    EXPECT_NEAR(s.tractions[0].layer.nx[q], -1.0, 1e-14);
  }
  EXPECT_NEAR(s.tractions[0].layer.length, 0.01, 1e-15);
}

// ---------------------------------------------------------------------------------------------
// meshes/: every .geo loads, follows the group convention, and has the documented areas.

TEST(GeometryMeshes, ConventionAndAreas) {
  const fs::path dir = fs::path(SMPM_SOURCE_DIR) / "meshes";
  ASSERT_TRUE(fs::is_directory(dir)) << dir;
  const std::map<std::string, std::vector<double>> areas = {
      {"impact.geo", {0.02 * 0.03, 0.1 * 0.1}},
      {"impact_extended.geo", {0.02 * 0.03, 0.3 * 0.1}},
      {"convergence.geo", {0.01, 0.01}},
      {"film_5um.geo", {10e-6 * 2.5e-6, 10e-6 * 5e-6}},
      {"film_15um.geo", {10e-6 * 2.5e-6, 10e-6 * 15e-6}},
      {"inclined_edge.geo", {0.16 * 0.16 - 0.5 * 0.16 * 0.16 * std::tan(M_PI / 6)}},
      {"ring.geo", {M_PI * (0.05 * 0.05 - 0.01 * 0.01)}},
  };
  int checked = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".geo") continue;
    const std::string name = entry.path().filename().string();
    const std::string text = read_text(entry.path());
    EXPECT_EQ(text.find("\nPhysical Point"), std::string::npos) << name << ": no Physical Points";
    EXPECT_NE(text.find("DefineConstant[ h ="), std::string::npos) << name << ": mesh size h";
    EXPECT_EQ(text.rfind("//", 0), 0u) << name << ": a comment block at the top";
    Geometry g;
    // Meshed coarsely to keep the test fast (0: the file's own h).
    const std::map<std::string, double> coarse = {
        {"impact.geo", 0.005}, {"impact_extended.geo", 0.005}, {"convergence.geo", 0.01},
        {"film_5um.geo", 5e-7}, {"film_15um.geo", 5e-7}, {"film.geo", 5e-7},
        {"inclined_edge.geo", 0.01}, {"ring.geo", 0.002}, {"pulse_plate.geo", 0.005},
        {"pulse_extended.geo", 0.005}, {"hybrid_film_substrate.geo", 5e-7},
        {"hybrid_film_substrate_graded.geo", 5e-7}, {"hybrid_pulse_50.geo", 0.005},
        {"hybrid_pulse_150.geo", 0.005}, {"film_30um.geo", 5e-7}, {"film_hybrid_1500nm.geo", 5e-7}};
    const auto cs = coarse.find(name);
    try {
      g = load_geometry(entry.path().string(), cs == coarse.end() ? 0.0 : cs->second);
    } catch (const GeometryError& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    for (std::size_t i = 0; i < g.surfaces.size(); ++i) {
      EXPECT_EQ(g.surfaces[i].tag, static_cast<int>(i + 1)) << name << ": surfaces numbered 1, 2, ...";
      EXPECT_FALSE(g.surfaces[i].name.empty()) << name;
      EXPECT_EQ(g.surfaces[i].name.find(':'), std::string::npos) << name;
    }
    for (const auto& c : g.curves) {
      EXPECT_GE(c.tag, 11) << name << ": curves numbered from 11";
      EXPECT_FALSE(c.name.empty()) << name;
      EXPECT_EQ(c.name.find(':'), std::string::npos) << name;
    }
    auto it = areas.find(name);
    if (it == areas.end()) continue;
    ASSERT_EQ(g.surfaces.size(), it->second.size()) << name;
    for (std::size_t i = 0; i < g.surfaces.size(); ++i) {
      const double a = g.area(g.surfaces[i]), want = it->second[i];
      const double tol = name == "ring.geo" ? 2e-3 * want : 1e-9 * want;  // inscribed polygons
      EXPECT_NEAR(a, want, tol) << name << ": surface " << g.surfaces[i].tag;
    }
    ++checked;
  }
  EXPECT_EQ(checked, static_cast<int>(areas.size()));
}

}  // namespace
