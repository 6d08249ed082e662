// Rotation-only and general two-view models of matched bearings: RANSAC (refined by
// scene_model_fit.h), a near-planar view's other solutions, and GRIC (scene_geometry.h). The
// rotation held near a prediction: scene_held_rotation.cpp.
#include "scene_geometry.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <random>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "scene_model_fit.h"

namespace camera_imu_alignment {
namespace scene_geometry {

using model_fit::kMinSigmaPx;
using model_fit::refineAndSelect;
using model_fit::State;

namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr int kRansacMaxIterations = 1000;
constexpr double kRansacConfidence = 0.999;
/// Triangulated depths (in baselines) up to which cheirality is judged in recoverPose.
constexpr double kCheiralityMaxDepth = 1e6;
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
