#include "camera_imu_alignment/estimation/joint_observability.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "camera_imu_alignment/estimation/joint_result.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

const char* const kAxisNames[3] = {"x", "y", "z"};

std::string format(const char* fmt, double a, double b) {
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer), fmt, a, b);
  return buffer;
}

/// A unit vector perpendicular to `direction` (unit), the least excited by the gyro when known.
Eigen::Vector3d perpendicularAxis(const Eigen::Vector3d& direction, const GyroExcitation& gyro) {
  const Eigen::Vector3d seed =
      std::abs(direction.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d p1 = direction.cross(seed).normalized();
  if (!gyro.has_segments) return p1;
  const Eigen::Vector3d p2 = direction.cross(p1).normalized();
  // Least excited direction within the plane spanned by p1, p2.
  Eigen::Matrix<double, 3, 2> basis;
  basis << p1, p2;
  const Eigen::Matrix2d E = basis.transpose() * gyro.excitation_rad * basis;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(E);
  return (basis * solver.eigenvectors().col(0)).normalized();
}

}  // namespace

double directionCoverage(const std::vector<Eigen::Vector3d>& unit_directions,
                         Eigen::Vector3d* least_covered_direction) {
  if (least_covered_direction) *least_covered_direction = Eigen::Vector3d::UnitZ();
  if (unit_directions.empty()) return 0.0;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& u : unit_directions) scatter += u * u.transpose();
  scatter /= static_cast<double>(unit_directions.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  if (solver.info() != Eigen::Success) return 0.0;
  if (least_covered_direction) *least_covered_direction = solver.eigenvectors().col(0);
  return std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
}

double directionSpread(const std::vector<Eigen::Vector3d>& unit_directions,
                       Eigen::Vector3d* least_spread_direction) {
  if (least_spread_direction) *least_spread_direction = Eigen::Vector3d::UnitZ();
  if (unit_directions.size() < 4) return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& u : unit_directions) mean += u;
  mean /= static_cast<double>(unit_directions.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& u : unit_directions) {
    covariance += (u - mean) * (u - mean).transpose();
  }
  covariance /= static_cast<double>(unit_directions.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  if (solver.info() != Eigen::Success) return 0.0;
  if (least_spread_direction) *least_spread_direction = solver.eigenvectors().col(0);
  return std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
}

bool informedByTheData(const Eigen::VectorXd& posterior_sigma, const Eigen::VectorXd& prior_sigma) {
  if (posterior_sigma.size() == 0 || posterior_sigma.size() != prior_sigma.size()) return false;
  for (int i = 0; i < posterior_sigma.size(); ++i) {
    if (!(prior_sigma(i) > 0.0)) continue;
    if (!(posterior_sigma(i) <= kInformedFraction * prior_sigma(i))) return false;
  }
  return true;
}

JointObservability decideObservability(const JointProblem& problem, const GyroExcitation& gyro,
                                       const JointSettings& settings) {
  JointObservability out;
  out.gyro_axis_rotation_deg = gyro.accumulated_abs_angle_rad * (180.0 / kPi);
  if (!gyro.has_segments) {
    out.notes.push_back(
        "no gyro segments: the gyro model is not estimated (accelerometer, magnetometer and camera "
        "only)");
  }
  out.gyro_column_estimated = {gyro.has_segments, gyro.has_segments, gyro.has_segments};
  // Without rests the accelerometer is not used (it measures gravity plus the acceleration).
  const bool rests = std::any_of(problem.poses.begin(), problem.poses.end(),
                                 [](const JointPose& pose) { return pose.at_rest; });
  out.accel_bias_estimated = rests;
  out.accel_matrix_estimated = rests || !problem.accel_links.empty();
  if (!rests && !problem.accel_links.empty()) {
    out.notes.push_back("no rests: the accelerometer is used through the acceleration model (" +
                        std::to_string(problem.accel_links.size()) +
                        " links between motion nodes against the camera's velocities)");
  } else if (!rests) {
    out.notes.push_back(
        "no rests: the accelerometer is not used; R_cam_imu relative to its axes (the IMU frame) "
        "rests on the gyro misalignment prior (gyro_cross_axis): a few rests of 1-2 s tie them");
  }

  // The geometry, for the notes and the suggestion only.
  std::vector<Eigen::Vector3d> gravity_directions;
  Eigen::Vector3d mean_gravity = Eigen::Vector3d::Zero();
  for (const JointPose& pose : problem.poses) {
    if (!pose.at_rest) continue;  // a motion node: no accelerometer
    gravity_directions.push_back(pose.accel_mean_m_s2.normalized());
    mean_gravity += gravity_directions.back();
  }
  mean_gravity = mean_gravity.norm() > 1e-9 ? mean_gravity.normalized() : Eigen::Vector3d::UnitZ();
  out.gravity_coverage = directionCoverage(gravity_directions);
  out.gravity_spread = directionSpread(gravity_directions);

  std::vector<Eigen::Vector3d> mag_directions;
  for (const JointPose& pose : problem.poses) {
    if (pose.mag_mean_t) mag_directions.push_back(pose.mag_mean_t->normalized());
  }
  out.usable_mag_poses = static_cast<int>(mag_directions.size());
  out.mag_coverage = directionCoverage(mag_directions);
  out.mag_spread = directionSpread(mag_directions);
  switch (settings.use_magnetometer) {
    case MagnetometerUse::kOff:
      out.magnetometer_used = false;
      if (out.usable_mag_poses > 0) out.notes.push_back("magnetometer not used (settings)");
      break;
    case MagnetometerUse::kOn:
      out.magnetometer_used = out.usable_mag_poses > 0;
      break;
    case MagnetometerUse::kAuto:
      out.magnetometer_used = out.usable_mag_poses >= settings.min_mag_poses_hard_iron;
      if (out.usable_mag_poses > 0 && !out.magnetometer_used) {
        out.notes.push_back(
            format("magnetometer not used: %.0f pose(s) with a usable field, ",
                   out.usable_mag_poses, 0) +
            format("fewer than the %.0f its hard iron needs (min_mag_poses_hard_iron)",
                   settings.min_mag_poses_hard_iron, 0));
      }
      break;
  }
  out.hard_iron_estimated = out.magnetometer_used;
  out.soft_iron_estimated = out.magnetometer_used;

  out.perpendicular_to_gravity_imu = perpendicularAxis(mean_gravity, gyro);
  out.least_excited_axis_imu = out.perpendicular_to_gravity_imu;
  if (gyro.has_segments) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(gyro.excitation_rad);
    if (solver.info() == Eigen::Success) {
      out.least_excited_axis_imu = solver.eigenvectors().col(0).normalized();
    }
  }
  for (Eigen::Vector3d* axis : {&out.least_excited_axis_imu, &out.perpendicular_to_gravity_imu}) {
    if (!axis->allFinite() || axis->norm() < 0.5) *axis = Eigen::Vector3d::UnitX();
  }
  out.suggested_rotation_axis_imu = out.least_excited_axis_imu;
  return out;
}

