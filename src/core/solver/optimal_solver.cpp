#include "camera_imu_alignment/solver/optimal_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>

#include "camera_imu_alignment/solver/closed_form_solver.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/solver/solution_quality.h"

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

/// Each pair's A and B^-1 as unit quaternions, computed once per solve. A residual is
/// Log(q_A q_X q_B^-1 q_X^-1) (the same value as pairResidual), and q_X q_B^-1 q_X^-1 is q_B^-1
/// with its vector part rotated by X: one 3x3 product and one Hamilton product instead of three
/// 3x3 products and a matrix logarithm.
class PairQuaternions {
 public:
  explicit PairQuaternions(const RotationPairs& pairs) {
    a_.reserve(pairs.size());
    b_inv_.reserve(pairs.size());
    for (const auto& p : pairs) {
      a_.push_back(Eigen::Quaterniond(p.A_cam).normalized());
      b_inv_.push_back(Eigen::Quaterniond(p.B_imu).normalized().conjugate());
    }
  }
  /// r_j at the rotation matrix X.
  Eigen::Vector3d residual(int j, const Eigen::Matrix3d& X) const {
    const Eigen::Quaterniond& b = b_inv_[j];
    Eigen::Quaterniond x_b_x;  // q_X q_B^-1 q_X^-1
    x_b_x.w() = b.w();
    x_b_x.vec().noalias() = X * b.vec();
    return logQuaternion(a_[j] * x_b_x);
  }

 private:
  std::vector<Eigen::Quaterniond> a_, b_inv_;
};

/// Residual vectors r_j at X for the pairs in idx; returns the total loss.
double evaluateResiduals(const PairQuaternions& quats, const std::vector<int>& idx,
                         const Eigen::Matrix3d& X, double cauchy_scale,
                         std::vector<Eigen::Vector3d>* residuals) {
  residuals->resize(idx.size());
  double cost = 0.0;
  for (size_t i = 0; i < idx.size(); ++i) {
    (*residuals)[i] = quats.residual(idx[i], X);
    cost += robustLoss((*residuals)[i].squaredNorm(), cauchy_scale);
  }
  return cost;
}

std::vector<double> normsOf(const std::vector<Eigen::Vector3d>& residuals, size_t count) {
  if (residuals.size() != count) return std::vector<double>(count, INFINITY);
  std::vector<double> norms;
  norms.reserve(count);
  for (const auto& r : residuals) norms.push_back(r.norm());
  return norms;
}

std::vector<double> residualNorms(const PairQuaternions& quats, const std::vector<int>& idx,
                                  const Eigen::Matrix3d& X) {
  std::vector<double> r;
  r.reserve(idx.size());
  for (int j : idx) r.push_back(quats.residual(j, X).norm());
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
  const Eigen::Matrix3d M =
      a1 * b1.transpose() + a2 * b2.transpose() + a1.cross(a2) * b1.cross(b2).transpose();
  *X = projectToSO3(M);
  return X->allFinite();
}

/// Pairs whose rotation axis is well defined (not near 0 or 180 deg): usable as RANSAC samples.
bool goodSample(const RotationPair& p) {
  const double angle = rotationAngle(p.A_cam);
  return angle > deg2rad(3.0) && angle < deg2rad(170.0);
}

}  // namespace

