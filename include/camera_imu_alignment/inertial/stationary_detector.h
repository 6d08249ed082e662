// Stationary (at-rest) segments from the IMU stream.
//
// A sample is "at rest" when, over a sliding window of `window_s` centred on it,
//   - the window's mean gyro, bias-compensated, is below max_gyro_rad_s (bias: the mean gyro of
//     the last stationary segment; before the first one the bias is unknown and the raw mean must
//     stay below max_initial_gyro_bias_rad_s),
//   - the gyro's scatter about that mean (RMS of |gyro - mean|) is below
//     max(max_gyro_std_rad_s, noise_factor x gyro noise),
//   - the standard deviation of the accelerometer norm is below
//     max(max_accel_std_m_s2, noise_factor x accelerometer noise), and
//   - | |mean accel| - gravity | is below max_gravity_error_m_s2.
// The noise terms adapt the limits to the sensor: the noise is measured from successive-sample
// differences (white noise doubles their variance; motion is smooth at IMU rates), the quietest
// window so far counting. A consumer-grade IMU thus needs no tuning; the fixed limits are floors.
// Consecutive at-rest samples form a segment; a segment shorter than min_duration_s is dropped.
// Segment ends are trimmed by half a window so that no motion leaks into the averages; the gyro
// integration between segments covers the trimmed parts, so nothing is lost.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "camera_imu_alignment/inertial/inertial_samples.h"

namespace camera_imu_alignment {

struct StationaryDetectorSettings {
  double window_s = 1.0;                     ///< sliding window length (s)
  double min_duration_s = 2.0;               ///< shortest segment emitted (s), after trimming
  double max_gyro_rad_s = 0.03;              ///< |window mean gyro - bias| (rad/s)
  double max_initial_gyro_bias_rad_s = 0.1;  ///< |window mean gyro| before any bias is known
  double max_gyro_std_rad_s = 0.01;          ///< RMS of |gyro - window mean|, floor (rad/s)
  double max_accel_std_m_s2 = 0.06;          ///< std of |accel| over the window, floor (m/s^2)
  double noise_factor = 2.0;  ///< limits >= this x the measured noise; 0: fixed limits only
  double max_gravity_error_m_s2 = 0.4;  ///< | |mean accel| - gravity_m_s2 |
  double gravity_m_s2 = 9.81;
  double max_gap_s = 0.1;  ///< a larger gap between samples ends the current segment
};

/// One stationary segment with the averages the attitude needs.
struct StationarySegment {
  double start_s = 0.0, end_s = 0.0;  ///< stamps of first / last sample used
  Eigen::Vector3d mean_accel_m_s2 = Eigen::Vector3d::Zero();  ///< IMU frame
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();  ///< mean gyro over the segment
  double accel_norm_std_m_s2 = 0.0;
  double gyro_norm_max_rad_s = 0.0;  ///< over the segment, compensated with the bias in use
                                     ///< during detection (the previous segment's)
  int num_samples = 0;
  double duration() const { return end_s - start_s; }
};

/// Streaming detector: feed IMU samples in stamp order (already validated), collect segments.
class StationaryDetector {
 public:
  explicit StationaryDetector(const StationaryDetectorSettings& settings = {});

  /// Adds one sample. Returns a segment when one has just ended (rest -> motion, or a gap).
  std::optional<StationarySegment> add(const ImuSample& sample);
  /// Ends the stream: returns the segment in progress if it is long enough.
  std::optional<StationarySegment> flush();
  /// True while the most recent fully-windowed sample is at rest.
  bool atRest() const;
  /// Start stamp (s) of the rest period in progress, if any (before trimming and length check).
  std::optional<double> restSince() const;
  void reset();
  const StationaryDetectorSettings& settings() const { return settings_; }

 private:
  struct Impl;
  StationaryDetectorSettings settings_;
  std::shared_ptr<Impl> impl_;
};

/// Convenience for whole recordings: segments of a sample sequence (stamp order).
std::vector<StationarySegment> detectStationarySegments(
    const std::vector<ImuSample>& samples, const StationaryDetectorSettings& settings = {});

}  // namespace camera_imu_alignment
