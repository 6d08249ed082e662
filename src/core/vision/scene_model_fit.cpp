// Fitting two-view models of matched bearings (scene_model_fit.h): distances, Levenberg-Marquardt
// refinement, robust inlier selection and the rotation's covariance.
#include "scene_model_fit.h"

#include <Eigen/LU>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace scene_geometry {
namespace model_fit {
namespace {

using Eigen::Vector2d;

constexpr double kLeverageGate = 0.2;  // a match's leverage (hat-matrix trace) to be cross-checked

}  // namespace

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
                   bool general, const Weights& weights) {
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

/// Jacobian of the residuals of the matches `idx` in the state's tangent space.
Eigen::MatrixXd jacobian(const BearingMatches& m, const State& s, const std::vector<int>& idx,
                         bool general, const Weights& weights = Weights()) {
  return numericJacobian(
      s, general ? 5 : 3, [&](const State& x) { return residuals(m, x, idx, general, weights); },
      perturb);
}

/// The state fitted to the matches `idx` (levenbergMarquardt).
State refine(const BearingMatches& m, State s, const std::vector<int>& idx, bool general,
             const Weights& weights = Weights()) {
  return levenbergMarquardt(
      s, general ? 5 : 3, [&](const State& x) { return residuals(m, x, idx, general, weights); },
      perturb);
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

double robustSigma2(const std::vector<double>& d2, double threshold2, int codim) {
  std::vector<double> gated;
  for (double d : d2) {
    if (d < threshold2) gated.push_back(d);
  }
  if (gated.empty()) return 0;
  std::nth_element(gated.begin(), gated.begin() + gated.size() / 2, gated.end());
  return std::max(gated[gated.size() / 2] / kChi2Median[codim], kMinSigmaPx * kMinSigmaPx);
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
  std::vector<int> idx;
  const double sigma2 = robustSigma2(d2, threshold2, codim);
  if (!(sigma2 > 0)) return idx;
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

}  // namespace model_fit
}  // namespace scene_geometry
}  // namespace camera_imu_alignment
