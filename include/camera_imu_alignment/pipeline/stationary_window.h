// The pipeline's sliding window of stationary poses: the one answer to which poses the next solve
// uses. Each entry holds the pose as assembled (camera and IMU orientations, for the pairs of the
// pair estimators) and its measurements for the joint estimate (averages with covariances, the raw
// gyro since the previous pose), so the two estimators always see the same poses.
#pragma once

#include <cstddef>
#include <deque>
#include <optional>
#include <vector>

#include "camera_imu_alignment/estimation/joint_types.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/solver/pose_window.h"

namespace camera_imu_alignment {

class StationaryWindow {
 public:
  struct Entry {
    StationaryPose pose;  ///< as assembled; its orientations form the pairs
    JointPose joint;      ///< the rest's measurements for the joint estimate
    /// Gyro samples from the previous pose's rest to this one's (same chain), if recorded.
    std::optional<GyroSegment> gyro_from_previous;
    /// Natural scene: camera rotations measured from earlier poses to this one, from_pose and
    /// to_pose being StationaryPose::index values (problem() maps them into the window).
    std::vector<CameraLink> camera_links;
  };

  /// Keeps the newest `max_poses` (at least 2) entries: the mount may drift, old poses leave.
  explicit StationaryWindow(std::size_t max_poses);

  /// Adds an entry, dropping the oldest when full. False (and the entry ignored, nothing dropped)
  /// when an orientation is not a finite rotation matrix.
  bool add(Entry entry);
  void clear() { entries_.clear(); }
  /// Keeps the entries whose StationaryPose::index >= pose_index (a remount: older ones describe
  /// the old mount).
  void keepFrom(int pose_index);
  std::size_t size() const { return entries_.size(); }
  std::size_t maxPoses() const { return max_poses_; }

  /// The poses, oldest first.
  std::vector<StationaryPose> poses() const;
  /// Their orientations (stamp: the middle of the rest), oldest first.
  std::vector<PoseOrientation> orientations() const;
  /// All pairs (k, t), k < t, of one group (makeAllPairs of orientations()).
  RotationPairs pairs() const;
  /// The joint estimator's problem: a gyro segment is kept when its previous pose is in the window
  /// and of the same group, a camera link when both its poses are.
  JointProblem problem() const;

 private:
  std::size_t max_poses_;
  std::deque<Entry> entries_;
};

/// The orientations of a stationary pose as the pairs and the poses CSV use them.
PoseOrientation orientationOf(const StationaryPose& pose);

}  // namespace camera_imu_alignment
