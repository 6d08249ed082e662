#include "camera_imu_alignment/simulation/target_renderer.h"

#include <cmath>

namespace camera_imu_alignment {
namespace simulation {

bool PinholeCamera::project(const Eigen::Vector3d& p_cam, Eigen::Vector2d* pixel) const {
  if (p_cam.z() <= 1e-9) return false;
  *pixel = Eigen::Vector2d(fx * p_cam.x() / p_cam.z() + cx, fy * p_cam.y() / p_cam.z() + cy);
  return true;
}

Eigen::Vector3d CheckerboardTarget::corner(int r, int c) const {
  return Eigen::Vector3d(c * col_spacing_m, r * row_spacing_m, 0.0);
}

std::vector<Eigen::Vector3d> CheckerboardTarget::corners() const {
  std::vector<Eigen::Vector3d> out;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) out.push_back(corner(r, c));
  }
  return out;
}

double CheckerboardTarget::reflectance(double x, double y) const {
  // Squares span [-1, cols] x [-1, rows] in units of the spacing; one more square of white border.
  const double u = x / col_spacing_m, v = y / row_spacing_m;
  if (u < -2.0 || u > cols + 1.0 || v < -2.0 || v > rows + 1.0) return -1.0;
  if (u < -1.0 || u > cols || v < -1.0 || v > rows) return 1.0;  // white border
  const long i = static_cast<long>(std::floor(u)), j = static_cast<long>(std::floor(v));
  return ((i + j) % 2 == 0) ? 0.0 : 1.0;
}

cv::Mat renderCheckerboard(const PinholeCamera& camera, const CheckerboardTarget& target,
                           const Eigen::Matrix3d& R_cam_target, const Eigen::Vector3d& t_cam_target,
                           int supersample) {
  const Eigen::Matrix3d R_target_cam = R_cam_target.transpose();
  const Eigen::Vector3d origin = -R_target_cam * t_cam_target;  // camera centre, target frame
  constexpr double kBlack = 20.0, kWhite = 235.0, kBackground = 128.0;
  cv::Mat image(camera.height, camera.width, CV_8UC1);
  const int n = std::max(1, supersample);
  for (int row = 0; row < camera.height; ++row) {
    auto* out = image.ptr<unsigned char>(row);
    for (int col = 0; col < camera.width; ++col) {
      double sum = 0.0;
      for (int sy = 0; sy < n; ++sy) {
        for (int sx = 0; sx < n; ++sx) {
          // Sub-pixel sample centres over the pixel's area [col - 0.5, col + 0.5).
          const double u = col - 0.5 + (sx + 0.5) / n, v = row - 0.5 + (sy + 0.5) / n;
          const Eigen::Vector3d ray_cam((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy,
                                        1.0);
          const Eigen::Vector3d ray = R_target_cam * ray_cam;
          double value = kBackground;
          if (std::abs(ray.z()) > 1e-12) {
            const double s = -origin.z() / ray.z();
            if (s > 0.0) {
              const double refl =
                  target.reflectance(origin.x() + s * ray.x(), origin.y() + s * ray.y());
              if (refl >= 0.0) value = kBlack + refl * (kWhite - kBlack);
            }
          }
          sum += value;
        }
      }
      out[col] = static_cast<unsigned char>(std::lround(sum / (n * n)));
    }
  }
  return image;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
