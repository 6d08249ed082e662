// Gyro preintegration between two rests under the gyro model w = T_g w_true + b(t) (joint_types.h).
//
// The rotation of the IMU frame from the end of rest k to the start of rest k+1 is
//   DeltaR(theta) = prod_i Exp(T_g^-1 (w_i - b(t_i)) dt_i),
//   b(t) = b_from + s(t) (b_to - b_from),  s = (t - t_from) / (t_to - t_from) clamped to [0, 1],
// with theta = [vec(T_g) (9, row-major: T_g(r, c) at 3 r + c), b_from (3), b_to (3)] (rad/s for the
// biases). DeltaR maps IMU vectors at the end of the motion into the IMU frame at its start:
// R_world_imu_{k+1} = R_world_imu_k DeltaR. The first-order correction for a change of theta is
//   DeltaR(theta0 + d) ~ DeltaR(theta0) Exp(J d),  J = jacobian (3 x 15),
// accumulated sample by sample (J <- Exp(phi_i)^T J + Jr(phi_i) d phi_i / d theta).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {

constexpr int kGyroModelSize = 15;  ///< T_g (9) + b_from (3) + b_to (3)
using GyroModelVector = Eigen::Matrix<double, kGyroModelSize, 1>;
using GyroPreintegrationJacobian = Eigen::Matrix<double, 3, kGyroModelSize>;

struct GyroPreintegration {
  Eigen::Matrix3d delta_R = Eigen::Matrix3d::Identity();  ///< R_imuStart_imuEnd at theta0
  GyroPreintegrationJacobian jacobian = GyroPreintegrationJacobian::Zero();
  GyroModelVector theta0 = GyroModelVector::Zero();  ///< linearisation point
  double duration_s = 0;                             ///< sum of the samples' intervals (s)
};

/// theta from its parts.
GyroModelVector gyroModelVector(const Eigen::Matrix3d& T_g, const Eigen::Vector3d& b_from,
                                const Eigen::Vector3d& b_to);

/// Sample intervals dt_i (s): stamps_s[i + 1] - stamps_s[i], the last one the median of the
/// others (the nominal period; 0 for a single sample). Requires increasing stamps.
std::vector<double> sampleIntervals(const std::vector<double>& stamps_s);

/// Preintegrates the segment's samples at theta0 = (T_g, b_from, b_to); the bias ramps from
/// b_from at t_from_s (end of the first rest) to b_to at t_to_s (start of the second). T_g must be
/// invertible; samples and stamps finite and increasing (the estimator checks its input).
GyroPreintegration preintegrateGyro(const std::vector<double>& stamps_s,
                                    const std::vector<Eigen::Vector3d>& gyro_rad_s, double t_from_s,
                                    double t_to_s, const Eigen::Matrix3d& T_g,
                                    const Eigen::Vector3d& b_from, const Eigen::Vector3d& b_to);

/// The sampled signal at time t, linear between the first n samples (each the value at its stamp;
/// the first or last sample outside them). Stamps increasing, n >= 1.
Eigen::Vector3d interpolateSamples(const std::vector<double>& stamps_s,
                                   const std::vector<Eigen::Vector3d>& values, size_t n, double t);

/// The same over exactly [t_from_s, t_to_s] of an unbroken stream (continuous motion, where the
/// interval's ends fall between samples): each sample is the rate at its stamp, the rate between
/// two samples is interpolated linearly (a zero-order hold would shift the rotation by half a
/// sample period, a time offset of 2.5 ms at 200 Hz), and the bias ramps from b_from at t_from_s to
/// b_to at t_to_s. The stream must cover the interval (stamps_s.front() <= t_from_s < t_to_s <=
/// stamps_s.back()). rate_from/rate_to (optional): the calibrated body rate T_g^-1 (w - b) at the
/// ends (rad/s, IMU frame), the derivative of the rotation with respect to the interval's ends.
GyroPreintegration preintegrateGyroInterval(
    const std::vector<double>& stamps_s, const std::vector<Eigen::Vector3d>& gyro_rad_s,
    double t_from_s, double t_to_s, const Eigen::Matrix3d& T_g, const Eigen::Vector3d& b_from,
    const Eigen::Vector3d& b_to, Eigen::Vector3d* rate_from = nullptr,
    Eigen::Vector3d* rate_to = nullptr);

/// DeltaR(theta) to first order from a preintegration at theta0: delta_R Exp(J (theta - theta0)).
Eigen::Matrix3d correctedDeltaR(const GyroPreintegration& preintegration,
                                const GyroModelVector& theta);

/// Right Jacobian of SO(3): Exp(phi + d) ~ Exp(phi) Exp(Jr(phi) d).
Eigen::Matrix3d rightJacobianSO3(const Eigen::Vector3d& phi);

}  // namespace camera_imu_alignment
