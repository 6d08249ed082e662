// Minimal "--name value" / "--flag" command-line parsing for the tools, with checked numbers.
// Every problem throws UsageError; tools print it with their usage and exit 2.
#pragma once

#include <map>
#include <set>
#include <stdexcept>
#include <string>

namespace camera_imu_alignment {

/// Exit codes of the tools (doc/CONVENTIONS.md).
constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;              ///< bad input or usage; the message names the culprit
constexpr int kExitNotEnoughInformation = 3;  ///< not observable, or the two-step did not fit
/// The estimate exists but fails the nodelet's quality gates (inconsistent data, 1-sigma too
/// large) or the mount changed during the recording: calibrate_bag prints it, does not write it.
constexpr int kExitQualityGate = 4;

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
