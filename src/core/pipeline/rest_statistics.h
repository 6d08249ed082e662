// What the joint estimator needs of a rest (estimation/joint_types.h): the averaged measurements
// with their covariances, measured on the rest itself, and the raw gyro samples since the previous
// pose. Private to the pipeline; not installed.
#pragma once

#include <deque>

#include "camera_imu_alignment/estimation/joint_types.h"
#include "camera_imu_alignment/inertial/inertial_samples.h"

namespace camera_imu_alignment {

/// Mean and covariance of the mean (scatter / N) of the accelerometer and the gyro over a rest, and
/// the gyro's white noise density measured from successive differences.
struct RestStatistics {
  int count = 0;
  Eigen::Vector3d accel_mean_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d accel_mean_cov = Eigen::Matrix3d::Zero();  ///< (m/s^2)^2
  Eigen::Vector3d gyro_mean_rad_s = Eigen::Vector3d::Zero();
  Eigen::Matrix3d gyro_mean_cov = Eigen::Matrix3d::Zero();  ///< (rad/s)^2
  double gyro_noise_density_rad_s_sqrt_hz = 0.0;
};

/// Statistics of the samples with stamps in [start_s, end_s] (count 0 when fewer than 2).
RestStatistics restStatistics(const std::deque<ImuSample>& samples, double start_s, double end_s);

/// Appends the raw gyro samples with stamps in [from_s, to_s] later than `segment`'s last one (its
/// stamps stay strictly increasing when spans sharing a boundary are appended in turn).
void appendGyroSamples(const std::deque<ImuSample>& samples, double from_s, double to_s,
                       GyroSegment* segment);

}  // namespace camera_imu_alignment
