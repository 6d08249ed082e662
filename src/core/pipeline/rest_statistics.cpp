// Rest statistics and gyro samples for the joint estimate (rest_statistics.h).
#include "rest_statistics.h"

#include <cmath>

namespace camera_imu_alignment {

RestStatistics restStatistics(const std::deque<ImuSample>& samples, double start_s, double end_s) {
  RestStatistics stats;
  Eigen::Vector3d accel_sum = Eigen::Vector3d::Zero(), gyro_sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const ImuSample& s : samples) {
    if (s.stamp_s < start_s || s.stamp_s > end_s) continue;
    accel_sum += s.accel_m_s2;
    gyro_sum += s.gyro_rad_s;
    ++n;
  }
  if (n < 2) return stats;
  stats.count = n;
  stats.accel_mean_m_s2 = accel_sum / n;
  stats.gyro_mean_rad_s = gyro_sum / n;
  Eigen::Matrix3d accel_scatter = Eigen::Matrix3d::Zero(), gyro_scatter = Eigen::Matrix3d::Zero();
  double diff_sq = 0.0, first_s = 0.0, last_s = 0.0;
  int diffs = 0;
  const ImuSample* previous = nullptr;
  for (const ImuSample& s : samples) {
    if (s.stamp_s < start_s || s.stamp_s > end_s) continue;
    const Eigen::Vector3d da = s.accel_m_s2 - stats.accel_mean_m_s2;
    const Eigen::Vector3d dg = s.gyro_rad_s - stats.gyro_mean_rad_s;
    accel_scatter += da * da.transpose();
    gyro_scatter += dg * dg.transpose();
    if (previous) {
      diff_sq += (s.gyro_rad_s - previous->gyro_rad_s).squaredNorm();
      ++diffs;
      last_s = s.stamp_s;
    } else {
      first_s = s.stamp_s;
    }
    previous = &s;
  }
  stats.accel_mean_cov = accel_scatter / (static_cast<double>(n - 1) * n);
  stats.gyro_mean_cov = gyro_scatter / (static_cast<double>(n - 1) * n);
  // White noise: successive differences have twice the per-sample variance (per axis: / 3 / 2);
  // density = sigma_sample * sqrt(dt).
  if (diffs > 0 && last_s > first_s) {
    const double sample_var = diff_sq / (6.0 * diffs);
    const double dt = (last_s - first_s) / diffs;
    stats.gyro_noise_density_rad_s_sqrt_hz = std::sqrt(sample_var * dt);
  }
  return stats;
}

void appendGyroSamples(const std::deque<ImuSample>& samples, double from_s, double to_s,
                       GyroSegment* segment) {
  for (const ImuSample& s : samples) {
    if (s.stamp_s < from_s || s.stamp_s > to_s) continue;
    // Spans appended one after the other share their boundary sample ([a, b] then [b, c]), and
    // a rest that became no pose is appended after the motion into it: each sample once.
    if (!segment->stamps_s.empty() && s.stamp_s <= segment->stamps_s.back()) continue;
    segment->stamps_s.push_back(s.stamp_s);
    segment->gyro_rad_s.push_back(s.gyro_rad_s);
  }
}

}  // namespace camera_imu_alignment
