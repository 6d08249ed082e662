// Image synthesis of the room scenarios (room_scene.h): for every supersample of a pixel the ray
// (undistorted once and cached, as ImageRenderer's) is intersected with the room's faces and the
// boxes, the nearest surface's texture is evaluated at the hit point, and the supersamples go
// through the same box average, photometry and blur as the board's images (renderer.h).
//
// Frames: room = world (ENU, m); camera optical (z forward, x right, y down). Pixel convention and
// distortion as renderer.h. Cost: the texture is evaluated per sample, about 0.23 s of one core
// per 640 x 480 frame at supersample 2 (the room scenarios' default), 0.55 s at 3 (measured on
// this package's development machine; cv::parallel_for_ spreads it over the cores).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/room_scene.h"
#include "camera_imu_alignment/simulation/trajectory.h"

namespace camera_imu_alignment {
namespace simulation {

class SceneRenderer {
 public:
  SceneRenderer(const CameraModel& camera, RoomScene scene, int supersample, double blur_sigma_px,
                Photometry photometry = Photometry());

  /// Noise-free, blurred image (CV_32F grey levels) of the room seen by a camera at `p_world_cam`
  /// (m) with orientation `R_world_cam`, the boxes where they are at time t (s).
  cv::Mat render(const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& p_world_cam,
                 double t = 0.0) const;

  /// Same at trajectory time t (s), with the motion-blur rule of exposureAverage (renderer.h).
  cv::Mat renderAt(const Trajectory& trajectory, double t, double exposure_s = 0.0) const;

  /// Depth (m, along the camera's z) of the nearest surface at every pixel centre: CV_32F,
  /// height x width, no supersampling; NaN where undistortion fails.
  cv::Mat depth(const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& p_world_cam,
                double t = 0.0) const;

  const CameraModel& camera() const { return camera_; }
  const RoomScene& scene() const { return scene_; }

 private:
  /// Reflectance (or depth) of every sample of a ray grid, through `value` of the hit.
  template <typename Value>
  cv::Mat trace(const cv::Mat& ray_x, const cv::Mat& ray_y, const Eigen::Matrix3d& R,
                const Eigen::Vector3d& p, double t, float missing, Value value) const;

  CameraModel camera_;
  RoomScene scene_;
  int supersample_;
  double blur_sigma_;
  Photometry photometry_;
  cv::Mat ray_x_, ray_y_;  ///< supersampled grid (undistortedRayGrid)
};

}  // namespace simulation
}  // namespace camera_imu_alignment
