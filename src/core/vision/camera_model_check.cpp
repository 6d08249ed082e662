// The camera-model check (camera_model_check.h): three nested fits of one view, and the
// recording's verdict over the views.
#include "camera_imu_alignment/vision/camera_model_check.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <sstream>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// Numerical floor of a residual variance (px^2): noise-free synthetic images only.
constexpr double kVarianceFloorPx2 = 1e-12;

/// The parameters of the pose and focal fits: the pose (R_cam_target, t_cam_target, m) and the
/// log of the focal factor.
struct PoseFocal {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double log_scale = 0.0;
};

/// Residuals (projection - measurement, px) and their Jacobian (2N x 7: left rotation
/// perturbation, translation, log factor); returns their sum of squares (infinite when a point is
/// behind the camera).
double residuals(const PoseFocal& x, const std::vector<Eigen::Vector3d>& object,
                 const std::vector<Eigen::Vector2d>& pixels, const Eigen::Matrix3d& K,
                 Eigen::VectorXd* r, Eigen::MatrixXd* J) {
  const int n = static_cast<int>(object.size());
  const double s = std::exp(x.log_scale);
  const double fx = s * K(0, 0), fy = s * K(1, 1), cx = K(0, 2), cy = K(1, 2);
  if (r) r->resize(2 * n);
  if (J) J->setZero(2 * n, 7);
  double ssr = 0.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d RX = x.R * object[i];
    const Eigen::Vector3d P = RX + x.t;
    if (!(P.z() > 1e-9)) return std::numeric_limits<double>::infinity();
    const double u = fx * P.x() / P.z() + cx, v = fy * P.y() / P.z() + cy;
    const double du = u - pixels[i].x(), dv = v - pixels[i].y();
    ssr += du * du + dv * dv;
    if (r) (*r)(2 * i) = du, (*r)(2 * i + 1) = dv;
    if (J) {
      Eigen::Matrix<double, 2, 3> d_uv_d_P;
      d_uv_d_P << fx / P.z(), 0.0, -fx * P.x() / (P.z() * P.z()), 0.0, fy / P.z(),
          -fy * P.y() / (P.z() * P.z());
      J->block<2, 3>(2 * i, 0) = d_uv_d_P * -skew(RX);  // d(Exp(e) R X)/de
      J->block<2, 3>(2 * i, 3) = d_uv_d_P;
      (*J)(2 * i, 6) = u - cx;  // d u / d log s
      (*J)(2 * i + 1, 6) = v - cy;
    }
  }
  return ssr;
}

