// Synthetic IMU recordings for the stationary detector's tests: a unit with a gyro bias and white
// noise carried through rests, minimum-jerk moves between poses and constant rotations, with the
// true intervals of each; and how a detector's segments match those intervals. Frames: world ENU
// (an accelerometer at rest reads +9.81 along up), rates and biases in the IMU frame (rad/s),
// specific force in m/s^2, times in s from 0.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "camera_imu_alignment/inertial/inertial_samples.h"
#include "camera_imu_alignment/inertial/stationary_detector.h"

namespace camera_imu_alignment {
namespace test {

/// Per-sample noise (std per axis): a density d (unit/sqrt(Hz)) at rate f gives d x sqrt(f).
struct ImuUnit {
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();
  double gyro_sigma_rad_s = 0.0;
  double accel_sigma_m_s2 = 0.0;
  double rate_hz = 200.0;
};

using Interval = std::pair<double, double>;  ///< [first, last] sample stamp (s)

class SyntheticImu {
 public:
  SyntheticImu(const ImuUnit& unit, const Eigen::Matrix3d& R_world_imu, std::uint32_t seed)
      : unit_(unit), R_world_imu_(R_world_imu), rng_(seed) {}

  /// Still for `seconds`.
  void rest(double seconds) {
    const double start = now();
    while (now() < start + seconds - 1e-9) push(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    rests_.push_back({start, now() - dt()});
  }

  /// Minimum-jerk move over `seconds`: rotation `rotvec_imu` (about a fixed IMU axis, rad) and
  /// translation `displacement_world_m`, both starting and ending at zero velocity/acceleration.
  void move(const Eigen::Vector3d& rotvec_imu, const Eigen::Vector3d& displacement_world_m,
            double seconds) {
    const Eigen::Matrix3d R0 = R_world_imu_;
    const double start = now();
    while (now() < start + seconds - 1e-9) {
      const double u = (now() - start) / seconds;
      const double s = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
      const double ds = 30.0 * u * u * (1.0 - u) * (1.0 - u) / seconds;
      const double dds = 60.0 * u * (1.0 - 3.0 * u + 2.0 * u * u) / (seconds * seconds);
      R_world_imu_ = R0 * rotation(s * rotvec_imu);
      push(ds * rotvec_imu, dds * displacement_world_m);
    }
    motions_.push_back({start, now() - dt()});
    R_world_imu_ = R0 * rotation(rotvec_imu);
  }

  /// Rotation about a fixed world axis: a minimum-jerk ramp from rest over `ramp_in_s` (0: already
  /// spinning), `rate_rad_s` for `constant_s` (the interval recorded in spins()), a ramp down to
  /// rest over `ramp_out_s`. The whole is recorded in motions().
  void spin(const Eigen::Vector3d& axis_world, double rate_rad_s, double ramp_in_s,
            double constant_s, double ramp_out_s) {
    const Eigen::Vector3d axis = axis_world.normalized();
    const Eigen::Matrix3d R0 = R_world_imu_;
    const Eigen::Vector3d axis_imu = R0.transpose() * axis;  // fixed in the IMU frame too
    const double start = now(), total = ramp_in_s + constant_s + ramp_out_s;
    double angle = 0.0;
    while (now() < start + total - 1e-9) {
      const double tau = now() - start;
      double rate = rate_rad_s;
      if (tau < ramp_in_s) rate *= smoothStep(tau / ramp_in_s);
      if (tau > ramp_in_s + constant_s) rate *= smoothStep((total - tau) / ramp_out_s);
      R_world_imu_ = rotation(angle * axis) * R0;
      push(rate * axis_imu, Eigen::Vector3d::Zero());
      angle += rate * dt();
    }
    spins_.push_back({start + ramp_in_s, start + ramp_in_s + constant_s});
    motions_.push_back({start, now() - dt()});
    R_world_imu_ = rotation(angle * axis) * R0;
  }

  ImuUnit& unit() { return unit_; }
  const std::vector<ImuSample>& samples() const { return samples_; }
  const std::vector<Interval>& rests() const { return rests_; }
  const std::vector<Interval>& motions() const { return motions_; }
  const std::vector<Interval>& spins() const { return spins_; }

 private:
  double dt() const { return 1.0 / unit_.rate_hz; }
  double now() const { return static_cast<double>(samples_.size()) * dt(); }
  static double smoothStep(double u) { return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u); }
  static Eigen::Matrix3d rotation(const Eigen::Vector3d& rotvec) {
    const double angle = rotvec.norm();
    if (angle < 1e-15) return Eigen::Matrix3d::Identity();
    return Eigen::AngleAxisd(angle, rotvec / angle).toRotationMatrix();
  }
  Eigen::Vector3d noise(double sigma) {
    return sigma * Eigen::Vector3d(normal_(rng_), normal_(rng_), normal_(rng_));
  }
  void push(const Eigen::Vector3d& omega_imu, const Eigen::Vector3d& accel_world) {
    const Eigen::Vector3d up(0.0, 0.0, 9.81);
    samples_.push_back(
        {now(), omega_imu + unit_.gyro_bias_rad_s + noise(unit_.gyro_sigma_rad_s),
         R_world_imu_.transpose() * (accel_world + up) + noise(unit_.accel_sigma_m_s2)});
  }

