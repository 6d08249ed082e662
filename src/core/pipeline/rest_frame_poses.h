// The camera poses of the frames taken at rest, for the sources that have one per frame (the
// board's PnP, the given camera poses): kept until their rest ends, then averaged into the pose's
// camera orientation. Private to the pipeline; not installed.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "camera_source.h"

namespace camera_imu_alignment {

/// The camera pose of one frame taken at rest (stamp: camera clock, s).
struct FrameDetection {
  double stamp_s = 0.0;
  CameraPose pose;
};

/// Why a rest's frames were too few, beyond their number (the board's; empty for given poses).
struct RestFrameShortfall {
  int refused = 0;           ///< frames whose target was seen but whose pose was refused
  std::string refused_text;  ///< CameraModelMonitor::endRest's "the camera pose was refused ..."
  std::string mismatch;      ///< the detector's TargetObservation::mismatch, "" when none
};

class RestFramePoses {
 public:
  /// `symmetries`: the target's (TargetDetector::symmetries), resolved against the IMU.
  RestFramePoses(const PipelineSettings& settings, std::vector<Eigen::Matrix3d> symmetries);

  /// Whether a frame at `stamp_s` is taken: at least `interval_s` after the last frame tried
  /// (markTried) and fewer than max_frames_per_pose frames kept since `rest_since_s`.
  bool due(double stamp_s, double interval_s, std::optional<double> rest_since_s) const;
  /// A frame is tried at `stamp_s` (the spacing counts from it, found or not).
  void markTried(double stamp_s) { last_tried_s_ = stamp_s; }
  void add(double stamp_s, const CameraPose& pose) { frames_.push_back({stamp_s, pose}); }
  std::size_t size() const { return frames_.size(); }
  /// The frames within [lo_s, hi_s] of a rest that ended at `end_s`, forgotten with every frame
  /// up to `end_s` (later frames stay for the next rest).
  std::vector<FrameDetection> takeRest(double lo_s, double hi_s, double end_s);

  /// The rest's camera orientation from `inside` (takeRest): at least min_frames_per_pose frames
  /// whose robust average scatters less than max_camera_spread_deg; the board's symmetry resolved
  /// against the IMU's rotation since the latest poses of the group. Fills the pose's camera side;
  /// returns the reason the rest is no pose, or "".
  std::string average(const std::vector<FrameDetection>& inside,
                      const RestFrameShortfall& shortfall, const CameraInputs& inputs,
                      const std::vector<StationaryPose>& poses, StationaryPose* pose) const;

 private:
  const PipelineSettings& settings_;
  std::vector<Eigen::Matrix3d> symmetries_;
  std::vector<FrameDetection> frames_;  ///< frames at rest with a camera pose, oldest first
  double last_tried_s_ = -std::numeric_limits<double>::infinity();
};

}  // namespace camera_imu_alignment
