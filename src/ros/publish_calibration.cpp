// Node publish_calibration: broadcasts a saved calibration (the result YAML that the alignment
// node, calibrate_bag and solve_rotation write; io/result_yaml.h) as the static tf, without
// calibrating: for a robot whose camera-IMU rotation is known. launch/publish_calibration.launch.
//
// Private parameters: ~file (the result YAML; "~" is $HOME), ~camera_frame and ~imu_frame (empty:
// the file's, else camera_optical_frame / imu_link), ~publish_inverse (false: camera -> IMU with
// R_cam_imu, as the alignment node; true: IMU -> camera with R_imu_cam). Exits 2, saying why, when
// the file cannot be read.
#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <exception>

#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/config/settings_error.h"
#include "camera_imu_alignment/io/default_frames.h"
#include "camera_imu_alignment/io/exit_codes.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/ros/message_conversion.h"
#include "camera_imu_alignment/ros/wrapper_settings.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace cia = camera_imu_alignment;

int main(int argc, char** argv) {
  ros::init(argc, argv, "publish_calibration");
  ros::NodeHandle nh, private_nh("~");  // held: rosconsole stays up for the message on failure
  const std::string name = ros::this_node::getName();
  std::string file, camera_frame, imu_frame;
  bool publish_inverse = false;
  private_nh.param<std::string>("file", file, "");
  private_nh.param<std::string>("camera_frame", camera_frame, "");
  private_nh.param<std::string>("imu_frame", imu_frame, "");
  private_nh.param("publish_inverse", publish_inverse, false);
  cia::StoredCalibration stored;
  try {
    if (file.empty()) throw cia::SettingsError("", "file", "~file is required (a result YAML)");
    stored = cia::readResultYaml(cia::expandHome(file));
  } catch (const std::exception& e) {
    ROS_FATAL("%s: cannot start: %s", name.c_str(), e.what());
    return cia::kExitBadInput;
  }
  const std::string failed = cia::failedVerdictNote(stored, file);
  if (!failed.empty()) ROS_WARN("%s: %s; broadcast as it is", name.c_str(), failed.c_str());
  if (camera_frame.empty())
    camera_frame = cia::frameOr(stored.camera_frame, cia::kDefaultCameraFrame);
  if (imu_frame.empty()) imu_frame = cia::frameOr(stored.imu_frame, cia::kDefaultImuFrame);
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  // A transform parent <- child maps child-frame points into the parent frame.
  t.header.frame_id = publish_inverse ? imu_frame : camera_frame;
  t.child_frame_id = publish_inverse ? camera_frame : imu_frame;
  t.transform.rotation =
      cia::toQuaternionMsg(publish_inverse ? stored.R_cam_imu.transpose() : stored.R_cam_imu);
  tf2_ros::StaticTransformBroadcaster broadcaster;
  broadcaster.sendTransform(t);
  ROS_INFO("%s: broadcasting %s -> %s from %s, R_cam_imu %s", name.c_str(),
           t.header.frame_id.c_str(), t.child_frame_id.c_str(), file.c_str(),
           cia::rollPitchYawText(stored.R_cam_imu, 3).c_str());
  ros::spin();
  return 0;
}
