// Checkpoints and restarts: a run continued from a checkpoint writes the same history.csv, byte
// for byte, the same summary.json (timing keys and the restart record aside) and the same
// snapshots as the run that was never stopped — for MPM (MUSL with Kelvin-Voigt springs and a
// damping band, USL multi-field contact with friction, the J2 film with bifurcation and
// decohesion), FEM and the hybrid. SIGTERM and SIGINT stop a run cleanly (exit 3, checkpoint,
// RUN_INCOMPLETE, no summary) and the restart of it equals an uninterrupted run.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <cstdio>
#include <fstream>

#include "silentmpm/case.hpp"
#include "silentmpm/driver.hpp"
#include "silentmpm/history.hpp"
#include "test_contact_common.hpp"
#include "test_film_common.hpp"
#include "test_restart_common.hpp"

namespace smpm {
namespace {

using namespace restart_testing;

// Runs `c` to its end writing checkpoints (the last one stays), then continues a copy of its
// output folder from that checkpoint; both folders must agree. Returns the checkpoint's step.
long expect_restart_identical(const std::string& name, json c, const std::string& ck_key,
                              double ck_value) {
  c["output"][ck_key] = ck_value;
  const std::string file = write_case("restart_" + name, c);
  const fs::path a = scratch() / ("restart_" + name + "_a"), b = scratch() / ("restart_" + name + "_b");
  fs::remove_all(a);
  fs::remove_all(b);
  {
    Case cs = load_case(file);
    run_case(cs, a.string());
  }
  EXPECT_TRUE(fs::exists(a / "checkpoint.smpm")) << name;
  fs::copy(a, b, fs::copy_options::recursive);
  fs::remove(b / "summary.json");
  {
    Case cs = load_case(file);
    RunOptions o;
    o.restart = (a / "checkpoint.smpm").string();
    run_case(cs, b.string(), o);
  }
  const std::string ha = read_file(a / "history.csv"), hb = read_file(b / "history.csv");
  EXPECT_GT(ha.size(), 1000u) << name;
  EXPECT_TRUE(ha == hb) << name << ": history.csv differs after the restart";
  const json sa = summary_without_timing(a), sb = summary_without_timing(b);
  EXPECT_EQ(sa, sb) << name;
  const json full = json::parse(read_file(b / "summary.json"));
  EXPECT_TRUE(full.contains("restart")) << name;
  for (const char* f : {"particles.xdmf", "fem.xdmf", "particles.h5", "fem.h5"})
    if (fs::exists(a / f)) {
      EXPECT_TRUE(fs::exists(b / f)) << name << " " << f;
      if (std::string(f).find("xdmf") != std::string::npos) {
        EXPECT_TRUE(read_file(a / f) == read_file(b / f)) << name << ": " << f << " differs";
      }
    }
  return full["restart"]["from_step"].get<long>();
}

TEST(Restart, MpmSpringsAndDampingBandBitIdentical) {
  using namespace hybrid_case_testing;
  json c = small_plate(4, 240);
  c["boundaries"][1]["type"] = "kelvin_voigt";
  c["boundaries"][1]["delta"] = 30 * h;
  c["boundaries"].push_back({{"type", "damping_layer"}, {"body", "plate"}, {"side", "top"},
                             {"width", 5 * h}, {"r0", 0.3}, {"beta", 0.3 * h / 5000}});
  c["output"]["snapshots"] = 4;
  const long from = expect_restart_identical("mpm_kv", c, "checkpoint_every", 100);
  EXPECT_EQ(from, 200);
}

// USF with the updated velocity at the silent edge's dashpot nodes: the last step's v+ there is
// state (the next step strains the particles with it). The pulse is at the edge at step 300.
TEST(Restart, MpmUsfUpdatedEdgeBitIdentical) {
  using namespace hybrid_case_testing;
  json c = small_plate(4, 340);
  c["scheme"]["update"] = "USF";
  c["boundaries"][1]["edge_velocity"] = "updated";
  const long from = expect_restart_identical("mpm_usf_updated", c, "checkpoint_every", 100);
  EXPECT_EQ(from, 300);
}

// The delayed closure at the silent edge (1 ppc): each edge node's ring of start velocities and
// forces is state (the dashpot acts with the velocity of h/c earlier), under MUSL and USF. The
// pulse is at the edge at step 300.
TEST(Restart, MpmDelayedEdgeBitIdentical) {
  using namespace hybrid_case_testing;
  for (const char* scheme : {"MUSL", "USF"}) {
    json c = small_plate(1, 340);
    c["scheme"]["update"] = scheme;
    c["boundaries"][1]["edge_velocity"] = "delayed";
    const long from = expect_restart_identical(std::string("mpm_delayed_") + scheme, c,
                                               "checkpoint_every", 100);
    EXPECT_EQ(from, 300) << scheme;
  }
}

// A perfectly matched layer on particles (USL, and MUSL and USF at 4 ppc, whose layer damps its
// particles within each step): its displacements and memories are state.
TEST(Restart, MpmPmlBitIdentical) {
  using namespace hybrid_case_testing;
  for (const char* scheme : {"USL", "MUSL", "USF"}) {
    json c = small_plate(4, 240);
    c["scheme"]["update"] = scheme;
    c["boundaries"].push_back({{"type", "pml"}, {"body", "plate"}, {"side", "top"},
                               {"width", 5 * h}, {"alpha", 1e5}});
    c["output"]["snapshots"] = 4;
    const long from =
        expect_restart_identical(std::string("mpm_pml_") + scheme, c, "checkpoint_every", 100);
    EXPECT_EQ(from, 200) << scheme;
  }
}

// Light nodes (scheme.light_nodes "extend", with two terms of the mass correction): found again
// every step from the masses, no state of their own. examples/half-space-pml.json with the grid
// 0.3 of a cell below its body, whose top node row is light.
TEST(Restart, MpmLightNodesBitIdentical) {
  json c = json::parse(read_file(fs::path(SMPM_SOURCE_DIR) / "examples" / "half-space-pml.json"));
  c["grid"]["origin"] = {0, -0.0006};
  c["grid"]["size"] = {0.2, 0.104};
  c["scheme"]["light_nodes"] = "extend";
  c["scheme"]["mass_correction"] = 2;
  c["time"]["end"] = 3e-5;
  c["output"]["snapshots"] = 0;
  const long from = expect_restart_identical("mpm_light_nodes", c, "checkpoint_every", 100);
  EXPECT_EQ(from, 100);
  const json summary = json::parse(read_file(scratch() / "restart_mpm_light_nodes_b" /
                                             "summary.json"));
  EXPECT_NE(summary.dump().find("\"extended\":97"), std::string::npos) << summary.dump();
}

TEST(Restart, MpmMultiFieldContactWithFrictionBitIdentical) {
  json c = contact_testing::impact_case();
  c["scheme"]["update"] = "USL";
  c["scheme"]["threads"] = 2;
  c["contact"]["friction"] = 0.2;
  c["output"]["snapshots"] = 3;
  expect_restart_identical("impact", c, "checkpoint_every", 150);
}

// USF with one velocity field per body and a Kelvin-Voigt boundary: the springs advance with
// the start-of-step velocity of the step they are in (computed for the centre-of-mass field too,
// not left from the step before), so a restart, whose grid starts empty, continues identically.
// The wave reaches the spring (the target's far end, 0.12 m) near step 400; the last checkpoint
// is at step 450.
TEST(Restart, MpmMultiFieldUsfSpringsBitIdentical) {
  json c = contact_testing::impact_case();
  c["scheme"]["update"] = "USF";
  c["time"]["end"] = 3.2e-5;
  c["boundaries"].push_back({{"type", "kelvin_voigt"}, {"body", "target"}, {"side", "right"},
                             {"delta", 0.03}});
  const long from = expect_restart_identical("impact_usf_kv", c, "checkpoint_every", 150);
  EXPECT_GE(from, 450);
}

// The film: J2 softening, bifurcation and decohesion state carried by the particles. The
// checkpoint falls after the onset of plasticity (the history's dissipated energy is non-zero
// there), so the restored film state is exercised.
TEST(Restart, FilmJ2StateBitIdentical) {
  std::ifstream f(film_testing::case_path("silent"));
  json c = json::parse(f);
  c["geometry"]["file"] = std::string(SMPM_SOURCE_DIR) + "/meshes/film_5um.geo";
  c["time"]["end"] = 2.0e-9;
  c["scheme"]["threads"] = 2;
  c["output"]["snapshots"] = 0;
  c["output"]["progress"] = false;
  const long from = expect_restart_identical("film", c, "checkpoint_every", 400);
  const History hist =
      read_history((scratch() / "restart_film_a" / "history.csv").string());
  const auto& diss = hist.column("energy.dissipated");
  const auto& t = hist.time;
  double at_ck = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] <= from * 3.2e-12 * (1 + 1e-9)) at_ck = diss[k];
  EXPECT_GT(at_ck, 0.0) << "no plastic dissipation before the checkpoint at step " << from;
}

