// Bilinear shape functions (exact identities, to round-off), the grid check of moving particles,
// and the passes that take four particles (or the grid update four dashpot nodes) at a time
// against the scalar loop (bit for bit).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "silentmpm/dashpot.hpp"
#include "silentmpm/kernels.hpp"

#include "common.hpp"
#include "silentmpm/shape.hpp"

using namespace smpm;
using namespace smpm::testing;

TEST(Shape, PartitionOfUnityAndGradients) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double h = 0.25, x0 = -1.0, y0 = 2.0;
  for (int trial = 0; trial < 1000; ++trial) {
    const double x = x0 + 10 * h * u(rng), y = y0 + 10 * h * u(rng);
    Bilinear s;
    s.eval(x, y, x0, y0, 1 / h);
    double sum = 0, gx = 0, gy = 0;
    for (int a = 0; a < 4; ++a) {
      EXPECT_GE(s.N[a], 0.0);
      sum += s.N[a]; gx += s.dNx[a]; gy += s.dNy[a];
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
    EXPECT_NEAR(gx, 0.0, 1e-12);
    EXPECT_NEAR(gy, 0.0, 1e-12);
    // A linear field f = 3 + 2x - 5y is reproduced exactly, with its gradient.
    double f = 0, fx = 0, fy = 0;
    for (int a = 0; a < 4; ++a) {
      const double xn = x0 + (s.ci + s.di[a]) * h, yn = y0 + (s.cj + s.dj[a]) * h;
      const double fn = 3 + 2 * xn - 5 * yn;
      f += s.N[a] * fn; fx += s.dNx[a] * fn; fy += s.dNy[a] * fn;
    }
    EXPECT_NEAR(f, 3 + 2 * x - 5 * y, 1e-12);
    EXPECT_NEAR(fx, 2.0, 1e-10);
    EXPECT_NEAR(fy, -5.0, 1e-10);
  }
}

// The transfer identities (mass and momentum to the grid and back, internal forces summing to
// zero, tractions summing to t L for 1, 4 and 9 ppc) are ShapeTransfer.* in test_shapes.cpp,
// for every shape and scheme, bilinear included.

// A particle that leaves the grid stops the run with an error naming the step, in x and in y.
TEST(Transfer, ParticleLeavingTheGridIsAnError) {
  for (int dir = 0; dir < 2; ++dir) {
    Solver s;
    s.materials.push_back(tungsten());
    s.grid.init(0, 0, 1e-3, 10, 10);
    const double v = 2000.0;  // m/s: crosses the 1 mm margin within 1 us
    s.seed_rectangle(1e-3, 1e-3, 9e-3, 9e-3, 1, 0, 0, dir == 0 ? v : 0, dir == 1 ? v : 0);
    s.dt = 0.2 * s.critical_dt();
    s.finalize();
    bool thrown = false;
    try {
      for (int i = 0; i < 10000; ++i) s.step();
    } catch (const std::runtime_error& e) {
      thrown = std::string(e.what()).find("left the grid at step") != std::string::npos;
    }
    EXPECT_TRUE(thrown) << "direction " << dir;
  }
}