namespace {

int refine(const RotationPairs& pairs, const PairQuaternions& quats,
           const std::vector<int>& indices, const RefineSettings& settings,
           Eigen::Matrix3d* R_cam_imu, bool* converged,
           std::vector<Eigen::Vector3d>* residuals_io = nullptr) {
  *converged = false;
  Eigen::Matrix3d X = *R_cam_imu;
  const double scale = settings.cauchy_scale_rad;
  double lambda = 0.0;  // Levenberg-Marquardt damping, used only after a failed Gauss-Newton step
  std::vector<Eigen::Vector3d> own_residuals, trial_residuals;
  std::vector<Eigen::Vector3d>& residuals = residuals_io ? *residuals_io : own_residuals;
  double cost = 0.0;
  if (residuals.size() == indices.size()) {
    for (const auto& r : residuals) cost += robustLoss(r.squaredNorm(), scale);
  } else {
    cost = evaluateResiduals(quats, indices, X, scale, &residuals);
  }
  const double c2 = scale * scale;
  const double dof = std::max(1.0, 3.0 * indices.size() - 3.0);
  int it = 0;
  while (it < settings.max_iterations && !*converged) {
    ++it;
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < indices.size(); ++i) {
      const Eigen::Vector3d& r = residuals[i];
      const Eigen::Matrix3d Jac = pairJacobian(pairs[indices[i]], r);
      const double w = scale > 0.0 ? 1.0 / (1.0 + r.squaredNorm() / c2) : 1.0;
      H.noalias() += w * Jac.transpose() * Jac;
      g.noalias() += w * Jac.transpose() * r;
    }
    // Tolerance on the step: absolute, or relative to the 1-sigma sqrt(s2 tr(H^-1)) (squared loss).
    double tolerance = settings.step_tolerance_rad;
    if (scale <= 0.0) {
      const double sigma = std::sqrt(cost / dof * H.inverse().trace());
      if (std::isfinite(sigma))
        tolerance = std::max(tolerance, settings.relative_step_tolerance * sigma);
    }
    bool accepted = false;
    for (int attempt = 0; attempt < 20 && !accepted; ++attempt) {
      const Eigen::Vector3d delta = -(H + lambda * Eigen::Matrix3d::Identity()).ldlt().solve(g);
      if (!delta.allFinite()) break;
      const Eigen::Matrix3d X_new = expSO3(delta) * X;
      const double new_cost = evaluateResiduals(quats, indices, X_new, scale, &trial_residuals);
      const bool small_step = delta.norm() < tolerance;
      if (new_cost <= cost || small_step) {
        accepted = true;
        X = X_new;
        cost = new_cost;
        residuals.swap(trial_residuals);
        lambda = lambda < 1e-12 ? 0.0 : 0.1 * lambda;
        *converged = small_step;
      } else {
        lambda = lambda == 0.0 ? 1e-4 * std::max(1e-9, H.trace() / 3.0) : 10.0 * lambda;
      }
    }
    // No decreasing step at machine precision: X is a (local) minimum.
    if (!accepted) *converged = true;
  }
  *R_cam_imu = X;
  return it;
}

}  // namespace

int refineRotation(const RotationPairs& pairs, const std::vector<int>& indices,
                   const RefineSettings& settings, Eigen::Matrix3d* R_cam_imu, bool* converged,
                   std::vector<Eigen::Vector3d>* residuals) {
  return refine(pairs, PairQuaternions(pairs), indices, settings, R_cam_imu, converged, residuals);
}

