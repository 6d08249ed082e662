#include "camera_imu_alignment/vision/camera_pose.h"

// Camera pose from a planar target: IPPE's two solutions, Levenberg-Marquardt refinement,
// reprojection and ambiguity checks.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <sstream>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

namespace {

Eigen::Matrix3d rotationFromRvec(const cv::Mat& rvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out(r, c) = R.at<double>(r, c);
  }
  return out;
}

/// Reprojection RMS (px) of a pose (rvec, tvec: target -> camera) through the full camera model;
/// the mean distance (px) in `mean`.
double reprojectionRms(const std::vector<cv::Point3d>& object,
                       const std::vector<cv::Point2f>& image, const cv::Mat& rvec,
                       const cv::Mat& tvec, const CameraIntrinsics& camera,
                       double* mean = nullptr) {
  std::vector<cv::Point2d> projected;
  if (camera.distortion == CameraIntrinsics::Distortion::kEquidistant) {
    cv::fisheye::projectPoints(object, projected, rvec, tvec, camera.cameraMatrix(),
                               camera.distCoeffs());
  } else {
    cv::projectPoints(object, rvec, tvec, camera.cameraMatrix(), camera.distCoeffs(), projected);
  }
  double sq = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    const double dx = projected[i].x - image[i].x, dy = projected[i].y - image[i].y;
    sq += dx * dx + dy * dy;
    sum += std::sqrt(dx * dx + dy * dy);
  }
  if (mean) *mean = sum / image.size();
  return std::sqrt(sq / image.size());
}

/// sigma^2 (J^T J)^-1's rotation block for a pose (R_cam_target, t_cam_target) and its points:
/// the pinhole projection's Jacobian with respect to a rotation Exp(e) R_cam_target (camera axes)
/// and t, sigma^2 the sum of the squared residual coordinates over 2N - 6. Zero when not
/// determined.
Eigen::Matrix3d rotationCovariance(const std::vector<cv::Point3d>& object, double reprojection_rms,
                                   const Eigen::Matrix3d& R_cam_target,
                                   const Eigen::Vector3d& t_cam_target,
                                   const CameraIntrinsics& camera) {
  const int n = static_cast<int>(object.size());
  if (n < 4) return Eigen::Matrix3d::Zero();
  const double fx = camera.K(0, 0), fy = camera.K(1, 1);
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  for (const cv::Point3d& point : object) {
    const Eigen::Vector3d X(point.x, point.y, point.z);
    const Eigen::Vector3d RX = R_cam_target * X;
    const Eigen::Vector3d P = RX + t_cam_target;
    if (!(P.z() > 1e-9)) return Eigen::Matrix3d::Zero();
    Eigen::Matrix<double, 2, 3> d_uv_d_P;
    d_uv_d_P << fx / P.z(), 0.0, -fx * P.x() / (P.z() * P.z()), 0.0, fy / P.z(),
        -fy * P.y() / (P.z() * P.z());
    Eigen::Matrix<double, 3, 6> d_P;
    d_P.leftCols<3>() = -skew(RX);  // d(Exp(e) R X)/de at e = 0
    d_P.rightCols<3>().setIdentity();
    const Eigen::Matrix<double, 2, 6> J = d_uv_d_P * d_P;
    information += J.transpose() * J;
  }
  // reprojection_rms^2 is the mean squared distance (both coordinates): per coordinate, its sum
  // over the 2N - 6 degrees of freedom left.
  const double sigma2 = reprojection_rms * reprojection_rms * n / std::max(1.0, 2.0 * n - 6.0);
  const Eigen::Matrix<double, 6, 6> covariance =
      sigma2 * information.ldlt().solve(Eigen::Matrix<double, 6, 6>::Identity());
  const Eigen::Matrix3d rotation = covariance.topLeftCorner<3, 3>();
  return rotation.allFinite() ? Eigen::Matrix3d(0.5 * (rotation + rotation.transpose()))
                              : Eigen::Matrix3d::Zero();
}

/// Refined PnP solutions closer than this are the same minimum.
constexpr double kSameMinimumDeg = 0.5;

}  // namespace

