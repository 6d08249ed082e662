// Minimal "--name value" / "--flag" command-line parsing for the tools, with checked numbers.
// Every problem throws UsageError; tools print it with their usage and exit 2 (kExitBadInput,
// io/exit_codes.h).
#pragma once

#include <map>
#include <set>
#include <stdexcept>
#include <string>

#include "camera_imu_alignment/io/exit_codes.h"  // the tools' exit codes

namespace camera_imu_alignment {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CliArgs {
 public:
  /// `with_value`: options that take a value; `flags`: options that do not.
  CliArgs(int argc, char** argv, const std::set<std::string>& with_value,
          const std::set<std::string>& flags);

  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::string get(const std::string& name, const std::string& fallback = "") const;
  /// Integer in [min, max]; `fallback` when absent.
  long getInt(const std::string& name, long fallback, long min, long max) const;
  /// Finite number in [min, max]; `fallback` when absent.
  double getDouble(const std::string& name, double fallback, double min, double max) const;

 private:
  std::map<std::string, std::string> values_;
};

}  // namespace camera_imu_alignment
