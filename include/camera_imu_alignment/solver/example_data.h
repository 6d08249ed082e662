// Synthetic stationary poses and pairs with a known R_cam_imu: the demo's built-in data and the
// benchmarks' input. (Tests build their own data independently.)
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "camera_imu_alignment/solver/pose_window.h"
#include "camera_imu_alignment/solver/rotation_pair.h"

namespace camera_imu_alignment {

struct ExampleOptions {
  unsigned int seed = 7;
  int num_poses = 12;
  /// Per-axis 1-sigma of the camera (PnP) orientation noise (deg).
  double camera_noise_deg = 0.1;
  /// Per-axis 1-sigma of the IMU (gravity + magnetometer) orientation noise (deg).
  double imu_noise_deg = 0.5;
  /// Ranges of the rig's yaw and of its roll/pitch tilt over the poses (deg).
  double yaw_range_deg = 120.0;
  double tilt_range_deg = 70.0;
  /// True mounting; a random rotation (from the seed) when empty.
  std::optional<Eigen::Matrix3d> R_cam_imu;
};

struct ExampleData {
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();  ///< truth
  std::vector<PoseOrientation> poses;
};

/// Stationary poses of a rig looking at a target: R_target_cam = R_target_world R_world_imu
/// R_cam_imu^T, each orientation perturbed on the right by Gaussian noise.
ExampleData generateExample(const ExampleOptions& options);

/// J independent pairs: B_j uniformly random rotations, A_j = X B_j X^T, each side perturbed on the
/// right by Exp(v), v uniform in the ball of radius `noise_radius_rad`.
RotationPairs generateRandomPairs(unsigned int seed, int num_pairs,
                                  const Eigen::Matrix3d& R_cam_imu, double noise_radius_rad);

}  // namespace camera_imu_alignment