namespace {

RefineSettings refineSettings(const OptimalOptions& o, double cauchy_scale) {
  RefineSettings s;
  s.cauchy_scale_rad = cauchy_scale;
  s.max_iterations = o.max_iterations;
  s.step_tolerance_rad = o.step_tolerance_rad;
  return s;
}

/// Step 1, the angle gate: camera and IMU rotation angles of a pair must agree. Returns the pairs
/// that pass; fills result.pair_angles_rad (kept for the quality diagnostics), marks the others
/// as rejected and returns each pair's angle difference in `angle_diff`.
std::vector<int> angleGate(const RotationPairs& pairs, const OptimalOptions& o,
                           OptimalResult* result, std::vector<double>* angle_diff) {
  const int n = static_cast<int>(pairs.size());
  angle_diff->resize(n);
  result->pair_angles_rad.resize(n);
  for (int j = 0; j < n; ++j) {
    Eigen::Vector2d& angles = result->pair_angles_rad[j];
    angles << rotationAngle(pairs[j].A_cam), rotationAngle(pairs[j].B_imu);
    (*angle_diff)[j] = std::abs(angles.x() - angles.y());
  }
  std::vector<int> gated;
  gated.reserve(n);
  const double gate =
      std::max(deg2rad(o.angle_gate_min_deg), o.angle_gate_sigmas * 1.4826 * median(*angle_diff));
  for (int j = 0; j < n; ++j) {
    if (!o.reject_outliers || (*angle_diff)[j] <= gate) {
      gated.push_back(j);
      continue;
    }
    result->inlier[j] = false;
    result->rejection[j] = "camera and IMU rotation angles differ by " +
                           std::to_string(rad2deg((*angle_diff)[j])) + " deg (gate " +
                           std::to_string(rad2deg(gate)) + " deg)";
  }
  return gated;
}

/// Step 2, the start: the paper's two-step on the gated pairs; the closed form instead when the
/// two-step did not converge, its iterates disagree, there are few pairs or it fits clearly worse
/// than the noise suggests (and the closed form fits better). Sets result->two_step and
/// result->start; returns the start with its residuals (gated order) in `start_residuals`.
Eigen::Matrix3d chooseStart(const RotationPairs& pairs, const PairQuaternions& quats,
                            const std::vector<int>& gated, const std::vector<double>& angle_diff,
                            const OptimalOptions& o, OptimalResult* result,
                            std::vector<Eigen::Vector3d>* start_residuals) {
  RotationPairs gated_pairs;
  gated_pairs.reserve(gated.size());
  for (int j : gated) gated_pairs.push_back(pairs[j]);
  result->two_step = solveTwoStep(gated_pairs, o.two_step);
  Eigen::Matrix3d X = result->two_step.R_cam_imu_left;
  result->start = "two_step";
  start_residuals->clear();
  if (result->two_step.valid) evaluateResiduals(quats, gated, X, 0.0, start_residuals);
  std::vector<double> start_norms = normsOf(*start_residuals, gated.size());
  const double start_median = median(start_norms);
  std::vector<double> gated_angle_diff;
  gated_angle_diff.reserve(gated.size());
  for (int j : gated) gated_angle_diff.push_back(angle_diff[j]);
  const double noise_proxy = median(gated_angle_diff);
  if (!result->two_step.converged || gated.size() <= 4 ||
      result->two_step.left_right_disagreement_rad > deg2rad(2.0) ||
      start_median > 4.0 * noise_proxy + 1e-9) {
    if (auto cf = solveClosedForm(pairs, gated)) {
      std::vector<Eigen::Vector3d> cf_residuals;
      evaluateResiduals(quats, gated, *cf, 0.0, &cf_residuals);
      std::vector<double> cf_norms = normsOf(cf_residuals, gated.size());
      if (median(cf_norms) < start_median) {
        X = *cf;
        start_residuals->swap(cf_residuals);
        result->start = "closed_form";
      }
    }
  }
  return X;
}

/// Pairs of `gated` whose residual norm (same order) is within the threshold.
std::vector<int> selectWithin(const std::vector<int>& gated, const std::vector<double>& norms,
                              double threshold) {
  std::vector<int> in;
  in.reserve(gated.size());
  for (size_t i = 0; i < gated.size(); ++i) {
    if (norms[i] <= threshold) in.push_back(gated[i]);
  }
  return in;
}

/// RANSAC over two-pair minimal solutions for a larger consensus than `*inliers` at `threshold`;
/// replaces `*inliers` and `*X` when it finds one. Stops adaptively: enough hypotheses to draw an
/// all-inlier pair with 99.9% probability at the current inlier ratio w: log(0.001)/log(1 - w^2).
void ransacConsensus(const RotationPairs& pairs, const PairQuaternions& quats,
                     const std::vector<int>& gated, double threshold, const OptimalOptions& o,
                     OptimalResult* result, std::vector<int>* inliers, Eigen::Matrix3d* X) {
  std::vector<int> samples;
  for (int j : gated) {
    if (goodSample(pairs[j])) samples.push_back(j);
  }
  if (inliers->size() >= gated.size() || samples.size() < 2) return;
  result->ransac_used = true;
  std::mt19937 rng(o.seed);
  std::uniform_int_distribution<size_t> pick(0, samples.size() - 1);
  const auto needed = [&]() {
    const double w = static_cast<double>(inliers->size()) / gated.size();
    return w >= 1.0 ? 0.0 : std::log(1e-3) / std::log(std::max(1e-12, 1.0 - w * w));
  };
  const auto classify = [&](const Eigen::Matrix3d& R) {
    return selectWithin(gated, residualNorms(quats, gated, R), threshold);
  };
  for (int h = 0; h < o.ransac_hypotheses && h < needed(); ++h) {
    const int i1 = samples[pick(rng)], i2 = samples[pick(rng)];
    if (i1 == i2) continue;
    Eigen::Matrix3d X_h;
    if (!minimalSolution(pairs[i1], pairs[i2], &X_h)) continue;
    std::vector<int> in_h = classify(X_h);
    if (in_h.size() > inliers->size()) {
      bool c = false;
      result->iterations += refine(pairs, quats, in_h, refineSettings(o, 0.0), &X_h, &c);
      std::vector<int> in_refined = classify(X_h);
      if (in_refined.size() > inliers->size()) {
        *inliers = std::move(in_refined);
        *X = X_h;
      }
    }
  }
}

/// Step 4: the result's residuals for every pair and the rejection reasons of the gated pairs
/// that are not inliers.
void recordResiduals(const RotationPairs& pairs, const std::vector<int>& gated,
                     const std::vector<int>& inliers,
                     const std::vector<Eigen::Vector3d>& inlier_residuals, OptimalResult* result) {
  const int n = static_cast<int>(pairs.size());
  const Eigen::Matrix3d& X = result->R_cam_imu;
  result->residuals.assign(n, Eigen::Vector3d::Zero());
  for (size_t i = 0; i < inliers.size(); ++i) result->residuals[inliers[i]] = inlier_residuals[i];
  std::vector<bool> is_inlier(n, false);
  for (int j : inliers) is_inlier[j] = true;
  for (int j = 0; j < n; ++j) {
    if (!result->inlier[j]) result->residuals[j] = pairResidual(pairs[j], X);
  }
  for (int j : gated) {
    if (!is_inlier[j]) {
      result->inlier[j] = false;
      result->residuals[j] = pairResidual(pairs[j], X);
      result->rejection[j] = "inconsistent with the consensus: residual " +
                             std::to_string(rad2deg(result->residuals[j].norm())) + " deg";
    }
  }
}

}  // namespace

