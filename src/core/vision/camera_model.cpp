// Camera intrinsics from CameraInfo fields, their validation and undistortion.
#include "camera_imu_alignment/vision/camera_model.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <sstream>

namespace camera_imu_alignment {

bool CameraIntrinsics::fromCameraInfo(int width, int height, const double K_row_major[9],
                                      const std::string& model, const std::vector<double>& D,
                                      CameraIntrinsics* intrinsics, std::string* error) {
  CameraIntrinsics c;
  c.width = width;
  c.height = height;
  for (int i = 0; i < 9; ++i) c.K(i / 3, i % 3) = K_row_major[i];
  c.D = D;
  bool all_zero = true;
  for (double d : D) all_zero = all_zero && d == 0.0;
  if (model == "plumb_bob" || model == "rational_polynomial") {
    c.distortion = Distortion::kPlumbBob;
  } else if (model == "equidistant" || model == "fisheye") {
    c.distortion = Distortion::kEquidistant;
  } else if (model.empty() || model == "none") {
    if (!all_zero) {
      if (error) *error = "distortion_model is empty but D has non-zero coefficients";
      return false;
    }
    c.distortion = Distortion::kNone;
    c.D.clear();
  } else {
    if (error) {
      *error = "distortion_model '" + model +
               "' is not supported (plumb_bob, "
               "rational_polynomial, equidistant)";
    }
    return false;
  }
  // A distortion model with all-zero coefficients is the pinhole model.
  if (c.distortion != Distortion::kNone && all_zero && !D.empty()) {
    c.distortion = Distortion::kNone;
    c.D.clear();
  }
  const std::string problem = c.validate();
  if (!problem.empty()) {
    if (error) *error = problem;
    return false;
  }
  if (intrinsics) *intrinsics = c;
  if (error) error->clear();
  return true;
}

std::string CameraIntrinsics::validate() const {
  std::ostringstream out;
  if (width <= 0 || height <= 0) {
    out << "image size " << width << "x" << height << " is not positive";
  } else if (!K.allFinite()) {
    out << "K has NaN or Inf";
  } else if (K.isZero()) {
    out << "K is zero (camera not calibrated?)";
  } else if (!(K(0, 0) > 0.0) || !(K(1, 1) > 0.0)) {
    out << "K has a non-positive focal length (fx " << K(0, 0) << ", fy " << K(1, 1) << ")";
  } else if (K(1, 0) != 0.0 || K(2, 0) != 0.0 || K(2, 1) != 0.0 || std::abs(K(2, 2) - 1.0) > 1e-9) {
    out << "K is not of the form [fx s cx; 0 fy cy; 0 0 1]";
  } else {
    for (double d : D) {
      if (!std::isfinite(d)) {
        out << "D has NaN or Inf";
        return out.str();
      }
    }
    const std::size_t n = D.size();
    if (distortion == Distortion::kPlumbBob && n != 4 && n != 5 && n != 8) {
      out << "D has " << n << " coefficients, plumb_bob needs 5 (or 4, rational_polynomial 8)";
    } else if (distortion == Distortion::kEquidistant && n != 4) {
      out << "D has " << n << " coefficients, equidistant needs 4";
    } else if (distortion == Distortion::kNone && n != 0) {
      out << "D has " << n << " coefficients but no distortion model";
    }
  }
  return out.str();
}

cv::Mat CameraIntrinsics::cameraMatrix() const {
  cv::Mat m(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.at<double>(r, c) = K(r, c);
  }
  return m;
}

cv::Mat CameraIntrinsics::distCoeffs() const {
  if (distortion == Distortion::kNone || D.empty()) return cv::Mat();
  cv::Mat d(1, static_cast<int>(D.size()), CV_64F);
  for (std::size_t i = 0; i < D.size(); ++i) d.at<double>(0, static_cast<int>(i)) = D[i];
  return d;
}

std::vector<cv::Point2d> CameraIntrinsics::undistortToNormalized(
    const std::vector<cv::Point2f>& pixels) const {
  std::vector<cv::Point2d> out;
  if (pixels.empty()) return out;
  std::vector<cv::Point2d> in(pixels.begin(), pixels.end());
  if (distortion == Distortion::kNone) {
    const double fx = K(0, 0), fy = K(1, 1), s = K(0, 1), cx = K(0, 2), cy = K(1, 2);
    for (const auto& p : in) {
      const double y = (p.y - cy) / fy;
      out.emplace_back((p.x - cx - s * y) / fx, y);
    }
    return out;
  }
  if (distortion == Distortion::kEquidistant) {
    cv::fisheye::undistortPoints(in, out, cameraMatrix(), distCoeffs());
  } else {
    // Iterative undistortion; more iterations than the default for strong lenses.
    cv::undistortPoints(
        in, out, cameraMatrix(), distCoeffs(), cv::noArray(), cv::noArray(),
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-12));
  }
  return out;
}

}  // namespace camera_imu_alignment