// Solver::nodal_projection (the MPM grid's snapshots, output.grid): for every shape, the nodal
// masses sum to the particles' mass and the nodal momenta to theirs (partition of unity, to
// round-off), a uniform stress comes back exactly at every node with mass, and nodes out of
// reach of every particle hold zeros.
TEST(Transfer, NodalProjectionConservesMassAndMomentum) {
  for (ShapeKind shape : {ShapeKind::Bilinear, ShapeKind::UGimp, ShapeKind::BSpline2}) {
    ColumnSpec spec;
    spec.cells = 20;
    spec.ppc_side = 2;
    spec.offset = 0.3e-3;  // partly filled cells at both ends
    spec.shape = shape;
    auto s = make_column(spec);
    double m = 0, px = 0, py = 0;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (std::size_t k = 0; k < s->p.size(); ++k) {
      s->p.vx[k] = u(rng);
      s->p.vy[k] = u(rng);
      s->p.sxx[k] = -3e8; s->p.syy[k] = 1e8; s->p.szz[k] = -0.5e8; s->p.sxy[k] = 2e8;
      m += s->p.mass[k];
      px += s->p.mass[k] * s->p.vx[k];
      py += s->p.mass[k] * s->p.vy[k];
    }
    const Solver::NodalProjection P = s->nodal_projection();
    ASSERT_EQ(P.mass.size(), s->grid.nodes());
    double M = 0, PX = 0, PY = 0, worst = 0;
    std::size_t empty = 0;
    for (std::size_t i = 0; i < P.mass.size(); ++i) {
      M += P.mass[i];
      PX += P.mass[i] * P.vx[i];
      PY += P.mass[i] * P.vy[i];
      if (P.mass[i] == 0) {
        ++empty;
        EXPECT_EQ(P.sxx[i], 0.0);
        EXPECT_EQ(P.vx[i], 0.0);
        continue;
      }
      worst = std::max({worst, std::abs(P.sxx[i] + 3e8), std::abs(P.syy[i] - 1e8),
                        std::abs(P.szz[i] + 0.5e8), std::abs(P.sxy[i] - 2e8)});
    }
    const char* name = shape_name(shape);
    EXPECT_NEAR(M, m, 1e-13 * m) << name;
    EXPECT_NEAR(PX, px, 1e-12 * m) << name;
    EXPECT_NEAR(PY, py, 1e-12 * m) << name;
    EXPECT_LT(worst, 1e-6) << name << ": a uniform stress of 1e8 Pa comes back to round-off";
    EXPECT_GT(empty, 0u) << name << ": the grid's cells beyond the column hold no mass";
  }
}

// The MPM passes take four particles (nodes) at a time with bilinear shapes and leave the last one
// to three of a range to the scalar loop. Each range here runs once whole (four at a time) and
// once particle by particle (ranges of one: the scalar loop), from the same state; every particle
// array and every nodal sum must come out with the same bits: p2g's mass, momenta and forces,
// g2p's velocities, positions and re-mapped momenta, the stress update's stresses, volumes,
// plastic strains and positions (elastic, and von Mises with about half the particles yielding),
// and the nodal velocities q / m against their formula. The sums over a range's particles in
// one number (g2p's kinetic energy, the plastic dissipation) are taken into a running sum per
// call, so a range of one rounds once more: those agree to 1e-14.
namespace {
struct KernelState {
  Grid g;
  Particles p;
  std::vector<double> a[11];  // m px py fx fy vx vy vnx vny qx qy
  NodalField f;
  // per_cell > 0: most particles along the grid's rows (14 cells to a row), per_cell of them in
  // each cell before the next (as a row of particles is seeded at 1, 4 and 9 per cell), every
  // eleventh one elsewhere: groups of four in a row of cells (bilinear and 3 x 3 supports), in
  // one or two cells, and scattered.
  KernelState(int n, unsigned seed, int per_cell = 0) {
    const double h = 1e-3;
    g.init(0, 0, h, 16, 16);
    p.resize(n);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < n; ++k) {
      p.x[k] = (1.5 + 13 * u(rng)) * h;
      p.y[k] = (1.5 + 13 * u(rng)) * h;
      if (per_cell > 0 && k % 11 != 7) {
        const int c = k / per_cell;  // the cell, counted along rows
        // (at 1 per cell in the cells' right halves, so that the 3 x 3 supports, which start
        // half a cell to the left, also follow each other)
        const double lo = per_cell == 1 ? 0.51 : 0.01, span = 0.99 - lo;
        p.x[k] = (1 + c % 14 + span * (p.x[k] / h - 1.5) / 13 + lo) * h;
        p.y[k] = (1 + (c / 14) % 14 + 0.98 * (p.y[k] / h - 1.5) / 13 + 0.01) * h;
      }
      p.vx[k] = u(rng) - 0.5;
      p.vy[k] = u(rng) - 0.5;
      p.mass[k] = 1e-3 * (0.5 + u(rng));
      p.vol[k] = 1e-7 * (0.5 + u(rng));
      p.sxx[k] = 2e9 * (u(rng) - 0.5);
      p.syy[k] = 2e9 * (u(rng) - 0.5);
      p.szz[k] = 2e9 * (u(rng) - 0.5);
      p.sxy[k] = 1e9 * (u(rng) - 0.5);
      if (k % 13 == 5) {  // in the grid's first or last cells: 3 x 3 supports folded there
        p.x[k] = (k % 2 ? 0.1 + 0.8 * u(rng) : 15.1 + 0.8 * u(rng)) * h;
        p.y[k] = (k % 3 ? 0.1 + 0.8 * u(rng) : 15.1 + 0.8 * u(rng)) * h;
      }
    }
    for (auto& v : a) {
      v.resize(g.nodes());
      for (double& x : v) x = u(rng) + 0.1;  // positive: a mass
    }
    f.m = a[0].data(); f.px = a[1].data(); f.py = a[2].data(); f.fx = a[3].data();
    f.fy = a[4].data(); f.vx = a[5].data(); f.vy = a[6].data(); f.vnx = a[7].data();
    f.vny = a[8].data(); f.qx = a[9].data(); f.qy = a[10].data();
  }
  KernelState(const KernelState& o) : g(o.g), p(o.p) {
    for (int i = 0; i < 11; ++i) a[i] = o.a[i];
    f = o.f;
    double** ptr[11] = {&f.m, &f.px, &f.py, &f.fx, &f.fy, &f.vx, &f.vy, &f.vnx, &f.vny, &f.qx, &f.qy};
    for (int i = 0; i < 11; ++i) *ptr[i] = a[i].data();
  }
};

