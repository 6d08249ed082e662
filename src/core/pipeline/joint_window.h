// What the joint estimator needs of the poses in the pipeline's window (estimation/joint_types.h):
// each pose's averaged measurements with their covariances, measured on the rest itself, and the
// raw gyro samples since the previous pose. Kept beside the PoseWindow and trimmed with it.
// Private to the pipeline; not installed.
#pragma once

#include <cstddef>
#include <deque>
#include <optional>

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

/// The joint estimator's view of the window: one entry per pose, oldest first.
class JointWindow {
 public:
  struct Entry {
    JointPose pose;
    /// Gyro samples from the previous pose's rest to this one's (same chain), if recorded.
    std::optional<GyroSegment> gyro_from_previous;
  };

  explicit JointWindow(std::size_t max_poses) : max_poses_(max_poses) {}
  void add(Entry entry);
  void keepNewest(std::size_t count);
  void clear() { entries_.clear(); }
  std::size_t size() const { return entries_.size(); }
  /// The problem of the poses in the window: a gyro segment is kept when its previous pose is in
  /// the window and of the same group.
  JointProblem problem() const;

 private:
  std::size_t max_poses_;
  std::deque<Entry> entries_;
};

}  // namespace camera_imu_alignment
