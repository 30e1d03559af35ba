// The pulse study (studies/pulse) at reduced resolution (2 mm cells): the silent right side
// tracks the extended plate at A within 5 % relative L2 over the extended run's reflection-free
// window, and at most a tenth of what the free side departs, for both load cases.
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

fs::path run_reduced(const std::string& load, const std::string& bc, const fs::path& out) {
  const fs::path src = fs::path(SMPM_SOURCE_DIR) / "studies/pulse/cases" / (load + "_" + bc + ".json");
  Case c = load_case(src.string(), {"grid.cell=0.002", "output.snapshots=0", "output.progress=false",
                                    "output.history_every=2"});
  const fs::path dir = out / (load + "_" + bc);
  run_case(c, dir.string());
  return dir / "history.csv";
}

}  // namespace

TEST(PulseStudy, SilentTracksExtendedAtReducedResolution) {
  const fs::path root(SMPM_SOURCE_DIR);
  std::ifstream f(root / "studies/pulse/study.json");
  ASSERT_TRUE(f.good());
  const auto study = nlohmann::json::parse(f);
  const fs::path out = fs::temp_directory_path() / ("smpm_pulse_study_test_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::string probe = study["probe"];
  for (const std::string load : {"compressive", "shear"}) {
    const auto& spec = study["loads"][load];
    const std::string col = probe + "." + spec["components"][0].get<std::string>();
    const double t0 = spec["window"][0], t1 = spec["window"][1];
    const History ext = read_history(run_reduced(load, "extended", out).string());
    const History sil = read_history(run_reduced(load, "silent", out).string());
    const History fre = read_history(run_reduced(load, "free", out).string());
    const double e_sil = relative_l2(sil, ext, col, t0, t1);
    const double e_free = relative_l2(fre, ext, col, t0, t1);
    std::printf("  %s %s: silent_vs_extended %.4f, free_vs_extended %.4f\n", load.c_str(),
                col.c_str(), e_sil, e_free);
    EXPECT_LE(e_sil, 0.05) << load;
    EXPECT_LE(e_sil, 0.1 * e_free) << load;
  }
  fs::remove_all(out);
}
