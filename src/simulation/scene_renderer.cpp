#include "camera_imu_alignment/simulation/scene_renderer.h"

#include <cmath>
#include <limits>
#include <utility>

namespace camera_imu_alignment {
namespace simulation {

SceneRenderer::SceneRenderer(const CameraModel& camera, RoomScene scene, int supersample,
                             double blur_sigma_px, Photometry photometry)
    : camera_(camera),
      scene_(std::move(scene)),
      supersample_(supersample),
      blur_sigma_(blur_sigma_px),
      photometry_(photometry) {
  undistortedRayGrid(camera_, supersample_, &ray_x_, &ray_y_);
}

template <typename Value>
cv::Mat SceneRenderer::trace(const cv::Mat& ray_x, const cv::Mat& ray_y, const Eigen::Matrix3d& R,
                             const Eigen::Vector3d& p, double t, float missing, Value value) const {
  const RoomScene frozen = scene_.frozenAt(t);
  cv::Mat out(ray_x.size(), CV_32F);
  cv::parallel_for_(cv::Range(0, ray_x.rows), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const float* rx = ray_x.ptr<float>(i);
      const float* ry = ray_y.ptr<float>(i);
      float* o = out.ptr<float>(i);
      for (int j = 0; j < ray_x.cols; ++j) {
        // The ray's direction in the room frame; its camera z component is 1, so the hit's ray
        // parameter is the depth along the optical axis.
        const Eigen::Vector3d d = R * Eigen::Vector3d(rx[j], ry[j], 1.0);
        SurfaceHit hit;
        o[j] = frozen.intersect(p, d, 0.0, &hit) ? static_cast<float>(value(frozen, hit)) : missing;
      }
    }
  });
  return out;
}

cv::Mat SceneRenderer::render(const Eigen::Matrix3d& R_world_cam,
                              const Eigen::Vector3d& p_world_cam, double t) const {
  const cv::Mat sampled =
      trace(ray_x_, ray_y_, R_world_cam, p_world_cam, t, static_cast<float>(photometry_.background),
            [](const RoomScene& scene, const SurfaceHit& hit) {
              return scene.reflectance(hit.surface, hit.u, hit.v);
            });
  return finishImage(sampled, camera_, supersample_, photometry_, blur_sigma_);
}

cv::Mat SceneRenderer::renderAt(const Trajectory& trajectory, double t, double exposure_s) const {
  const auto view = [&](double time) {
    const RigState st = trajectory.at(time);
    return render(st.R_world_cam, st.p_world_cam, time);
  };
  return exposureAverage(trajectory, t, exposure_s, view);
}

cv::Mat SceneRenderer::depth(const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& p_world_cam,
                             double t) const {
  cv::Mat ray_x, ray_y;
  undistortedRayGrid(camera_, 1, &ray_x, &ray_y);
  return trace(ray_x, ray_y, R_world_cam, p_world_cam, t, std::numeric_limits<float>::quiet_NaN(),
               [](const RoomScene&, const SurfaceHit& hit) { return hit.distance; });
}

}  // namespace simulation
}  // namespace camera_imu_alignment