template <class S>
const char* shape_of() {
  return std::is_same_v<S, Bilinear> ? ", bilinear" : std::is_same_v<S, BSpline2> ? ", B-spline" : ", uGIMP";
}

bool same_bits(const std::vector<double>& x, const std::vector<double>& y) {
  return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0;
}

void expect_same(const KernelState& w, const KernelState& s, const char* pass) {
  const Particles &a = w.p, &b = s.p;
  EXPECT_TRUE(same_bits(a.x, b.x) && same_bits(a.y, b.y)) << pass << ": positions";
  EXPECT_TRUE(same_bits(a.vx, b.vx) && same_bits(a.vy, b.vy)) << pass << ": velocities";
  EXPECT_TRUE(same_bits(a.sxx, b.sxx) && same_bits(a.syy, b.syy) && same_bits(a.szz, b.szz) &&
              same_bits(a.sxy, b.sxy))
      << pass << ": stresses";
  EXPECT_TRUE(same_bits(a.vol, b.vol) && same_bits(a.eps_p, b.eps_p)) << pass << ": volumes";
  for (int i = 0; i < 11; ++i) EXPECT_TRUE(same_bits(w.a[i], s.a[i])) << pass << ": nodal array " << i;
}

// Two solvers' particles (positions, velocities, stresses) and energy account (absorbed,
// external work), bit for bit.
void expect_same_run(const Solver& a, const Solver& b, const std::string& what) {
  const Particles &p = a.p, &q = b.p;
  EXPECT_TRUE(same_bits(p.x, q.x) && same_bits(p.y, q.y)) << what;
  EXPECT_TRUE(same_bits(p.vx, q.vx) && same_bits(p.vy, q.vy)) << what;
  EXPECT_TRUE(same_bits(p.sxx, q.sxx) && same_bits(p.syy, q.syy) && same_bits(p.sxy, q.sxy)) << what;
  const double e0[] = {a.energy.absorbed, a.energy.external_work};
  const double e1[] = {b.energy.absorbed, b.energy.external_work};
  EXPECT_EQ(std::memcmp(e0, e1, sizeof e0), 0) << what;
}
}  // namespace

