// Fitting two-view models of matched bearings (private to scene_geometry.cpp and
// scene_held_rotation.cpp): the model's state, its first-order geometric distances in pixels, a
// Levenberg-Marquardt with numeric Jacobians, and refineAndSelect (robust rounds, the final
// inliers, the rotation's covariance). Frames and units as scene_geometry.h.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "scene_geometry.h"

namespace camera_imu_alignment {
namespace scene_geometry {
namespace model_fit {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;

// Chi-square quantiles: medians (for the robust sigma) and 99.9 % bounds (inlier re-selection)
// for 1 and 2 degrees of freedom.
constexpr double kChi2Median[3] = {0, 0.4549, 1.3863};
constexpr double kChi2Bound999[3] = {0, 10.828, 13.816};
constexpr double kMinSigmaPx = 1e-3;             // noise-free data: keep the covariance invertible
constexpr int kRefinementRounds = 4;             // robust rounds of refineAndSelect
constexpr double kCauchyScale2 = 2.385 * 2.385;  // Cauchy loss scale (per coordinate, in sigmas)

/// The model's state: the rotation and (general model) the translation direction.
struct State {
  Matrix3d R = Matrix3d::Identity();
  Vector3d t = Vector3d::UnitZ();
};

/// Two unit vectors spanning the plane orthogonal to the unit vector t.
Eigen::Matrix<double, 3, 2> tangentBasis(const Vector3d& t);

/// step: 3 (rotation, right perturbation) or 5 (and the translation direction's tangent).
State perturb(const State& s, const VectorXd& step);

/// General-model distance of one match: the Sampson distance to the epipolar constraint
/// x_from^T E x_to = 0 with E = [t]x R (pixels).
double sampsonResidual(const Matrix3d& E, const Vector3d& a, const Vector3d& b, double fx,
                       double fy);

/// Per-match weights of an iteratively reweighted fit (one per entry of `idx`); empty: all 1.
using Weights = std::vector<double>;

/// General model: whether the match's scene point, triangulated from both rays (least squares on
/// depth_from a = depth_to R b + t), lies in front of both cameras. A mismatch near its epipolar
/// line that the epipolar distance cannot reject is behind a camera about half the time.
bool inFrontOfBoth(const State& s, const Vector3d& a, const Vector3d& b);

/// Stacked residuals of the matches `idx` (2 per match rotation-only, 1 general), each match's
/// scaled by the square root of its weight.
VectorXd residuals(const BearingMatches& m, const State& s, const std::vector<int>& idx,
                   bool general, const Weights& weights = Weights());

/// Squared distances of every match (px^2; the residual's squared norm).
std::vector<double> distances2(const BearingMatches& m, const State& s, bool general);

/// The robust noise per coordinate (px^2) of squared distances `d2` of codimension `codim`: the
/// median of those below `threshold2` over chi-square(codim)'s median, at least kMinSigmaPx^2; 0
/// when none is below.
double robustSigma2(const std::vector<double>& d2, double threshold2, int codim);

/// From a model's state: robust rounds over the matches within the gate `threshold_px`, the final
/// inliers, their fit and the rotation's covariance (scene_model_fit.cpp has the details).
ModelFit refineAndSelect(const BearingMatches& m, State s, double threshold_px, bool general,
                         bool screen);

/// Central-difference Jacobian of `residual(state)` in the tangent space of `perturb(state, step)`
/// (`parameters` dimensions).
template <class S, class Residual, class Perturb>
Eigen::MatrixXd numericJacobian(const S& s, int parameters, const Residual& residual,
                                const Perturb& perturb) {
  const double h = 1e-6;
  Eigen::MatrixXd J;
  for (int j = 0; j < parameters; ++j) {
    VectorXd step = VectorXd::Zero(parameters);
    step(j) = h;
    const VectorXd column = (residual(perturb(s, step)) - residual(perturb(s, -step))) / (2 * h);
    if (j == 0) J.resize(column.size(), parameters);
    J.col(j) = column;
  }
  return J;
}

/// Levenberg-Marquardt on the sum of squared `residual(state)`; stops when the step is negligible
/// (1e-9 rad) or the cost decreases by less than 1e-8 of itself (a pure rotation leaves the general
/// model's translation flat: it would otherwise iterate to the limit).
template <class S, class Residual, class Perturb>
S levenbergMarquardt(S s, int parameters, const Residual& residual, const Perturb& perturb) {
  VectorXd r = residual(s);
  double cost = r.squaredNorm();
  double lambda = 1e-6;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Eigen::MatrixXd J = numericJacobian(s, parameters, residual, perturb);
    Eigen::MatrixXd H = J.transpose() * J;
    const VectorXd g = J.transpose() * r;
    H.diagonal() *= 1 + lambda;
    const VectorXd step = -H.ldlt().solve(g);
    if (!step.allFinite() || step.norm() < 1e-9) break;
    const S candidate = perturb(s, step);
    const VectorXd candidate_r = residual(candidate);
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

}  // namespace model_fit
}  // namespace scene_geometry
}  // namespace camera_imu_alignment
