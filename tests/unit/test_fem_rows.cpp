// The FE stiffness's storage (fem::Solver): rows of K equal bit for bit share one copy of their
// values (fem::Spec::share_rows). On a structured mesh:
//   * few kinds of rows are stored (a 40 x 30 rectangle: at most 5 % of the blocks; measured
//     1.4 % for Q1, 1.9 % for Q2, 2.7 % and 2.5 % with springs), and
//     K u equals that of the same model keeping every row's values, to the bit, Q1 and Q2, with
//     Kelvin-Voigt springs on a side (they change that side's rows);
//   * K u of a linear displacement field vanishes at every node away from the boundary (the
//     patch test: within 1e-10 of the largest force it gives on the boundary, the traction of
//     that uniform strain).
// On a mesh whose rows are nearly all different nothing is shared.
// fem::Solver::step makes one pass over the rows (-K u and the nodal update together; Q1's rows
// of consecutive nodes mostly four at a time, reaching half the nodes so at least); it equals,
// bit for bit, the two passes the hybrid makes (internal_force, then advance_free_nodes): u, v
// and the booked work and absorbed energy (on two threads within 1e-14: the sums' order), with a
// traction and rollers on one side, LK dashpots, Kelvin-Voigt springs, a PML, a damping band
// with a stiffness part, with and without gravity (without it, a group of four free, unloaded
// nodes without dashpots books no work), Q1 and Q2, on one and two threads;
// and above the size from which it runs on several threads, with the groups of four rows, the
// work and absorbed energy too (the threads take the rows of a static schedule).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fem_common.hpp"