std::optional<CameraPose> estimateCameraPose(const TargetObservation& observation,
                                             const TargetDescription& target,
                                             const CameraIntrinsics& intrinsics,
                                             const PoseSettings& settings, std::string* why) {
  auto fail = [&](const std::string& reason) -> std::optional<CameraPose> {
    if (why) *why = reason;
    return std::nullopt;
  };
  const std::size_t n = observation.image_points.size();
  if (n < 4 || observation.point_ids.size() != n) return fail("fewer than 4 target points");
  const std::string camera_problem = intrinsics.validate();
  if (!camera_problem.empty()) return fail("camera model: " + camera_problem);
  std::vector<cv::Point3d> object;
  for (const int id : observation.point_ids) {
    if (id < 0 || id >= target.numPoints()) return fail("target point id out of range");
    const Eigen::Vector3d p = target.point(id);
    object.emplace_back(p.x(), p.y(), p.z());
  }
  for (const auto& p : observation.image_points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return fail("non-finite image point");
  }

  // IPPE on undistorted normalised points: both planar solutions.
  const std::vector<cv::Point2d> normalized =
      intrinsics.undistortToNormalized(observation.image_points);
  const cv::Mat identity = cv::Mat::eye(3, 3, CV_64F);
  std::vector<cv::Mat> rvecs, tvecs;
  int found = 0;
  try {
    found = cv::solvePnPGeneric(object, normalized, identity, cv::noArray(), rvecs, tvecs, false,
                                cv::SOLVEPNP_IPPE);
  } catch (const cv::Exception& e) {
    return fail(std::string("PnP failed: ") + e.what());
  }
  if (found < 1) return fail("PnP found no solution");

  // Refine each solution (LM on the normalised plane, where both lens models are exact), then
  // judge them in pixels through the full camera model.
  std::vector<double> rms(found, std::numeric_limits<double>::infinity());
  int best = -1;
  for (int k = 0; k < found; ++k) {
    cv::Mat rvec = rvecs[k].clone(), tvec = tvecs[k].clone();
    cv::solvePnPRefineLM(
        object, normalized, identity, cv::noArray(), rvec, tvec,
        cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 50, 1e-10));
    rvecs[k] = rvec, tvecs[k] = tvec;
    if (tvec.at<double>(2) > 0.0) {  // in front of the camera
      rms[k] = reprojectionRms(object, observation.image_points, rvec, tvec, intrinsics);
    }
    if (best < 0 || rms[k] < rms[best]) best = k;
  }
  const double best_rms = rms[best];
  // Ambiguity: another local minimum, distinct from the best after refinement, that explains the
  // image nearly as well. Near-frontal views give two IPPE solutions that refine onto the same
  // minimum: no ambiguity there, whatever IPPE's raw errors say.
  double ambiguity = std::numeric_limits<double>::infinity();
  for (int k = 0; k < found; ++k) {
    if (k == best || !std::isfinite(rms[k])) continue;
    const Eigen::Matrix3d R_best = rotationFromRvec(rvecs[best]), R_k = rotationFromRvec(rvecs[k]);
    const double separation_deg =
        std::acos(std::max(-1.0, std::min(1.0, 0.5 * ((R_best.transpose() * R_k).trace() - 1.0)))) *
        180.0 / M_PI;
    if (separation_deg < kSameMinimumDeg) continue;
    ambiguity = std::min(ambiguity, rms[k] / std::max(best_rms, 1e-3));  // 1e-3 px: noise-free
  }
  if (best < 0 || !std::isfinite(best_rms)) return fail("PnP solution behind the camera");
  std::ostringstream reason;
  if (best_rms > settings.max_reprojection_rms_px) {
    reason << "reprojection RMS " << best_rms << " px > " << settings.max_reprojection_rms_px;
    return fail(reason.str());
  }
  if (ambiguity < settings.min_ambiguity_ratio) {
    reason << "ambiguous planar pose (second solution fits " << ambiguity
           << "x as badly, need >= " << settings.min_ambiguity_ratio
           << "): view the target more obliquely or closer";
    return fail(reason.str());
  }
  CameraPose pose;
  const Eigen::Matrix3d R_cam_target = rotationFromRvec(rvecs[best]);
  const Eigen::Vector3d t_cam_target(tvecs[best].at<double>(0), tvecs[best].at<double>(1),
                                     tvecs[best].at<double>(2));
  pose.R_target_cam = R_cam_target.transpose();
  pose.p_target_cam = -(R_cam_target.transpose() * t_cam_target);
  pose.reprojection_rms_px = reprojectionRms(object, observation.image_points, rvecs[best],
                                             tvecs[best], intrinsics, &pose.reprojection_mean_px);
  pose.ambiguity_ratio = ambiguity;
  pose.num_points = static_cast<int>(n);
  // A left perturbation of R_cam_target is a right one of R_target_cam (sign flipped).
  pose.cov_rotation_rad2 =
      rotationCovariance(object, pose.reprojection_rms_px, R_cam_target, t_cam_target, intrinsics);
  if (why) why->clear();
  return pose;
}

}  // namespace camera_imu_alignment