namespace {

/// Largest posterior/prior 1-sigma ratio over the entries (the prior's share of the estimate).
double largestShare(const Eigen::VectorXd& posterior_sigma, const Eigen::VectorXd& prior_sigma) {
  double share = 0.0;
  for (int i = 0; i < posterior_sigma.size() && i < prior_sigma.size(); ++i) {
    if (prior_sigma(i) > 0.0) share = std::max(share, posterior_sigma(i) / prior_sigma(i));
  }
  return share;
}

Eigen::VectorXd flat(const Eigen::Matrix3d& m) {
  return Eigen::Map<const Eigen::VectorXd>(m.data(), 9);
}

}  // namespace

void describeInformation(const JointObservability& observability, const JointSettings& settings,
                         JointResult* result) {
  const ImuIntrinsics& in = result->intrinsics;
  const ImuModelPriors& p = settings.priors;
  const bool identity = result->imu_matrices == ImuMatrixModel::kIdentity;
  const double unscale = 1.0 / std::sqrt(std::max(1.0, result->covariance_scale));
  const std::string rests = settings.pin_unexcited_parameters
                                ? "held at its prior mean (pin_unexcited_parameters)"
                                : "rests on its prior (its prior uncertainty is in R_cam_imu's "
                                  "1-sigma)";
  auto note = [&](const std::string& what, double share) {
    result->notes.push_back(
        what + " " + rests +
        format(": the poses carry little information about it (posterior 1-sigma up to %.0f %% "
               "of the prior's)",
               100.0 * share, 0));
  };
  bool gyro_undetermined = false, accel_undetermined = false;
  if (!identity && observability.gyro_column_estimated[0]) {
    for (int c = 0; c < 3; ++c) {
      if (in.gyro_matrix_column_estimated[c]) continue;
      gyro_undetermined = true;
      const Eigen::Vector3d prior = Eigen::Vector3d::Constant(p.gyro_cross_axis) +
                                    Eigen::Vector3d::Unit(c) * (p.gyro_scale - p.gyro_cross_axis);
      const std::string name = kAxisNames[c];
      note("gyro scale " + name + " and its cross-axis terms",
           largestShare(in.gyro_matrix_sigma.col(c) * unscale, prior));
    }
  }
  if (!identity && !in.accel_matrix_estimated) {
    accel_undetermined = true;
    note("accelerometer scale and non-orthogonality",
         largestShare(flat(in.accel_matrix_sigma) * unscale,
                      flat(Eigen::Matrix3d::Constant(p.accel_cross_axis) +
                           Eigen::Matrix3d::Identity() * (p.accel_scale - p.accel_cross_axis))));
  }
  if (!in.accel_bias_estimated) {
    accel_undetermined = true;
    note("accelerometer bias", largestShare(in.accel_bias_sigma_m_s2 * unscale,
                                            Eigen::Vector3d::Constant(p.accel_bias_m_s2)));
  }
  if (in.magnetometer_used && !in.hard_iron_estimated) {
    note("magnetometer hard iron",
         largestShare(in.hard_iron_sigma_t * unscale, Eigen::Vector3d::Constant(p.hard_iron_t)));
  }
  if (in.magnetometer_used && !in.soft_iron_estimated) {
    note("magnetometer soft iron",
         largestShare(flat(in.soft_iron_sigma) * unscale,
                      flat(Eigen::Matrix3d::Constant(p.soft_iron_cross) +
                           Eigen::Matrix3d::Identity() * (p.soft_iron_scale - p.soft_iron_cross))));
  }
  const Eigen::Vector3d& axis = !gyro_undetermined && accel_undetermined
                                    ? observability.perpendicular_to_gravity_imu
                                    : observability.least_excited_axis_imu;
  result->suggested_rotation_axis_imu = axis;
  if (gyro_undetermined || accel_undetermined) {
    char buffer[160];
    std::snprintf(
        buffer, sizeof(buffer),
        "next, rotate about the IMU axis (%.2f, %.2f, %.2f) (suggested_rotation_axis_imu)",
        axis.x(), axis.y(), axis.z());
    result->notes.push_back(buffer);
  }
}

}  // namespace camera_imu_alignment
