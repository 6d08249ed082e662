// Rotation-only and general two-view models of matched bearings: RANSAC, Gauss-Newton refinement
// on first-order geometric distances in pixels, covariance and GRIC (scene_geometry.h).
#include "scene_geometry.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <random>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace scene_geometry {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::VectorXd;

// Chi-square quantiles: medians (for the robust sigma) and 99.9 % bounds (inlier re-selection)
// for 1 and 2 degrees of freedom.
constexpr double kChi2Median[3] = {0, 0.4549, 1.3863};
constexpr double kChi2Bound999[3] = {0, 10.828, 13.816};
constexpr double kMinSigmaPx = 1e-3;  // noise-free data: keep the covariance invertible
constexpr int kRansacMaxIterations = 1000;
constexpr double kRansacConfidence = 0.999;
constexpr int kRefinementRounds = 4;
/// Translation hypotheses (pairs of matches) with the rotation held.
constexpr int kHeldRotationIterations = 500;
constexpr double kLeverageGate = 0.2;  // a match's leverage (hat-matrix trace) to be cross-checked
/// Triangulated depths (in baselines) up to which cheirality is judged in recoverPose.
constexpr double kCheiralityMaxDepth = 1e6;
constexpr double kCauchyScale2 = 2.385 * 2.385;  // Cauchy loss scale (per coordinate, in sigmas)

/// The model's state: the rotation and (general model) the translation direction.
struct State {
  Matrix3d R = Matrix3d::Identity();
  Vector3d t = Vector3d::UnitZ();
};

