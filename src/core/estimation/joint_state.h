// Internal pieces of the joint estimator (private to src/core/estimation): the parameter blocks,
// input checks, initial values, the Ceres problem and the result. Blocks and units: see
// joint_residuals.h.
#pragma once

#include <ceres/problem.h>

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/estimation/joint_observability.h"
#include "camera_imu_alignment/estimation/joint_types.h"
#include "joint_motion.h"

namespace camera_imu_alignment {
namespace joint {

constexpr double kMicroteslaPerTesla = 1e6;

/// The unknowns, as Ceres parameter blocks.
struct State {
  Eigen::Matrix3d R_cam_imu_0 = Eigen::Matrix3d::Identity();       ///< X0 (linearisation point)
  Eigen::Matrix3d R_world_target_0 = Eigen::Matrix3d::Identity();  ///< T0
  std::array<double, 3> e_X{}, e_T{};
  /// With a mount change (JointProblem::mount_change_pose): R_cam_imu of the later poses,
  /// Exp(e_X_after) X0_after.
  Eigen::Matrix3d R_cam_imu_after_0 = Eigen::Matrix3d::Identity();
  std::array<double, 3> e_X_after{};
  std::vector<std::array<double, 3>> delta;       ///< per pose (rad)
  std::array<double, 6> accel_matrix{};           ///< T_a - I
  std::vector<std::array<double, 3>> accel_bias;  ///< per pose (m/s^2)
  std::array<double, 9> gyro_matrix{};            ///< T_g - I, row-major
  std::vector<std::array<double, 3>> gyro_bias;   ///< per pose (rad/s)
  std::array<double, 6> soft_iron{};              ///< S_m - I: [xx, yy, zz, xy, xz, yz]
  std::array<double, 3> hard_iron_ut{};
  std::array<double, 2> field_ut{};  ///< m_world = (0, field[0], field[1]) uT
  /// timeshift_cam_imu (s) and the value the gyro was last preintegrated at (motion nodes).
  std::array<double, 1> timeshift{};
  double timeshift_0 = 0;
  /// The acceleration model (JointProblem::accel_links): the accelerometer bias during each link
  /// (m/s^2; a random walk from link to link) and the IMU's position in the camera frame (m).
  std::vector<std::array<double, 3>> link_accel_bias;
  std::array<double, 3> lever_arm_m{};
  /// Per pose, used at the links' keyframes: the camera centre (m) and the IMU's velocity (m/s),
  /// both in the target frame.
  std::vector<std::array<double, 6>> keyframe_pv;

