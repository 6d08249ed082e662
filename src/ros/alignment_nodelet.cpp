// Nodelet camera_imu_alignment/AlignmentNodelet: a thin shell over AlignmentWrapper. When it cannot
// start it logs why (FATAL, naming itself: several may share a manager) and its load fails: the
// manager unloads it, `nodelet load` exits with an error and a `required` launch stops.
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
      NODELET_FATAL("%s: cannot start: %s", getName().c_str(), e.what());
      throw;  // not an empty shell without status or services: the load fails visibly
    }
  }
  std::unique_ptr<AlignmentWrapper> wrapper_;
};

}  // namespace camera_imu_alignment

PLUGINLIB_EXPORT_CLASS(camera_imu_alignment::AlignmentNodelet, nodelet::Nodelet)
