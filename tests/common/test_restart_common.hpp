#pragma once
// Helpers shared by the checkpoint tests (tests/physics/test_restart.cpp: restarted runs equal
// uninterrupted ones; tests/errors/test_restart_errors.cpp: unusable checkpoints and faults):
// the command run as a child process, and summaries compared without their timing keys.
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_case_common.hpp"
#include "test_hybrid_case_common.hpp"

#ifndef SMPM_CLI
#define SMPM_CLI ""
#endif

namespace smpm::restart_testing {

namespace fs = std::filesystem;
using nlohmann::json;
using case_testing::read_file;
using case_testing::scratch;

inline bool have_cli() { return std::string(SMPM_CLI).size() > 0 && fs::exists(SMPM_CLI); }

struct Cli {
  int code = -1;  // exit status (WEXITSTATUS), -1 when killed
  std::string err;
};

// `silentmpm ARGS`, stdout discarded, stderr kept.
inline Cli cli(const std::string& args, const std::string& tag) {
  const fs::path err = scratch() / ("restart_" + tag + ".err");
  const std::string cmd = "\"" + std::string(SMPM_CLI) + "\" " + args + " >/dev/null 2>\"" +
                          err.string() + "\"";
  const int st = std::system(cmd.c_str());
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, read_file(err)};
}

inline std::string write_case(const std::string& name, const json& c) {
  const fs::path p = scratch() / (name + ".json");
  std::ofstream(p) << c.dump(2);
  return p.string();
}

// summary.json without what differs between two runs of one computation: wall-clock figures
// and the record of a restart.
inline json summary_without_timing(const fs::path& dir) {
  json s = json::parse(read_file(dir / "summary.json"));
  for (const char* k : {"wall_seconds", "step_seconds", "particle_updates_per_second",
                        "dof_updates_per_second", "restart"})
    s.erase(k);
  return s;
}

// The elastic plate of the hybrid tests (60 x 30 cells of 1 mm) as an all-MPM case with `ppc`
// particles per cell, LK right end, `steps` steps, no snapshots.
inline json small_plate(int ppc, long steps) {
  using namespace hybrid_case_testing;
  json c = plate_case("mpm");
  c["bodies"][0]["particles_per_cell"] = ppc;
  c["time"]["end"] = steps * 0.3 * h / cd;
  c["output"]["snapshots"] = 0;
  return c;
}

}  // namespace smpm::restart_testing
