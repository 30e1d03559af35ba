// The convergence study at CI size (studies/convergence, paper Figs. 11-13): the study's case file
// with the plates shrunk to 40 x 40 mm, cells 4, 2 and 1 mm at 1 particle per cell. sigma_xx at
// D (centre of the steel plate) is recorded every step; the relative L2 difference between
// successive refinements (relative_l2, the metric the study uses) must decrease.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "silentmpm/case.hpp"
#include "silentmpm/history.hpp"

#ifndef SMPM_SOURCE_DIR
#define SMPM_SOURCE_DIR "."
#endif

using namespace smpm;

namespace {

History run_level(const std::string& cell, const std::string& extra = "") {
  std::vector<std::string> ov = {
      "grid.origin=[-0.048, -0.008]", "grid.size=[0.096, 0.056]", "grid.cell=" + cell,
      "geometry.parameters={\"L\": 0.04}", "time.end=4e-5",  // plates 0.04 m (meshes/convergence.geo)
      "probes.0.at=[0.02, 0.02]", "scheme.threads=1", "output.snapshots=0",
      "output.progress=false"};
  if (!extra.empty()) ov.push_back(extra);
  Case c = load_case(std::string(SMPM_SOURCE_DIR) + "/studies/convergence/cases/plates.json", ov);
  Solver& s = *c.solver;
  History h;
  h.columns = {"D.sxx"};
  h.data.resize(1);
  while (s.t < c.t_end - 0.5 * s.dt) {
    s.step();
    h.time.push_back(s.t);
    h.data[0].push_back(s.sample(0.02, 0.02).sxx);
  }
  return h;
}

}  // namespace

TEST(ContactConvergence, SuccessiveRefinementsGetCloser) {
  const History a = run_level("0.004"), b = run_level("0.002"), c = run_level("0.001");
  const double e1 = relative_l2(a, b, "D.sxx", 0, 4e-5);
  const double e2 = relative_l2(b, c, "D.sxx", 0, 4e-5);
  std::printf("convergence at D: |4 mm - 2 mm| = %.4f, |2 mm - 1 mm| = %.4f\n", e1, e2);
  // Measured 0.483 and 0.404: the sharp impact front rings at the grid frequency, so the
  // pointwise histories converge slowly in L2 (see studies/convergence/README.md).
  EXPECT_LT(e2, e1);
}
