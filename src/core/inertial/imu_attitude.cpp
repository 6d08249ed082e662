// Attitude at rest from gravity and the magnetic field; gyro integration on SO(3).
#include "camera_imu_alignment/inertial/imu_attitude.h"

#include <cmath>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

namespace {
bool finiteVector(const Eigen::Vector3d& v) { return v.allFinite(); }
}  // namespace

AttitudeFromVectors attitudeFromAccelMag(const Eigen::Vector3d& accel_m_s2,
                                         const Eigen::Vector3d& field_t, double accel_weight) {
  AttitudeFromVectors out;
  if (!finiteVector(accel_m_s2) || !finiteVector(field_t) || !std::isfinite(accel_weight) ||
      accel_weight <= 0.0 || accel_weight >= 1.0) {
    return out;
  }
  const double accel_norm = accel_m_s2.norm(), field_norm = field_t.norm();
  if (accel_norm < 1e-9 || field_norm < 1e-15) return out;
  const Eigen::Vector3d up_imu = accel_m_s2 / accel_norm;
  const Eigen::Vector3d horizontal = field_t - field_t.dot(up_imu) * up_imu;
  // A field (nearly) along gravity gives no heading (magnetic poles, or a sensor fault).
  if (horizontal.norm() < 1e-3 * field_norm) return out;
  const Eigen::Vector3d north_imu = horizontal.normalized();
  const Eigen::Vector3d east_imu = north_imu.cross(up_imu);
  // The q-method's optimum for two observations is the rotation that aligns the weighted pair
  // best. Here the observations are orthogonal unit vectors in both frames (north is taken
  // perpendicular to the measured up), so the optimum aligns both exactly whatever the weights:
  // the rows of R_world_imu are east, north and up expressed in the IMU frame. The weight only
  // matters through the construction: the field never tilts the estimate.
  out.R_world_imu.row(0) = east_imu.transpose();
  out.R_world_imu.row(1) = north_imu.transpose();
  out.R_world_imu.row(2) = up_imu.transpose();
  out.dip_deg = rad2deg(std::atan2(-field_t.dot(up_imu), horizontal.norm()));
  out.field_norm_t = field_norm;
  out.valid = true;
  return out;
}

Eigen::Matrix3d attitudeFromAccel(const Eigen::Vector3d& accel_m_s2) {
  const double norm = accel_m_s2.norm();
  if (!finiteVector(accel_m_s2) || norm < 1e-9) return Eigen::Matrix3d::Identity();
  const Eigen::Vector3d up = accel_m_s2 / norm;
  // R = Ry(pitch) Rx(roll) (yaw zero) maps the IMU's up vector to world z:
  // up_imu = (-sin p, sin r cos p, cos r cos p).
  const double pitch = std::atan2(-up.x(), std::hypot(up.y(), up.z()));
  const double roll = std::atan2(up.y(), up.z());
  return (Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

bool integrateGyro(const std::vector<ImuSample>& samples, const Eigen::Vector3d& gyro_bias_rad_s,
                   double t_begin_s, double t_end_s, Eigen::Matrix3d* R_imu_begin_imu_end,
                   double max_gap_s) {
  if (!R_imu_begin_imu_end || !std::isfinite(t_begin_s) || !std::isfinite(t_end_s) ||
      t_end_s < t_begin_s || !gyro_bias_rad_s.allFinite()) {
    return false;
  }
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (t_end_s == t_begin_s) {
    *R_imu_begin_imu_end = R;
    return true;
  }
  if (samples.empty()) return false;
  // The span must be covered: at most max_gap_s without a sample at either end.
  if (samples.front().stamp_s > t_begin_s + max_gap_s ||
      samples.back().stamp_s < t_end_s - max_gap_s) {
    return false;
  }
  auto rate = [&](const ImuSample& s) { return Eigen::Vector3d(s.gyro_rad_s - gyro_bias_rad_s); };
  // Before the first sample (within max_gap_s) hold its rate.
  if (samples.front().stamp_s > t_begin_s) {
    const double dt = std::min(samples.front().stamp_s, t_end_s) - t_begin_s;
    R = R * expSO3(rate(samples.front()) * dt);
  }
  for (std::size_t i = 0; i + 1 < samples.size(); ++i) {
    const double a = samples[i].stamp_s, b = samples[i + 1].stamp_s;
    if (b <= t_begin_s) continue;
    if (a >= t_end_s) break;
    if (b - a > max_gap_s) return false;
    const double dt = std::min(b, t_end_s) - std::max(a, t_begin_s);
    if (dt <= 0.0) continue;
    const Eigen::Vector3d w = 0.5 * (rate(samples[i]) + rate(samples[i + 1]));
    R = R * expSO3(w * dt);
  }
  // After the last sample (within max_gap_s) hold its rate.
  if (samples.back().stamp_s < t_end_s) {
    const double dt = t_end_s - std::max(samples.back().stamp_s, t_begin_s);
    R = R * expSO3(rate(samples.back()) * dt);
  }
  *R_imu_begin_imu_end = projectToSO3(R);
  return true;
}

}  // namespace camera_imu_alignment
