// MPM-FEM hybrid guards: each wrong set-up stops with one HybridError that says what is wrong.
#include <gtest/gtest.h>

#include <string>

#include "test_hybrid_common.hpp"

using namespace smpm;
using namespace smpm::hybrid_testing;

namespace {

// Particles on [0, 20h] x [0, 4h] (grid from -2h to 32h), no loads unless asked; the grid moved
// left and down by `shift` cells, `side` particles per cell side.
std::unique_ptr<Solver> particles(double x1_cells = 20, double v0 = 0, bool top_load = false,
                                  double shift = 0, int side = 1) {
  const double h = 1e-3, H = 4 * h;
  auto s = std::make_unique<Solver>();
  s->materials.push_back(smpm::testing::tungsten());
  s->grid.init((-2 - shift) * h, -shift * h, h, 34, shift > 0 ? 5 : 4);
  s->seed_rectangle(0, 0, x1_cells * h, H, side, 0, 0, v0, 0);
  if (top_load) {
    TractionLoad tl;
    tl.layer = s->select_layer("top", 0, x1_cells * h, H, 0, H, 0, 1, h);
    tl.normal = -1e6;
    s->tractions.push_back(tl);
  }
  s->opt.threads = 1;
  s->dt = 0.3 * h / s->materials[0].cd;
  s->finalize();
  return s;
}

// Q-degree elements on [x0, 30h] x [0, 4h] of size hf; optional FE traction on the top curve.
std::unique_ptr<fem::Solver> elements(double x0, double hf, int degree = 1, bool top_load = false) {
  const double h = 1e-3;
  fem::Spec spec;
  spec.mesh = fem::load_mesh(box_geo("err_" + std::to_string(x0) + "_" + std::to_string(hf), x0, 0,
                                     30 * h, 4 * h, hf),
                             hf);
  spec.degree = degree;
  spec.materials = {smpm::testing::tungsten()};
  spec.region_material = {{1, 0}};
  spec.threads = 1;
  if (top_load) {
    auto b = fe_bc(fem::Boundary::Kind::Traction, 14, "top");
    b.normal = -1e6;
    spec.boundaries.push_back(b);
  }
  return std::make_unique<fem::Solver>(spec);
}

// The message of the HybridError thrown by fn ("" if none).
template <class Fn>
std::string error_of(Fn&& fn) {
  try {
    fn();
  } catch (const HybridError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(HybridErrors, GoodSetupFindsTheInterface) {
  auto s = particles();
  auto f = elements(20e-3, 1e-3);
  Hybrid hy(*s, *f);
  EXPECT_EQ(hy.interface_nodes(), 5u);  // x = 20h, y = 0..4h
  // Grid cells [20h, 30h] x [0, 4h] are FE cells: 10 x 4.
  std::size_t n = 0;
  for (auto c : hy.fe_cells()) n += c;
  EXPECT_EQ(n, 40u);
}

TEST(HybridErrors, QuadraticElements) {
  auto s = particles();
  auto f = elements(20e-3, 1e-3, 2);
  EXPECT_NE(error_of([&] { Hybrid hy(*s, *f); }).find("fem.degree 1"), std::string::npos);
}

TEST(HybridErrors, FinerSpacingAtTheInterface) {
  auto s = particles();
  auto f = elements(20e-3, 0.5e-3);
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("not on a grid node"), std::string::npos) << e;
}

TEST(HybridErrors, CoarserSpacingAtTheInterface) {
  auto s = particles();
  auto f = elements(20e-3, 2e-3);
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("is not one grid cell"), std::string::npos) << e;
}

TEST(HybridErrors, MeshOverlapsTheParticles) {
  auto s = particles();
  auto f = elements(19e-3, 1e-3);
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("inside an FE cell at setup"), std::string::npos) << e;
}

// A grid whose origin is off the mesh's nodes (0.3 of a cell) is named as such, at 1 and 4 ppc,
// not as particles inside the FE cells that the misaligned grid cells mark.
TEST(HybridErrors, GridOriginOffTheMesh) {
  for (int side : {1, 2}) {
    auto s = particles(20, 0, false, 0.3, side);
    auto f = elements(20e-3, 1e-3);
    const std::string e = error_of([&] { Hybrid hy(*s, *f); });
    EXPECT_NE(e.find("not on a grid node"), std::string::npos) << side << ": " << e;
  }
}

TEST(HybridErrors, MeshDoesNotTouchTheParticles) {
  auto s = particles();
  auto f = elements(21e-3, 1e-3);
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("does not touch the particles"), std::string::npos) << e;
}

TEST(HybridErrors, PartlyFilledCellAtTheInterface) {
  auto s = particles(19.5);  // 20 particles spread over 19.5 cells: the cell at 19h is 0.5 full...
  auto f = elements(20e-3, 1e-3);
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("partly filled"), std::string::npos) << e;
}

// The mass correction next to cells of one particle (docs/physics.md section 7): refused when
// the hybrid is built, and at the first step when it is turned on afterwards.
TEST(HybridErrors, MassCorrectionAtOneParticlePerCell) {
  auto s = particles();
  auto f = elements(20e-3, 1e-3);
  s->opt.mass_correction = 1;
  std::string e = error_of([&] { Hybrid hy(*s, *f); });
  const std::string want = "hybrid: scheme.mass_correction needs 2 or more particles per cell side "
                           "next to the interface, but the MPM cell (21, 0) at (0.0195, 0.0005) "
                           "holds a particle of 1 h^2";
  EXPECT_NE(e.find(want), std::string::npos) << e;
  s->opt.mass_correction = 0;
  Hybrid hy(*s, *f);
  hy.set_dt(s->dt);
  s->opt.mass_correction = 1;
  e = error_of([&] { hy.step(); });
  EXPECT_NE(e.find(want), std::string::npos) << e;
}