TEST(Restart, FemBitIdenticalWithCheckpointTime) {
  using namespace hybrid_case_testing;
  json c = plate_case("fem");
  c["output"]["snapshots"] = 3;
  // A perfectly matched layer in front of the dashpots: its memories are part of the state.
  c["fem"]["boundaries"].push_back(
      {{"type", "pml"}, {"curve", "right"}, {"width", 5 * h}, {"alpha", 1e5}});
  // Every 100 steps of simulated time: the last checkpoint at step 200 of 300.
  const long from = expect_restart_identical("fem", c, "checkpoint_time", 100 * 0.3 * h / cd);
  EXPECT_EQ(from, 200);
}

TEST(Restart, HybridBitIdentical) {
  json c = hybrid_case_testing::plate_case("hybrid");
  c["output"]["snapshots"] = 3;
  c["fem"]["boundaries"].push_back(
      {{"type", "pml"}, {"curve", "right"}, {"width", 5 * hybrid_case_testing::h}, {"alpha", 1e5}});
  expect_restart_identical("hybrid", c, "checkpoint_every", 120);
}

// Another thread count: the particles are re-cut into strips, sums over them run in another
// order, and the continuation agrees to round-off (relative L2 below 1e-12), with a note.
TEST(Restart, OtherThreadCountAgreesToRoundOff) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built";
  json c = small_plate(4, 300);
  c["output"]["checkpoint_every"] = 100;
  c.erase("scheme");  // --threads then creates the section: still the same case
  const std::string file = write_case("restart_threads", c);
  const fs::path a = scratch() / "restart_threads_a", b = scratch() / "restart_threads_b";
  fs::remove_all(a);
  fs::remove_all(b);
  ASSERT_EQ(cli("run " + file + " --out " + a.string() + " --threads 1", "threads_a").code, 0);
  const Cli r = cli("run " + file + " --out " + b.string() + " --threads 2 --restart " +
                        (a / "checkpoint.smpm").string(), "threads_b");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("continuing on 2 thread(s); the checkpoint was written on 1"),
            std::string::npos) << r.err;
  const History ha = read_history((a / "history.csv").string());
  const History hb = read_history((b / "history.csv").string());
  for (const char* col : {"A.sxx", "B.sxx", "B.vx", "energy.kinetic"}) {
    const double e = relative_l2(hb, ha, col, 0, 1);
    std::printf("%s: relative L2 %.2e\n", col, e);
    EXPECT_LT(e, 1e-12) << col;
  }
}

