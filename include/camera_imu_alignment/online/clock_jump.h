// Clock jumps back on the calibrator's inputs: a bag played with --loop, a restarted simulation
// clock. Judged per input, because a camera's stamps may lag the IMU's by its latency (tens of ms,
// or a second for a slow driver) without the clock having jumped. No ROS type; unit-tested alone.
#pragma once

#include <map>
#include <string>

namespace camera_imu_alignment {

class ClockJumpDetector {
 public:
  /// A stamp earlier than the same input's newest by more than `tolerance_s` is a jump.
  explicit ClockJumpDetector(double tolerance_s = 1.0) : tolerance_s_(tolerance_s) {}

  /// Records `stamp_s` (s) for `input`. Returns how far the clock jumped back (s, > 0) when it
  /// did; then every input starts over from this stamp. 0 otherwise (small disorder is left to
  /// the pipeline's stamp-order check).
  double update(const std::string& input, double stamp_s);
  /// Newest stamp seen on any input since the last jump (s); -1 before the first.
  double newest() const { return newest_s_; }

 private:
  double tolerance_s_;
  std::map<std::string, double> newest_by_input_;
  double newest_s_ = -1.0;
};

}  // namespace camera_imu_alignment
