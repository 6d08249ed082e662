// The pipeline's record of what the frames at rest say about camera_info's camera model
// (vision/camera_model_check.h): each frame whose target was detected is fitted, whether its pose
// was accepted or refused, and the frames of one rest become one view. Also remembers the frames
// whose target was found but whose pose was refused, so that a rest is not reported as one where
// the target was never seen. Private to the pipeline; not installed.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "camera_imu_alignment/vision/camera_model_check.h"

namespace camera_imu_alignment {

class CameraModelMonitor {
 public:
  /// Views kept (the newest), as the pipeline's histories.
  explicit CameraModelMonitor(std::size_t max_views) : max_views_(max_views) {}
  /// A frame at rest (stamp, s) whose target was detected, fitted.
  void addFrame(double stamp_s, const CameraModelFit& fit);
  /// A frame at rest whose target was detected but whose pose was refused, and why.
  void addRefused(double stamp_s, const std::string& why);
  /// A rest ended: its frames within [lo_s, hi_s] become one view; frames after end_s are kept for
  /// the next rest. Returns "" when no pose was refused within [lo_s, hi_s], else "the camera pose
  /// was refused in N of them (<the latest reason>)".
  std::string endRest(double lo_s, double hi_s, double end_s);
  /// Frames within [lo_s, hi_s] whose pose was refused (call before endRest).
  int refusedIn(double lo_s, double hi_s) const;
  /// The recording's verdict at `level` (checkCameraModel).
  CameraModelCheck check(double level, const CameraIntrinsics* intrinsics) const;

 private:
  std::size_t max_views_;
  std::vector<std::pair<double, CameraModelFit>> frames_;
  std::vector<std::pair<double, std::string>> refused_;
  std::vector<CameraModelFit> views_;
};

}  // namespace camera_imu_alignment
