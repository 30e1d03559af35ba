// MPM-FEM hybrid (docs/physics.md section 7): a plane P wave crossing the interface, and the
// reflection of a wide pulse there. Energy balance, momentum and the uniform-strain patches are in
// test_hybrid_conservation.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "test_hybrid_common.hpp"

using namespace smpm;
using namespace smpm::hybrid_testing;

namespace {

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

std::vector<double> record(HybRun& m, const Strip& c, double x, double y, double t_end) {
  Probe p(m, x, y, c.mpm_cells * c.h);
  std::vector<double> out;
  while (m.time() < t_end - 0.5 * m.dt) {
    m.step();
    out.push_back(p.sxx());
  }
  return out;
}

}  // namespace

// A sin^2 pulse 20 cells wide travels along a column with rollers: particles on [0, 60h], Q1
// elements on [60h, 200h]. The wave reflected by the interface is the difference, at a probe in
// the MPM part, between the hybrid and an all-MPM column of the same length; in the window where
// only that reflection can reach the probe it must stay below 2 % of the pulse amplitude
// (docs/physics.md: ~0.5 % in a 1D prototype). With one particle per cell at the cell centre and u
// a function of x only, MPM and lumped Q1 coincide, so the reflection is the MPM noise floor.
// Measured (MUSL, 1 ppc): 0.86 % for this 20-cell pulse; 0.24 % for 40 cells; USL 0.15 %.
TEST(Hybrid, PlanePWaveCrossesTheInterface) {
  Strip c;
  const double cd = smpm::testing::tungsten().cd;
  c.fn = bell(20 * c.h / cd);
  c.right = Right::Free;
  const double xp = 30.5 * c.h, yp = 1.0 * c.h;
  // Reflection from x = 60h is at the probe from (60 + 29.5) h / c; the free end's (x = 200h)
  // only after (200 + 169.5) h / c.
  const double t0 = 80 * c.h / cd, t_end = 140 * c.h / cd;
  HybRun hyb = make_strip(c);
  ASSERT_TRUE(hyb.hyb);
  EXPECT_EQ(hyb.hyb->interface_nodes(), 3u);  // the interface x = 60h: 3 nodes across 2 cells
  Strip ref = c;
  ref.mpm_cells = c.cells;
  HybRun all = make_strip(ref);
  const auto a = record(hyb, c, xp, yp, t_end);
  const auto b = record(all, ref, xp, yp, t_end);
  ASSERT_EQ(a.size(), b.size());
  double peak = 0, diff = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    peak = std::max(peak, std::abs(b[k]));
    if ((k + 1) * hyb.dt > t0) diff = std::max(diff, std::abs(a[k] - b[k]));
  }
  EXPECT_NEAR(peak, c.amplitude, 0.05 * c.amplitude);  // the incident pulse passed the probe
  RecordProperty("reflection", std::to_string(diff / c.amplitude));
  std::printf("interface reflection %.3e of the amplitude\n", diff / c.amplitude);
  EXPECT_LT(diff / c.amplitude, 0.02);
}

// docs/physics.md section 7 acceptance: a pulse >= 40 cells wide reflects <= 1 %. Particles on
// [0, 100h], elements on [100h, 300h]; probe 50 cells from the interface. Measured 0.24 % (MUSL,
// 1 particle per cell).
TEST(Hybrid, WidePulseReflectsUnderOnePercent) {
  Strip c;
  c.cells = 300;
  c.mpm_cells = 100;
  const double cd = smpm::testing::tungsten().cd;
  c.fn = bell(40 * c.h / cd);
  const double xp = 50.5 * c.h, yp = 1.0 * c.h;
  // Incident pulse past the probe by (50.5 + 40) h / c; reflection back at (100 + 49.5) h / c.
  const double t0 = 95 * c.h / cd, t_end = (100 + 49.5 + 50) * c.h / cd;
  HybRun hyb = make_strip(c);
  Strip ref = c;
  ref.mpm_cells = c.cells;
  HybRun all = make_strip(ref);
  const auto a = record(hyb, c, xp, yp, t_end);
  const auto b = record(all, ref, xp, yp, t_end);
  ASSERT_EQ(a.size(), b.size());
  double diff = 0;
  for (std::size_t k = 0; k < a.size(); ++k)
    if ((k + 1) * hyb.dt > t0) diff = std::max(diff, std::abs(a[k] - b[k]));
  std::printf("wide pulse: interface reflection %.3e of the amplitude\n", diff / c.amplitude);
  EXPECT_LT(diff / c.amplitude, 0.01);
}
