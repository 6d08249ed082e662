// The tf frame names used when the data does not name its frames (an empty frame_id, a result file
// without frame keys): ROS's usual names for a camera's optical frame and an IMU.
#pragma once

#include <string>

namespace camera_imu_alignment {

inline constexpr char kDefaultCameraFrame[] = "camera_optical_frame";
inline constexpr char kDefaultImuFrame[] = "imu_link";

/// `frame`, or `fallback` when it is empty.
inline std::string frameOr(const std::string& frame, const char* fallback) {
  return frame.empty() ? std::string(fallback) : frame;
}

}  // namespace camera_imu_alignment