  Eigen::Matrix3d gyroMatrix() const;  ///< T_g
  Eigen::Vector3d gyroBias(int pose) const;
  Eigen::Vector3d accelBias(int pose) const;
  /// Folds e_X and e_T into X0 and T0 (then zero).
  void foldRotationIncrements();
  /// Puts the columns of T_g that `observability` does not estimate back at their prior (I).
  void holdUnexcitedGyroColumns(const JointObservability& observability);
};

/// Whitened measurements of the problem (L^-1 of each covariance plus its floor).
struct Whitening {
  std::vector<Eigen::Matrix3d> accel, gyro_mean, mag_ut, camera;  ///< per pose
  std::vector<Eigen::Matrix3d> gyro_relative;                     ///< per segment (1/rad)
  std::vector<Eigen::Matrix3d> camera_link;  ///< per JointProblem::camera_links entry (1/rad)
};

/// Which pose (or two) a residual block belongs to, for the per-pose residual norms.
struct ResidualRecord {
  ceres::ResidualBlockId id = nullptr;
  int pose = -1, other_pose = -1;  ///< -1 for priors; other_pose for gyro and walk residuals
  int size = 0;
  bool magnetometer = false;  ///< the pose's magnetometer residual
  int camera_link = -1;       ///< index into JointProblem::camera_links, or -1
  int noise_kind = -1;        ///< the learned NoiseKind it measures, or -1
  int segment = -1;           ///< index into JointProblem::segments (gyro residuals), or -1
};

/// The built problem's bookkeeping.
struct BuiltProblem {
  std::vector<ResidualRecord> residuals;
  std::vector<double*> free_blocks;  ///< blocks that are not constant
};

/// Empty when the input is usable, else the reason (names the pose, segment or setting).
std::string validateProblem(const JointProblem& problem, const Eigen::Matrix3d& R_cam_imu_initial,
                            const JointSettings& settings);

/// L^-1 for cov + floor^2 I = L L^T; false when that is not positive definite or not finite.
bool whiteningMatrix(const Eigen::Matrix3d& covariance, double floor_sigma,
                     Eigen::Matrix3d* whitening);

/// Whitening of every measurement; false (with `error`) when a covariance is unusable.
bool computeWhitening(const JointProblem& problem, const std::vector<GyroPreintegration>& segments,
                      const JointSettings& settings, Whitening* whitening, std::string* error);

/// Where a gyro link around a motion node (GyroSegment::interval) starts or ends at this pose: a
/// rest's middle (the IMU is at rest there, whatever the stationary detector's lag at the rest's
/// ends; the bias the rest measures holds over it), a node's stamp (IMU clock at the initial
/// offset).
inline double linkTime(const JointPose& pose) {
  return pose.at_rest ? 0.5 * (pose.start_s + pose.end_s) : pose.start_s;
}

/// The accelerometer links preintegrated at T_g, the per-pose biases and the time offset.
std::vector<AccelLinkIntegral> integrateAccelLinks(const JointProblem& problem,
                                                   const Eigen::Matrix3d& T_g,
                                                   const std::vector<Eigen::Vector3d>& biases,
                                                   double timeshift);

/// True when a segment has a motion node at an end (then the time offset is estimated).
bool hasMotionSegments(const JointProblem& problem);

/// Preintegrates every segment at T_g, the per-pose biases and the time offset (interval
/// segments: the ends at motion nodes shifted by timeshift - problem.timeshift_initial_s).
/// rates_from/rates_to: per segment, the calibrated body rate at each end (zero at a rest's end).
std::vector<GyroPreintegration> preintegrateSegments(const JointProblem& problem,
                                                     const Eigen::Matrix3d& T_g,
                                                     const std::vector<Eigen::Vector3d>& biases,
                                                     double timeshift,
                                                     std::vector<Eigen::Vector3d>* rates_from,
                                                     std::vector<Eigen::Vector3d>* rates_to);

/// Poses that take part in a gyro segment (they get a gyro bias block).
std::vector<bool> posesWithGyro(const JointProblem& problem);

/// Initial values: biases from the rests, T = I, R_world_target from the accelerometer (and the
/// magnetometer's heading and field when used), the hard iron from a sphere fit when estimated.
State initialState(const JointProblem& problem, const Eigen::Matrix3d& R_cam_imu_initial,
                   const JointObservability& observability, const JointSettings& settings);

/// Adds every residual and prior of the problem at `state` (relinearised at its X0 and T0) and
/// holds what `observability` does not estimate.
BuiltProblem buildProblem(const JointProblem& problem, const std::vector<GyroPreintegration>& gyro,
                          const std::vector<Eigen::Vector3d>& rates_from,
                          const std::vector<Eigen::Vector3d>& rates_to,
                          const std::vector<AccelLinkIntegral>& accel_links,
                          const Whitening& whitening, const JointObservability& observability,
                          const JointSettings& settings, State* state,
                          ceres::Problem* ceres_problem);

/// Covariances, chi2, per-pose norms, intrinsics and the parameter list into `result` (R_cam_imu
/// and notes are set by the caller). False (with result->message) when the covariance fails.
bool fillResult(const JointProblem& problem, const State& state, const BuiltProblem& built,
                const Whitening& whitening, const JointObservability& observability,
                const JointSettings& settings, ceres::Problem* ceres_problem, JointResult* result);

/// Upper tail P(X > chi2) of a chi-square distribution with dof degrees of freedom (1 for dof <=
/// 0).
double chiSquareUpperTail(double chi2, int dof);

}  // namespace joint
}  // namespace camera_imu_alignment
