// Absolute orientations at stationary poses and the relative-rotation pairs formed from them.
#pragma once

#include <Eigen/Core>
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
  /// Poses whose camera orientations are in different frames (two natural scenes whose views
  /// never overlapped, pipeline/calibration_pipeline.h) are never paired either.
  int camera_frame = 0;
};

/// Pair choice: every pair (k, t), k < t, of the same group. Each pose then informs the estimate
/// through all the others, large relative rotations are never skipped, and the result does not
/// depend on pose order (consecutive-only pairs would waste the information between distant
/// poses). Pairs share poses, so their noise is correlated; each pair carries its pose indices and
/// the solver's covariance accounts for the correlation. Cost: P (P - 1) / 2 pairs, so the window
/// (pipeline/stationary_window.h) is capped.
/// All pairs (k, t), k < t, of `poses` within the same group, with pose indices set.
RotationPairs makeAllPairs(const std::vector<PoseOrientation>& poses);

}  // namespace camera_imu_alignment
