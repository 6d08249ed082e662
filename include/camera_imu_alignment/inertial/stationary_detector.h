// Stationary (at-rest) segments from the IMU stream.
//
// A rest is judged over a sliding window of `window_s` centred on each sample, from what does not
// depend on the gyro bias (an uncalibrated MEMS gyro may have 5 deg/s of it; each rest's bias is
// its own mean gyro). A sample is "at rest" when, over its window,
//   - the gyro's scatter about the window mean (RMS of |gyro - mean|) is below
//     max(max_gyro_std_rad_s, noise_factor x gyro noise),
//   - the standard deviation of the accelerometer norm is below
//     max(max_accel_std_m_s2, noise_factor x accelerometer noise),
//   - | |mean accel| - gravity | is below max_gravity_error_m_s2,
//   - the mean gyro does not change (at rest it is the bias): |mean of the window's second half -
//     mean of its first half|, and |window mean - mean of the rest so far|, are below
//     max(max_gyro_change_rad_s, change_noise_factor x the per-axis noise of that difference),
//   - the mean accelerometer direction does not turn: the angle between the halves' means over
//     their time apart is below max(max_gravity_turn_rate_rad_s, change_noise_factor x its noise).
//     A constant rotation has the gyro mean and scatter of a rest, but turns gravity in the IMU
//     frame at its rate across gravity,
//   - |window mean gyro| is below max_gyro_bias_rad_s (the largest bias the unit may have), and
//   - about gravity, where the accelerometer sees no rotation, the window mean agrees with the
//     previous rest's bias: |(mean gyro - previous bias) . up| <= max_rate_about_gravity_rad_s.
// The previous bias is a hint, not a requirement. It is ignored when the difference across
// gravity exceeds twice the turn-rate limit (a rotation that fast would have turned gravity: the
// bias changed), and dropped after a stretch of windows as long as min_duration_s that only it
// refused (a rotation about gravity, or a wrong hint: the next rest is then taken on its own).
// So a constant rotation is refused when its rate across gravity exceeds the turn-rate limit
// (1 deg/s, or more for a noisy accelerometer) or, after a rest, its rate about gravity exceeds
// max_rate_about_gravity_rad_s; before any rest, a slow constant rotation about gravity cannot be
// told from a bias by an IMU alone and is taken as a rest.
// The noise terms adapt the limits to the sensor: the noise is measured from successive-sample
// differences (white noise doubles their variance; motion is smooth at IMU rates), the quietest
// window so far counting. A consumer-grade IMU thus needs no tuning; the fixed limits are floors.
// Consecutive at-rest samples form a segment; a segment shorter than min_duration_s is dropped.
// Segment ends are trimmed by half a window so that no motion leaks into the averages; the gyro
// integration between segments covers the trimmed parts, so nothing is lost.
// Cost: O(1) per sample (running sums over the window and its second half).
#pragma once

#include <Eigen/Core>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "camera_imu_alignment/inertial/inertial_samples.h"

namespace camera_imu_alignment {

struct StationaryDetectorSettings {
  double window_s = 1.0;        ///< sliding window length (s)
  double min_duration_s = 2.0;  ///< shortest segment emitted (s), after trimming
  // Scatter within the window.
  double max_gyro_std_rad_s = 0.01;  ///< RMS of |gyro - window mean|, floor (rad/s)
  double max_accel_std_m_s2 = 0.06;  ///< std of |accel| over the window, floor (m/s^2)
  double noise_factor = 2.0;  ///< scatter limits >= this x the measured noise; 0: floors only
  // Change of the means (second half of the window against the first; the rest so far).
  double max_gyro_change_rad_s = 0.01;          ///< |change of the mean gyro|, floor (rad/s)
  double max_gravity_turn_rate_rad_s = 0.0175;  ///< turn rate of the mean accel, floor (rad/s)
  double change_noise_factor = 7.0;  ///< change limits >= this x their noise (std per axis)
  // Bias.
  double max_gyro_bias_rad_s = 0.3;            ///< |window mean gyro| at any rest (rad/s)
  double max_rate_about_gravity_rad_s = 0.03;  ///< |(window mean gyro - previous bias) . up|
  /// | |mean accel| - gravity_m_s2 |: an uncalibrated accelerometer reads g off by its bias and
  /// scale error along the vertical, so the limit is generous: an MPU-9250 class unit (zero-g
  /// +-60-80 mg, sensitivity +-3 %) is off by about 0.7 m/s^2 (1-sigma), 2 at 3 sigma; 1.2 lost a
  /// third of such a unit's rests in 4 of 10 simulated recordings.
  double max_gravity_error_m_s2 = 2.5;
  double gravity_m_s2 = 9.81;
  double max_gap_s = 0.1;  ///< a larger gap between samples ends the current segment
};

/// One stationary segment with the averages the attitude needs.
struct StationarySegment {
  double start_s = 0.0, end_s = 0.0;  ///< stamps of first / last sample used
  Eigen::Vector3d mean_accel_m_s2 = Eigen::Vector3d::Zero();  ///< IMU frame
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();  ///< mean gyro over the segment
  double accel_norm_std_m_s2 = 0.0;
  double gyro_std_rad_s = 0.0;  ///< RMS of |gyro - gyro_bias_rad_s| over the segment
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
