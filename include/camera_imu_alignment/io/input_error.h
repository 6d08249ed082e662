// The one exception type for bad input files and settings: CSV and YAML readers, the target
// description, the pipeline's and the nodelet's settings. Its message names the file (and line) or
// the key, so a caller prints it as it is.
#pragma once

#include <stdexcept>

namespace camera_imu_alignment {

/// Bad input: the message names the file and, where it applies, the line ("file:line: what"), or
/// the setting's key.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace camera_imu_alignment