class Kernels : public ::testing::TestWithParam<int> {};

TEST_P(Kernels, FourAtATimeEqualsTheScalarLoopBitForBit) {
  const int n = 103;  // 25 groups of four and a tail of three
  const KernelState start(n, 11, GetParam());
  {  // the groups of four in the row form (1 per cell), two by two (2) and in two cells (3)
    int in_row = 0, in_pairs = 0, in_two = 0;
    for (int k = 0; k + 4 <= n; k += 4) {
      long n0[4];
      for (int l = 0; l < 4; ++l)
        n0[l] = static_cast<long>(std::floor(start.p.y[k + l] / start.g.h)) * start.g.nnx +
                static_cast<long>(std::floor(start.p.x[k + l] / start.g.h));
      in_row += kernels::simd::in_a_row(n0);
      in_pairs += kernels::simd::in_pairs(n0);
      in_two += kernels::simd::layout(n0).kind == kernels::simd::kInTwo;
    }
    if (GetParam() == 1) EXPECT_GE(in_row, 10) << "groups in a row";
    else EXPECT_EQ(in_row, 0) << "groups in a row";
    if (GetParam() == 2) {
      EXPECT_GE(in_pairs, 10) << "groups two by two";
    }
    if (GetParam() == 3) {  // three and one, one and three: kInTwo
      EXPECT_GE(in_two, 5) << "groups in two cells";
    }
  }
  const double dt = 1e-8, inv_rho = 1.0 / tungsten().rho;
  auto p2g = [&](auto shape_c) {  // p2g: mass, momenta, forces
    using S = decltype(shape_c);
    KernelState w = start, s = start;
    kernels::p2g<S, kMomentum | kForce>(w.g, w.p, 0, n, w.f, inv_rho);
    for (int k = 0; k < n; ++k)
      kernels::p2g<S, kMomentum | kForce>(s.g, s.p, k, k + 1, s.f, inv_rho);
    expect_same(w, s, (std::string("p2g") + shape_of<S>()).c_str());
  };
  p2g(Bilinear());
  p2g(BSpline2());
  p2g(UGimp());
  // g2p with the re-map and the move (USF's), bilinear and B-spline.
  auto g2p = [&](auto shape_c, double flip) {
    using S = decltype(shape_c);
    const std::string pass = std::string("g2p, flip ") + std::to_string(flip) +
                             shape_of<S>();
    KernelState w = start, s = start;
    RowSpan rw, rs;
    kernels::g2p<S, true, true>(w.g, w.p, 0, n, w.f, inv_rho, flip, dt, rw);
    for (int k = 0; k < n; ++k)
      kernels::g2p<S, true, true>(s.g, s.p, k, k + 1, s.f, inv_rho, flip, dt, rs);
    expect_same(w, s, pass.c_str());
    EXPECT_EQ(rw.lo, rs.lo) << pass;
    EXPECT_EQ(rw.hi, rs.hi) << pass;
    EXPECT_EQ(rw.out, rs.out) << pass;
    EXPECT_EQ(rw.speed2, rs.speed2) << pass;
    EXPECT_NEAR(rw.kinetic, rs.kinetic, 1e-14 * rs.kinetic) << pass;
  };
  for (double flip : {1.0, 0.95}) {
    g2p(Bilinear(), flip);
    g2p(BSpline2(), flip);
    g2p(UGimp(), flip);
  }
  // The stress update, moving, with the bilinear and the quadratic B-spline shapes.
  auto stress = [&](auto shape_c, Model model) {
    using S = decltype(shape_c);
    const Material mat = tungsten(model, 1.2e9);
    KernelState w = start, s = start;
    RowSpan rw, rs;
    const double dw = kernels::update_stress<S, Model::Elastic, true>(
        w.g, w.p, 0, 0, mat, w.f.qx, w.f.qy, w.f.vnx, w.f.vny, dt, rw);  // an empty range
    EXPECT_EQ(dw, 0.0);
    double a = 0, b = 0;
    if (model == Model::Elastic) {
      a = kernels::update_stress<S, Model::Elastic, true>(w.g, w.p, 0, n, mat, w.f.qx, w.f.qy,
                                                          w.f.vnx, w.f.vny, dt, rw);
      for (int k = 0; k < n; ++k)
        b += kernels::update_stress<S, Model::Elastic, true>(
            s.g, s.p, k, k + 1, mat, s.f.qx, s.f.qy, s.f.vnx, s.f.vny, dt, rs);
    } else {
      a = kernels::update_stress<S, Model::VonMises, true>(
          w.g, w.p, 0, n, mat, w.f.qx, w.f.qy, w.f.vnx, w.f.vny, dt, rw);
      for (int k = 0; k < n; ++k)
        b += kernels::update_stress<S, Model::VonMises, true>(
            s.g, s.p, k, k + 1, mat, s.f.qx, s.f.qy, s.f.vnx, s.f.vny, dt, rs);
      int yielded = 0;
      for (int k = 0; k < n; ++k) yielded += w.p.eps_p[k] > 0;
      EXPECT_GT(yielded, n / 4) << "the von Mises lanes take the return";
      EXPECT_LT(yielded, n) << "and some stay elastic";
      EXPECT_GT(a, 0.0);
    }
    const std::string pass = std::string("stress, ") + (model == Model::Elastic ? "elastic" : "von Mises") +
                             shape_of<S>();
    expect_same(w, s, pass.c_str());
    EXPECT_NEAR(a, b, 1e-14 * std::abs(b) + 1e-300) << pass;
    EXPECT_EQ(rw.lo, rs.lo) << pass;
    EXPECT_EQ(rw.hi, rs.hi) << pass;
  };
  for (Model model : {Model::Elastic, Model::VonMises}) {
    stress(Bilinear(), model);
    stress(BSpline2(), model);
    stress(UGimp(), model);
  }
  {  // the nodal velocities q / m, with fixed components and light nodes
    KernelState w = start;
    std::vector<uint8_t> fix(w.g.nodes());
    for (std::size_t i = 0; i < fix.size(); ++i) fix[i] = static_cast<uint8_t>(i % 4);
    for (std::size_t i = 0; i < fix.size(); i += 7) w.a[0][i] = 1e-30;  // below the floor
    std::vector<double> ux(fix.size()), uy(fix.size());
    kernels::nodal_velocity(w.g, NodeBox{0, w.g.nnx - 1, 0, w.g.nny - 1}, w.f.m, fix.data(),
                            w.f.qx, w.f.qy, ux.data(), uy.data(), 1e-20, 1);
    for (std::size_t i = 0; i < fix.size(); ++i) {
      const bool heavy = w.a[0][i] > 1e-20;
      const double ex = heavy && !(fix[i] & 1) ? w.a[9][i] / w.a[0][i] : 0.0;
      const double ey = heavy && !(fix[i] & 2) ? w.a[10][i] / w.a[0][i] : 0.0;
      ASSERT_EQ(std::memcmp(&ux[i], &ex, sizeof ex), 0) << "node " << i;
      ASSERT_EQ(std::memcmp(&uy[i], &ey, sizeof ey), 0) << "node " << i;
    }
  }
}

