// The one exception type for bad input files and settings: CSV and YAML readers, the target
// description (vision), the pipeline's and the nodelet's settings. Header-only and below every
// room, so that vision, io and config throw the same type without depending on each other. Its
// message names the file (and line) or the key, so a caller prints it as it is. It is an
// std::invalid_argument; a bad setting is its subclass SettingsError (config/settings_error.h).
#pragma once

#include <stdexcept>

namespace camera_imu_alignment {

/// Bad input: the message names the file and, where it applies, the line ("file:line: what"), or
/// the setting's key.
class InputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace camera_imu_alignment
