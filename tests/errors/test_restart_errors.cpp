// Checkpoints that cannot be used and faults around them: each is one error naming the file and
// what is wrong, with the documented exit status (1: bad input; 2: the run failed), and the
// output folder is left without anything that looks complete.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "silentmpm/case.hpp"
#include "silentmpm/state_io.hpp"
#include "test_restart_common.hpp"

namespace smpm {
namespace {

using namespace restart_testing;

// A finished plate run with a checkpoint at step 100 of 150: its case file and its folder.
struct Source {
  std::string file;
  fs::path out, ck;
};

const Source& source() {
  static const Source s = [] {
    Source r;
    json c = small_plate(1, 150);
    c["output"]["checkpoint_every"] = 100;
    r.file = write_case("ck_source", c);
    r.out = scratch() / "ck_source_out";
    r.ck = r.out / "checkpoint.smpm";
    const Cli run = cli("run " + r.file + " --out " + r.out.string(), "ck_source");
    EXPECT_EQ(run.code, 0) << run.err;
    return r;
  }();
  return s;
}

std::string restart_args(const std::string& file, const fs::path& ck, const std::string& tag) {
  return "run " + file + " --out " + (scratch() / ("ck_" + tag)).string() + " --restart " +
         ck.string();
}

void expect_refused(const std::string& file, const fs::path& ck, const std::string& tag,
                    const std::string& expect) {
  const Cli r = cli(restart_args(file, ck, tag), tag);
  EXPECT_EQ(r.code, 1) << tag << ": " << r.err;
  EXPECT_NE(r.err.find(expect), std::string::npos) << tag << ": expected \"" << expect
                                                   << "\" in:\n" << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << tag << ": one line:\n" << r.err;
  EXPECT_FALSE(fs::exists(scratch() / ("ck_" + tag) / "summary.json")) << tag;
}

TEST(RestartErrors, UnusableCheckpointsAreRefused) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built";
  const Source& s = source();
  ASSERT_TRUE(fs::exists(s.ck));
  const std::string bytes = read_file(s.ck);

  expect_refused(s.file, scratch() / "nonexistent.smpm", "missing", "no such checkpoint file");
  expect_refused(s.file, fs::path(s.file), "json", "not a silentmpm checkpoint");

  const fs::path cut = scratch() / "cut.smpm";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  expect_refused(s.file, cut, "truncated", "truncated");

  std::string flipped = bytes;
  flipped[flipped.size() / 3] ^= 0x10;
  const fs::path bad = scratch() / "flipped.smpm";
  std::ofstream(bad, std::ios::binary) << flipped;
  expect_refused(s.file, bad, "corrupt", "checksum mismatch");

  // Another case: one material value changed.
  json other = small_plate(1, 150);
  other["materials"]["tungsten"]["young"] = 400e9;
  expect_refused(write_case("ck_other", other), s.ck, "other_case", "written for another case");

  // What a restart may change: time.end, output.*, scheme.threads (here all three).
  json longer = small_plate(1, 160);
  longer["output"]["history_every"] = 2;
  longer["scheme"]["threads"] = 2;
  const Cli ok = cli(restart_args(write_case("ck_longer", longer), s.ck, "longer"), "longer");
  EXPECT_EQ(ok.code, 0) << ok.err;

  // Nothing left to run: the case ends before the checkpoint.
  expect_refused(write_case("ck_shorter", small_plate(1, 80)), s.ck, "shorter",
                 "nothing left to run");

  // Another kind of run: an FEM case with an MPM checkpoint.
  expect_refused(write_case("ck_fem", hybrid_case_testing::plate_case("fem")), s.ck, "fem",
                 "a checkpoint of a run of kind \"mpm\", this case is of kind \"fem\"");

