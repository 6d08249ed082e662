// The rotation held near a prediction while the inliers are chosen, and two motions that share it
// (scene_geometry.h, fitNearRotation).
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "scene_geometry.h"
#include "scene_model_fit.h"

namespace camera_imu_alignment {
namespace scene_geometry {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using model_fit::distances2;
using model_fit::inFrontOfBoth;
using model_fit::kCauchyScale2;
using model_fit::kChi2Bound999;
using model_fit::kMinSigmaPx;
using model_fit::kRefinementRounds;
using model_fit::levenbergMarquardt;
using model_fit::numericJacobian;
using model_fit::perturb;
using model_fit::refineAndSelect;
using model_fit::residuals;
using model_fit::robustSigma2;
using model_fit::sampsonResidual;
using model_fit::State;
using model_fit::Weights;

namespace {

/// Translation hypotheses (pairs of matches) with the rotation held.
constexpr int kHeldRotationIterations = 500;
/// Matches within the gate a second motion must hold before it is fitted (fitNearRotation).
constexpr int kMinSecondMotion = 8;
/// A two-motion fit's second motion: this share of its inliers at least outside the first
/// motion's gate.
constexpr double kSecondMotionShare = 0.1;

/// The translation direction that explains most of the matches `candidates` with the rotation R
/// held: t . (R to x from) = 0 for every match of a motion (R, t), so two matches' epipolar-plane
/// normals give t (RANSAC over pairs, scored by the squared Sampson distance truncated at the
/// gate), its sign by cheirality (more of the matches within the gate in front of both cameras).
/// Zero when no pair has parallax.
Vector3d heldRotationTranslation(const BearingMatches& m, const Matrix3d& R,
                                 const std::vector<int>& candidates, double gate_px) {
  const int n = static_cast<int>(candidates.size());
  if (n < 2) return Vector3d::Zero();
  const double focal = std::sqrt(m.fx * m.fy);
  const double gate2 = gate_px * gate_px;
  std::vector<Vector3d> normals(n);
  for (int k = 0; k < n; ++k) normals[k] = (R * m.to[candidates[k]]).cross(m.from[candidates[k]]);
  const auto distance2 = [&](const Matrix3d& E, int k) {
    return std::pow(sampsonResidual(E, m.from[candidates[k]], m.to[candidates[k]], m.fx, m.fy), 2);
  };
  const auto score = [&](const Vector3d& t) {
    const Matrix3d E = skew(t) * R;
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += std::min(distance2(E, k), gate2);
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
  if (!(t_best.norm() > 0)) return t_best;
  State s;
  s.R = R;
  const Matrix3d E = skew(t_best) * R;
  int front = 0, behind = 0;
  for (int k = 0; k < n; ++k) {
    if (distance2(E, k) >= gate2) continue;
    s.t = t_best;
    front += inFrontOfBoth(s, m.from[candidates[k]], m.to[candidates[k]]);
    s.t = -t_best;
    behind += inFrontOfBoth(s, m.from[candidates[k]], m.to[candidates[k]]);
  }
  return front >= behind ? t_best : Vector3d(-t_best);
}

/// Two motions that share the rotation: the room's (`a`) and that of an object slid between the
/// views (`b`: the same R, another translation direction).
struct TwoMotions {
  State a, b;
};

/// step: the rotation (3, right perturbation, both motions), a's translation tangent (2), b's (2).
TwoMotions perturbTwo(const TwoMotions& s, const VectorXd& step) {
  TwoMotions out;
  VectorXd part(5);
  part << step.head<3>(), step.segment<2>(3);
  out.a = perturb(s.a, part);
  part << step.head<3>(), step.segment<2>(5);
  out.b = perturb(s.b, part);
  return out;
}

/// Each match's squared Sampson distance (px^2) to the nearer motion, and which one (true: b).
void nearerMotion(const BearingMatches& m, const TwoMotions& s, std::vector<double>* d2,
                  std::vector<bool>* on_b) {
  const std::vector<double> da = distances2(m, s.a, true), db = distances2(m, s.b, true);
  d2->resize(da.size());
  on_b->resize(da.size());
  for (size_t i = 0; i < da.size(); ++i) {
    (*on_b)[i] = db[i] < da[i];
    (*d2)[i] = std::min(da[i], db[i]);
  }
}

/// The general model with a second motion sharing its rotation, fitted like refineAndSelect's
/// robust rounds and final selection: each match belongs to the nearer motion within the gate
/// (in front of both cameras under it, in the final selection), the rotation and both translation
/// directions are fitted together, and the rotation's covariance marginalises both. The object's
/// matches then measure the rotation too, instead of pulling the room's fit towards a compromise.
/// `distinct`: the second motion's inliers outside the first motion's gate.
ModelFit refineTwoMotions(const BearingMatches& m, TwoMotions s, double threshold_px,
                          int* distinct) {
  ModelFit fit;
  fit.codimension = 1;
  const int n = static_cast<int>(m.from.size());
  const double threshold2 = threshold_px * threshold_px;
  std::vector<int> idx_a, idx_b;
  Weights w_a, w_b;
  const auto residual = [&](const TwoMotions& x) {
    const VectorXd ra = residuals(m, x.a, idx_a, true, w_a),
                   rb = residuals(m, x.b, idx_b, true, w_b);
    VectorXd r(ra.size() + rb.size());
    r << ra, rb;
    return r;
  };
  std::vector<double> d2;
  std::vector<bool> on_b;
  double sigma2 = 0;
  for (int round = 0; round < kRefinementRounds; ++round) {
    nearerMotion(m, s, &d2, &on_b);
    sigma2 = robustSigma2(d2, threshold2, 1);
    idx_a.clear();
    idx_b.clear();
    w_a.clear();
    w_b.clear();
    for (int i = 0; i < n; ++i) {
      if (!(sigma2 > 0) || d2[i] >= threshold2) continue;
      const double w = 1 / (1 + d2[i] / (kCauchyScale2 * sigma2));
      (on_b[i] ? idx_b : idx_a).push_back(i);
      (on_b[i] ? w_b : w_a).push_back(w);
    }
    if (static_cast<int>(idx_a.size() + idx_b.size()) <= 8) return fit;
    s = levenbergMarquardt(s, 7, residual, perturbTwo);
  }
  // Final: the matches within the chi-square 99.9 % bound of the robust noise, in front of both
  // cameras under their motion; their least-squares fit; the noise from their residuals.
  nearerMotion(m, s, &d2, &on_b);
  sigma2 = robustSigma2(d2, threshold2, 1);
  const double bound = std::min(threshold2, kChi2Bound999[1] * sigma2);
  idx_a.clear();
  idx_b.clear();
  w_a.clear();
  w_b.clear();
  for (int i = 0; i < n; ++i) {
    if (d2[i] >= bound || !inFrontOfBoth(on_b[i] ? s.b : s.a, m.from[i], m.to[i])) continue;
    (on_b[i] ? idx_b : idx_a).push_back(i);
  }
  const int count = static_cast<int>(idx_a.size() + idx_b.size());
  if (count <= 8) return fit;
  s = levenbergMarquardt(s, 7, residual, perturbTwo);
  const VectorXd r = residual(s);
  sigma2 = std::max(r.squaredNorm() / (count - 7), kMinSigmaPx * kMinSigmaPx);
  const Eigen::MatrixXd J = numericJacobian(s, 7, residual, perturbTwo);
  const Eigen::MatrixXd H = J.transpose() * J;
  const Matrix3d information =
      H.topLeftCorner<3, 3>() - H.topRightCorner<3, 4>() * H.bottomRightCorner<4, 4>().ldlt().solve(
                                                               H.bottomLeftCorner<4, 3>());
  // The second motion's inliers that the first motion's gate leaves out.
  const std::vector<double> d2_a = distances2(m, s.a, true);
  *distinct = 0;
  for (int i : idx_b) *distinct += d2_a[i] >= threshold2;
  fit.found = true;
  fit.R_from_to = s.a.R;
  fit.t_from = s.a.t;
  nearerMotion(m, s, &fit.distance2_px2, &on_b);
  fit.inlier.assign(n, false);
  for (int i : idx_a) fit.inlier[i] = true;
  for (int i : idx_b) fit.inlier[i] = true;
  fit.inliers = count;
  fit.second_motion = static_cast<int>(idx_b.size());
  fit.sigma_px = std::sqrt(sigma2);
  fit.cov_rad2 = sigma2 * information.inverse();
  return fit;
}

/// The second motion's translation with the rotation R held, among the matches that `t_a` leaves
/// outside the gate: zero unless it holds kMinSecondMotion of them within the gate.
Vector3d secondTranslation(const BearingMatches& m, const Matrix3d& R, const Vector3d& t_a,
                           double gate_px) {
  const double gate2 = gate_px * gate_px;
  State s;
  s.R = R;
  s.t = t_a;
  const std::vector<double> da = distances2(m, s, true);
  std::vector<int> outside;
  for (size_t i = 0; i < da.size(); ++i) {
    if (da[i] >= gate2) outside.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(outside.size()) < kMinSecondMotion) return Vector3d::Zero();
  s.t = heldRotationTranslation(m, R, outside, gate_px);
  if (!(s.t.norm() > 0)) return s.t;
  const std::vector<double> db = distances2(m, s, true);
  int support = 0;
  for (int i : outside) support += db[i] < gate2;
  return support >= kMinSecondMotion ? s.t : Vector3d::Zero();
}

}  // namespace

HeldRotationFits fitNearRotation(const BearingMatches& m, const Matrix3d& R_from_to,
                                 double gate_px) {
  HeldRotationFits out;
  const int n = static_cast<int>(m.from.size());
  if (n < 6 || !(gate_px > 0)) return out;
  State held;
  held.R = projectToSO3(R_from_to);
  out.rotation = refineAndSelect(m, held, gate_px, false, true);
  std::vector<int> every(n);
  std::iota(every.begin(), every.end(), 0);
  State general = held;
  general.t = heldRotationTranslation(m, held.R, every, gate_px);
  if (!(general.t.norm() > 0)) return out;
  out.general = refineAndSelect(m, general, gate_px, true, true);
  if (!out.general.found) return out;
  // A second motion sharing the rotation, sought with the rotation held among the matches outside
  // the first translation's gate, and the two fitted together (refineTwoMotions). Taken when it
  // has kSecondMotionShare of the inliers outside the first motion's gate (a room split in two by a
  // prediction error gives two near-equal motions, each within the other's gate), and GRIC
  // prefers it over the matches either fit holds (its two more parameters against the matches it
  // explains better).
  TwoMotions two;
  two.a = general;
  two.b = general;
  two.b.t = secondTranslation(m, held.R, general.t, gate_px);
  if (!(two.b.t.norm() > 0)) return out;
  int distinct = 0;
  const ModelFit both = refineTwoMotions(m, two, gate_px, &distinct);
  if (!both.found ||
      distinct < std::max<double>(kMinSecondMotion, kSecondMotionShare * both.inliers))
    return out;
  std::vector<bool> counted(n);
  for (int i = 0; i < n; ++i) counted[i] = both.inlier[i] || out.general.inlier[i];
  const double sigma = out.general.sigma_px;
  if (gric(both, counted, sigma, 7) < gric(out.general, counted, sigma, 5)) out.two_motions = both;
  return out;
}

}  // namespace scene_geometry
}  // namespace camera_imu_alignment
