// Shared helpers of the joint estimator's tests (test_joint_estimator*.cpp).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "joint_problem_simulation.h"

namespace camera_imu_alignment {
namespace test {

inline double errorDeg(const JointResult& result, const JointSimulation& sim) {
  return rad2deg(rotationError(result.R_cam_imu, sim.R_cam_imu).norm());
}

inline bool hasNote(const JointResult& result, const std::string& text) {
  for (const std::string& note : result.notes) {
    if (note.find(text) != std::string::npos) return true;
  }
  return false;
}

inline std::string allNotes(const JointResult& result) {
  std::string out;
  for (const std::string& note : result.notes) out += "\n  " + note;
  return out;
}

/// Every number of the result is finite (a failed solve included).
inline void expectFinite(const JointResult& r) {
  EXPECT_TRUE(r.R_cam_imu.allFinite());
  EXPECT_TRUE(r.covariance_rad2.allFinite());
  EXPECT_TRUE(r.std_dev_deg.allFinite());
  EXPECT_TRUE(std::isfinite(r.chi2));
  EXPECT_TRUE(std::isfinite(r.chi2_p_value));
  EXPECT_TRUE(r.suggested_rotation_axis_imu.allFinite());
  for (double v : r.pose_residual_norm) EXPECT_TRUE(std::isfinite(v));
  EXPECT_TRUE(r.intrinsics.gyro_matrix.allFinite());
  EXPECT_TRUE(r.intrinsics.accel_matrix.allFinite());
  EXPECT_TRUE(r.intrinsics.hard_iron_t.allFinite());
}

inline double rms(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return v.empty() ? 0.0 : std::sqrt(sum / v.size());
}

inline double fractionWithin(const std::vector<double>& v, double bound) {
  const auto inside =
      std::count_if(v.begin(), v.end(), [&](double x) { return std::abs(x) <= bound; });
  return v.empty() ? 0.0 : static_cast<double>(inside) / v.size();
}

inline JointResult solveSimulation(const JointSimulation& sim, const JointSettings& settings = {},
                                   double initial_error_deg = 1.0, uint64_t seed = 7) {
  return JointEstimator(settings).solve(
      sim.problem, perturbedRotation(sim.R_cam_imu, deg2rad(initial_error_deg), seed));
}

/// Largest per-axis error of R_cam_imu in sigma units.
inline double maxNormalisedError(const JointResult& r, const JointSimulation& sim) {
  const Eigen::Vector3d error = rotationError(r.R_cam_imu, sim.R_cam_imu);
  double worst = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    worst = std::max(worst, std::abs(error(axis)) / std::sqrt(r.covariance_rad2(axis, axis)));
  }
  return worst;
}

/// Motions about IMU z of 40-80 deg (all one way: the heading goes round) and one of `other_deg`
/// about IMU x.
inline std::vector<Eigen::Vector3d> motionsAboutZ(int count, double other_deg) {
  std::vector<Eigen::Vector3d> motions;
  for (int i = 0; i < count; ++i) {
    const double angle = deg2rad(40.0 + 40.0 * ((i * 7) % 5) / 4.0);
    motions.push_back(angle * Eigen::Vector3d::UnitZ());
  }
  motions[count / 2] = deg2rad(other_deg) * Eigen::Vector3d::UnitX();
  return motions;
}

}  // namespace test
}  // namespace camera_imu_alignment