/// Two unit vectors spanning the plane orthogonal to the unit vector t.
Eigen::Matrix<double, 3, 2> tangentBasis(const Vector3d& t) {
  const Vector3d seed = std::abs(t.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = t.cross(seed).normalized();
  B.col(1) = t.cross(B.col(0));
  return B;
}

/// step: 3 (rotation, right perturbation) or 5 (and the translation direction's tangent).
State perturb(const State& s, const VectorXd& step) {
  State out = s;
  out.R = s.R * expSO3(step.head<3>());
  if (step.size() == 5) out.t = (s.t + tangentBasis(s.t) * step.tail<2>()).normalized();
  return out;
}

/// Rotation-only distance of one match: the transfer error of `to` into the `from` image
/// (pixels), whitened by the noise of both images (first order), so that its two components
/// have the per-coordinate noise's variance. A point mapped behind the camera gets a large
/// finite distance.
Vector2d rotationResidual(const State& s, const Vector3d& a, const Vector3d& b, double fx,
                          double fy) {
  const Vector3d p = s.R * (b / b.z());  // the `to` point's normalised coordinates, rotated
  if (p.z() <= 1e-9) return Vector2d(1e6, 1e6);
  const Vector2d eps((p.x() / p.z() - a.x() / a.z()) * fx, (p.y() / p.z() - a.y() / a.z()) * fy);
  Eigen::Matrix<double, 2, 3> dproj;
  dproj << 1 / p.z(), 0, -p.x() / (p.z() * p.z()), 0, 1 / p.z(), -p.y() / (p.z() * p.z());
  Eigen::Matrix2d M = dproj * s.R.leftCols<2>();  // d transfer / d to-point (normalised)
  M.row(0) *= fx;
  M.row(1) *= fy;
  M.col(0) /= fx;
  M.col(1) /= fy;
  const Eigen::Matrix2d C = Eigen::Matrix2d::Identity() + M * M.transpose();
  return C.llt().matrixL().solve(eps);
}

/// General-model distance of one match: the Sampson distance to the epipolar constraint
/// x_from^T E x_to = 0 with E = [t]x R (pixels).
double sampsonResidual(const Matrix3d& E, const Vector3d& a, const Vector3d& b, double fx,
                       double fy) {
  const Vector3d xa = a / a.z(), xb = b / b.z();
  const Vector3d Eb = E * xb, Ea = E.transpose() * xa;
  const double g2 = std::pow(Eb.x() / fx, 2) + std::pow(Eb.y() / fy, 2) + std::pow(Ea.x() / fx, 2) +
                    std::pow(Ea.y() / fy, 2);
  if (!(g2 > 1e-30)) return 0;
  return xa.dot(Eb) / std::sqrt(g2);
}

/// Per-match weights of an iteratively reweighted fit (one per entry of `idx`); empty: all 1.
using Weights = std::vector<double>;

/// General model: whether the match's scene point, triangulated from both rays (least squares on
/// depth_from a = depth_to R b + t), lies in front of both cameras. A mismatch near its epipolar
/// line that the epipolar distance cannot reject is behind a camera about half the time.
bool inFrontOfBoth(const State& s, const Vector3d& a, const Vector3d& b) {
  Eigen::Matrix<double, 3, 2> A;
  A << a, -(s.R * b);
  const Eigen::Vector2d depths = (A.transpose() * A).ldlt().solve(A.transpose() * s.t);
  return depths.x() > 0 && depths.y() > 0;
}

/// Stacked residuals of the matches `idx` (2 per match rotation-only, 1 general), each match's
/// scaled by the square root of its weight.
VectorXd residuals(const BearingMatches& m, const State& s, const std::vector<int>& idx,
                   bool general, const Weights& weights = Weights()) {
  VectorXd r(idx.size() * (general ? 1 : 2));
  const Matrix3d E = skew(s.t) * s.R;
  for (size_t k = 0; k < idx.size(); ++k) {
    const int i = idx[k];
    if (general) {
      r(k) = sampsonResidual(E, m.from[i], m.to[i], m.fx, m.fy);
    } else {
      r.segment<2>(2 * k) = rotationResidual(s, m.from[i], m.to[i], m.fx, m.fy);
    }
  }
  if (!weights.empty()) {
    const int per_match = general ? 1 : 2;
    for (size_t k = 0; k < idx.size(); ++k)
      r.segment(per_match * k, per_match) *= std::sqrt(weights[k]);
  }
  return r;
}

/// Central-difference Jacobian of the residuals in the state's tangent space.
Eigen::MatrixXd jacobian(const BearingMatches& m, const State& s, const std::vector<int>& idx,
                         bool general, const Weights& weights = Weights()) {
  const int p = general ? 5 : 3;
  const double h = 1e-6;
  Eigen::MatrixXd J(idx.size() * (general ? 1 : 2), p);
  for (int j = 0; j < p; ++j) {
    VectorXd step = VectorXd::Zero(p);
    step(j) = h;
    J.col(j) = (residuals(m, perturb(s, step), idx, general, weights) -
                residuals(m, perturb(s, -step), idx, general, weights)) /
               (2 * h);
  }
  return J;
}

/// Levenberg-Marquardt on the sum of squared residuals of the matches `idx`; stops when the step
/// is negligible (1e-9 rad) or the cost decreases by less than 1e-8 of itself (a pure rotation
/// leaves the general model's translation flat: it would otherwise iterate to the limit).
State refine(const BearingMatches& m, State s, const std::vector<int>& idx, bool general,
             const Weights& weights = Weights()) {
  VectorXd r = residuals(m, s, idx, general, weights);
  double cost = r.squaredNorm();
  double lambda = 1e-6;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Eigen::MatrixXd J = jacobian(m, s, idx, general, weights);
    Eigen::MatrixXd H = J.transpose() * J;
    const VectorXd g = J.transpose() * r;
    H.diagonal() *= 1 + lambda;
    const VectorXd step = -H.ldlt().solve(g);
    if (!step.allFinite() || step.norm() < 1e-9) break;
    const State candidate = perturb(s, step);
    const VectorXd candidate_r = residuals(m, candidate, idx, general, weights);
    const double candidate_cost = candidate_r.squaredNorm();
    if (std::isfinite(candidate_cost) && candidate_cost <= cost) {
      const bool converged = cost - candidate_cost <= 1e-8 * cost;
      s = candidate;
      r = candidate_r;
      cost = candidate_cost;
      lambda = std::max(lambda / 10, 1e-9);
      if (converged) break;
    } else {
      lambda *= 10;
      if (lambda > 1e6) break;
    }
  }
  return s;
}

/// Squared distances of every match (px^2; the residual's squared norm).
std::vector<double> distances2(const BearingMatches& m, const State& s, bool general) {
  std::vector<double> d2(m.from.size());
  const Matrix3d E = skew(s.t) * s.R;
  for (size_t i = 0; i < d2.size(); ++i) {
    d2[i] = general ? std::pow(sampsonResidual(E, m.from[i], m.to[i], m.fx, m.fy), 2)
                    : rotationResidual(s, m.from[i], m.to[i], m.fx, m.fy).squaredNorm();
  }
  return d2;
}

