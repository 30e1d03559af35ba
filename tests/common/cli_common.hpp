#pragma once
// Helpers of the tests that run programs (the CLI, scripts) through the shell: the command's exit
// status and output, files of the source tree, whether the CLI is built.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "test_case_common.hpp"

#ifndef SMPM_CLI
#define SMPM_CLI ""
#endif
#ifndef SMPM_SOURCE_DIR
#define SMPM_SOURCE_DIR "."
#endif

namespace smpm::cli_testing {

struct Proc {
  int status;  // the exit status, -1 when the command did not exit
  std::string out, err;
};

// Runs `command` (environment assignments, program and arguments, quoted as the shell needs);
// its stdout and stderr are kept in the scratch directory as <tag>.out and <tag>.err.
inline Proc run_shell(const std::string& command, const std::string& tag) {
  const std::filesystem::path out = case_testing::scratch() / (tag + ".out");
  const std::filesystem::path err = case_testing::scratch() / (tag + ".err");
  const int s = std::system((command + " >\"" + out.string() + "\" 2>\"" + err.string() + "\"").c_str());
  return {WIFEXITED(s) ? WEXITSTATUS(s) : -1, case_testing::read_file(out),
          case_testing::read_file(err)};
}

// A file of the source tree.
inline std::string source_file(const std::string& rel) {
  return (std::filesystem::path(SMPM_SOURCE_DIR) / rel).string();
}

inline bool have_cli() {
  return std::string(SMPM_CLI).size() > 0 && std::filesystem::exists(SMPM_CLI);
}

}  // namespace smpm::cli_testing
