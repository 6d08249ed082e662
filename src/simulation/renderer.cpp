#include "camera_imu_alignment/simulation/renderer.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>

namespace camera_imu_alignment {
namespace simulation {

double textureTexelFor(const SimulationConfig& c) {
  const double distance = 0.5 * (c.min_distance_m + c.max_distance_m);
  const double texel = distance / (std::max(c.fx, c.fy) * c.supersample);
  return std::min(std::max(texel, 0.1e-3), std::min(2e-3, c.target.spacing_m / 40.0));
}

CameraModel CameraModel::fromConfig(const SimulationConfig& c) {
  CameraModel cam;
  cam.width = c.width;
  cam.height = c.height;
  cam.fx = c.fx;
  cam.fy = c.fy;
  cam.cx = c.cx;
  cam.cy = c.cy;
  cam.distortion = c.distortion;
  return cam;
}

Eigen::Vector2d CameraModel::distort(const Eigen::Vector2d& xy) const {
  const double k1 = distortion[0], k2 = distortion[1], p1 = distortion[2], p2 = distortion[3],
               k3 = distortion[4];
  const double x = xy.x(), y = xy.y(), r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return Eigen::Vector2d(x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
                         y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y);
}

Eigen::Vector2d CameraModel::project(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d d = distort(Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()));
  return Eigen::Vector2d(fx * d.x() + cx, fy * d.y() + cy);
}

bool CameraModel::undistort(const Eigen::Vector2d& pixel, Eigen::Vector2d* xy) const {
  const Eigen::Vector2d xd((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  Eigen::Vector2d x = xd;
  // Newton's method on distort(x) = xd with a numerical Jacobian.
  for (int it = 0; it < 30; ++it) {
    const Eigen::Vector2d r = distort(x) - xd;
    if (r.norm() < 1e-12) break;
    constexpr double h = 1e-7;
    Eigen::Matrix2d J;
    J.col(0) = (distort(x + Eigen::Vector2d(h, 0.0)) - distort(x)) / h;
    J.col(1) = (distort(x + Eigen::Vector2d(0.0, h)) - distort(x)) / h;
    if (std::abs(J.determinant()) < 1e-9) return false;
    x -= J.inverse() * r;
  }
  *xy = x;
  return x.allFinite() && (distort(x) - xd).norm() < 1e-9;
}

void undistortedRayGrid(const CameraModel& camera, int supersample, cv::Mat* ray_x,
                        cv::Mat* ray_y) {
  const int S = supersample, W = camera.width * S, H = camera.height * S;
  ray_x->create(H, W, CV_32F);
  ray_y->create(H, W, CV_32F);
  const bool distorted = camera.distortion != std::array<double, 5>{0.0, 0.0, 0.0, 0.0, 0.0};
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      float* rx = ray_x->ptr<float>(i);
      float* ry = ray_y->ptr<float>(i);
      const double v = (i + 0.5) / S - 0.5;
      for (int j = 0; j < W; ++j) {
        const double u = (j + 0.5) / S - 0.5;
        Eigen::Vector2d xy((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy);
        if (distorted && !camera.undistort(Eigen::Vector2d(u, v), &xy)) {
          xy.setConstant(std::numeric_limits<double>::quiet_NaN());
        }
        rx[j] = static_cast<float>(xy.x());
        ry[j] = static_cast<float>(xy.y());
      }
    }
  });
}

cv::Mat finishImage(const cv::Mat& sampled, const CameraModel& camera, int supersample,
                    const Photometry& photometry, double blur_sigma_px) {
  cv::Mat image;
  if (supersample > 1) {
    cv::resize(sampled, image, cv::Size(camera.width, camera.height), 0, 0, cv::INTER_AREA);
  } else {
    image = sampled;
  }
  image = photometry.black + (photometry.white - photometry.black) * image;
  if (blur_sigma_px > 0.0) cv::GaussianBlur(image, image, cv::Size(0, 0), blur_sigma_px);
  return image;
}

cv::Mat exposureAverage(const Trajectory& trajectory, double t, double exposure_s,
                        const std::function<cv::Mat(double)>& view) {
  const bool moving = trajectory.at(t).pose < 0 || trajectory.at(t - 0.5 * exposure_s).pose < 0 ||
                      trajectory.at(t + 0.5 * exposure_s).pose < 0;
  if (exposure_s <= 0.0 || !moving) return view(t);
  constexpr int kSubframes = 5;
  cv::Mat sum;
  for (int i = 0; i < kSubframes; ++i) {
    const cv::Mat frame = view(t + exposure_s * ((i + 0.5) / kSubframes - 0.5));
    if (sum.empty()) {
      sum = frame.clone();
    } else {
      sum += frame;
    }
  }
  return sum / kSubframes;
}

ImageRenderer::ImageRenderer(const CameraModel& camera, TargetTexture texture, int supersample,
                             double blur_sigma_px, Photometry photometry)
    : camera_(camera),
      texture_(std::move(texture)),
      supersample_(supersample),
      blur_sigma_(blur_sigma_px),
      photometry_(photometry) {
  undistortedRayGrid(camera_, supersample_, &ray_x_, &ray_y_);
}

cv::Mat ImageRenderer::render(const Eigen::Matrix3d& R, const Eigen::Vector3d& c) const {
  const int H = ray_x_.rows, W = ray_x_.cols;
  cv::Mat map_x(H, W, CV_32F), map_y(H, W, CV_32F);
  const TargetTexture& tex = texture_;
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const float* rx = ray_x_.ptr<float>(i);
      const float* ry = ray_y_.ptr<float>(i);
      float* mx = map_x.ptr<float>(i);
      float* my = map_y.ptr<float>(i);
      for (int j = 0; j < W; ++j) {
        const double x = rx[j], y = ry[j];
        const double dx = R(0, 0) * x + R(0, 1) * y + R(0, 2);
        const double dy = R(1, 0) * x + R(1, 1) * y + R(1, 2);
        const double dz = R(2, 0) * x + R(2, 1) * y + R(2, 2);
        const double lambda = -c.z() / dz;  // ray c + lambda d meets z = 0
        if (!(lambda > 0.0) || !std::isfinite(lambda)) {
          mx[j] = my[j] = -1e6f;
          continue;
        }
        mx[j] = static_cast<float>(tex.col(c.x() + lambda * dx));
        my[j] = static_cast<float>(tex.row(c.y() + lambda * dy));
      }
    }
  });
  cv::Mat sampled;
  cv::remap(tex.reflectance, sampled, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(photometry_.background));
  return finishImage(sampled, camera_, supersample_, photometry_, blur_sigma_);
}

cv::Mat ImageRenderer::renderAt(const Trajectory& trajectory, double t, double exposure_s) const {
  const auto view = [&](double time) {
    const RigState st = trajectory.at(time);
    const Eigen::Matrix3d R_target_cam = trajectory.R_world_target().transpose() * st.R_world_cam;
    const Eigen::Vector3d p_target_cam =
        trajectory.R_world_target().transpose() * (st.p_world_cam - trajectory.p_world_target());
    return render(R_target_cam, p_target_cam);
  };
  return exposureAverage(trajectory, t, exposure_s, view);
}

cv::Mat ImageRenderer::toMono8(const cv::Mat& grey, double noise_sigma, std::uint64_t noise_seed) {
  cv::Mat noisy = grey.clone();
  if (noise_sigma > 0.0) {
    cv::Mat noise(grey.size(), CV_32F);
    cv::RNG rng(noise_seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    noisy += noise;
  }
  cv::Mat out;
  noisy.convertTo(out, CV_8U);  // rounds to nearest and saturates
  return out;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
