// Initial values of the joint estimator.
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "joint_state.h"

namespace camera_imu_alignment {
namespace joint {
namespace {

Eigen::Matrix3d rotationZ(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

/// Heading and field from the magnetometer, given R_world_imu up to a common yaw: in the tilt-only
/// world frame W0 the field is (a, b, f1), and m_k = R_W0_imu_k^T (a, b, f1) + h is linear in
/// (a, b, f1, h). Returns false when the fit is not usable.
bool fitMagneticField(const JointProblem& problem, const std::vector<Eigen::Matrix3d>& R_w0_imu,
                      bool with_hard_iron, Eigen::Vector3d* field_w0_ut,
                      Eigen::Vector3d* hard_iron_ut) {
  std::vector<int> usable;
  for (size_t k = 0; k < problem.poses.size(); ++k) {
    if (problem.poses[k].mag_mean_t) usable.push_back(static_cast<int>(k));
  }
  const int columns = with_hard_iron ? 6 : 3;
  if (static_cast<int>(usable.size()) * 3 < columns) return false;
  Eigen::MatrixXd A(3 * usable.size(), columns);
  Eigen::VectorXd b(3 * usable.size());
  for (size_t i = 0; i < usable.size(); ++i) {
    const int k = usable[i];
    A.block<3, 3>(3 * i, 0) = R_w0_imu[k].transpose();
    if (with_hard_iron) A.block<3, 3>(3 * i, 3) = Eigen::Matrix3d::Identity();
    b.segment<3>(3 * i) = *problem.poses[k].mag_mean_t * kMicroteslaPerTesla;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < columns) return false;
  const Eigen::VectorXd x = qr.solve(b);
  if (!x.allFinite()) return false;
  *field_w0_ut = x.head<3>();
  *hard_iron_ut = with_hard_iron ? Eigen::Vector3d(x.tail<3>()) : Eigen::Vector3d::Zero();
  // A hard iron larger than the field itself is a failed fit, not a magnetometer.
  return field_w0_ut->norm() > 0.0 && hard_iron_ut->norm() < 2.0 * field_w0_ut->norm();
}

}  // namespace

State initialState(const JointProblem& problem, const Eigen::Matrix3d& R_cam_imu_initial,
                   const JointObservability& observability, const JointSettings&) {
  State state;
  const size_t n = problem.poses.size();
  state.R_cam_imu_0 = projectToSO3(R_cam_imu_initial);
  state.R_cam_imu_after_0 = state.R_cam_imu_0;
  state.delta.assign(n, {0.0, 0.0, 0.0});
  state.accel_bias.assign(n, {0.0, 0.0, 0.0});
  state.gyro_bias.resize(n);
  // Motion nodes start from the rests' mean bias (zero without rests).
  Eigen::Vector3d rest_bias = Eigen::Vector3d::Zero();
  int rests = 0;
  for (const JointPose& pose : problem.poses) {
    if (!pose.at_rest) continue;
    rest_bias += pose.gyro_mean_rad_s;
    ++rests;
  }
  if (rests > 0) rest_bias /= rests;
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d& b =
        problem.poses[k].at_rest ? problem.poses[k].gyro_mean_rad_s : rest_bias;
    state.gyro_bias[k] = {b.x(), b.y(), b.z()};
  }
  state.timeshift = {problem.timeshift_initial_s};
  state.timeshift_0 = problem.timeshift_initial_s;

  // Up (the accelerometer's direction at rest) in the target frame, averaged over the poses.
  std::vector<Eigen::Matrix3d> R_target_imu(n);
  Eigen::Vector3d up_target = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < n; ++k) {
    R_target_imu[k] = projectToSO3(problem.poses[k].R_target_cam) * state.R_cam_imu_0;
    if (!problem.poses[k].at_rest) continue;  // a motion node: no accelerometer
    up_target += R_target_imu[k] * problem.poses[k].accel_mean_m_s2.normalized();
  }
  if (!(up_target.norm() > 1e-6)) {
    for (size_t k = 0; k < n && !(up_target.norm() > 1e-6); ++k) {
      if (problem.poses[k].at_rest) up_target = R_target_imu[k] * problem.poses[k].accel_mean_m_s2;
    }
  }
  // Without rests, up from the accelerometer links: R_target_imu_from int f dt = dv_target + up g T
  // (the keyframes' start velocities).
  if (!(up_target.norm() > 1e-6)) {
    for (const AccelLink& link : problem.accel_links) {
      const JointPose& from = problem.poses[link.from_pose];
      const Eigen::Vector3d b(state.gyro_bias[link.from_pose][0],
                              state.gyro_bias[link.from_pose][1],
                              state.gyro_bias[link.from_pose][2]);
      const AccelLinkIntegral in =
          integrateAccelLink(link.samples, from.start_s, problem.poses[link.to_pose].start_s,
                             Eigen::Matrix3d::Identity(), b, b);
      up_target += projectToSO3(from.R_target_cam) * state.R_cam_imu_0 * in.d0[0] -
                   (link.v_to_target_m_s - link.v_from_target_m_s);
    }
  }
  // Without rests or links W is a gauge: any axis.
  if (!(up_target.norm() > 1e-6)) up_target = Eigen::Vector3d::UnitZ();
  Eigen::Matrix3d R_world_target =
      Eigen::Quaterniond::FromTwoVectors(up_target.normalized(), Eigen::Vector3d::UnitZ())
          .toRotationMatrix();

  if (observability.magnetometer_used) {
    std::vector<Eigen::Matrix3d> R_w0_imu(n);
    for (size_t k = 0; k < n; ++k) R_w0_imu[k] = R_world_target * R_target_imu[k];
    Eigen::Vector3d field_w0, hard_iron;
    bool fitted = fitMagneticField(problem, R_w0_imu, observability.hard_iron_estimated, &field_w0,
                                   &hard_iron);
    if (!fitted && observability.hard_iron_estimated) {
      fitted = fitMagneticField(problem, R_w0_imu, false, &field_w0, &hard_iron);
    }
    if (fitted) {
      // Turn W0 about z so that the field's horizontal part points along +y (north).
      const double yaw = 0.5 * kPi - std::atan2(field_w0.y(), field_w0.x());
      R_world_target = rotationZ(yaw) * R_world_target;
      state.field_ut = {std::hypot(field_w0.x(), field_w0.y()), field_w0.z()};
      state.hard_iron_ut = {hard_iron.x(), hard_iron.y(), hard_iron.z()};
    } else {
      // Degenerate fit: the mean field of the poses in W0, no hard iron.
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (size_t k = 0; k < n; ++k) {
        if (problem.poses[k].mag_mean_t) {
          mean += R_w0_imu[k] * *problem.poses[k].mag_mean_t * kMicroteslaPerTesla;
        }
      }
      const double yaw = 0.5 * kPi - std::atan2(mean.y(), mean.x());
      R_world_target = rotationZ(yaw) * R_world_target;
      const double count = std::max(1, observability.usable_mag_poses);
      state.field_ut = {std::hypot(mean.x(), mean.y()) / count, mean.z() / count};
    }
  }
  state.R_world_target_0 = projectToSO3(R_world_target);
  return state;
}

}  // namespace joint
}  // namespace camera_imu_alignment