/// Levenberg-Marquardt over the pose and, with `free_scale`, the log factor; `information` gets
/// J^T J at the solution. Returns the final sum of squares.
double refine(PoseFocal* x, bool free_scale, const std::vector<Eigen::Vector3d>& object,
              const std::vector<Eigen::Vector2d>& pixels, const Eigen::Matrix3d& K,
              Eigen::Matrix<double, 7, 7>* information) {
  const int dims = free_scale ? 7 : 6;
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  double cost = residuals(*x, object, pixels, K, &r, &J);
  double lambda = 1e-3;
  bool converged = false;
  for (int iteration = 0; iteration < 50 && !converged && std::isfinite(cost); ++iteration) {
    const Eigen::MatrixXd Jd = J.leftCols(dims);
    Eigen::MatrixXd A = Jd.transpose() * Jd;
    const Eigen::VectorXd g = Jd.transpose() * r;
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::MatrixXd damped = A;
      damped.diagonal() += lambda * A.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd step = damped.ldlt().solve(-g);
      if (!step.allFinite()) break;
      PoseFocal trial = *x;
      trial.R = projectToSO3(expSO3(step.head<3>()) * x->R);
      trial.t = x->t + step.segment<3>(3);
      if (free_scale) trial.log_scale = x->log_scale + step(6);
      Eigen::VectorXd r_trial;
      Eigen::MatrixXd J_trial;
      const double trial_cost = residuals(trial, object, pixels, K, &r_trial, &J_trial);
      if (trial_cost < cost) {
        const double drop = cost - trial_cost;
        *x = trial, r = r_trial, J = J_trial;
        cost = trial_cost;
        lambda = std::max(1e-9, lambda * 0.3);
        improved = true;
        converged = drop < 1e-12 * (1.0 + cost);
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  if (information) *information = J.transpose() * J;
  return cost;
}

double fisherTail(double f, int d1, int d2) {
  if (!(f > 0.0) || d1 < 1 || d2 < 1) return 1.0;
  if (!std::isfinite(f)) return 0.0;
  return boost::math::cdf(boost::math::complement(boost::math::fisher_f(d1, d2), f));
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

/// F and p of the focal test from the three sums.
void judgeView(CameraModelFit* fit) {
  const int dof = 2 * fit->num_points - 8;
  const double noise = std::max(fit->ssr_homography_px2 / dof, kVarianceFloorPx2);
  fit->f_statistic = std::max(0.0, fit->ssr_pose_px2 - fit->ssr_focal_px2) / noise;
  fit->p_value = fisherTail(fit->f_statistic, 1, dof);
}

}  // namespace

double CameraModelFit::reprojectionRmsPx() const {
  return num_points > 0 ? std::sqrt(ssr_pose_px2 / num_points) : 0.0;
}
double CameraModelFit::noiseRmsPx() const {
  return num_points > 0 ? std::sqrt(ssr_homography_px2 / num_points) : 0.0;
}

std::optional<CameraModelFit> fitCameraModel(const TargetObservation& observation,
                                             const TargetDescription& target,
                                             const CameraIntrinsics& intrinsics) {
  const std::size_t n = observation.image_points.size();
  if (n < 6 || observation.point_ids.size() != n || !intrinsics.validate().empty()) {
    return std::nullopt;
  }
  std::vector<Eigen::Vector3d> object;
  std::vector<cv::Point3d> object_cv;
  std::vector<cv::Point2d> plane_cv;
  for (const int id : observation.point_ids) {
    if (id < 0 || id >= target.numPoints()) return std::nullopt;
    const Eigen::Vector3d p = target.point(id);
    if (std::abs(p.z()) > 1e-12) return std::nullopt;  // the fits assume a planar board
    object.push_back(p);
    object_cv.emplace_back(p.x(), p.y(), p.z());
    plane_cv.emplace_back(p.x(), p.y());
  }
  for (const auto& p : observation.image_points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return std::nullopt;
  }
  const Eigen::Matrix3d& K = intrinsics.K;
  const std::vector<cv::Point2d> normalized =
      intrinsics.undistortToNormalized(observation.image_points);
  std::vector<Eigen::Vector2d> pixels;
  std::vector<cv::Point2d> pixels_cv;
  for (const cv::Point2d& q : normalized) {
    pixels.emplace_back(K(0, 0) * q.x + K(0, 2), K(1, 1) * q.y + K(1, 2));
    if (!pixels.back().allFinite()) return std::nullopt;
    pixels_cv.emplace_back(pixels.back().x(), pixels.back().y());
  }

  CameraModelFit fit;
  fit.num_points = static_cast<int>(n);
  // Homography (least squares, Levenberg-Marquardt refined on the pixel error by OpenCV).
  cv::Mat H;
  try {
    H = cv::findHomography(plane_cv, pixels_cv, 0);
  } catch (const cv::Exception&) {
    return std::nullopt;
  }
  if (H.empty()) return std::nullopt;
  for (std::size_t i = 0; i < n; ++i) {
    const cv::Mat X = (cv::Mat_<double>(3, 1) << plane_cv[i].x, plane_cv[i].y, 1.0);
    const cv::Mat y = H * X;
    const double w = y.at<double>(2);
    if (!(std::abs(w) > 1e-12)) return std::nullopt;
    const double du = y.at<double>(0) / w - pixels[i].x(), dv = y.at<double>(1) / w - pixels[i].y();
    fit.ssr_homography_px2 += du * du + dv * dv;
  }

  // PnP start: IPPE's better solution on the normalised points.
  std::vector<cv::Mat> rvecs, tvecs;
  const cv::Mat identity = cv::Mat::eye(3, 3, CV_64F);
  try {
    if (cv::solvePnPGeneric(object_cv, normalized, identity, cv::noArray(), rvecs, tvecs, false,
                            cv::SOLVEPNP_IPPE) < 1) {
      return std::nullopt;
    }
  } catch (const cv::Exception&) {
    return std::nullopt;
  }
  PoseFocal best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < rvecs.size(); ++k) {
    PoseFocal x;
    x.R = expSO3(
        Eigen::Vector3d(rvecs[k].at<double>(0), rvecs[k].at<double>(1), rvecs[k].at<double>(2)));
    x.t = Eigen::Vector3d(tvecs[k].at<double>(0), tvecs[k].at<double>(1), tvecs[k].at<double>(2));
    const double cost = refine(&x, false, object, pixels, K, nullptr);
    if (cost < best_cost) best_cost = cost, best = x;
  }
  if (!std::isfinite(best_cost)) return std::nullopt;
  fit.ssr_pose_px2 = best_cost;
  PoseFocal focal = best;
  Eigen::Matrix<double, 7, 7> information;
  fit.ssr_focal_px2 = std::min(best_cost, refine(&focal, true, object, pixels, K, &information));
  fit.focal_scale = std::exp(focal.log_scale);
  const double noise =
      std::max(fit.ssr_homography_px2 / (2.0 * fit.num_points - 8.0), kVarianceFloorPx2);
  const Eigen::Matrix<double, 7, 7> covariance =
      noise * information.ldlt().solve(Eigen::Matrix<double, 7, 7>::Identity());
  const double sigma_log = std::sqrt(std::max(0.0, covariance(6, 6)));
  fit.focal_scale_sigma = std::isfinite(sigma_log) && covariance(6, 6) > 0.0
                              ? fit.focal_scale * sigma_log
                              : std::numeric_limits<double>::infinity();
  judgeView(&fit);
  return fit;
}

std::optional<CameraModelFit> combineFrames(const std::vector<CameraModelFit>& frames) {
  if (frames.empty()) return std::nullopt;
  CameraModelFit view;
  const double count = static_cast<double>(frames.size());
  double points = 0.0;
  for (const CameraModelFit& f : frames) {
    points += f.num_points;
    view.ssr_pose_px2 += f.ssr_pose_px2 / count;
    view.ssr_focal_px2 += f.ssr_focal_px2 / count;
    view.ssr_homography_px2 += f.ssr_homography_px2 / count;
    view.focal_scale_sigma += f.focal_scale_sigma / count;
  }
  // The factor: the frames' mean (their sigmas are alike: one view).
  view.focal_scale = 0.0;
  for (const CameraModelFit& f : frames) view.focal_scale += f.focal_scale / count;
  view.num_points = static_cast<int>(std::lround(points / count));
  if (view.num_points < 6) return std::nullopt;
  judgeView(&view);
  return view;
}

CameraModelCheck checkCameraModel(const std::vector<CameraModelFit>& views, double level,
                                  const CameraIntrinsics* intrinsics) {
  CameraModelCheck check;
  std::vector<double> scales, weights, view_p, reprojection, noise;
  for (const CameraModelFit& v : views) {
    reprojection.push_back(v.reprojectionRmsPx());
    noise.push_back(v.noiseRmsPx());
    view_p.push_back(v.p_value);
    if (std::isfinite(v.focal_scale) && std::isfinite(v.focal_scale_sigma) &&
        v.focal_scale_sigma > 0.0) {
      scales.push_back(v.focal_scale);
      weights.push_back(1.0 / (v.focal_scale_sigma * v.focal_scale_sigma));
    }
  }
  check.views = static_cast<int>(views.size());
  check.reprojection_rms_px = median(reprojection);
  check.noise_rms_px = median(noise);
  check.view_p_value = views.empty() ? 1.0 : median(view_p);
  if (static_cast<int>(scales.size()) < CameraModelCheck::kMinViews) return check;
  check.tested = true;
  double sum_w = 0.0, mean = 0.0;
  for (std::size_t i = 0; i < scales.size(); ++i)
    sum_w += weights[i], mean += weights[i] * scales[i];
  mean /= sum_w;
  double chi2 = 0.0;
  for (std::size_t i = 0; i < scales.size(); ++i) {
    chi2 += weights[i] * (scales[i] - mean) * (scales[i] - mean);
  }
  // The views' own sigmas, or their scatter about the mean when it is larger (model errors that
  // differ from view to view: a lens the distortion model misses, a board that is not flat).
  const double scatter_scale = std::max(1.0, chi2 / static_cast<double>(scales.size() - 1));
  check.focal_scale = mean;
  check.focal_scale_sigma = std::sqrt(scatter_scale / sum_w);
  const double z = std::abs(mean - 1.0) / check.focal_scale_sigma;
  check.p_value = std::erfc(z / std::sqrt(2.0));
  check.wrong = check.p_value < level && check.view_p_value < level;
  if (!check.wrong) return check;
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(2);
  out << "the camera intrinsics in camera_info do not fit the images: reprojection "
      << check.reprojection_rms_px << " px against " << check.noise_rms_px
      << " px image noise (a free homography's fit) over " << check.views
      << " rests; the images fit a focal length about " << check.focal_scale << "x camera_info's";
  if (intrinsics) {
    out.precision(0);
    out << " (fx, fy about " << check.focal_scale * intrinsics->K(0, 0) << ", "
        << check.focal_scale * intrinsics->K(1, 1) << " px, camera_info says "
        << intrinsics->K(0, 0) << ", " << intrinsics->K(1, 1) << ")";
  }
  out << ": recalibrate the camera or fix its camera_info (K)";
  check.message = out.str();
  return check;
}

}  // namespace camera_imu_alignment