// Particles anywhere, and along rows of cells 1, 2 and 3 to a cell (p2g's row form and its sums
// carried from particle to particle).
INSTANTIATE_TEST_SUITE_P(Layouts, Kernels, ::testing::Values(0, 1, 2, 3), [](const auto& i) {
  return i.param == 0 ? std::string("Scattered") : "AlongRows" + std::to_string(i.param) + "PerCell";
});

// The grid's write-only passes with streaming stores (past the cache) against plain ones
// (Solver::streaming): every particle array and the energy account bit for bit after 100 steps
// of a column with a free and with a silent end, under MUSL, USL and USF, on one and two threads;
// and the choice by timing, which a small grid skips.
TEST(Step, StreamingStoresGiveTheSameBits) {
  for (Scheme scheme : {Scheme::MUSL, Scheme::USL, Scheme::USF})
  for (End end : {End::Free, End::Silent})  // (the dashpot nodes' whole lines: by a buffer)
  for (int threads : {1, 2}) {
    std::unique_ptr<Solver> run[2];
    for (int mode : {0, 1}) {
      ColumnSpec spec;
      spec.scheme = scheme;
      spec.end = end;
      spec.cells = 60;
      spec.height = 6;  // 67 x 7 nodes: the second thread starts at an odd node
      spec.threads = threads;
      spec.fn = sin2_pulse(2e-6, 1e-6);
      spec.gravity = 1e4;
      run[mode] = make_column(spec);
      run[mode]->streaming = mode;
      EXPECT_EQ(run[mode]->store_mode(), mode);
      for (int i = 0; i < 100; ++i) run[mode]->step();
    }
    const std::string c = std::string(scheme_name(scheme)) + ", " + std::to_string(threads) +
                          " threads, " + (end == End::Free ? "free end" : "silent end");
    expect_same_run(*run[0], *run[1], c);
    if (end == End::Silent) {
      EXPECT_GT(run[0]->energy.absorbed, 0.0) << c;
    }
  }
  ColumnSpec small;
  auto s = make_column(small);
  EXPECT_EQ(s->store_mode(), -1);
  s->step();
  EXPECT_EQ(s->store_mode(), 0) << "a grid far below the trial's size keeps plain stores";
}

