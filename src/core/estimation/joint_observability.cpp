#include "camera_imu_alignment/estimation/joint_observability.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>

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

JointObservability decideObservability(const JointProblem& problem, const GyroExcitation& gyro,
                                       const JointSettings& settings) {
  JointObservability out;
  const std::string held = settings.pin_unexcited_parameters
                               ? "held at its prior"
                               : "held at its prior (with its prior uncertainty)";

  // Gyro: column j of T_g multiplies the rate about IMU axis j.
  out.gyro_axis_rotation_deg = gyro.accumulated_abs_angle_rad * (180.0 / kPi);
  if (!gyro.has_segments) {
    out.notes.push_back(
        "no gyro segments: the gyro model is not estimated (accelerometer, magnetometer and camera "
        "only)");
  } else {
    for (int axis = 0; axis < 3; ++axis) {
      out.gyro_column_estimated[axis] =
          out.gyro_axis_rotation_deg(axis) >= settings.min_gyro_axis_rotation_deg;
      if (!out.gyro_column_estimated[axis]) {
        const std::string name = kAxisNames[axis];
        out.notes.push_back("gyro scale " + name + " and its cross-axis terms " + held + ": " +
                            format("%.1f", out.gyro_axis_rotation_deg(axis), 0) +
                            " deg accumulated about IMU " + name + "; rotate about IMU " + name +
                            format(" by %.0f deg or more", settings.min_gyro_axis_rotation_deg, 0));
      }
    }
  }

  // Accelerometer: gravity seen in several directions.
  std::vector<Eigen::Vector3d> gravity_directions;
  Eigen::Vector3d mean_gravity = Eigen::Vector3d::Zero();
  for (const JointPose& pose : problem.poses) {
    gravity_directions.push_back(pose.accel_mean_m_s2.normalized());
    mean_gravity += gravity_directions.back();
  }
  mean_gravity = mean_gravity.norm() > 1e-9 ? mean_gravity.normalized() : Eigen::Vector3d::UnitZ();
  out.gravity_coverage = directionCoverage(gravity_directions);
  out.gravity_spread = directionSpread(gravity_directions);
  out.accel_bias_estimated = out.gravity_coverage >= settings.min_gravity_coverage_bias;
  out.accel_matrix_estimated = out.gravity_spread >= settings.min_gravity_spread_matrix;
  if (!out.accel_bias_estimated) {
    out.notes.push_back("accelerometer bias " + held +
                        format(": gravity direction coverage %.3f < %.3f", out.gravity_coverage,
                               settings.min_gravity_coverage_bias) +
                        "; tilt the rig much further between poses (on its sides, upside down)");
  }
  if (!out.accel_matrix_estimated) {
    out.notes.push_back("accelerometer scale and non-orthogonality " + held +
                        format(": gravity direction spread %.3f < %.3f", out.gravity_spread,
                               settings.min_gravity_spread_matrix) +
                        " (needs 4 or more poses whose gravity directions are not in one plane); "
                        "show gravity along "
                        "each IMU axis, both ways");
  }

  // Magnetometer: enough distinct orientations with a usable field.
  std::vector<Eigen::Vector3d> mag_directions;
  for (const JointPose& pose : problem.poses) {
    if (pose.mag_mean_t) mag_directions.push_back(pose.mag_mean_t->normalized());
  }
  out.usable_mag_poses = static_cast<int>(mag_directions.size());
  out.mag_coverage = directionCoverage(mag_directions);
  out.mag_spread = directionSpread(mag_directions);
  const bool hard_iron_excited = out.usable_mag_poses >= settings.min_mag_poses_hard_iron &&
                                 out.mag_coverage >= settings.min_mag_coverage_hard_iron;
  const bool soft_iron_excited = out.usable_mag_poses >= settings.min_mag_poses_soft_iron &&
                                 out.mag_spread >= settings.min_mag_spread_soft_iron;
  switch (settings.use_magnetometer) {
    case MagnetometerUse::kOff:
      out.magnetometer_used = false;
      if (out.usable_mag_poses > 0) out.notes.push_back("magnetometer not used (settings)");
      break;
    case MagnetometerUse::kOn:
      out.magnetometer_used = out.usable_mag_poses > 0;
      break;
    case MagnetometerUse::kAuto:
      out.magnetometer_used = hard_iron_excited;
      if (out.usable_mag_poses > 0 && !hard_iron_excited) {
        out.notes.push_back(
            format("magnetometer not used: its hard iron is not excited (%.0f usable poses, "
                   "coverage %.3f; ",
                   out.usable_mag_poses, out.mag_coverage) +
            format("needs %.0f and %.2f)", settings.min_mag_poses_hard_iron,
                   settings.min_mag_coverage_hard_iron));
      }
      break;
  }
  if (out.magnetometer_used) {
    out.hard_iron_estimated = hard_iron_excited;
    out.soft_iron_estimated = soft_iron_excited;
    if (!hard_iron_excited) {
      out.notes.push_back("magnetometer hard iron " + held +
                          " (magnetometer forced on with too few or too similar orientations)");
    }
    if (!soft_iron_excited) {
      out.notes.push_back(
          "magnetometer soft iron " + held +
          format(": %.0f usable poses, spread %.3f", out.usable_mag_poses, out.mag_spread) +
          format(" (needs %.0f and %.2f); more distinct orientations with a usable "
                 "field",
                 settings.min_mag_poses_soft_iron, settings.min_mag_spread_soft_iron));
    }
  }

  // The rotation axis that would add the most: the least-excited gyro axis when a column is held,
  // else (accelerometer held) one perpendicular to the mean gravity direction, else the least
  // excited axis overall.
  Eigen::Vector3d least_excited = perpendicularAxis(mean_gravity, gyro);
  if (gyro.has_segments) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(gyro.excitation_rad);
    if (solver.info() == Eigen::Success) least_excited = solver.eigenvectors().col(0).normalized();
  }
  const bool gyro_held =
      gyro.has_segments && !(out.gyro_column_estimated[0] && out.gyro_column_estimated[1] &&
                             out.gyro_column_estimated[2]);
  const bool accel_held = !out.accel_bias_estimated || !out.accel_matrix_estimated;
  if (!gyro_held && accel_held) {
    out.suggested_rotation_axis_imu = perpendicularAxis(mean_gravity, gyro);
  } else {
    out.suggested_rotation_axis_imu = least_excited;
  }
  if (!out.suggested_rotation_axis_imu.allFinite() ||
      out.suggested_rotation_axis_imu.norm() < 0.5) {
    out.suggested_rotation_axis_imu = Eigen::Vector3d::UnitX();
  }
  if (gyro_held || accel_held) {
    const Eigen::Vector3d& a = out.suggested_rotation_axis_imu;
    char buffer[160];
    std::snprintf(
        buffer, sizeof(buffer),
        "next, rotate about the IMU axis (%.2f, %.2f, %.2f) (suggested_rotation_axis_imu)", a.x(),
        a.y(), a.z());
    out.notes.push_back(buffer);
  }
  return out;
}

}  // namespace camera_imu_alignment
