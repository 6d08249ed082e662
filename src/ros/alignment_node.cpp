// Node alignment_node: a thin shell over AlignmentWrapper (same behaviour as the nodelet). When it
// cannot start it says why on stderr (FATAL, naming itself) and exits 2.
#include <ros/ros.h>

#include <memory>

#include "camera_imu_alignment/io/exit_codes.h"
#include "camera_imu_alignment/ros/alignment_wrapper.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "camera_imu_alignment");
  // Held here, outside the try: when the last NodeHandle goes, ros::shutdown() also shuts
  // rosconsole down, and the reason a failed start would print was lost (exit 2, no output).
  ros::NodeHandle nh, private_nh("~");
  std::unique_ptr<camera_imu_alignment::AlignmentWrapper> wrapper;
  try {
    wrapper = std::make_unique<camera_imu_alignment::AlignmentWrapper>(nh, private_nh);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: cannot start: %s", ros::this_node::getName().c_str(), e.what());
    return camera_imu_alignment::kExitBadInput;
  }
  ros::spin();
  return 0;
}
