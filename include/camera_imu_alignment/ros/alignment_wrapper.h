// The ROS side of online calibration, shared by the nodelet and the node: subscribes to the IMU,
// magnetometer and camera, converts the messages, drives the core CalibrationPipeline (the class
// calibrate_bag drives too), and publishes its results: a static tf R_cam_imu, ~status,
// /diagnostics, ~stationary_poses; services ~calibrate, ~reset, ~save, ~capture_pose.
//
// Topics (relative names, remap them): imu/data_raw (sensor_msgs/Imu), imu/mag
// (sensor_msgs/MagneticField, optional), camera/image_raw + camera/camera_info (image_transport
// CameraSubscriber; ~image_transport: compressed for CompressedImage); camera_pose
// (geometry_msgs/PoseStamped, the camera in the target frame, optional: for users with their own
// detector or motion capture, instead of images).
#pragma once

#include <ros/ros.h>

#include <memory>

namespace camera_imu_alignment {

class AlignmentWrapper {
 public:
  /// Reads and validates the private parameters (config/default.yaml), loads the target, loads
  /// and broadcasts a saved calibration when asked, subscribes and advertises. Throws InputError
  /// naming the parameter or file when it cannot start.
  AlignmentWrapper(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~AlignmentWrapper();
  AlignmentWrapper(const AlignmentWrapper&) = delete;
  AlignmentWrapper& operator=(const AlignmentWrapper&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace camera_imu_alignment