/// The matches within the chi-square 99.9 % bound of the noise at state `s` (and within the
/// RANSAC gate; with `cheirality`, in front of both cameras). The noise is the median distance of
/// every match within the gate (robust: not from a previous selection, whose trimming would shrink
/// it round after round).
std::vector<int> selectInliers(const BearingMatches& m, const State& s, double threshold_px,
                               bool general, bool cheirality, double* sigma2_out = nullptr) {
  const int codim = general ? 1 : 2;
  const double threshold2 = threshold_px * threshold_px;
  const std::vector<double> d2 = distances2(m, s, general);
  std::vector<double> gated_d2;
  for (double d : d2) {
    if (d < threshold2) gated_d2.push_back(d);
  }
  std::vector<int> idx;
  if (gated_d2.empty()) return idx;
  std::nth_element(gated_d2.begin(), gated_d2.begin() + gated_d2.size() / 2, gated_d2.end());
  const double sigma2 =
      std::max(gated_d2[gated_d2.size() / 2] / kChi2Median[codim], kMinSigmaPx * kMinSigmaPx);
  const double bound = std::min(threshold2, kChi2Bound999[codim] * sigma2);
  for (size_t i = 0; i < d2.size(); ++i) {
    if (d2[i] < bound && (!cheirality || inFrontOfBoth(s, m.from[i], m.to[i]))) {
      idx.push_back(static_cast<int>(i));
    }
  }
  if (sigma2_out) *sigma2_out = sigma2;
  return idx;
}

/// From the RANSAC model: rounds of a robust fit over the matches within the RANSAC gate
/// (iteratively reweighted least squares with Cauchy weights at the robust noise: a mismatch that
/// the gate let in cannot bend the model towards itself, as it can in plain least squares, most of
/// all the general model's translation near the epipole), then the inliers at the robust estimate
/// (selectInliers), their least-squares fit and the covariance from their residuals over their
/// degrees of freedom. `screen`: the final inliers are also screened for mismatches (cheirality
/// for the general model, leave-one-out of high-leverage matches); off for the general model's
/// fit for GRIC only, where under a pure rotation the translation is arbitrary and the screens
/// would cost time and bias the choice.
ModelFit refineAndSelect(const BearingMatches& m, State s, double threshold_px, bool general,
                         bool screen) {
  ModelFit fit;
  const int codim = general ? 1 : 2, params = general ? 5 : 3;
  fit.codimension = codim;
  std::vector<int> idx;
  // Fewer robust rounds when the fit only serves the model choice.
  for (int round = 0; round < (screen ? kRefinementRounds : 2); ++round) {
    double sigma2 = 0;
    selectInliers(m, s, threshold_px, general, false, &sigma2);
    idx.clear();
    Weights weights;
    const std::vector<double> d2 = distances2(m, s, general);
    for (size_t i = 0; i < d2.size(); ++i) {
      if (d2[i] >= threshold_px * threshold_px) continue;
      idx.push_back(static_cast<int>(i));
      weights.push_back(1 / (1 + d2[i] / (kCauchyScale2 * codim * sigma2)));
    }
    if (static_cast<int>(idx.size()) * codim <= params + 1) return fit;
    s = refine(m, s, idx, general, weights);
  }
  // Final inliers. A match that alone holds the model where it is (high leverage h, as a mismatch
  // near the epipole or the image border can have in the general model) cannot be judged by its
  // own residual, which the fit has pulled to zero: it is judged by its residual under the model
  // fitted without it (an exact leave-one-out: the model is not linear enough for r / (1 - h)).
  for (int pass = 0; pass < 3; ++pass) {
    double sigma2 = 0;
    idx = selectInliers(m, s, threshold_px, general, general && screen, &sigma2);
    if (static_cast<int>(idx.size()) * codim <= params + 1) return fit;
    s = refine(m, s, idx, general);
    if (!screen) break;
    const Eigen::MatrixXd J = jacobian(m, s, idx, general);
    const Eigen::MatrixXd A = (J.transpose() * J).inverse();
    const double leverage_gate = std::max(kLeverageGate, 3.0 * params / idx.size());
    std::vector<int> rejected;
    for (size_t k = 0; k < idx.size() && rejected.size() < 5; ++k) {
      const Eigen::MatrixXd J_k = J.middleRows(codim * k, codim);
      if ((J_k * A * J_k.transpose()).trace() < leverage_gate) continue;
      std::vector<int> others = idx;
      others.erase(others.begin() + k);
      const State without = refine(m, s, others, general);
      const double d2 =
          general
              ? std::pow(sampsonResidual(skew(without.t) * without.R, m.from[idx[k]], m.to[idx[k]],
                                         m.fx, m.fy),
                         2)
              : rotationResidual(without, m.from[idx[k]], m.to[idx[k]], m.fx, m.fy).squaredNorm();
      if (d2 >= kChi2Bound999[codim] * sigma2) rejected.push_back(idx[k]);
    }
    if (rejected.empty()) break;
    std::vector<int> kept;
    for (int i : idx) {
      if (std::find(rejected.begin(), rejected.end(), i) == rejected.end()) kept.push_back(i);
    }
    idx = std::move(kept);
    s = refine(m, s, idx, general);
  }
  const int residual_count = static_cast<int>(idx.size()) * codim;
  if (residual_count <= params + 1) return fit;
  s = refine(m, s, idx, general);
  const VectorXd r = residuals(m, s, idx, general);
  const double sigma2 =
      std::max(r.squaredNorm() / (residual_count - params), kMinSigmaPx * kMinSigmaPx);
  const Eigen::MatrixXd J = jacobian(m, s, idx, general);
  const Eigen::MatrixXd H = J.transpose() * J;
  // The rotation's information with the translation direction marginalised (Schur complement).
  Matrix3d information = H.topLeftCorner<3, 3>();
  if (general) {
    information -= H.topRightCorner<3, 2>() *
                   H.bottomRightCorner<2, 2>().ldlt().solve(H.bottomLeftCorner<2, 3>());
  }
  fit.found = true;
  fit.R_from_to = s.R;
  fit.t_from = general ? s.t : Vector3d::Zero();
  fit.distance2_px2 = distances2(m, s, general);
  fit.inlier.assign(m.from.size(), false);
  for (int i : idx) fit.inlier[i] = true;
  fit.inliers = static_cast<int>(idx.size());
  fit.sigma_px = std::sqrt(sigma2);
  fit.cov_rad2 = sigma2 * information.inverse();
  return fit;
}

