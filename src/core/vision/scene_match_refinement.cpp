// Matched features placed at the full resolution (scene_match_refinement.h): OpenCV's homography,
// perspective warp and pyramidal Lucas-Kanade.
#include "scene_match_refinement.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace camera_imu_alignment {
namespace scene_geometry {
namespace {

/// Lucas-Kanade's window (pixels): large enough for a keypoint's texture at the finest SIFT scale
/// of a half-resolution image, small enough that a view's perspective changes little across it.
constexpr int kWindowPx = 15;
/// The homography's RANSAC gate (pixels): it only has to bring each patch within the window.
constexpr double kHomographyGatePx = 8.0;

cv::Point2f apply(const cv::Matx33d& H, const cv::Point2f& p) {
  const cv::Vec3d q = H * cv::Vec3d(p.x, p.y, 1.0);
  return {static_cast<float>(q[0] / q[2]), static_cast<float>(q[1] / q[2])};
}

}  // namespace

std::vector<cv::Point2f> refineMatchesAtFullResolution(const cv::Mat& from, const cv::Mat& to,
                                                       const std::vector<cv::Point2f>& from_px,
                                                       const std::vector<cv::Point2f>& to_px,
                                                       double max_shift_px,
                                                       std::vector<bool>* refined) {
  std::vector<cv::Point2f> out = to_px;
  refined->assign(to_px.size(), false);
  if (from.empty() || to.empty() || from.type() != CV_8UC1 || to.type() != CV_8UC1 ||
      from.size() != to.size() || from_px.size() != to_px.size() || to_px.size() < 8) {
    return out;
  }
  // `to` into `from`'s view: warped(H p) = to(p).
  const cv::Mat H = cv::findHomography(to_px, from_px, cv::RANSAC, kHomographyGatePx);
  if (H.empty() || !cv::checkRange(H)) return out;
  const cv::Matx33d to_into_from(H);
  cv::Matx33d back;
  if (!cv::invert(to_into_from, back, cv::DECOMP_LU)) return out;
  cv::Mat warped, covered;
  cv::warpPerspective(to, warped, to_into_from, from.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  // An exposure change between the views, as a gain and an offset over the shared area (the
  // warp's border is black; the few black pixels of the image itself count as outside).
  cv::compare(warped, 0, covered, cv::CMP_GT);
  cv::Scalar mean_from, std_from, mean_to, std_to;
  cv::meanStdDev(from, mean_from, std_from, covered);
  cv::meanStdDev(warped, mean_to, std_to, covered);
  if (std_to[0] > 1.0 && std_from[0] > 1.0) {
    const double gain = std_from[0] / std_to[0];
    warped.convertTo(warped, CV_8UC1, gain, mean_from[0] - gain * mean_to[0]);
  }
  std::vector<cv::Point2f> start(to_px.size()), tracked;
  for (size_t k = 0; k < to_px.size(); ++k) start[k] = apply(to_into_from, to_px[k]);
  tracked = start;
  std::vector<uchar> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(
      from, warped, from_px, tracked, status, error, cv::Size(kWindowPx, kWindowPx), 0,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.005),
      cv::OPTFLOW_USE_INITIAL_FLOW);
  for (size_t k = 0; k < to_px.size(); ++k) {
    if (!status[k] || !std::isfinite(tracked[k].x) || !std::isfinite(tracked[k].y)) continue;
    const cv::Point2f p = apply(back, tracked[k]);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || cv::norm(p - to_px[k]) > max_shift_px)
      continue;
    out[k] = p;
    (*refined)[k] = true;
  }
  return out;
}

}  // namespace scene_geometry
}  // namespace camera_imu_alignment