// Gravity's force m g: without hooks the grid update's pass adds it to each node's force before
// the update; with a hook (whose after_forces comes between) apply_loads' own pass adds it. The
// same bits either way: every particle array and the energy account after 100 steps of a column
// under gravity with a silent end, and with a damping band before it, under MUSL, USL and USF,
// with plain and streaming stores, on one and two threads (a hook that does nothing forces the
// own pass).
TEST(Step, GravityInTheGridUpdateAsInItsOwnPass) {
  struct Nothing : StepHooks {};
  for (Scheme scheme : {Scheme::MUSL, Scheme::USL, Scheme::USF})
  for (const bool band : {false, true})
  for (int mode : {0, 1})
  for (int threads : {1, 2}) {
    std::unique_ptr<Solver> run[2];
    Nothing nothing;
    for (int hooked : {0, 1}) {
      ColumnSpec spec;
      spec.scheme = scheme;
      spec.end = End::Silent;
      spec.cells = 60;
      spec.height = 6;  // 67 x 7 nodes: the second thread starts at an odd node
      spec.threads = threads;
      spec.fn = sin2_pulse(2e-6, 1e-6);
      spec.gravity = 1e4;
      if (band) spec.damp_cells = 12;
      run[hooked] = make_column(spec);
      run[hooked]->streaming = mode;
      if (hooked) run[hooked]->attach(&nothing);
      for (int i = 0; i < 100; ++i) run[hooked]->step();
      if (hooked) run[hooked]->detach(&nothing);
    }
    const Particles& p = run[0]->p;
    const std::string c = std::string(scheme_name(scheme)) + (band ? ", band" : ", LK end") +
                          (mode ? ", streaming, " : ", plain, ") + std::to_string(threads) +
                          " thread(s)";
    expect_same_run(*run[0], *run[1], c);
    // Gravity acted (along +x): against the same column without it, the particles' momentum
    // grew by more than a tenth of M g t (the end's dashpot takes back less than half of it
    // while its wave has not crossed the column).
    if (mode == 0 && threads == 1) {
      ColumnSpec spec;
      spec.scheme = scheme;
      spec.end = End::Silent;
      spec.cells = 60;
      spec.height = 6;
      spec.fn = sin2_pulse(2e-6, 1e-6);
      if (band) spec.damp_cells = 12;
      auto free = make_column(spec);
      for (int i = 0; i < 100; ++i) free->step();
      double dp = 0, M = 0;
      for (std::size_t k = 0; k < p.size(); ++k) {
        dp += p.mass[k] * (p.vx[k] - free->p.vx[k]);
        M += p.mass[k];
      }
      EXPECT_GT(dp, 0.1 * M * 1e4 * run[0]->t) << c;
    }
  }
}