// The correction's symmetric form: the far field's nodes take the increment form only.
TEST(HybridErrors, SymmetricMassCorrection) {
  auto s = particles();
  auto f = elements(20e-3, 1e-3);
  s->opt.mass_correction = 2;
  s->opt.mass_correction_symmetric = true;
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("hybrid: scheme.mass_correction_form \"symmetric\" is not supported with an "
                   "FEM region"), std::string::npos) << e;
}

// The light nodes' extension: the window's edge nodes are the far field's.
TEST(HybridErrors, LightNodes) {
  auto s = particles();
  auto f = elements(20e-3, 1e-3);
  s->opt.light_node_ratio = 0.15;
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("hybrid: scheme.light_nodes \"extend\" is not supported with an FEM region"),
            std::string::npos) << e;
}

TEST(HybridErrors, MpmLoadOnAnInterfaceNode) {
  auto s = particles(20, 0, true);
  auto f = elements(20e-3, 1e-3);
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("MPM traction \"top\" loads the interface node"), std::string::npos) << e;
}

TEST(HybridErrors, FemLoadOnAnInterfaceNode) {
  auto s = particles();
  auto f = elements(20e-3, 1e-3, 1, true);
  Hybrid hy(*s, *f);
  hy.set_dt(s->dt);
  const std::string e = error_of([&] { hy.step(); });
  EXPECT_NE(e.find("FEM boundary load acts on the interface node at (0.02, 0.004)"), std::string::npos) << e;
}

// Particles thrown at 2000 m/s into the elements: the check after each step stops the run as soon
// as one particle is inside an FE cell (the interface node moves at about v0 / 2, ~0.05 h a step).
TEST(HybridErrors, ParticleEntersAnElement) {
  auto s = particles(20, 2000.0);
  auto f = elements(20e-3, 1e-3);
  Hybrid hy(*s, *f);
  hy.set_dt(s->dt);
  long steps = -1;
  const std::string e = error_of([&] {
    for (int k = 0; k < 200; ++k) hy.step();
  });
  steps = s->steps;
  EXPECT_NE(e.find("is inside an FE cell at step"), std::string::npos) << e;
  EXPECT_GT(steps, 3);
  EXPECT_LT(steps, 40);
}

TEST(HybridErrors, TimeStepAboveTheElementBound) {
  auto s = particles();
  auto f = elements(20e-3, 1e-3);
  Hybrid hy(*s, *f);
  const std::string e = error_of([&] { hy.set_dt(2 * hy.critical_dt()); });
  EXPECT_NE(e.find("stability limit"), std::string::npos) << e;
}

// Both regions must pull with one gravity (a shared node weighs m_MPM + m_FE).
TEST(HybridErrors, GravityDiffersBetweenTheRegions) {
  auto s = particles();
  s->opt.gravity_y = -9.81;
  auto f = elements(20e-3, 1e-3);
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("the MPM region's gravity (0, -9.81) m/s^2 differs from the FEM region's (0, 0)"),
            std::string::npos)
      << e;
}

// A perfectly matched layer or a damping layer with beta on the nodes the regions share: the
// grid's update would not take their forces.
TEST(HybridErrors, LayerOnTheSharedNodes) {
  for (const bool pml : {false, true}) {
    auto s = particles();
    const double h = 1e-3;
    fem::Spec spec;
    spec.mesh = fem::load_mesh(box_geo("err_layer", 20 * h, 0, 30 * h, 4 * h, h), h);
    spec.materials = {smpm::testing::tungsten()};
    spec.region_material = {{1, 0}};
    spec.threads = 1;
    auto b = fe_bc(pml ? fem::Boundary::Kind::Pml : fem::Boundary::Kind::Damping, 11, "band");
    b.width = 3 * h;
    if (!pml) b.beta = 1e-8;
    spec.boundaries.push_back(b);
    fem::Solver f(spec);
    const std::string e = error_of([&] { Hybrid hy(*s, f); });
    EXPECT_NE(e.find("which the FEM region shares with the MPM grid, lies in a perfectly matched "
                     "layer or in a damping layer with beta"),
              std::string::npos)
        << e;
  }
}

// The delayed closure of an MPM silent edge: the coupled step's interface takes the FE region's
// velocity, which the closure's ring does not follow: refused, naming the edge.
TEST(HybridErrors, DelayedSilentEdge) {
  auto s = particles();
  const double h = 1e-3;
  SilentBoundary sb;
  sb.layer = s->select_layer("bottom", 0, 0, 0, 20 * h, 0, 0, -1, h);
  sb.delayed = true;
  s->silents.push_back(sb);
  auto f = elements(20e-3, 1e-3);
  const std::string e = error_of([&] { Hybrid hy(*s, *f); });
  EXPECT_NE(e.find("the MPM region's silent edge \"bottom\" has \"edge_velocity\": \"delayed\""),
            std::string::npos)
      << e;
}
