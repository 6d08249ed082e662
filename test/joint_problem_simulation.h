// Joint problems (estimation/joint_types.h) generated from a known truth, for the tests of the
// joint estimator and bench_joint: a rig with a random R_cam_imu rests at poses joined by smooth
// (minimum-jerk) rotations about one axis each; the IMU has drawn systematic errors (T_g, T_a,
// biases, hard and soft iron) and white noise; the gyro bias walks.
//
// Sample i of a motion is the mean rate over [t_i, t_i + 1/rate] (the output of a decimating
// gyro), so without noise the estimator's integration reproduces the true rotation exactly. The
// rests' means are drawn directly with the noise of the mean of rest_s * rate_hz samples.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {
namespace test {

struct JointSimulationOptions {
  int num_poses = 12;
  int groups = 1;  ///< contiguous groups; no segment between them, the gyro bias jumps
  bool with_gyro = true;
  bool with_magnetometer = true;
  int unusable_mag_every = 0;  ///< every n-th pose has no usable field (0: none)
  double min_rotation_deg = 20.0, max_rotation_deg = 90.0;
  std::optional<Eigen::Vector3d> rotation_axis_imu;  ///< all motions about this IMU axis
  bool vertical_rotations_only = false;  ///< all motions about the vertical (gravity unchanged)
  /// Explicit motions (rotation vectors, IMU frame, rad), one per motion (num_poses - 1); they
  /// replace the random ones when given.
  std::vector<Eigen::Vector3d> motions_imu_rad;
  std::optional<Eigen::Matrix3d> initial_R_world_imu;  ///< the first pose (random when empty)
  double rest_s = 3.0, motion_s = 2.0, rate_hz = 200.0;

  bool noise = true;  ///< false: exact measurements (the stated covariances stay as below)
  double camera_sigma_rad = 0.05 * 3.14159265358979323846 / 180.0;
  double accel_noise_m_s2 = 0.02;      ///< per sample
  double gyro_noise_density = 1.7e-4;  ///< rad/s/sqrt(Hz)
  double gyro_bias_walk = 1e-4;        ///< rad/s/sqrt(s); 0 without noise
  double gyro_bias_step_rad_s = 0.0;   ///< bias level change per rest (1-sigma), ramped
  /// Accelerometer bias random walk (m/s^2/sqrt(s); 0 without noise): the default prior's. Drawn
  /// from a random stream of its own, so that it leaves every other draw of a seed unchanged.
  double accel_bias_walk = 1e-3;
  double mag_noise_t = 0.3e-6;  ///< per sample
  double gravity_m_s2 = 9.81;
  double field_t = 50e-6, dip_rad = 60.0 * 3.14159265358979323846 / 180.0;

  // Systematic errors drawn per seed (1-sigma; 0 = ideal).
  double gyro_scale = 0.015, gyro_cross_axis = 0.01;
  double gyro_bias_max_rad_s = 3.0 * 3.14159265358979323846 / 180.0;  ///< uniform +-
  double accel_scale = 0.01, accel_cross_axis = 0.01, accel_bias_m_s2 = 0.2;
  double hard_iron_t = 15e-6, soft_iron = 0.05;
  bool soft_iron_isotropic = false;  ///< S_m = (1 + s) I only
  AccelMatrixForm accel_matrix_form = AccelMatrixForm::kLowerTriangular;
};

struct JointSimulation {
  JointProblem problem;
  Eigen::Matrix3d R_cam_imu, R_world_target;
  std::vector<Eigen::Matrix3d> R_world_imu;
  Eigen::Matrix3d T_g, T_a, soft_iron;
  Eigen::Vector3d accel_bias_m_s2, hard_iron_t;       ///< accel_bias_m_s2: at the first rest
  std::vector<Eigen::Vector3d> accel_bias_rest_mean;  ///< true mean bias over each rest (m/s^2)
  std::vector<Eigen::Vector3d> gyro_bias_rest_mean;   ///< true mean bias over each rest (rad/s)
};

JointSimulation simulateJointProblem(const JointSimulationOptions& options, uint64_t seed);

/// R perturbed by a rotation of `angle_rad` about a random axis (an initial guess).
Eigen::Matrix3d perturbedRotation(const Eigen::Matrix3d& R, double angle_rad, uint64_t seed);

/// Log(R_est R_true^T) (rad, left/camera axes): the error in the estimator's covariance frame.
Eigen::Vector3d rotationError(const Eigen::Matrix3d& R_est, const Eigen::Matrix3d& R_true);

}  // namespace test
}  // namespace camera_imu_alignment
