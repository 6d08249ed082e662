// Runs a command-line tool of the package for an end-to-end test: exit code, stdout and stderr;
// simulate_bag writing a bag into the per-process temporary directory.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <string>

#include "test_helpers.h"

namespace camera_imu_alignment {
namespace test {

struct ToolRun {
  int exit_code = -1;  ///< -1: killed by a signal (a crash); 124: timed out
  std::string out;
  std::string err;
};

/// Runs `command` under `timeout` (a hang fails the test instead of blocking it).
inline ToolRun runTool(const std::string& command, int timeout_s = 120) {
  const std::string out_path = processTempDir() + "tool_stdout.txt";
  const std::string err_path = processTempDir() + "tool_stderr.txt";
  const std::string cmd =
      "timeout " + std::to_string(timeout_s) + " " + command + " >" + out_path + " 2>" + err_path;
  const int status = std::system(cmd.c_str());
  ToolRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = readFile(out_path);
  r.err = readFile(err_path);
  return r;
}

/// Runs `simulate_bag_exe` (simulate_bag) to write tempPath(name + ".bag") with its truth and
/// target files beside it, with `options` (scenario, seed, ...) and a 5 Hz camera (a third of the
/// default 15 Hz's bag size and rendering, the same information); returns the bag's path.
inline std::string simulateBag(const std::string& simulate_bag_exe, const std::string& name,
                               const std::string& options) {
  const std::string bag = tempPath(name + ".bag");
  const ToolRun r = runTool(simulate_bag_exe + " --out " + bag + " --camera-rate-hz 5 " + options);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return bag;
}

/// "dir/x.bag" -> "dir/x" (the truth and target files are stem + ".truth.yaml", ".target.yaml").
inline std::string bagStem(const std::string& bag) { return bag.substr(0, bag.size() - 4); }

}  // namespace test
}  // namespace camera_imu_alignment