// SIGTERM and SIGINT: the run finishes its step, writes the checkpoint, the history so far (whole
// rows) and RUN_INCOMPLETE, writes no summary.json and exits 3; continued with --restart (and a
// nearer time.end) it equals a run that was never stopped.
void expect_clean_interrupt(int sig, const std::string& tag) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built";
  const long steps = 1500;
  const json base = small_plate(1, steps);
  const std::string short_case = write_case("sig_" + tag + "_short", base);
  json long_run = base;
  long_run["time"]["end"] = 1e6 * 0.3 * hybrid_case_testing::h / hybrid_case_testing::cd;
  long_run["output"]["checkpoint_every"] = 1000000;  // only the interrupt writes one
  const std::string long_case = write_case("sig_" + tag + "_long", long_run);
  const fs::path u = scratch() / ("sig_" + tag + "_u"), d = scratch() / ("sig_" + tag + "_d");
  fs::remove_all(u);
  fs::remove_all(d);
  ASSERT_EQ(cli("run " + short_case + " --out " + u.string(), tag + "_u").code, 0);

  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string out = d.string();
    const int fd = ::open("/dev/null", O_WRONLY);
    dup2(fd, 1);
    const std::string err = (scratch() / ("sig_" + tag + ".err")).string();
    const int fe = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fe, 2);
    execl(SMPM_CLI, SMPM_CLI, "run", long_case.c_str(), "--out", out.c_str(), "--threads", "1",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until the run is stepping (history rows appear), then signal it.
  for (int k = 0; k < 2000; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (read_file(d / "history.csv").size() > 4000) break;
  }
  kill(pid, sig);
  int st = 0;
  waitpid(pid, &st, 0);
  const std::string err = read_file(scratch() / ("sig_" + tag + ".err"));
  ASSERT_TRUE(WIFEXITED(st)) << "killed by the signal instead of stopping cleanly";
  EXPECT_EQ(WEXITSTATUS(st), 3) << err;
  const std::string name = sig == SIGINT ? "SIGINT" : "SIGTERM";
  EXPECT_NE(err.find("interrupted by " + name), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(d / "summary.json"));
  ASSERT_TRUE(fs::exists(d / "checkpoint.smpm"));
  const std::string marker = read_file(d / "RUN_INCOMPLETE");
  EXPECT_NE(marker.find("interrupted by " + name), std::string::npos) << marker;
  EXPECT_NE(marker.find("--restart"), std::string::npos) << marker;
  const std::string hist = read_file(d / "history.csv");
  ASSERT_FALSE(hist.empty());
  EXPECT_EQ(hist.back(), '\n') << "history.csv cut inside a row";

  const Cli r = cli("run " + short_case + " --out " + d.string() + " --restart " +
                        (d / "checkpoint.smpm").string(), tag + "_restart");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(d / "RUN_INCOMPLETE"));
  EXPECT_TRUE(read_file(u / "history.csv") == read_file(d / "history.csv"))
      << "the restarted run's history differs from the uninterrupted one";
  EXPECT_EQ(summary_without_timing(u), summary_without_timing(d));
}

TEST(Restart, SigtermStopsCleanlyAndRestartIsBitIdentical) { expect_clean_interrupt(SIGTERM, "term"); }
TEST(Restart, SigintStopsCleanlyAndRestartIsBitIdentical) { expect_clean_interrupt(SIGINT, "int"); }

}  // namespace
}  // namespace smpm
