// One relative-rotation pair of the rotation-only hand-eye problem A X = X B, X = R_cam_imu.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace camera_imu_alignment {

/// Relative rotations between two stationary poses k and t (doc/CONVENTIONS.md):
///   A_cam = R_target_cam_k^T * R_target_cam_t   (camera, from pose t to pose k)
///   B_imu = R_world_imu_k^T  * R_world_imu_t    (IMU, same two poses)
/// They satisfy A_cam * R_cam_imu = R_cam_imu * B_imu.
struct RotationPair {
  Eigen::Matrix3d A_cam = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d B_imu = Eigen::Matrix3d::Identity();
  /// Indices of the two stationary poses the pair was formed from, or -1 when the pair is an
  /// independent measurement. When every pair has both indices, the solver's covariance accounts
  /// for pairs that share a pose (their noise is correlated).
  int pose_k = -1;
  int pose_t = -1;
};

using RotationPairs = std::vector<RotationPair>;

}  // namespace camera_imu_alignment