/// The rotation taking the pair (b1, b2) onto (a1, a2) best (triad: b1 exactly onto a1, the
/// planes aligned); false for (nearly) parallel bearings.
bool twoPointRotation(const Vector3d& a1, const Vector3d& a2, const Vector3d& b1,
                      const Vector3d& b2, Matrix3d* R) {
  const Vector3d na = a1.cross(a2), nb = b1.cross(b2);
  if (na.norm() < 1e-6 || nb.norm() < 1e-6) return false;
  Matrix3d A, B;
  A << a1, na.normalized(), a1.cross(na.normalized());
  B << b1, nb.normalized(), b1.cross(nb.normalized());
  *R = A * B.transpose();
  return true;
}

double transferError2(const Matrix3d& R, const Vector3d& a, const Vector3d& b, double fx,
                      double fy) {
  const Vector3d p = R * b;
  if (p.z() <= 1e-9) return std::numeric_limits<double>::infinity();
  return std::pow((p.x() / p.z() - a.x() / a.z()) * fx, 2) +
         std::pow((p.y() / p.z() - a.y() / a.z()) * fy, 2);
}

}  // namespace

ModelFit fitRotationOnly(const BearingMatches& m, double threshold_px,
                         const std::optional<Matrix3d>& R_prediction) {
  const int n = static_cast<int>(m.from.size());
  if (n < 5) return ModelFit();
  const double threshold2 = threshold_px * threshold_px;
  auto inliersOf = [&](const Matrix3d& R) {
    std::vector<int> idx;
    for (int i = 0; i < n; ++i) {
      if (transferError2(R, m.from[i], m.to[i], m.fx, m.fy) < threshold2) idx.push_back(i);
    }
    return idx;
  };
  std::vector<int> best;
  Matrix3d R_best = Matrix3d::Identity();
  if (R_prediction) {
    R_best = projectToSO3(*R_prediction);
    best = inliersOf(R_best);
  }
  std::mt19937 rng(20260526);  // deterministic: the same views give the same rotation
  std::uniform_int_distribution<int> pick(0, n - 1);
  int needed = kRansacMaxIterations;
  for (int iteration = 0; iteration < needed; ++iteration) {
    const int i = pick(rng), j = pick(rng);
    Matrix3d R;
    if (i == j || !twoPointRotation(m.from[i], m.from[j], m.to[i], m.to[j], &R)) continue;
    std::vector<int> idx = inliersOf(R);
    if (idx.size() <= best.size()) continue;
    best = std::move(idx);
    R_best = R;
    const double w = static_cast<double>(best.size()) / n;
    const double miss = std::max(1 - w * w, 1e-12);
    needed =
        std::min(kRansacMaxIterations,
                 static_cast<int>(std::ceil(std::log(1 - kRansacConfidence) / std::log(miss))));
  }
  if (best.size() < 5) return ModelFit();
  State s;
  s.R = R_best;
  return refineAndSelect(m, s, threshold_px, false, true);
}