  // Edited values behind a recomputed checksum: a material group out of range and a particle off
  // the grid are refused, not indexed with.
  auto edited = [&](const std::string& block, std::size_t offset, const void* v, std::size_t n,
                    const std::string& tag) {
    std::string b = bytes;
    const std::size_t at = b.find(block);
    EXPECT_NE(at, std::string::npos) << block;
    std::memcpy(&b[at + block.size() + 12 + offset], v, n);  // after elem size and count
    const std::uint64_t sum = state_hash(b.data(), b.size() - 8);
    std::memcpy(&b[b.size() - 8], &sum, 8);
    const fs::path f = scratch() / (tag + ".smpm");
    std::ofstream(f, std::ios::binary) << b;
    return f;
  };
  const std::uint16_t group = 200;
  expect_refused(s.file, edited("mpm.p.group", 2 * 7, &group, 2, "group"), "group",
                 "particle material group out of range");
  const double far = 1e9;
  expect_refused(s.file, edited("mpm.p.x", 8 * 5, &far, 8, "far"), "far", "is not on the grid");
  {  // USF's kept edge velocities (edge_velocity "updated"): a node off the grid
    json u = small_plate(1, 150);
    u["scheme"]["update"] = "USF";
    u["boundaries"][1]["edge_velocity"] = "updated";
    u["output"]["checkpoint_every"] = 100;
    const std::string file = write_case("ck_usf_edge", u);
    const fs::path out = scratch() / "ck_usf_edge_out";
    const Cli run = cli("run " + file + " --out " + out.string(), "ck_usf_edge");
    ASSERT_EQ(run.code, 0) << run.err;
    std::string b = read_file(out / "checkpoint.smpm");
    const std::string block = "mpm.edge_velocity";
    const std::size_t at = b.find(block);
    ASSERT_NE(at, std::string::npos);
    std::memcpy(&b[at + block.size() + 12], &far, 8);  // the first node's i
    const std::uint64_t sum = state_hash(b.data(), b.size() - 8);
    std::memcpy(&b[b.size() - 8], &sum, 8);
    const fs::path f = scratch() / "edge_far.smpm";
    std::ofstream(f, std::ios::binary) << b;
    expect_refused(file, f, "edge_far", "edge_velocity names a node outside the grid");
  }

  // Another version: a checkpoint written by "0.0.1".
  StateWriter w;
  w.put_string("run.version", "0.0.1");
  const fs::path old = scratch() / "old.smpm";
  std::ofstream(old, std::ios::binary) << w.bytes();
  expect_refused(s.file, old, "version", "written by silentmpm 0.0.1");
}

// Bad checkpoint keys in the case file.
TEST(RestartErrors, CheckpointKeys) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built";
  const std::vector<std::pair<json, std::string>> bad = {
      {{{"checkpoint_every", -5}}, "output.checkpoint_every: must be >= 0"},
      {{{"checkpoint_time", -1e-6}}, "output.checkpoint_time: must be >= 0"},
      {{{"checkpoint_every", 10}, {"checkpoint_time", 1e-6}},
       "output.checkpoint_time: give checkpoint_every (steps) or checkpoint_time (seconds), not both"},
      {{{"checkpoint_evry", 10}}, "checkpoint_every"},
  };
  int k = 0;
  for (const auto& [out, expect] : bad) {
    json c = small_plate(1, 20);
    for (const auto& [key, v] : out.items()) c["output"][key] = v;
    const std::string f = write_case("ck_key_" + std::to_string(k), c);
    const Cli r = cli("check " + f, "ck_key_" + std::to_string(k++));
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << "expected \"" << expect << "\" in:\n" << r.err;
  }
}

// Disk full while writing a checkpoint (its temporary file is a link to /dev/full): one error
// naming the file and the cause, exit 2, RUN_INCOMPLETE saying why, no summary.json.
TEST(RestartErrors, DiskFullWritingCheckpoint) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built";
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  json c = small_plate(1, 50);
  c["output"]["checkpoint_every"] = 10;
  const std::string f = write_case("ck_full", c);
  const fs::path out = scratch() / "ck_full_out";
  fs::remove_all(out);
  fs::create_directories(out);
  fs::create_symlink("/dev/full", out / "checkpoint.smpm.tmp");
  const Cli r = cli("run " + f + " --out " + out.string(), "ck_full");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("checkpoint.smpm: cannot write: No space left on device"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  EXPECT_FALSE(fs::exists(out / "checkpoint.smpm"));
  EXPECT_NE(read_file(out / "RUN_INCOMPLETE").find("No space left on device"), std::string::npos);
}

