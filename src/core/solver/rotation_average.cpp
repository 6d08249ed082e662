// Robust rotation averaging: geodesic L1 (Weiszfeld) then L2 over the inliers.
#include "camera_imu_alignment/solver/rotation_average.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

namespace {

/// Chordal L2 mean: projection of the arithmetic mean onto SO(3).
Eigen::Matrix3d chordalMean(const std::vector<Eigen::Matrix3d>& rotations) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const auto& R : rotations) sum += R;
  return projectToSO3(sum);
}

/// Geodesic L2 mean by Gauss-Newton in the tangent space.
Eigen::Matrix3d geodesicMean(const std::vector<Eigen::Matrix3d>& rotations, Eigen::Matrix3d mean) {
  for (int it = 0; it < 20; ++it) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (const auto& R : rotations) step += logSO3(mean.transpose() * R);
    step /= static_cast<double>(rotations.size());
    mean = projectToSO3(mean * expSO3(step));
    if (step.norm() < 1e-12) break;
  }
  return mean;
}

}  // namespace

RotationAverage averageRotations(const std::vector<Eigen::Matrix3d>& rotations,
                                 double outlier_deg) {
  RotationAverage out;
  std::vector<Eigen::Matrix3d> valid;
  for (const auto& R : rotations) {
    if (R.allFinite() && isRotationMatrix(R, 1e-4)) valid.push_back(R);
  }
  out.num_outliers = static_cast<int>(rotations.size() - valid.size());
  if (valid.empty()) return out;

  // Start: the input rotation with the smallest sum of distances to the others (a medoid; robust
  // to a minority of outliers, unlike the chordal mean).
  std::size_t best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < valid.size(); ++i) {
    double cost = 0.0;
    for (const auto& R : valid) cost += geodesicDistance(valid[i], R);
    if (cost < best_cost) best_cost = cost, best = i;
  }
  Eigen::Matrix3d median = valid[best];
  // Weiszfeld on SO(3): geodesic L1 mean.
  for (int it = 0; it < 50; ++it) {
    Eigen::Vector3d num = Eigen::Vector3d::Zero();
    double den = 0.0;
    for (const auto& R : valid) {
      const Eigen::Vector3d v = logSO3(median.transpose() * R);
      const double d = std::max(v.norm(), 1e-9);
      num += v / d;
      den += 1.0 / d;
    }
    const Eigen::Vector3d step = num / den;
    median = projectToSO3(median * expSO3(step));
    if (step.norm() < 1e-12) break;
  }

  const double limit = deg2rad(outlier_deg);
  std::vector<Eigen::Matrix3d> inliers;
  for (const auto& R : valid) {
    if (geodesicDistance(median, R) <= limit) inliers.push_back(R);
  }
  out.num_outliers += static_cast<int>(valid.size() - inliers.size());
  out.num_inliers = static_cast<int>(inliers.size());
  if (inliers.empty()) {
    out.mean = median;
    return out;
  }
  out.mean = geodesicMean(inliers, chordalMean(inliers));
  double sq = 0.0;
  for (const auto& R : inliers) {
    const double d = rad2deg(geodesicDistance(out.mean, R));
    sq += d * d;
    out.spread_max_deg = std::max(out.spread_max_deg, d);
  }
  out.spread_rms_deg = std::sqrt(sq / inliers.size());
  return out;
}

}  // namespace camera_imu_alignment
