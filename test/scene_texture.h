// A deterministic corner-rich texture and pinhole views of it under a pure rotation, for the
// natural-scene rotation's test and benchmark (test_scene_rotation, bench_scene_rotation).
//
// The texture is the image of a scene at infinity seen by a reference camera G (orientation
// identity, focal `f` pixels, principal point at the texture's centre). A view with orientation
// R_G_cam and intrinsics K sees the texture pixel K_G R_G_cam K^-1 u at its pixel u, rendered with
// cv::warpPerspective (bilinear).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace camera_imu_alignment {
namespace test {

/// Random filled rectangles and ellipses at several scales (5-160 px) and grey levels on a
/// mid-grey ground, with a little blur (anti-aliasing), seeded by `seed`.
inline cv::Mat cornerTexture(int width, int height, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat texture(height, width, CV_8UC1, cv::Scalar(128));
  for (int scale = 160; scale >= 5; scale /= 2) {
    const int shapes = static_cast<int>(4.0 * width * height / (scale * scale * 8.0));
    for (int k = 0; k < shapes; ++k) {
      const cv::Point centre(rng.uniform(0, width), rng.uniform(0, height));
      const cv::Size half(rng.uniform(scale / 2, scale + 1), rng.uniform(scale / 2, scale + 1));
      const cv::Scalar grey(rng.uniform(0, 256));
      if (rng.uniform(0, 2) == 0) {
        cv::rectangle(texture, centre - cv::Point(half.width, half.height),
                      centre + cv::Point(half.width, half.height), grey, cv::FILLED);
      } else {
        cv::ellipse(texture, centre, half, rng.uniform(0.0, 180.0), 0, 360, grey, cv::FILLED,
                    cv::LINE_AA);
      }
    }
  }
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 0.8);
  return texture;
}

/// The view of `texture` (focal f, centred) by a camera with intrinsics K (pixels), image size
/// `size`, orientation R_G_cam. Rendered at 4x the resolution and averaged down (warpPerspective
/// interpolates at 1/32 pixel: without the supersampling its quantisation would be a systematic
/// error of a few hundredths of a pixel, above SIFT's noise on a clean rendering).
inline cv::Mat renderRotatedView(const cv::Mat& texture, double f, const Eigen::Matrix3d& K,
                                 const Eigen::Matrix3d& R_G_cam, cv::Size size) {
  constexpr int kSuper = 4;
  Eigen::Matrix3d K_G, K_super;
  K_G << f, 0, texture.cols / 2.0, 0, f, texture.rows / 2.0, 0, 0, 1;
  // Pixel centres: output pixel u averages the fine pixels kSuper u .. kSuper u + kSuper - 1.
  K_super << kSuper, 0, (kSuper - 1) / 2.0, 0, kSuper, (kSuper - 1) / 2.0, 0, 0, 1;
  const Eigen::Matrix3d H = K_G * R_G_cam * (K_super * K).inverse();  // fine pixel -> texture
  cv::Mat H_cv(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) H_cv.at<double>(r, c) = H(r, c);
  }
  cv::Mat fine, view;
  cv::warpPerspective(texture, fine, H_cv, size * kSuper, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(128));
  cv::resize(fine, view, size, 0, 0, cv::INTER_AREA);
  return view;
}

}  // namespace test
}  // namespace camera_imu_alignment