// A run that fails after it started (a particle leaves the grid) exits 2 and leaves
// RUN_INCOMPLETE naming the cause instead of a summary, and the failed step's state for
// inspection: failed.smpm (a checkpoint that a restart refuses, naming the failure and the
// checkpoint to use) and a last snapshot.
TEST(RestartErrors, RunFailureExitsTwoWithMarker) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built";
  json c = small_plate(1, 400);
  c["bodies"][0]["velocity"] = {3000.0, 0.0};  // flies out of the grid within the run
  c["boundaries"] = json::array();
  c["output"]["snapshots"] = 4;
  const std::string f = write_case("ck_fail", c);
  const fs::path out = scratch() / "ck_fail_out";
  const Cli r = cli("run " + f + " --out " + out.string(), "ck_fail");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("left the grid"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the failed step's state: " + (out / "failed.smpm").string() +
                       ", and the last snapshot"),
            std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  EXPECT_NE(read_file(out / "RUN_INCOMPLETE").find("left the grid"), std::string::npos);
  ASSERT_TRUE(fs::exists(out / "failed.smpm"));
  const Cli again = cli("run " + f + " --out " + (scratch() / "ck_fail_again").string() +
                        " --restart " + (out / "failed.smpm").string(), "ck_fail_again");
  EXPECT_EQ(again.code, 1) << again.err;
  EXPECT_NE(again.err.find("failed.smpm"), std::string::npos) << again.err;
  EXPECT_NE(again.err.find("the state of a step that failed (particle"), std::string::npos) << again.err;
  EXPECT_NE(again.err.find("restart from the last checkpoint of the run (checkpoint.smpm)"),
            std::string::npos) << again.err;
}


// An FE far field that blows up stops like an MPM run: exit 2, RUN_INCOMPLETE naming the step,
// no summary. The trigger: a perfectly matched layer on the left and right sides of a square
// whose top and bottom are free (a plate with absorbing ends), which grows within 2 000 steps
// (docs/physics.md section 9.3). Before the check the run finished with a kinetic energy of
// 8e55 J and a summary.
TEST(RestartErrors, FemRunThatBlowsUpStops) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built";
  const fs::path geo = scratch() / "fe_plate.geo";
  std::ofstream(geo)
      << "DefineConstant[ h = {0.002, Name \"Parameters/h\"} ];\n"
         "Point(1) = {0, 0, 0}; Point(2) = {0.08, 0, 0}; Point(3) = {0.08, 0.08, 0};\n"
         "Point(4) = {0, 0.08, 0};\n"
         "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
         "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
         "Transfinite Curve{1, 2, 3, 4} = Round(0.08 / h) + 1; Transfinite Surface{1}; Recombine Surface{1};\n"
         "Physical Surface(\"body\", 1) = {1};\n"
         "Physical Curve(\"bottom\", 11) = {1}; Physical Curve(\"right\", 12) = {2};\n"
         "Physical Curve(\"top\", 13) = {3}; Physical Curve(\"left\", 14) = {4};\n";
  json c = json::parse(R"({
    "time": {"end": 1e-3, "cfl": 0.5},
    "materials": {"steel": {"model": "elastic", "young": 200e9, "poisson": 0.3, "density": 7850}},
    "fem": {"mesh": "", "size": 0.002, "degree": 1, "regions": {"body": "steel"},
            "boundaries": [
              {"type": "traction", "curve": "top", "normal": -1e7,
               "time": {"shape": "sin2", "start": 0, "duration": 4e-6, "ramp": 2e-6}},
              {"type": "pml", "curve": "right", "width": 0.02, "r0": 0.01},
              {"type": "pml", "curve": "left", "width": 0.02, "r0": 0.01},
              {"type": "dashpot", "curve": "right"}, {"type": "dashpot", "curve": "left"}]},
    "output": {"snapshots": 0, "progress": false, "history_every": 100}
  })");
  c["fem"]["mesh"] = geo.string();
  const std::string f = write_case("fe_blowup", c);
  const fs::path out = scratch() / "fe_blowup_out";
  const Cli r = cli("run " + f + " --out " + out.string(), "fe_blowup");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("the FEM run is unstable at step"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("exceeds 10 times the energy put in"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  EXPECT_NE(read_file(out / "RUN_INCOMPLETE").find("the FEM run is unstable"), std::string::npos);
}

// USL and a node that holds a sliver of mass (docs/physics.md section 9.3): a steel half-space at
// 4 ppc, free, under a 100 MPa line load, its grid 0.3 of a cell lower than the body's, so that
// the top particles lie 0.05 h past a grid line and the row above holds 5 % of their weight.
// Under USL at CFL 0.5 the run stops on the energy check within 20 steps, and the error names
// USL's sliver node and MUSL; at CFL 0.3, and under MUSL at 0.5, the same case runs.
TEST(RestartErrors, UslSliverNodeBlowUpNamesTheScheme) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built";
  json c = json::parse(R"({
    "grid": {"origin": [-0.0006, -0.0006], "size": [0.062, 0.032], "cell": 0.002},
    "time": {"end": 4e-6, "cfl": 0.5},
    "scheme": {"update": "USL"},
    "materials": {"steel": {"model": "elastic", "young": 200e9, "poisson": 0.3, "density": 7850}},
    "bodies": [{"name": "ground", "material": "steel", "box": [0, 0, 0.06, 0.03],
                "particles_per_cell": 4}],
    "boundaries": [{"type": "traction", "body": "ground", "side": "top", "interval": [0.028, 0.032],
                    "normal": -1e8,
                    "time": {"shape": "sin2", "start": 0, "duration": 4e-6, "ramp": 2e-6}}],
    "output": {"snapshots": 0, "progress": false, "history_every": 10}
  })");
  const std::string f = write_case("usl_sliver", c);
  const fs::path out = scratch() / "usl_sliver_out";
  const Cli r = cli("run " + f + " --out " + out.string(), "usl_sliver");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("exceeds 10 times the energy put in"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("under USL a node that holds a sliver of a particle's mass"),
            std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  EXPECT_NE(read_file(out / "RUN_INCOMPLETE").find("under USL"), std::string::npos);
  c["time"]["cfl"] = 0.3;
  const Cli slow = cli("run " + write_case("usl_sliver_03", c) + " --out " +
                           (scratch() / "usl_sliver_03").string(), "usl_sliver_03");
  EXPECT_EQ(slow.code, 0) << slow.err;
  c["time"]["cfl"] = 0.5;
  c["scheme"]["update"] = "MUSL";
  const Cli musl = cli("run " + write_case("usl_sliver_musl", c) + " --out " +
                           (scratch() / "usl_sliver_musl").string(), "usl_sliver_musl");
  EXPECT_EQ(musl.code, 0) << musl.err;
}
}  // namespace
}  // namespace smpm

