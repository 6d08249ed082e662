// Does camera_info's camera model fit the images? A wrong focal length (the commonest camera_info
// mistake: another resolution's K, a nominal lens value) bends every PnP pose of an oblique board:
// the orientations are biased, the reprojection residuals form a scale-like pattern about the
// principal point, and downstream the poses disagree with the IMU as a remount or a bad axis would.
//
// One image of the board is fitted three ways, in undistorted pixels (camera_info's distortion
// removed, its K applied), each model nesting the one before:
//   pose:        PnP with camera_info's K (6 parameters),
//   focal:       PnP with both focal lengths scaled by one free factor s about the principal
//                point (7): the images' focal length is s times camera_info's,
//   homography:  a free plane-to-image homography (8). Any error of K is absorbed by it, so its
//                residual is the image's own noise (corner detection, the board's flatness, what
//                the distortion model misses), measured on the image, not assumed.
// The focal test of one view is the nested F test F = (SSR_pose - SSR_focal) / (SSR_homography /
// (2N - 8)), F(1, 2N - 8) distributed when K is right: the scale pattern stands out from the
// image's noise. Over a recording (checkCameraModel) one value per rest (its frames see the same
// view: averaged, not counted as independent) is combined: the views' focal factors must agree on
// a factor other than 1 beyond their own scatter, and the typical view must show the pattern on
// its own. No pixel threshold: both decisions are significance tests at one level.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/vision/camera_model.h"
#include "camera_imu_alignment/vision/target_description.h"
#include "camera_imu_alignment/vision/target_detector.h"

namespace camera_imu_alignment {

/// One view's three fits (see above). Sums of squared residuals over both coordinates, px^2.
struct CameraModelFit {
  int num_points = 0;
  double ssr_pose_px2 = 0.0;        ///< camera_info's K, 2N - 6 degrees of freedom
  double ssr_focal_px2 = 0.0;       ///< focal lengths scaled by focal_scale, 2N - 7
  double ssr_homography_px2 = 0.0;  ///< free homography, 2N - 8
  /// The images' focal length over camera_info's (both fx and fy), and its 1-sigma from the
  /// homography's noise. Large sigma: the view cannot tell (a board seen face on).
  double focal_scale = 1.0;
  double focal_scale_sigma = 0.0;
  double f_statistic = 0.0;          ///< (ssr_pose - ssr_focal) / (ssr_homography / (2N - 8))
  double p_value = 1.0;              ///< P(F(1, 2N - 8) > f_statistic)
  double reprojectionRmsPx() const;  ///< RMS distance of the pose fit, px
  double noiseRmsPx() const;         ///< RMS distance of the homography fit, px
};

/// The three fits of one observation; none with fewer than 6 points or when a fit fails.
std::optional<CameraModelFit> fitCameraModel(const TargetObservation& observation,
                                             const TargetDescription& target,
                                             const CameraIntrinsics& intrinsics);

/// The frames of one rest as one view: means of the sums, of the factor and of its 1-sigma (the
/// frames see the same view, so their agreement says nothing about the model), F and p of the
/// mean sums. Empty input: nullopt.
std::optional<CameraModelFit> combineFrames(const std::vector<CameraModelFit>& frames);

/// The recording's verdict on camera_info's model, from one view per rest.
struct CameraModelCheck {
  int views = 0;        ///< rests with at least one fitted frame
  bool tested = false;  ///< at least kMinViews views
  /// Both tests below are significant: camera_info does not describe the camera.
  bool wrong = false;
  /// The views' common focal factor (inverse-variance mean) and its 1-sigma, scaled by the views'
  /// scatter about it when that is larger than their own sigmas say.
  double focal_scale = 1.0, focal_scale_sigma = 0.0;
  double p_value = 1.0;              ///< of focal_scale != 1 (normal, two-sided)
  double view_p_value = 1.0;         ///< median over the views of their own p_value
  double reprojection_rms_px = 0.0;  ///< median over the views: with camera_info's K
  double noise_rms_px = 0.0;         ///< median over the views: the free homography's
  /// "" unless wrong; then "the camera intrinsics in camera_info do not fit the images: ...".
  std::string message;
  static constexpr int kMinViews = 2;
};

/// Judges `views` (combineFrames of each rest) at significance `level` (each test); the message
/// names the focal lengths in pixels when `intrinsics` (camera_info's) is given.
CameraModelCheck checkCameraModel(const std::vector<CameraModelFit>& views, double level,
                                  const CameraIntrinsics* intrinsics = nullptr);

}  // namespace camera_imu_alignment