// The grid update's dashpot nodes (a damping band's, a perfectly matched layer's, an LK end's),
// four at a time where four in a row are free and heavier than the mass floor: each node's
// updated velocity equals dashpot_velocity's from its own mass, block, start velocity and force,
// bit for bit, with plain and with streaming stores, on one and two threads. USL (no dashpot
// solve follows), and MUSL with the band's nodes that carry no silent weight (the solve replaces
// the others'). Checked after the update of every step while the pulse crosses the layer.
TEST(Step, DashpotNodesFourAtATimeAsOneByOne) {
  struct Check : StepHooks {
    bool all_nodes = true;  // false: only the nodes without a silent layer's weight
    long compared = 0, moving = 0, fours = 0, wrong = 0;
    void after_grid_update(Solver& s) override {
      const Grid& g = s.grid;
      const long n = static_cast<long>(g.nodes());
      auto eligible = [&](long i) {
        return g.fix[i] == Grid::kDashpotNode && g.m[i] > s.mass_floor();
      };
      for (long i = 0; i < n; ++i) {
        if (!(g.fix[i] & Grid::kDashpotNode) || !(g.m[i] > s.mass_floor())) continue;
        if (!all_nodes && g.dash_weight(i) > 0) continue;
        double ux = 0, uy = 0;
        dashpot_velocity(g.m[i], g.cxx(i), g.cxy(i), g.cyy(i), g.vx[i], g.vy[i], g.fx[i], g.fy[i],
                         s.dt, g.fix[i], ux, uy);
        ++compared;
        moving += ux != 0;
        wrong += std::memcmp(&ux, &g.vnx[i], sizeof ux) != 0 || std::memcmp(&uy, &g.vny[i], sizeof uy) != 0;
        if (i + 3 < n && i % 4 == 0 && eligible(i) && eligible(i + 1) && eligible(i + 2) && eligible(i + 3))
          ++fours;
      }
    }
  };
  for (const Scheme scheme : {Scheme::USL, Scheme::MUSL})
  for (const bool pml : {false, true})
  for (const int mode : {0, 1})
  for (const int threads : {1, 2}) {
    if (pml && scheme != Scheme::USL) continue;  // (MUSL damps the layer's particles instead)
    ColumnSpec spec;
    spec.scheme = scheme;
    spec.cells = 40;
    spec.height = 6;
    spec.threads = threads;
    spec.fn = sin2_pulse(2e-6, 1e-6);
    (pml ? spec.pml_cells : spec.damp_cells) = 12;
    auto s = make_column(spec);
    s->streaming = mode;
    Check check;
    check.all_nodes = scheme == Scheme::USL;
    s->attach(&check);
    for (int k = 0; k < 500; ++k) s->step();
    s->detach(&check);
    const std::string c = std::string(scheme_name(scheme)) + (pml ? ", PML" : ", band") +
                          (mode ? ", streaming" : ", plain") + ", " + std::to_string(threads) +
                          " thread(s)";
    EXPECT_EQ(check.wrong, 0) << c;
    EXPECT_GT(check.moving, check.compared / 4) << c;  // the pulse crossed the layer
    EXPECT_GT(check.fours, 500L) << c;                // rows of four free dashpot nodes
    if (mode == 0 && threads == 1)
      std::printf("  %s: %ld node updates compared (%ld moving), %ld rows of four\n", c.c_str(),
                  check.compared, check.moving, check.fours);
  }
}