OptimalResult solveOptimal(const RotationPairs& pairs, const OptimalOptions& o) {
  OptimalResult result;
  const int n = static_cast<int>(pairs.size());
  result.inlier.assign(n, true);
  result.rejection.assign(n, "");
  if (n == 0) return result;

  std::vector<double> angle_diff;
  const std::vector<int> gated = angleGate(pairs, o, &result, &angle_diff);
  if (gated.empty()) return result;

  const PairQuaternions quats(pairs);
  std::vector<Eigen::Vector3d> residuals;
  Eigen::Matrix3d X = chooseStart(pairs, quats, gated, angle_diff, o, &result, &residuals);
  if (!X.allFinite()) return result;
  const Eigen::Matrix3d X_start = X;

  // 3. Least squares on the gated pairs, then the consensus test at that fit (testing at the start
  //    would flag good pairs: the two-step's bias inflates some residuals).
  bool converged = false;
  result.iterations +=
      refine(pairs, quats, gated, refineSettings(o, 0.0), &X, &converged, &residuals);
  std::vector<int> inliers = gated;
  if (o.reject_outliers && gated.size() > 2) {
    double threshold = inlierThreshold(normsOf(residuals, gated.size()), o);
    inliers = selectWithin(gated, normsOf(residuals, gated.size()), threshold);
    if (inliers.size() < gated.size()) {
      // Suspected outliers: the least-squares fit may have been dragged by them. Robust (Cauchy)
      // refit from the start, then RANSAC for a larger consensus.
      X = X_start;
      bool conv = false;
      const double scale = std::max(deg2rad(o.inlier_min_deg), threshold / o.inlier_sigmas);
      result.iterations += refine(pairs, quats, gated, refineSettings(o, scale), &X, &conv);
      const std::vector<double> robust_norms = residualNorms(quats, gated, X);
      threshold = inlierThreshold(robust_norms, o);
      inliers = selectWithin(gated, robust_norms, threshold);
      ransacConsensus(pairs, quats, gated, threshold, o, &result, &inliers, &X);
      if (inliers.size() < 2) inliers = gated;  // never fit fewer pairs than the minimum
      // 4. Final least squares on the inliers.
      residuals.clear();
      result.iterations +=
          refine(pairs, quats, inliers, refineSettings(o, 0.0), &X, &converged, &residuals);
    }
  }
  result.converged = converged;
  result.R_cam_imu = X;
  result.valid = X.allFinite();
  recordResiduals(pairs, gated, inliers, residuals, &result);
  return result;
}

}  // namespace camera_imu_alignment
