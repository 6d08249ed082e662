// Node alignment_node: a thin shell over AlignmentWrapper (same behaviour as the nodelet).
#include <ros/ros.h>

#include "camera_imu_alignment/ros/alignment_wrapper.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "camera_imu_alignment");
  try {
    camera_imu_alignment::AlignmentWrapper wrapper(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("camera_imu_alignment: cannot start: %s", e.what());
    return 2;
  }
  return 0;
}
