// ClockJumpDetector: per-input newest stamps; a jump back resets all of them.
#include "camera_imu_alignment/online/clock_jump.h"

#include <algorithm>

namespace camera_imu_alignment {

double ClockJumpDetector::update(const std::string& input, double stamp_s) {
  const auto it = newest_by_input_.find(input);
  if (it != newest_by_input_.end() && stamp_s < it->second - tolerance_s_) {
    const double jump_s = it->second - stamp_s;
    newest_by_input_.clear();
    newest_by_input_[input] = stamp_s;
    newest_s_ = stamp_s;
    return jump_s;
  }
  double& newest = newest_by_input_[input];
  newest = it == newest_by_input_.end() ? stamp_s : std::max(newest, stamp_s);
  newest_s_ = std::max(newest_s_, stamp_s);
  return 0.0;
}

}  // namespace camera_imu_alignment
