// Runs a command-line tool of the package for an end-to-end test: exit code, stdout and stderr.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "test_helpers.h"

namespace camera_imu_alignment {
namespace test {

struct ToolRun {
  int exit_code = -1;  ///< -1: killed by a signal (a crash); 124: timed out
  std::string out;
  std::string err;
};

inline std::string readTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Runs `command` under `timeout` (a hang fails the test instead of blocking it).
inline ToolRun runTool(const std::string& command, int timeout_s = 120) {
  const std::string out_path = processTempDir() + "tool_stdout.txt";
  const std::string err_path = processTempDir() + "tool_stderr.txt";
  const std::string cmd =
      "timeout " + std::to_string(timeout_s) + " " + command + " >" + out_path + " 2>" + err_path;
  const int status = std::system(cmd.c_str());
  ToolRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = readTextFile(out_path);
  r.err = readTextFile(err_path);
  return r;
}

}  // namespace test
}  // namespace camera_imu_alignment
