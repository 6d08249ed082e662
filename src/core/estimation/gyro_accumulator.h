// Private to src/core/estimation: the one step of gyro preintegration that both the rotation
// integrals (gyro_preintegration.cpp) and the accelerometer links (joint_motion.cpp) take.
#pragma once

#include <Eigen/Core>

#include "camera_imu_alignment/estimation/gyro_preintegration.h"

namespace camera_imu_alignment {

/// The rotation integrated so far in the IMU frame at the interval's start, and its derivative
/// with respect to theta = [T_g row-major (9), gyro bias at the start (3), at the end (3)] as a
/// right perturbation: DeltaR(theta + d) = DeltaR Exp(J d). Rates are calibrated as
/// omega = T_g^-1 (raw - b(s)), the bias ramping linearly from b_from (s = 0) to b_to (s = 1).
struct GyroAccumulator {
  Eigen::Matrix3d T_g_inverse;
  Eigen::Vector3d b_from, b_to;
  Eigen::Matrix3d delta_R = Eigen::Matrix3d::Identity();
  GyroPreintegrationJacobian J = GyroPreintegrationJacobian::Zero();
  double duration_s = 0.0;

  /// The calibrated rate (rad/s, IMU frame) of raw gyro `raw` (rad/s) at ramp fraction s.
  Eigen::Vector3d rateOf(const Eigen::Vector3d& raw, double s) const {
    return T_g_inverse * (raw - (b_from + s * (b_to - b_from)));
  }

  /// Holds the raw rate `raw` (rad/s) for dt (s) at ramp fraction s.
  void step(const Eigen::Vector3d& raw, double s, double dt);

  /// The integral as a GyroPreintegration taken at theta0.
  GyroPreintegration result(const GyroModelVector& theta0) const;
};

}  // namespace camera_imu_alignment
