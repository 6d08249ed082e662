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
};

/// Fills the topics not given (empty) by type; checks the given ones exist with the right type.
/// Throws std::runtime_error with a message naming the topic (missing, wrong type, ambiguous:
/// several candidates, listed).
BagTopics selectBagTopics(const rosbag::Bag& bag, const BagTopics& requested);

}  // namespace camera_imu_alignment