namespace smpm::fem_testing {
namespace {

fem::Spec rectangle(int degree, bool share, bool springs) {
  fem::Spec s = steel_rectangle("rows_rect", 40, 30, degree);
  s.share_rows = share;
  if (springs) {
    fem::Boundary kv = bc(fem::Boundary::Kind::Dashpot, 12, "kv");
    kv.delta = 10e-3;
    s.boundaries.push_back(kv);
  }
  return s;
}

std::vector<double> field(const fem::Solver& s, bool linear) {
  std::vector<double> u(s.dofs());
  for (std::size_t i = 0; i < s.nodes(); ++i) {
    const double x = s.node_x()[i], y = s.node_y()[i];
    u[2 * i] = linear ? 1e-3 * x + 2e-3 * y : 1e-6 * std::sin(300 * x) * std::cos(170 * y);
    u[2 * i + 1] = linear ? -4e-3 * x + 1.5e-3 * y : 1e-6 * std::cos(230 * x + 0.4) * std::sin(90 * y);
  }
  return u;
}

// `steps` steps of two solvers of one model at 0.4 of the critical step: one by step(), the
// other by the hybrid's two passes (internal_force, then advance_free_nodes), which book their
// work and absorbed energy into `work` and `absorbed`.
void step_both(fem::Solver& one, fem::Solver& two, int steps, double& work, double& absorbed) {
  const double dt = 0.4 * one.critical_dt();
  one.set_dt(dt);
  two.set_dt(dt);
  const std::vector<std::int64_t> skip(two.nodes(), -1);
  std::vector<double> f_int(two.dofs()), f_ext(two.dofs(), 0.0);
  for (int k = 0; k < steps; ++k) {
    one.step();
    two.internal_force(two.displacement().data(), f_int.data());
    two.refresh_external_force(two.t, f_ext.data());
    two.advance_free_nodes(skip.data(), f_int.data(), f_ext.data(), dt, work, absorbed);
    two.t += dt;
  }
}

TEST(FemRows, SharedRowsGiveTheSameInternalForce) {
  for (const int degree : {1, 2})
    for (const bool springs : {false, true}) {
      fem::Solver shared(rectangle(degree, true, springs)), own(rectangle(degree, false, springs));
      ASSERT_TRUE(shared.rows_shared());
      ASSERT_FALSE(own.rows_shared());
      EXPECT_EQ(own.stored_blocks(), own.matrix_blocks());
      EXPECT_LE(shared.stored_blocks(), own.matrix_blocks() / 20);
      const std::vector<double> u = field(shared, false);
      std::vector<double> f1(u.size()), f2(u.size());
      shared.internal_force(u.data(), f1.data());
      own.internal_force(u.data(), f2.data());
      std::printf("  Q%d%s: %zu of %zu blocks stored\n", degree, springs ? ", springs" : "",
                  shared.stored_blocks(), shared.matrix_blocks());
      double worst = 0;
      for (std::size_t k = 0; k < u.size(); ++k) worst = std::max(worst, std::fabs(f1[k] - f2[k]));
      EXPECT_EQ(worst, 0.0);
    }
}

TEST(FemRows, PatchTestThroughSharedRows) {
  fem::Solver s(rectangle(1, true, false));
  ASSERT_TRUE(s.rows_shared());
  std::vector<double> f(s.dofs());
  const std::vector<double> lin = field(s, true);
  s.internal_force(lin.data(), f.data());
  double scale = 0, worst = 0;
  const double h = 1e-3, tol = 1e-9 * h;
  const auto b = s.bounds();
  for (std::size_t i = 0; i < s.nodes(); ++i) {
    const double x = s.node_x()[i], y = s.node_y()[i];
    const double here = std::max(std::fabs(f[2 * i]), std::fabs(f[2 * i + 1]));
    if (x < b[0] + tol || x > b[2] - tol || y < b[1] + tol || y > b[3] - tol)
      scale = std::max(scale, here);
    else
      worst = std::max(worst, here);
  }
  std::printf("  interior %.3e, boundary %.3e\n", worst, scale);
  EXPECT_GT(scale, 0.0);
  EXPECT_LE(worst, 1e-10 * scale);
}

TEST(FemRows, OnePassStepEqualsForceThenUpdate) {
  for (const int degree : {1, 2})
    for (const int threads : {1, 2})
      for (const int variant : {0, 1, 2}) {
        // Gravity with rollers on the loaded side; without gravity, without and with them (so
        // that groups hold loaded free nodes, and masked ones once the load has passed).
        const bool gravity = variant == 0, rollers = variant != 1;
        auto spec = [&] {
          fem::Spec s = steel_rectangle("one_pass_rect", 40, 30, degree);
          s.threads = threads;
          s.gravity_y = gravity ? -9.81 : 0.0;
          fem::Boundary load = bc(fem::Boundary::Kind::Traction, 14, "load");
          load.normal = -1e8;
          load.fn = sin2_bell(2e-6);
          fem::Boundary lk = bc(fem::Boundary::Kind::Dashpot, 11, "lk");
          fem::Boundary kv = bc(fem::Boundary::Kind::Dashpot, 13, "kv");
          kv.delta = 10e-3;
          fem::Boundary pml = bc(fem::Boundary::Kind::Pml, 12, "pml");
          pml.width = 5e-3;
          pml.r0 = 1e-2;
          fem::Boundary band = bc(fem::Boundary::Kind::Damping, 13, "band");
          band.width = 4e-3;
          band.r0 = 0.9;
          band.beta = 1e-8;
          fem::Boundary roller = bc(fem::Boundary::Kind::Roller, 14, "roller");  // the load's side
          roller.component = 0;
          s.boundaries = {load, lk, kv, pml, bc(fem::Boundary::Kind::Dashpot, 12, "pml_lk"), band};
          if (rollers) s.boundaries.push_back(roller);
          return s;
        };
        fem::Solver one(spec()), two(spec());
        // Q1: most rows go four at a time (step's groups; internal_force takes rows one by one).
        const std::size_t groups = one.row_groups();
        std::printf("  Q%d: %zu groups of four rows of %zu nodes\n", degree, groups, one.nodes());
        if (degree == 1) {
          EXPECT_GE(4 * groups, one.nodes() / 2);
        }
        double work = 0, absorbed = 0;
        step_both(one, two, 300, work, absorbed);
        EXPECT_TRUE(one.displacement() == two.displacement())
            << "Q" << degree << ", " << threads << ", variant " << variant;
        EXPECT_TRUE(one.velocity() == two.velocity())
            << "Q" << degree << ", " << threads << ", variant " << variant;
        // advance_free_nodes sums over the threads whatever the size, step() on one thread below
        // a size (the sums' order then differs on two threads).
        const double tol = threads == 1 ? 0.0 : 1e-14;
        EXPECT_LE(std::fabs(one.energy.external_work - work), tol * std::fabs(work));
        EXPECT_LE(std::fabs(one.energy.absorbed - absorbed), tol * std::fabs(absorbed));
        double umax = 0;
        for (const double u : one.displacement()) umax = std::max(umax, std::fabs(u));
        std::printf("  Q%d, %d thread(s): max |u| %.3e, work %.6e J/m, absorbed %.6e J/m\n", degree,
                    threads, umax, work, absorbed);
        EXPECT_GT(umax, 0.0);  // the pulse is in
        EXPECT_GT(absorbed, 0.0);
      }
}

// Above the size from which the step runs on several threads (40 000 rows), step()'s threads
// take the rows a static schedule gives them, as advance_free_nodes does: on two threads the
// work and the absorbed energy are the same sums, to the bit, with the groups of four rows (and
// LK dashpots among them) on, with gravity and without (then the groups of free, unloaded nodes
// book nothing). The square is large enough (207 000 nodes) for the step to time its groups'
// stores both ways over its first twelve steps, then keep one: the same bits.
TEST(FemRows, GroupsOnTwoThreadsBookAsTheRowLoop) {
  for (const bool gravity : {true, false}) {
    auto spec = [&] {
      fem::Spec s = steel_rectangle("two_thread_rect", 460, 450, 1);
      s.threads = 2;
      s.gravity_y = gravity ? -9.81 : 0.0;
      fem::Boundary load = bc(fem::Boundary::Kind::Traction, 14, "load");
      load.normal = -1e8;
      load.fn = sin2_bell(2e-6);
      s.boundaries = {load, bc(fem::Boundary::Kind::Dashpot, 11, "lk"),
                      bc(fem::Boundary::Kind::Dashpot, 12, "lk_side")};
      return s;
    };
    fem::Solver one(spec()), two(spec());
    ASSERT_GE(one.nodes(), 40000u);
    EXPECT_GE(4 * one.row_groups(), one.nodes() / 2);
    EXPECT_EQ(one.store_mode(), -1);
    double work = 0, absorbed = 0;
    step_both(one, two, 16, work, absorbed);
    EXPECT_GE(one.store_mode(), 0);
    EXPECT_TRUE(one.displacement() == two.displacement()) << "gravity " << gravity;
    EXPECT_TRUE(one.velocity() == two.velocity()) << "gravity " << gravity;
    EXPECT_EQ(one.energy.external_work, work) << "gravity " << gravity;
    EXPECT_EQ(one.energy.absorbed, absorbed) << "gravity " << gravity;
    EXPECT_GT(work, 0.0);
    std::printf("  gravity %d: %zu nodes, %zu groups, stores %s: work %.17g J/m, absorbed %.17g "
                "J/m\n",
                gravity, one.nodes(), one.row_groups(), one.store_mode() ? "streaming" : "plain",
                work, absorbed);
  }
}

TEST(FemRows, UnstructuredMeshKeepsEveryRow) {
  // The hybrid film's unstructured substrate (gmsh's frontal quads): most rows differ.
  fem::Spec s;
  s.mesh = fem::load_mesh(std::string(SMPM_SOURCE_DIR) + "/meshes/hybrid_film_substrate_unstructured.geo", 0);
  s.materials = {elastic("steel", 2e11, 0.25, 7800)};
  for (const auto& g : s.mesh.surfaces) s.region_material[g.tag] = 0;
  s.threads = 1;
  fem::Solver f(s);
  std::printf("  %zu nodes, %zu blocks\n", f.nodes(), f.matrix_blocks());
  EXPECT_FALSE(f.rows_shared());
  EXPECT_EQ(f.stored_blocks(), f.matrix_blocks());
}

}  // namespace
}  // namespace smpm::fem_testing
