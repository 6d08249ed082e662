#include "camera_imu_alignment/optimal_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>

#include "camera_imu_alignment/closed_form_solver.h"
#include "camera_imu_alignment/rotation_math.h"
#include "camera_imu_alignment/solution_quality.h"

namespace camera_imu_alignment {
namespace {

constexpr double kChi3Median = 1.5382;  // median of |x| for x ~ N(0, I_3)

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  double m = v[mid];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + mid));
  return m;
}

double robustLoss(double r2, double cauchy_scale) {
  if (cauchy_scale <= 0.0) return r2;
  const double c2 = cauchy_scale * cauchy_scale;
  return c2 * std::log1p(r2 / c2);
}

double totalLoss(const RotationPairs& pairs, const std::vector<int>& idx, const Eigen::Matrix3d& X,
                 double cauchy_scale) {
  double cost = 0.0;
  for (int j : idx) cost += robustLoss(pairResidual(pairs[j], X).squaredNorm(), cauchy_scale);
  return cost;
}

std::vector<double> residualNorms(const RotationPairs& pairs, const std::vector<int>& idx,
                                  const Eigen::Matrix3d& X) {
  std::vector<double> r;
  r.reserve(idx.size());
  for (int j : idx) r.push_back(pairResidual(pairs[j], X).norm());
  return r;
}

/// Robust per-axis residual sigma (rad) and the inlier threshold on |r| (rad).
double inlierThreshold(const std::vector<double>& norms, const OptimalOptions& o) {
  const double sigma = median(norms) / kChi3Median;
  return std::max(deg2rad(o.inlier_min_deg), o.inlier_sigmas * sigma);
}

/// Two-pair minimal solution: the rotation taking the IMU rotation vectors onto the camera ones.
bool minimalSolution(const RotationPair& p1, const RotationPair& p2, Eigen::Matrix3d* X) {
  const Eigen::Vector3d a1 = logSO3(p1.A_cam), a2 = logSO3(p2.A_cam);
  const Eigen::Vector3d b1 = logSO3(p1.B_imu), b2 = logSO3(p2.B_imu);
  const Eigen::Matrix3d M = a1 * b1.transpose() + a2 * b2.transpose() +
                            a1.cross(a2) * b1.cross(b2).transpose();
  *X = projectToSO3(M);
  return X->allFinite();
}

/// Pairs whose rotation axis is well defined (not near 0 or 180 deg): usable as RANSAC samples.
bool goodSample(const RotationPair& p) {
  const double angle = rotationAngle(p.A_cam);
  return angle > deg2rad(3.0) && angle < deg2rad(170.0);
}

}  // namespace

int refineRotation(const RotationPairs& pairs, const std::vector<int>& indices,
                   double cauchy_scale_rad, int max_iterations, double step_tolerance_rad,
                   Eigen::Matrix3d* R_cam_imu, bool* converged) {
  *converged = false;
  Eigen::Matrix3d X = *R_cam_imu;
  double lambda = 0.0;  // Levenberg-Marquardt damping, used only after a failed Gauss-Newton step
  double cost = totalLoss(pairs, indices, X, cauchy_scale_rad);
  int it = 0;
  for (; it < max_iterations; ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (int j : indices) {
      const Eigen::Vector3d r = pairResidual(pairs[j], X);
      const Eigen::Matrix3d Jac = pairJacobian(pairs[j], r);
      double w = 1.0;
      if (cauchy_scale_rad > 0.0) w = 1.0 / (1.0 + r.squaredNorm() / (cauchy_scale_rad * cauchy_scale_rad));
      H.noalias() += w * Jac.transpose() * Jac;
      g.noalias() += w * Jac.transpose() * r;
    }
    bool accepted = false;
    for (int attempt = 0; attempt < 20 && !accepted; ++attempt) {
      const Eigen::Matrix3d H_damped = H + lambda * Eigen::Matrix3d::Identity();
      const Eigen::Vector3d delta = -H_damped.ldlt().solve(g);
      if (!delta.allFinite()) break;
      const Eigen::Matrix3d X_new = expSO3(delta) * X;
      const double new_cost = totalLoss(pairs, indices, X_new, cauchy_scale_rad);
      if (new_cost <= cost || delta.norm() < step_tolerance_rad) {
        accepted = true;
        X = X_new;
        cost = new_cost;
        lambda *= 0.1;
        if (lambda < 1e-12) lambda = 0.0;
        if (delta.norm() < step_tolerance_rad) {
          *converged = true;
        }
      } else {
        lambda = lambda == 0.0 ? 1e-4 * std::max(1e-9, H.trace() / 3.0) : 10.0 * lambda;
      }
    }
    if (!accepted) {
      // No decreasing step exists at machine precision: X is a (local) minimum.
      *converged = true;
      ++it;
      break;
    }
    if (*converged) {
      ++it;
      break;
    }
  }
  *R_cam_imu = X;
  return it;
}

