// Cross-method check on the pulse plate (studies/pulse, Shen & Chen 2005 Figs. 3-7) at reduced
// resolution: 2 mm cells, and the compressive pulse with 5 us sin^2 ramps instead of 2 us, so
// that its rise spans 15 cells (with 2 us ramps at 2 mm the two discretisations still differ by
// 8 % through dispersion alone, 2.6 % at 1 mm). Over the extended run's reflection-free window:
//  * MPM and FEM sigma_xx at A agree within 3 % relative L2, for the extended plate and for the
//    MPM silent layer against the FEM dashpots;
//  * sigma_yy at A departs from the extended plate by the same amount (about 0.29) with the MPM
//    silent layer and with the FEM dashpots: that departure is the LK boundary's own error for
//    the grazing waves on the right side, not an MPM artefact.
#include <gtest/gtest.h>

#include <unistd.h>
#include <string>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"
#include "silentmpm/driver.hpp"
#include "silentmpm/history.hpp"

using namespace smpm;
namespace fs = std::filesystem;

namespace {

History run(const std::string& name, const std::vector<std::string>& overrides, const fs::path& out) {
  const fs::path src = fs::path(SMPM_SOURCE_DIR) / "studies/pulse/cases" / (name + ".json");
  std::vector<std::string> o = overrides;
  o.insert(o.end(), {"output.snapshots=0", "output.progress=false", "output.history_every=2"});
  Case c = load_case(src.string(), o);
  run_case(c, (out / name).string());
  return read_history((out / name / "history.csv").string());
}

}  // namespace

TEST(FemPulse, MpmAndFemAgreeOnThePulsePlate) {
  std::ifstream f(fs::path(SMPM_SOURCE_DIR) / "studies/pulse/study.json");
  ASSERT_TRUE(f.good());
  const auto study = nlohmann::json::parse(f);
  const double t0 = study["loads"]["compressive"]["window"][0];
  const double t1 = study["loads"]["compressive"]["window"][1];
  const fs::path out = fs::temp_directory_path() / ("smpm_fem_pulse_test_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::vector<std::string> mpm = {"grid.cell=0.002", "boundaries.0.time.ramp=5e-6"};
  const std::vector<std::string> fem = {"fem.size=0.002", "fem.boundaries.0.time.ramp=5e-6"};
  const History m_ext = run("compressive_extended", mpm, out);
  const History m_sil = run("compressive_silent", mpm, out);
  const History f_ext = run("compressive_fem_extended", fem, out);
  const History f_dash = run("compressive_fem_dashpot", fem, out);
  const double e_ext = relative_l2(f_ext, m_ext, "A.sxx", t0, t1);
  const double e_bnd = relative_l2(f_dash, m_sil, "A.sxx", t0, t1);
  const double syy_fem = relative_l2(f_dash, f_ext, "A.syy", t0, t1);
  const double syy_mpm = relative_l2(m_sil, m_ext, "A.syy", t0, t1);
  std::printf("  sxx FEM vs MPM: extended %.4f, dashpot vs silent %.4f\n", e_ext, e_bnd);
  std::printf("  syy absorbing vs extended: FEM dashpots %.4f, MPM silent layer %.4f\n", syy_fem, syy_mpm);
  EXPECT_LE(e_ext, 0.03);
  EXPECT_LE(e_bnd, 0.03);
  EXPECT_GT(syy_fem, 0.2);
  EXPECT_NEAR(syy_fem, syy_mpm, 0.1 * syy_mpm);
  fs::remove_all(out);
}
