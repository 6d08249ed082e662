// Pinhole camera intrinsics as sensor_msgs/CameraInfo carries them (K, D, distortion_model).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace camera_imu_alignment {

struct CameraIntrinsics {
  enum class Distortion { kNone, kPlumbBob, kEquidistant };
  int width = 0, height = 0;                    ///< pixels
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();  ///< fx 0 cx; 0 fy cy; 0 0 1 (pixels)
  Distortion distortion = Distortion::kNone;
  std::vector<double> D;  ///< plumb_bob: k1 k2 p1 p2 k3 (5, or 4/8); equidistant: k1..k4

  /// From CameraInfo fields; `model` is the distortion_model string ("plumb_bob",
  /// "rational_polynomial", "equidistant", "" = none). Fails on an unknown model.
  static bool fromCameraInfo(int width, int height, const double K_row_major[9],
                             const std::string& model, const std::vector<double>& D,
                             CameraIntrinsics* intrinsics, std::string* error);
  /// Empty when usable, else what is wrong ("K is zero", "D has 3 coefficients, plumb_bob needs
  /// 5").
  std::string validate() const;
  cv::Mat cameraMatrix() const;  ///< CV_64F 3x3
  cv::Mat distCoeffs() const;    ///< CV_64F 1xN (empty for kNone)
  /// Undistorts pixels to normalised image coordinates (x/z, y/z), for either model.
  std::vector<cv::Point2d> undistortToNormalized(const std::vector<cv::Point2f>& pixels) const;
};

}  // namespace camera_imu_alignment
