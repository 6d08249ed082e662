// Continuous hand-held motion in front of the board (scenario `waving`, MotionKind::kWaving): the
// way Kalibr recordings are made, never still. Everything is analytic and exact.
//
// In the target frame (trajectory.h), the camera's orientation is
//   R_target_cam(t) = R_facing * Ry(pan(t)) * Rx(tilt(t)) * Rz(roll(t))
// with R_facing the camera looking straight at the board (optical axis -z_target, image x along
// x_target), and each angle a sum of two sinusoids of incommensurate frequencies (0.17-0.67 Hz,
// jittered per seed) and random phases. The viewing direction stays within config.max_tilt_deg of
// the board's normal (|pan|, |tilt| <= acos(sqrt(cos(max_tilt)))) and the roll within
// config.max_roll_deg. The camera centre is
//   p_target_cam(t) = centre + look(t) - d(t) * R_target_cam(t) * e_z
// so the optical axis passes through the pattern's centre shifted by look(t) (a few cm in the
// board's plane); d(t) sweeps [min_distance_m, max_distance_m]. Body rate and acceleration come
// from the exact first and second time derivatives of these products.
#pragma once

#include <Eigen/Core>
#include <array>
#include <random>

#include "camera_imu_alignment/simulation/sim_config.h"

namespace camera_imu_alignment {
namespace simulation {

/// A sum of sinusoids a_i sin(2 pi f_i t + phi_i) with its exact derivatives.
struct SinusoidSum {
  std::array<double, 2> amplitude{}, frequency_hz{}, phase_rad{};
  double value(double t) const;
  double rate(double t) const;          ///< first derivative (per s)
  double acceleration(double t) const;  ///< second derivative (per s^2)
};

/// The camera's state in the target frame at one instant.
struct WavingState {
  Eigen::Matrix3d R_target_cam = Eigen::Matrix3d::Identity();
  Eigen::Vector3d omega_cam = Eigen::Vector3d::Zero();     ///< body rate, camera frame, rad/s
  Eigen::Vector3d p_target_cam = Eigen::Vector3d::Zero();  ///< camera centre, m
  Eigen::Vector3d a_target = Eigen::Vector3d::Zero();      ///< acceleration, target frame, m/s^2
};

class WavingMotion {
 public:
  WavingMotion() = default;
  /// Draws frequencies and phases from `rng`; `centre` is the pattern's centre (target frame, m).
  WavingMotion(const SimulationConfig& config, const Eigen::Vector3d& centre, std::mt19937_64* rng);
  WavingState at(double t) const;

 private:
  SinusoidSum pan_, tilt_, roll_, distance_, look_x_, look_y_;
  double distance_mid_m_ = 0.7;
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
};

}  // namespace simulation
}  // namespace camera_imu_alignment
