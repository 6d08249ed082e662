// Nodelet camera_imu_alignment/AlignmentNodelet: a thin shell over AlignmentWrapper.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

#include "camera_imu_alignment/ros/alignment_wrapper.h"

namespace camera_imu_alignment {

class AlignmentNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      wrapper_ = std::make_unique<AlignmentWrapper>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("camera_imu_alignment: cannot start: %s", e.what());
    }
  }
  std::unique_ptr<AlignmentWrapper> wrapper_;
};

}  // namespace camera_imu_alignment

PLUGINLIB_EXPORT_CLASS(camera_imu_alignment::AlignmentNodelet, nodelet::Nodelet)