ModelFit fitGeneral(const BearingMatches& m, double threshold_px, bool screen) {
  const int n = static_cast<int>(m.from.size());
  if (n < 6) return ModelFit();
  std::vector<cv::Point2d> to, from;
  for (int i = 0; i < n; ++i) {
    to.emplace_back(m.to[i].x() / m.to[i].z(), m.to[i].y() / m.to[i].z());
    from.emplace_back(m.from[i].x() / m.from[i].z(), m.from[i].y() / m.from[i].z());
  }
  // OpenCV: points2^T E points1 = 0 and x2 = R x1 + t; with points1 = `to`, points2 = `from`,
  // R is R_from_to and t the `to` centre in the `from` frame.
  const double focal = std::sqrt(m.fx * m.fy);
  cv::Mat mask;
  const cv::Mat E = cv::findEssentialMat(to, from, 1.0, cv::Point2d(0, 0), cv::RANSAC,
                                         kRansacConfidence, threshold_px / focal, mask);
  if (E.rows < 3 || E.cols != 3) return ModelFit();
  cv::Mat R_cv, t_cv;
  // Cheirality over every depth: OpenCV's default counts points beyond 50 baselines as at
  // infinity and not in front, which fails a hand-held rig's few centimetres before a wall metres
  // away (the rotation-only model then took the translation as a rotation, 0.2-1.3 deg off).
  if (cv::recoverPose(E.rowRange(0, 3), to, from, cv::Mat::eye(3, 3, CV_64F), R_cv, t_cv,
                      kCheiralityMaxDepth, mask) < 6) {
    return ModelFit();
  }
  State s;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) s.R(r, c) = R_cv.at<double>(r, c);
    s.t(r) = t_cv.at<double>(r);
  }
  s.R = projectToSO3(s.R);
  s.t.normalize();
  return refineAndSelect(m, s, threshold_px, true, screen);
}

ModelFit fitGeneralFrom(const BearingMatches& m, double threshold_px, const Matrix3d& R_from_to,
                        const Vector3d& t_from) {
  if (m.from.size() < 6 || !(t_from.norm() > 0)) return ModelFit();
  State s;
  s.R = projectToSO3(R_from_to);
  s.t = t_from.normalized();
  return refineAndSelect(m, s, threshold_px, true, true);
}

