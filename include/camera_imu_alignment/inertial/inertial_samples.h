// Time-stamped inertial and magnetic samples as the core library takes them (plain structs, no ROS
// messages). Inputs refused on the way in are counted in pipeline/input_rejections.h.
//
// Frames and units: every vector is in the IMU frame (REP-145). Gyro in rad/s, accelerometer as
// specific force in m/s^2 (at rest it points up: about +9.81 along the IMU's up axis), magnetic
// field in tesla (sensor_msgs/MagneticField). Stamps in seconds on one clock (bag or ROS time).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace camera_imu_alignment {

struct ImuSample {
  double stamp_s = 0.0;
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_m_s2 = Eigen::Vector3d::Zero();
  /// The sensor's own orientation estimate (sensor_msgs/Imu orientation, q_world_imu), when it
  /// sends one; used only with imu_orientation: message.
  std::optional<Eigen::Quaterniond> q_world_imu;
};

struct MagneticSample {
  double stamp_s = 0.0;
  Eigen::Vector3d field_t = Eigen::Vector3d::Zero();
};

}  // namespace camera_imu_alignment
