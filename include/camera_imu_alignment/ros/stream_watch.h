// Which input streams are silent while others flow (a wrong topic name, a stopped driver): the
// nodelet warns about each, naming the topic, and its diagnostics go to WARN. Plain C++ (wall
// time in seconds passed in), unit-tested without ROS.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "camera_imu_alignment/pipeline/input_rejections.h"

namespace camera_imu_alignment {

class StreamWatch {
 public:
  /// A stream is silent when nothing came for `silent_after_s` while another stream flowed.
  explicit StreamWatch(double silent_after_s = 5.0) : silent_after_s_(silent_after_s) {}
  void seen(InputStream stream, double now_s);
  /// The streams expected now that are silent: the IMU; the camera as images + camera info unless
  /// camera_pose flows (and camera_pose only when neither images nor camera info flow); the
  /// magnetometer when `magnetometer_expected`. Empty while nothing flows at all (nothing to
  /// compare with: the node waits for data) or during the first silent_after_s.
  std::vector<InputStream> silent(double now_s, bool magnetometer_expected) const;
  bool everSeen(InputStream stream) const;

 private:
  bool flowing(InputStream stream, double now_s) const;
  double silent_after_s_;
  std::array<double, 5> last_s_{{-1, -1, -1, -1, -1}};  ///< per InputStream, -1: never
  double first_s_ = -1;                                 ///< first message of any stream
};

}  // namespace camera_imu_alignment
