// Topic selection for calibrate_bag: the IMU, magnetometer, image and camera-info topics of a bag,
// given by the user or detected by message type.
#pragma once

#include <rosbag/bag.h>

#include <string>

namespace camera_imu_alignment {

struct BagTopics {
  std::string imu;    ///< sensor_msgs/Imu (required)
  std::string mag;    ///< sensor_msgs/MagneticField ("" = none)
  std::string image;  ///< sensor_msgs/Image or CompressedImage ("" = none in the bag)
  bool image_compressed = false;
  std::string camera_info;  ///< sensor_msgs/CameraInfo ("" = none)
  /// geometry_msgs/PoseStamped, the camera in the target frame ("" = not used). When set, it is
  /// the camera source: image and camera_info are empty (not read).
  std::string camera_pose;
  std::string camera_source_note;  ///< which camera source was chosen and why (one line)
};

/// Fills the topics not given (empty) by type; checks the given ones exist with the right type.
/// Throws std::runtime_error with a message naming the topic (missing, wrong type, ambiguous:
/// several candidates, listed). The camera source is one of images (Image / CompressedImage and
/// CameraInfo) and camera poses (PoseStamped): camera poses when requested.camera_pose is given,
/// or when the bag has no image topic and one PoseStamped topic named camera_pose (in any
/// namespace); images otherwise (a camera_pose topic beside them is named in the note). Giving
/// both an image and a camera pose topic is an error.
BagTopics selectBagTopics(const rosbag::Bag& bag, const BagTopics& requested);

}  // namespace camera_imu_alignment