HeldRotationFits fitNearRotation(const BearingMatches& m, const Matrix3d& R_from_to,
                                 double gate_px) {
  HeldRotationFits out;
  const int n = static_cast<int>(m.from.size());
  if (n < 6 || !(gate_px > 0)) return out;
  State held;
  held.R = projectToSO3(R_from_to);
  out.rotation = refineAndSelect(m, held, gate_px, false, true);
  // t . (R to x from) = 0 for every match of a motion (R, t): two matches' normals give t.
  const double focal = std::sqrt(m.fx * m.fy);
  const double gate2 = gate_px * gate_px;
  std::vector<Vector3d> normals(n);
  for (int i = 0; i < n; ++i) normals[i] = (held.R * m.to[i]).cross(m.from[i]);
  const auto score = [&](const Vector3d& t) {
    const Matrix3d E = skew(t) * held.R;
    double sum = 0;
    for (int i = 0; i < n; ++i)
      sum += std::min(std::pow(sampsonResidual(E, m.from[i], m.to[i], m.fx, m.fy), 2), gate2);
    return sum;
  };
  // A match whose normal is within the gate of zero says nothing of t (no parallax).
  const double min_normal = gate_px / focal;
  std::mt19937 rng(20261127);  // deterministic: the same views give the same rotation
  std::uniform_int_distribution<int> pick(0, n - 1);
  double best = std::numeric_limits<double>::infinity();
  Vector3d t_best = Vector3d::Zero();
  for (int iteration = 0; iteration < kHeldRotationIterations; ++iteration) {
    const int i = pick(rng), j = pick(rng);
    if (i == j || normals[i].norm() < min_normal || normals[j].norm() < min_normal) continue;
    const Vector3d t = normals[i].cross(normals[j]);
    if (t.norm() < 1e-3 * normals[i].norm() * normals[j].norm()) continue;
    const double cost = score(t.normalized());
    if (cost < best) {
      best = cost;
      t_best = t.normalized();
    }
  }
  if (!(t_best.norm() > 0)) return out;
  // The sign: more of the matches within the gate in front of both cameras.
  State general = held;
  const Matrix3d E = skew(t_best) * held.R;
  int front = 0, behind = 0;
  for (int i = 0; i < n; ++i) {
    if (std::pow(sampsonResidual(E, m.from[i], m.to[i], m.fx, m.fy), 2) >= gate2) continue;
    general.t = t_best;
    front += inFrontOfBoth(general, m.from[i], m.to[i]);
    general.t = -t_best;
    behind += inFrontOfBoth(general, m.from[i], m.to[i]);
  }
  general.t = front >= behind ? t_best : Vector3d(-t_best);
  out.general = refineAndSelect(m, general, gate_px, true, true);
  return out;
}

std::vector<ModelFit> planarAlternatives(const BearingMatches& m, const ModelFit& fit,
                                         double threshold_px, double min_separation_rad) {
  std::vector<ModelFit> out;
  if (!fit.found || fit.inlier.size() != m.from.size()) return out;
  std::vector<cv::Point2d> to, from;
  for (size_t i = 0; i < m.from.size(); ++i) {
    if (!fit.inlier[i]) continue;
    to.emplace_back(m.to[i].x() / m.to[i].z(), m.to[i].y() / m.to[i].z());
    from.emplace_back(m.from[i].x() / m.from[i].z(), m.from[i].y() / m.from[i].z());
  }
  if (to.size() < 8) return out;
  // `from` ~ H `to`, H = R_from_to + t_from n^T / d (OpenCV: points2 ~ H points1).
  const double focal = std::sqrt(m.fx * m.fy);
  const cv::Mat H = cv::findHomography(to, from, cv::RANSAC, threshold_px / focal);
  if (H.rows != 3 || H.cols != 3) return out;
  std::vector<cv::Mat> rotations, translations, normals;
  cv::decomposeHomographyMat(H, cv::Mat::eye(3, 3, CV_64F), rotations, translations, normals);
  std::vector<Matrix3d> kept = {fit.R_from_to};
  const auto nearKept = [&](const Matrix3d& R) {
    return std::any_of(kept.begin(), kept.end(), [&](const Matrix3d& other) {
      return rotationAngle(other.transpose() * R) < min_separation_rad;
    });
  };
  for (size_t k = 0; k < rotations.size(); ++k) {
    Matrix3d R;
    Vector3d t;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R(r, c) = rotations[k].at<double>(r, c);
      t(r) = translations[k].at<double>(r);
    }
    R = projectToSO3(R);
    if (!R.allFinite() || !(t.norm() > 1e-9)) continue;
    if (nearKept(R)) continue;  // refining it would only find a kept solution again
    ModelFit alternative = fitGeneralFrom(m, threshold_px, R, t);
    if (!alternative.found || nearKept(alternative.R_from_to)) continue;
    kept.push_back(alternative.R_from_to);
    out.push_back(std::move(alternative));
  }
  return out;
}

double gric(const ModelFit& fit, const std::vector<bool>& counted, double sigma_px,
            int parameters) {
  const double sigma2 = std::max(sigma_px * sigma_px, kMinSigmaPx * kMinSigmaPx);
  const int manifold_dimension = 4 - fit.codimension;
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < counted.size(); ++i) {
    if (!counted[i]) continue;
    sum += std::min(fit.distance2_px2[i] / sigma2, 2.0 * fit.codimension);
    ++n;
  }
  return sum + n * manifold_dimension * std::log(4.0) + parameters * std::log(4.0 * n);
}

}  // namespace scene_geometry
}  // namespace camera_imu_alignment