  ImuUnit unit_;
  Eigen::Matrix3d R_world_imu_;
  std::mt19937 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::vector<ImuSample> samples_;
  std::vector<Interval> rests_, motions_, spins_;
};

/// The unit the detector must cope with: an uncalibrated MEMS gyro at its datasheet's +-5 deg/s
/// bias (a different sign per axis) with white noise of 0.004 rad/s/sqrt(Hz) (0.057 rad/s per
/// sample at 200 Hz), and a consumer accelerometer (0.13 m/s^2 per sample, as the noisy test unit
/// of test_imu_orientation).
inline ImuUnit noisyBiasedUnit() {
  ImuUnit unit;
  unit.gyro_bias_rad_s = 5.0 * M_PI / 180.0 * Eigen::Vector3d(1.0, -1.0, 1.0);
  unit.gyro_sigma_rad_s = 0.004 * std::sqrt(200.0);
  unit.accel_sigma_m_s2 = 0.13;
  return unit;
}

/// How the detected segments match the true rests of a synthetic recording.
struct RestMatch {
  int rests_found_once = 0;          ///< rests overlapped by exactly one segment
  int stray_segments = 0;            ///< segments not within 0.5 s of one rest
  double recall = 0.0;               ///< share of the rests' time, half a window in from each end
  double moving_detected_s = 0.0;    ///< segment time inside motions, 0.5 s in from their ends
  double spinning_detected_s = 0.0;  ///< segment time inside constant rotations
};

inline double overlapS(const Interval& a, double from, double to) {
  return std::max(0.0, std::min(a.second, to) - std::max(a.first, from));
}

inline RestMatch matchRests(const SyntheticImu& imu, const std::vector<StationarySegment>& segments,
                            double window_s = 1.0) {
  RestMatch m;
  double interior = 0.0, covered = 0.0;
  for (const auto& rest : imu.rests()) {
    int overlapping = 0;
    const Interval inside{rest.first + 0.5 * window_s, rest.second - 0.5 * window_s};
    interior += inside.second - inside.first;
    for (const auto& s : segments) {
      overlapping += s.end_s > rest.first && s.start_s < rest.second;
      covered += overlapS(inside, s.start_s, s.end_s);
    }
    m.rests_found_once += overlapping == 1;
  }
  m.recall = covered / interior;
  for (const auto& s : segments) {
    bool near_a_rest = false;
    for (const auto& rest : imu.rests()) {
      near_a_rest |= s.start_s >= rest.first - 0.5 && s.end_s <= rest.second + 0.5;
    }
    m.stray_segments += !near_a_rest;
    for (const auto& motion : imu.motions()) {
      m.moving_detected_s +=
          overlapS({motion.first + 0.5, motion.second - 0.5}, s.start_s, s.end_s);
    }
    for (const auto& spin : imu.spins())
      m.spinning_detected_s += overlapS(spin, s.start_s, s.end_s);
  }
  return m;
}

}  // namespace test
}  // namespace camera_imu_alignment
