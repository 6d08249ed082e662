// Sliding window of stationary poses and the relative-rotation pairs formed from them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <deque>
#include <vector>

#include "camera_imu_alignment/solver/rotation_pair.h"

namespace camera_imu_alignment {

/// Absolute orientations of the camera and the IMU at one stationary pose.
struct PoseOrientation {
  double stamp_s = 0.0;  ///< time of the pose (s), for ordering and reporting
  Eigen::Matrix3d R_target_cam = Eigen::Matrix3d::Identity();  ///< camera in the target frame (PnP)
  Eigen::Matrix3d R_world_imu = Eigen::Matrix3d::Identity();   ///< IMU in the world frame (ENU)
  /// Poses of different groups are never paired: their world (or target) frames are unrelated,
  /// e.g. IMU orientations from two gyro chains without a magnetometer heading between them.
  int group = 0;
};

/// Keeps the most recent `max_poses` stationary poses (the mount may drift: old poses leave the
/// window) and forms pairs from them.
///
/// Pair choice: every pair (k, t), k < t, in the window (of the same group). Each pose then informs
/// the estimate through all the others, large relative rotations are never skipped, and the result
/// does not depend on pose order (consecutive-only pairs would waste the information between
/// distant poses). Pairs share poses, so their noise is correlated; each pair carries its pose
/// indices and the solver's covariance accounts for the correlation. Cost: P (P - 1) / 2 pairs, so
/// the window is capped.
class PoseWindow {
 public:
  explicit PoseWindow(std::size_t max_poses = 30);

  /// Adds a pose; drops the oldest when the window is full. Returns false (and ignores the pose)
  /// when an orientation is not a finite rotation matrix.
  bool add(const PoseOrientation& pose);
  void clear();
  /// Drops all but the newest `count` poses (a remount: the older ones describe the old mount).
  void keepNewest(std::size_t count);
  std::size_t size() const { return poses_.size(); }
  std::size_t maxPoses() const { return max_poses_; }
  const std::deque<PoseOrientation>& poses() const { return poses_; }

  /// All pairs (k, t), k < t, of the poses in the window, with pose indices set.
  RotationPairs makePairs() const;

 private:
  std::size_t max_poses_;
  std::deque<PoseOrientation> poses_;
};

/// All pairs (k, t), k < t, of `poses` within the same group (see PoseWindow).
RotationPairs makeAllPairs(const std::vector<PoseOrientation>& poses);

}  // namespace camera_imu_alignment
