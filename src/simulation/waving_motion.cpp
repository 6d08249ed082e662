#include "camera_imu_alignment/simulation/waving_motion.h"

#include <cmath>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace simulation {

namespace {

/// Elementary rotation about axis `axis` (0 x, 1 y, 2 z) by `angle` rad.
Eigen::Matrix3d axisRotation(int axis, double angle) {
  return expSO3(angle * Eigen::Vector3d::Unit(axis));
}

/// An elementary rotation R(theta(t)) with its exact first and second time derivatives:
/// R' = R [e]x theta',  R'' = R ([e]x^2 theta'^2 + [e]x theta'').
struct RotationAndDerivatives {
  Eigen::Matrix3d R, dR, ddR;
  RotationAndDerivatives(int axis, const SinusoidSum& angle, double t) {
    const Eigen::Matrix3d E = skew(Eigen::Vector3d::Unit(axis));
    const double th = angle.value(t), dth = angle.rate(t), ddth = angle.acceleration(t);
    R = axisRotation(axis, th);
    dR = R * E * dth;
    ddR = R * (E * E * dth * dth + E * ddth);
  }
};

SinusoidSum draw(double amplitude, double f1, double f2, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  SinusoidSum s;
  s.amplitude = {0.6 * amplitude, 0.4 * amplitude};
  s.frequency_hz = {f1 * (0.9 + 0.2 * uni(*rng)), f2 * (0.9 + 0.2 * uni(*rng))};
  s.phase_rad = {2.0 * kPi * uni(*rng), 2.0 * kPi * uni(*rng)};
  return s;
}

}  // namespace

double SinusoidSum::value(double t) const {
  double v = 0.0;
  for (int i = 0; i < 2; ++i)
    v += amplitude[i] * std::sin(2.0 * kPi * frequency_hz[i] * t + phase_rad[i]);
  return v;
}

double SinusoidSum::rate(double t) const {
  double v = 0.0;
  for (int i = 0; i < 2; ++i) {
    const double w = 2.0 * kPi * frequency_hz[i];
    v += amplitude[i] * w * std::cos(w * t + phase_rad[i]);
  }
  return v;
}

double SinusoidSum::acceleration(double t) const {
  double v = 0.0;
  for (int i = 0; i < 2; ++i) {
    const double w = 2.0 * kPi * frequency_hz[i];
    v -= amplitude[i] * w * w * std::sin(w * t + phase_rad[i]);
  }
  return v;
}

WavingMotion::WavingMotion(const SimulationConfig& config, const Eigen::Vector3d& centre,
                           std::mt19937_64* rng)
    : centre_(centre) {
  // |pan|, |tilt| <= a keep the viewing angle acos(cos(pan) cos(tilt)) within max_tilt_deg.
  const double view = deg2rad(config.max_tilt_deg);
  const double a = 0.97 * std::acos(std::sqrt(std::cos(view)));
  const double roll = 0.95 * deg2rad(config.max_roll_deg);
  pan_ = draw(a, 0.23, 0.55, rng);
  tilt_ = draw(a, 0.29, 0.67, rng);
  roll_ = draw(roll, 0.17, 0.43, rng);
  distance_mid_m_ = 0.5 * (config.min_distance_m + config.max_distance_m);
  distance_ = draw(0.5 * (config.max_distance_m - config.min_distance_m), 0.11, 0.31, rng);
  look_x_ = draw(0.02, 0.13, 0.37, rng);
  look_y_ = draw(0.02, 0.19, 0.47, rng);
}

WavingState WavingMotion::at(double t) const {
  // Camera looking straight at the board: optical axis -z_target, image x along x_target.
  Eigen::Matrix3d R_facing;
  R_facing << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  const RotationAndDerivatives A(1, pan_, t), B(0, tilt_, t), C(2, roll_, t);
  const Eigen::Matrix3d R = R_facing * A.R * B.R * C.R;
  const Eigen::Matrix3d dR = R_facing * (A.dR * B.R * C.R + A.R * B.dR * C.R + A.R * B.R * C.dR);
  const Eigen::Matrix3d ddR =
      R_facing * (A.ddR * B.R * C.R + A.R * B.ddR * C.R + A.R * B.R * C.ddR +
                  2.0 * (A.dR * B.dR * C.R + A.dR * B.R * C.dR + A.R * B.dR * C.dR));
  WavingState s;
  s.R_target_cam = R;
  const Eigen::Matrix3d Omega = R.transpose() * dR;  // [omega_cam]x
  s.omega_cam = Eigen::Vector3d(Omega(2, 1), Omega(0, 2), Omega(1, 0));
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d v = R * z, dv = dR * z, ddv = ddR * z;  // optical axis
  const double d = distance_mid_m_ + distance_.value(t), dd = distance_.rate(t),
               ddd = distance_.acceleration(t);
  const Eigen::Vector3d look(look_x_.value(t), look_y_.value(t), 0.0);
  const Eigen::Vector3d ddlook(look_x_.acceleration(t), look_y_.acceleration(t), 0.0);
  s.p_target_cam = centre_ + look - d * v;
  s.a_target = ddlook - ddd * v - 2.0 * dd * dv - d * ddv;
  return s;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