namespace smpm {
namespace {

using namespace restart_testing;

// A disk that fills during the run (a 1 MB tmpfs; skipped where mounting is not allowed): the
// snapshots, the history or a checkpoint fail to write, and the run stops with exit 2, an error
// naming the file and no summary.json; RUN_INCOMPLETE, written when the run started, stays.
TEST(RestartErrors, DiskFillsDuringTheRun) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built";
  const fs::path mnt = scratch() / "small_disk";
  fs::create_directories(mnt);
  if (std::system(("mount -t tmpfs -o size=1M tmpfs \"" + mnt.string() + "\" 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "cannot mount a tmpfs here";
  struct Unmount {
    fs::path p;
    ~Unmount() { std::system(("umount \"" + p.string() + "\"").c_str()); }
  } unmount{mnt};
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"snapshots", "--set output.snapshots=20"},
      {"checkpoints", "--set output.snapshots=0 --set output.checkpoint_every=5"},
  };
  for (const auto& [tag, args] : runs) {
    json c = small_plate(4, 120);
    const std::string f = write_case("full_" + tag, c);
    const fs::path out = mnt / tag;
    const Cli r = cli("run " + f + " --out " + out.string() + " " + args, "full_" + tag);
    EXPECT_EQ(r.code, 2) << tag << ": " << r.err;
    EXPECT_NE(r.err.find(out.string()), std::string::npos) << tag << ": " << r.err;
    EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << tag << ": " << r.err;
    EXPECT_FALSE(fs::exists(out / "summary.json")) << tag;
    EXPECT_TRUE(fs::exists(out / "RUN_INCOMPLETE")) << tag;
    fs::remove_all(out);
  }
}

}  // namespace
}  // namespace smpm
