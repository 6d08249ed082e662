#include "camera_imu_alignment/estimation/gyro_preintegration.h"

#include "gyro_accumulator.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// Exp(phi) and Jr(phi) from one sine and cosine; series below 1e-4 rad.
void expAndRightJacobian(const Eigen::Vector3d& phi, Eigen::Matrix3d* R, Eigen::Matrix3d* Jr) {
  const double angle2 = phi.squaredNorm();
  const Eigen::Matrix3d Phi = skew(phi);
  const Eigen::Matrix3d Phi2 = Phi * Phi;
  double a, b, c, d;  // R = I + a Phi + b Phi^2;  Jr = I - c Phi + d Phi^2
  if (angle2 < 1e-8) {
    a = 1.0 - angle2 / 6.0;
    b = 0.5 - angle2 / 24.0;
    c = 0.5 - angle2 / 24.0;
    d = 1.0 / 6.0 - angle2 / 120.0;
  } else {
    const double angle = std::sqrt(angle2);
    const double s = std::sin(angle), co = std::cos(angle);
    a = s / angle;
    b = (1.0 - co) / angle2;
    c = b;
    d = (angle - s) / (angle2 * angle);
  }
  *R = Eigen::Matrix3d::Identity() + a * Phi + b * Phi2;
  *Jr = Eigen::Matrix3d::Identity() - c * Phi + d * Phi2;
}

}  // namespace

Eigen::Matrix3d rightJacobianSO3(const Eigen::Vector3d& phi) {
  Eigen::Matrix3d R, Jr;
  expAndRightJacobian(phi, &R, &Jr);
  return Jr;
}

GyroModelVector gyroModelVector(const Eigen::Matrix3d& T_g, const Eigen::Vector3d& b_from,
                                const Eigen::Vector3d& b_to) {
  GyroModelVector theta;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) theta(3 * r + c) = T_g(r, c);
  }
  theta.segment<3>(9) = b_from;
  theta.segment<3>(12) = b_to;
  return theta;
}

std::vector<double> sampleIntervals(const std::vector<double>& stamps_s) {
  const size_t n = stamps_s.size();
  std::vector<double> dt(n, 0.0);
  if (n < 2) return dt;
  for (size_t i = 0; i + 1 < n; ++i) dt[i] = stamps_s[i + 1] - stamps_s[i];
  std::vector<double> sorted(dt.begin(), dt.end() - 1);
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  dt[n - 1] = sorted[sorted.size() / 2];
  return dt;
}

void GyroAccumulator::step(const Eigen::Vector3d& raw, double s, double dt) {
  const Eigen::Vector3d rate = rateOf(raw, s);
  Eigen::Matrix3d step_R, step_Jr;
  expAndRightJacobian(rate * dt, &step_R, &step_Jr);
  // d rate / d T_g(r, c) = -T_g^-1 e_r rate_c; d rate / d b = -(1 - s or s) T_g^-1.
  const Eigen::Matrix3d M = -dt * step_Jr * T_g_inverse;
  J = step_R.transpose() * J;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) J.col(3 * r + c) += M.col(r) * rate(c);
  }
  J.block<3, 3>(0, 9) += (1.0 - s) * M;
  J.block<3, 3>(0, 12) += s * M;
  delta_R = delta_R * step_R;
  duration_s += dt;
}

GyroPreintegration GyroAccumulator::result(const GyroModelVector& theta0) const {
  GyroPreintegration out;
  out.theta0 = theta0;
  out.delta_R = projectToSO3(delta_R);
  out.jacobian = J;
  out.duration_s = duration_s;
  return out;
}

GyroPreintegration preintegrateGyro(const std::vector<double>& stamps_s,
                                    const std::vector<Eigen::Vector3d>& gyro_rad_s, double t_from_s,
                                    double t_to_s, const Eigen::Matrix3d& T_g,
                                    const Eigen::Vector3d& b_from, const Eigen::Vector3d& b_to) {
  GyroAccumulator acc{T_g.inverse(), b_from, b_to};
  const std::vector<double> dt = sampleIntervals(stamps_s);
  const double ramp_s = t_to_s - t_from_s;
  const size_t n = std::min(stamps_s.size(), gyro_rad_s.size());
  for (size_t i = 0; i < n; ++i) {
    double s = ramp_s > 0.0 ? (stamps_s[i] - t_from_s) / ramp_s : 0.0;
    acc.step(gyro_rad_s[i], std::clamp(s, 0.0, 1.0), dt[i]);
  }
  return acc.result(gyroModelVector(T_g, b_from, b_to));
}

Eigen::Vector3d interpolateSamples(const std::vector<double>& stamps_s,
                                   const std::vector<Eigen::Vector3d>& values, size_t n, double t) {
  const size_t i = static_cast<size_t>(std::upper_bound(stamps_s.begin(), stamps_s.begin() + n, t) -
                                       stamps_s.begin());
  if (i == 0) return values[0];
  if (i >= n) return values[n - 1];
  const double w = (t - stamps_s[i - 1]) / (stamps_s[i] - stamps_s[i - 1]);
  return (1.0 - w) * values[i - 1] + w * values[i];
}

GyroPreintegration preintegrateGyroInterval(
    const std::vector<double>& stamps_s, const std::vector<Eigen::Vector3d>& gyro_rad_s,
    double t_from_s, double t_to_s, const Eigen::Matrix3d& T_g, const Eigen::Vector3d& b_from,
    const Eigen::Vector3d& b_to, Eigen::Vector3d* rate_from, Eigen::Vector3d* rate_to) {
  GyroAccumulator acc{T_g.inverse(), b_from, b_to};
  const GyroModelVector theta0 = gyroModelVector(T_g, b_from, b_to);
  const size_t n = std::min(stamps_s.size(), gyro_rad_s.size());
  const double ramp_s = t_to_s - t_from_s;
  if (n < 2 || !(ramp_s > 0.0)) return acc.result(theta0);
  const auto rawAt = [&](double t) { return interpolateSamples(stamps_s, gyro_rad_s, n, t); };
  // Sub-intervals between the interval's ends and the samples inside it; each is integrated at
  // its midpoint's interpolated rate (exact for a rate linear between samples).
  double t = t_from_s;
  size_t i = static_cast<size_t>(
      std::upper_bound(stamps_s.begin(), stamps_s.begin() + n, t_from_s) - stamps_s.begin());
  while (t < t_to_s) {
    const double next = i < n ? std::min(stamps_s[i], t_to_s) : t_to_s;
    if (next > t) {
      const double mid = 0.5 * (t + next);
      acc.step(rawAt(mid), (mid - t_from_s) / ramp_s, next - t);
    }
    t = next;
    ++i;
  }
  if (rate_from) *rate_from = acc.rateOf(rawAt(t_from_s), 0.0);
  if (rate_to) *rate_to = acc.rateOf(rawAt(t_to_s), 1.0);
  return acc.result(theta0);
}

Eigen::Matrix3d correctedDeltaR(const GyroPreintegration& preintegration,
                                const GyroModelVector& theta) {
  return preintegration.delta_R * expSO3(preintegration.jacobian * (theta - preintegration.theta0));
}

}  // namespace camera_imu_alignment
