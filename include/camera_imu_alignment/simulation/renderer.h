// Image synthesis of the simulator: exact pinhole + plumb_bob projection of the target texture.
// For every (supersampled) output pixel the distorted pixel is undistorted (once, cached), the ray
// is intersected with the target plane and the texture is sampled bilinearly; supersamples are
// box-averaged into pixels, so edges and corners keep their sub-pixel positions.
//
// Pixel convention: OpenCV's, pixel (0, 0) is centred on (0, 0); camera frame optical (z forward,
// x right, y down); distortion coefficients (k1, k2, p1, p2, k3) as in OpenCV/ROS plumb_bob.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>

#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/simulation/trajectory.h"

namespace camera_imu_alignment {
namespace simulation {

struct CameraModel {
  int width = 640, height = 480;
  double fx = 500.0, fy = 500.0, cx = 319.5, cy = 239.5;      ///< pixels
  std::array<double, 5> distortion{0.0, 0.0, 0.0, 0.0, 0.0};  ///< k1, k2, p1, p2, k3

  static CameraModel fromConfig(const SimulationConfig& config);
  /// Normalised undistorted (x/z, y/z) -> normalised distorted coordinates.
  Eigen::Vector2d distort(const Eigen::Vector2d& xy) const;
  /// Pixel of a point in the camera frame (m, z > 0), distortion applied.
  Eigen::Vector2d project(const Eigen::Vector3d& p_cam) const;
  /// Normalised undistorted coordinates of a (distorted) pixel; false if the iteration fails.
  bool undistort(const Eigen::Vector2d& pixel, Eigen::Vector2d* xy) const;
};

/// Texel size (m) for `config`: about the footprint of one supersample on the target at the mean
/// viewing distance, so that the area-exact texture is also the right prefilter (a much finer
/// texture point-sampled by the supersamples aliases at edges; measured: 0.25 mm gives ~0.1 px
/// corner errors, 0.5 mm ~0.07 px at the default camera).
double textureTexelFor(const SimulationConfig& config);

/// Grey levels of the rendered scene (mono8).
struct Photometry {
  double black = 25.0, white = 225.0;  ///< grey levels of reflectance 0 and 1
  double background = 0.45;            ///< reflectance outside the board
};

/// The undistorted normalised coordinates (x/z, y/z; NaN where undistortion fails) of every
/// supersample of `camera`'s image: CV_32F, (height * supersample) x (width * supersample), the
/// supersample (i, j) centred on pixel ((j + 0.5) / S - 0.5, (i + 0.5) / S - 0.5). Computed once
/// per renderer: the ray of every sample in the camera frame is (x, y, 1).
void undistortedRayGrid(const CameraModel& camera, int supersample, cv::Mat* ray_x, cv::Mat* ray_y);

/// The path every render ends with: the supersampled reflectance (CV_32F, 0-1) box-averaged into
/// pixels, mapped to grey levels by `photometry`, Gaussian-blurred by blur_sigma_px (CV_32F).
cv::Mat finishImage(const cv::Mat& sampled_reflectance, const CameraModel& camera, int supersample,
                    const Photometry& photometry, double blur_sigma_px);

/// The motion-blur rule of renderAt: with exposure_s > 0 and the rig moving at t or at either end
/// of the exposure, the mean of view() at 5 times spread over it; else view(t).
cv::Mat exposureAverage(const Trajectory& trajectory, double t, double exposure_s,
                        const std::function<cv::Mat(double)>& view);

class ImageRenderer {
 public:
  ImageRenderer(const CameraModel& camera, TargetTexture texture, int supersample,
                double blur_sigma_px, Photometry photometry = Photometry());

  /// Noise-free, blurred image (CV_32F grey levels) of the target seen by a camera at
  /// `p_target_cam` (camera centre in the target frame, m) with orientation `R_target_cam`.
  cv::Mat render(const Eigen::Matrix3d& R_target_cam, const Eigen::Vector3d& p_target_cam) const;

  /// Same at trajectory time t (s); with exposure_s > 0 and the rig moving, the average of 5
  /// renders over [t - exposure/2, t + exposure/2] (motion blur).
  cv::Mat renderAt(const Trajectory& trajectory, double t, double exposure_s = 0.0) const;

  /// Adds Gaussian pixel noise (sigma in grey levels; deterministic in `noise_seed`), rounds and
  /// saturates to CV_8U.
  static cv::Mat toMono8(const cv::Mat& grey, double noise_sigma, std::uint64_t noise_seed);

  const CameraModel& camera() const { return camera_; }

 private:
  CameraModel camera_;
  TargetTexture texture_;
  int supersample_;
  double blur_sigma_;
  Photometry photometry_;
  cv::Mat ray_x_, ray_y_;  ///< CV_32F, supersampled grid: undistorted x/z, y/z (NaN: invalid)
};

}  // namespace simulation
}  // namespace camera_imu_alignment
