// The camera's noise as the recording shows it (camera_excess.h).
#include "camera_excess.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "joint_state.h"

namespace camera_imu_alignment {
namespace joint {
namespace {

/// Median of chi-square(3): the median rest's camera chi-square when its covariance is right.
constexpr double kChiSquare3Median = 2.366;

/// The isotropic variance that brings the median chi-square of the residuals under their
/// covariances plus it to chi-square(3)'s median; 0 when their total passes its test at `level`
/// or the median already fits.
double excessVariance(const std::vector<Eigen::Vector3d>& residuals,
                      const std::vector<Eigen::Matrix3d>& covariances, double level) {
  if (residuals.size() < 3) return 0.0;
  const auto chi2s = [&](double variance) {
    std::vector<double> out;
    for (size_t i = 0; i < residuals.size(); ++i) {
      const Eigen::Matrix3d covariance = covariances[i] + variance * Eigen::Matrix3d::Identity();
      out.push_back(residuals[i].dot(covariance.ldlt().solve(residuals[i])));
    }
    return out;
  };
  const auto median = [](std::vector<double> values) {
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    return values[values.size() / 2];
  };
  const std::vector<double> at_stated = chi2s(0.0);
  double total = 0.0;
  for (double chi2 : at_stated) total += chi2;
  const int dof = 3 * static_cast<int>(residuals.size());
  if (!(chiSquareUpperTail(total, dof) < level)) return 0.0;
  if (!(median(at_stated) > kChiSquare3Median)) return 0.0;
  // The median chi-square falls as the variance grows: bisection in log(variance), from a
  // nanoradian to a radian.
  double low = std::log(1e-18), high = 0.0;
  for (int i = 0; i < 60; ++i) {
    const double middle = 0.5 * (low + high);
    (median(chi2s(std::exp(middle))) > kChiSquare3Median ? low : high) = middle;
  }
  return std::exp(high);
}

}  // namespace

double cameraExcessVariance(const JointProblem& problem, const JointResult& result,
                            const JointSettings& settings) {
  std::vector<Eigen::Vector3d> residuals;
  std::vector<Eigen::Matrix3d> covariances;
  const double floor2 = settings.camera_sigma_floor_rad * settings.camera_sigma_floor_rad;
  for (size_t k = 0; k < problem.poses.size() && k < result.camera_residual_rad.size(); ++k) {
    const JointPose& pose = problem.poses[k];
    if (!pose.at_rest || !pose.camera_absolute) continue;
    residuals.push_back(result.camera_residual_rad[k]);
    covariances.push_back(pose.cov_cam_rad2 + floor2 * Eigen::Matrix3d::Identity());
  }
  return excessVariance(residuals, covariances, settings.camera_excess_level);
}

double cameraLinkExcessVariance(const JointProblem& problem, const JointResult& result,
                                const JointSettings& settings) {
  std::vector<Eigen::Vector3d> residuals;
  std::vector<Eigen::Matrix3d> covariances;
  const double floor2 = settings.camera_sigma_floor_rad * settings.camera_sigma_floor_rad;
  for (size_t j = 0; j < problem.camera_links.size() && j < result.camera_link_residual_rad.size();
       ++j) {
    residuals.push_back(result.camera_link_residual_rad[j]);
    covariances.push_back(problem.camera_links[j].cov_rad2 + floor2 * Eigen::Matrix3d::Identity());
  }
  return excessVariance(residuals, covariances, settings.camera_excess_level);
}

}  // namespace joint

void addCameraLinkExcessVariance(double variance_rad2, JointProblem* problem) {
  if (!(variance_rad2 > 0.0)) return;
  for (CameraLink& link : problem->camera_links) {
    link.cov_rad2 += variance_rad2 * Eigen::Matrix3d::Identity();
  }
}

void addCameraExcessVariance(double variance_rad2, JointProblem* problem) {
  if (!(variance_rad2 > 0.0)) return;
  for (JointPose& pose : problem->poses) {
    if (pose.at_rest && pose.camera_absolute) {
      pose.cov_cam_rad2 += variance_rad2 * Eigen::Matrix3d::Identity();
    }
  }
}

}  // namespace camera_imu_alignment