OptimalResult solveOptimal(const RotationPairs& pairs, const OptimalOptions& o) {
  OptimalResult result;
  const int n = static_cast<int>(pairs.size());
  result.inlier.assign(n, true);
  result.rejection.assign(n, "");
  if (n == 0) return result;

  // 1. Angle gate.
  std::vector<int> gated;
  if (o.reject_outliers) {
    std::vector<double> diff(n);
    for (int j = 0; j < n; ++j) {
      diff[j] = std::abs(rotationAngle(pairs[j].A_cam) - rotationAngle(pairs[j].B_imu));
    }
    const double gate = std::max(deg2rad(o.angle_gate_min_deg), o.angle_gate_sigmas * 1.4826 * median(diff));
    for (int j = 0; j < n; ++j) {
      if (diff[j] > gate) {
        result.inlier[j] = false;
        result.rejection[j] = "camera and IMU rotation angles differ by " +
                              std::to_string(rad2deg(diff[j])) + " deg (gate " +
                              std::to_string(rad2deg(gate)) + " deg)";
      } else {
        gated.push_back(j);
      }
    }
  } else {
    for (int j = 0; j < n; ++j) gated.push_back(j);
  }
  if (gated.empty()) return result;

  // 2. Start: the paper's two-step; the closed form when it did not converge or fits worse.
  RotationPairs gated_pairs;
  gated_pairs.reserve(gated.size());
  for (int j : gated) gated_pairs.push_back(pairs[j]);
  result.two_step = solveTwoStep(gated_pairs, o.two_step);
  Eigen::Matrix3d X = result.two_step.R_cam_imu_left;
  result.start = "two_step";
  double start_median = result.two_step.valid ? median(residualNorms(pairs, gated, X)) : INFINITY;
  // A converged two-step lands within a fraction of the noise of the optimum; if its residuals are
  // large compared with the angle mismatch of the data (a noise proxy) or it did not converge, try the
  // closed form too and keep the better start.
  std::vector<double> angle_diff;
  for (int j : gated) angle_diff.push_back(std::abs(rotationAngle(pairs[j].A_cam) - rotationAngle(pairs[j].B_imu)));
  const double noise_proxy = median(angle_diff);
  if (!result.two_step.converged || gated.size() <= 4 ||
      result.two_step.left_right_disagreement_rad > 1e-3 ||
      start_median > 4.0 * noise_proxy + 1e-9) {
    if (auto cf = solveClosedForm(pairs, gated)) {
      const double cf_median = median(residualNorms(pairs, gated, *cf));
      if (cf_median < start_median) {
        X = *cf;
        start_median = cf_median;
        result.start = "closed_form";
      }
    }
  }
  if (!X.allFinite()) return result;

  // 3. Consensus.
  std::vector<int> inliers = gated;
  if (o.reject_outliers && gated.size() > 2) {
    auto classify = [&](const Eigen::Matrix3d& R, double threshold) {
      std::vector<int> in;
      for (int j : gated) {
        if (pairResidual(pairs[j], R).norm() <= threshold) in.push_back(j);
      }
      return in;
    };
    double threshold = inlierThreshold(residualNorms(pairs, gated, X), o);
    inliers = classify(X, threshold);
    if (inliers.size() < gated.size()) {
      // Suspected outliers: robust refit from the start, then RANSAC for a larger consensus.
      bool conv = false;
      const double scale = std::max(deg2rad(o.inlier_min_deg), threshold / o.inlier_sigmas);
      result.iterations += refineRotation(pairs, gated, scale, o.max_iterations, o.step_tolerance_rad, &X, &conv);
      threshold = inlierThreshold(residualNorms(pairs, gated, X), o);
      inliers = classify(X, threshold);
      std::vector<int> samples;
      for (int j : gated) {
        if (goodSample(pairs[j])) samples.push_back(j);
      }
      if (inliers.size() < gated.size() && samples.size() >= 2) {
        result.ransac_used = true;
        std::mt19937 rng(o.seed);
        std::uniform_int_distribution<size_t> pick(0, samples.size() - 1);
        for (int h = 0; h < o.ransac_hypotheses; ++h) {
          const int i1 = samples[pick(rng)], i2 = samples[pick(rng)];
          if (i1 == i2) continue;
          Eigen::Matrix3d X_h;
          if (!minimalSolution(pairs[i1], pairs[i2], &X_h)) continue;
          std::vector<int> in_h = classify(X_h, threshold);
          if (in_h.size() > inliers.size()) {
            bool c = false;
            result.iterations += refineRotation(pairs, in_h, 0.0, o.max_iterations, o.step_tolerance_rad, &X_h, &c);
            std::vector<int> in_refined = classify(X_h, threshold);
            if (in_refined.size() > inliers.size()) {
              inliers = std::move(in_refined);
              X = X_h;
            }
          }
        }
      }
    }
    if (inliers.size() < 2) inliers = gated;  // never fit fewer pairs than the minimum
  }

  // 4. Final least squares on the inliers.
  bool converged = false;
  result.iterations += refineRotation(pairs, inliers, 0.0, o.max_iterations, o.step_tolerance_rad, &X, &converged);
  result.converged = converged;
  result.R_cam_imu = X;
  result.valid = X.allFinite();

  std::vector<bool> is_inlier(n, false);
  for (int j : inliers) is_inlier[j] = true;
  for (int j : gated) {
    if (!is_inlier[j]) {
      result.inlier[j] = false;
      result.rejection[j] = "inconsistent with the consensus: residual " +
                            std::to_string(rad2deg(pairResidual(pairs[j], X).norm())) + " deg";
    }
  }
  return result;
}

}  // namespace camera_imu_alignment
