// Matched features placed at the full resolution: where a `from` view's keypoint lies in the `to`
// view, to a fraction of SIFT's localisation at a reduced image scale (scene_rotation.cpp).
// Frames: image pixels, centres at integer coordinates.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace camera_imu_alignment {
namespace scene_geometry {

/// For each match (from_px[k] in `from`, to_px[k] in `to`, the keypoints as detected), the point
/// of the `to` image that shows the patch around from_px[k]: the `to` image is warped into the
/// `from` view by the matches' homography (the rotation's homography at infinity where the views
/// differ by a rotation; locally right elsewhere) and its brightness matched to `from`'s, then
/// Lucas-Kanade aligns a window around each `from` keypoint. refined[k] = false keeps to_px[k]
/// (no homography, the window lost or moved more than `max_shift_px` from the detection). Both
/// images mono8 of the same size; otherwise nothing is refined.
std::vector<cv::Point2f> refineMatchesAtFullResolution(const cv::Mat& from, const cv::Mat& to,
                                                       const std::vector<cv::Point2f>& from_px,
                                                       const std::vector<cv::Point2f>& to_px,
                                                       double max_shift_px,
                                                       std::vector<bool>* refined);

}  // namespace scene_geometry
}  // namespace camera_imu_alignment
