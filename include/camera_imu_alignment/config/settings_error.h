// The one exception for a bad setting: a config file's key, a ROS parameter, a settings struct
// handed to the library, a simulate_bag option. It is an InputError (so also an
// std::invalid_argument): callers that report bad input print it as it is (calibrate_bag exits 2
// with it, the node logs it as FATAL and exits).
#pragma once

#include <string>

#include "camera_imu_alignment/common/input_error.h"

namespace camera_imu_alignment {

class SettingsError : public InputError {
 public:
  /// `source`: the file, "parameters of <namespace>", an option list, or "" (a struct in code);
  /// `key`: the setting (or the first of two); `detail`: "<key> = <value>: must be <allowed>" or
  /// a check across keys naming both. what() is "<source>: <detail>" ("<detail>" without source).
  SettingsError(const std::string& source, const std::string& key, const std::string& detail)
      : InputError(source.empty() ? detail : source + ": " + detail), source_(source), key_(key) {}
  const std::string& source() const { return source_; }
  const std::string& key() const { return key_; }

 private:
  std::string source_;
  std::string key_;
};

}  // namespace camera_imu_alignment
