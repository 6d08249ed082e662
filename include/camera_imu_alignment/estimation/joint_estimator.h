// Joint maximum-likelihood estimate of R_cam_imu and the IMU's systematic errors over the
// stationary poses (Ceres), instead of relative-rotation pairs.
//
// Unknowns (joint_types.h for frames and sensor models): R_cam_imu; R_world_target (its yaw is a
// gauge held fixed unless the magnetometer is used); per pose a small correction delta_k of the PnP
// camera orientation, R_target_cam_k' = R_target_cam_k Exp(delta_k), held by the pose's camera
// covariance; the accelerometer matrix T_a and a bias b_a per rest (random-walk prior between
// consecutive rests: a rest's mean is precise to ~1e-3 m/s^2, and a constant bias would turn a walk
// of a few 1e-3 over the recording into tilt errors); the gyro matrix T_g and a gyro bias per
// rest (linear in time during a motion, random-walk prior between consecutive rests); the
// magnetometer's soft iron S_m, hard iron h and the field m_world. The IMU orientation at pose k
// is R_world_imu_k = R_world_target R_target_cam_k' R_cam_imu.
//
// Residuals (each whitened by its covariance plus a floor): per pose the accelerometer mean, the
// magnetometer mean (usable poses, when the magnetometer is used), the rest's gyro mean (= bias),
// the camera prior on delta_k; per consecutive pose pair of one group the gyro relative rotation
// Log(DeltaR_k^T R_world_imu_k^T R_world_imu_k+1) (gyro_preintegration.h), weighted by the
// integrated white noise (density^2 x duration) plus the bias walk's bridge (walk^2 T^3 / 12);
// both biases' random walks between consecutive rests (the accelerometer's across groups too: a
// break of the gyro chain does not reset it); Gaussian priors on every IMU parameter
// (ImuModelPriors; the accelerometer bias prior on the first pose's). Robust loss (settings) on the
// camera, accelerometer, magnetometer and gyro relative-rotation residuals.
//
// Parameters the motion does not excite are held at their priors (joint_observability.h) and named
// in JointResult::notes. The gyro preintegration is linearised and re-run when the gyro model moved
// (JointResult::relinearisations). The covariance of R_cam_imu is from ceres::Covariance, scaled by
// chi2 / dof when that exceeds 1. Where the rests' camera residuals say the camera's noise exceeds
// its stated covariance on most poses, that noise is measured and added first
// (JointSettings::camera_excess_level).
#pragma once

#include <Eigen/Core>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {

class JointEstimator {
 public:
  explicit JointEstimator(JointSettings settings = {});

  /// Starts from R_cam_imu_initial (e.g. the pair estimator's answer; must be a rotation). Never
  /// throws for bad data: returns ok = false with a message (non-finite or inconsistent input,
  /// fewer than 3 poses, empty or malformed gyro segments, a failed solve or covariance).
  JointResult solve(const JointProblem& problem, const Eigen::Matrix3d& R_cam_imu_initial) const;

  const JointSettings& settings() const { return settings_; }

 private:
  JointSettings settings_;
};

/// Adds `variance_rad2` x I to the camera covariance of every rest with an absolute camera
/// orientation (JointResult::camera_excess_variance_rad2 of a solve of `problem`).
void addCameraExcessVariance(double variance_rad2, JointProblem* problem);

}  // namespace camera_imu_alignment
