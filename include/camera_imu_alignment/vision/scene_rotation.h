// The camera's rotation between two views of a natural scene (no calibration target): features
// at each view (SIFT: sub-pixel, scale-invariant), robust matching, and the relative rotation with
// its covariance, for any baseline: a rotation about the camera centre or a distant scene (the
// homography at infinity, rotation only) as well as a rig moved metres between the views (the
// essential matrix), the model chosen by the data (GRIC), refined with a translation-free cost.
//
// Frames: camera optical frames (z forward, x right, y down). R_from_to maps vectors in the `to`
// view's camera frame into the `from` view's: with a world-fixed frame G,
// R_G_cam_to = R_G_cam_from R_from_to. Bearings are unit vectors in the camera frame
// (undistorted through camera_info's model). Covariances are in rad^2, `to` camera axes, right
// perturbation R_from_to Exp(delta).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "camera_imu_alignment/vision/camera_model.h"

namespace camera_imu_alignment {

struct SceneFeatureSettings {
  int max_features = 1500;  ///< strongest SIFT keypoints kept per view
  int octave_layers = 3;    ///< SIFT layers per octave (fewer: faster, fewer keypoints)
  /// SIFT's contrast threshold (OpenCV's default; OpenCV divides it by octave_layers): lower finds
  /// keypoints in fainter texture (a plain wall, a table), weaker ones.
  double contrast_threshold = 0.04;
  /// The image is resized by this factor (0 < image_scale <= 1, area averaging) before SIFT;
  /// keypoints and bearings are in the full image's pixels. 0.5 costs less than half the time of
  /// 1 (SIFT's first octave works at twice the resolution it is given) and drops the finest
  /// scale. With 1000 features and SceneRotationSettings::refine_matches (the fast profile) it
  /// meets the cost targets and is more accurate hand-held, less so where a robot drove between
  /// views with objects moved (BENCHMARKS.md, "Natural-scene rotation").
  double image_scale = 1.0;
};

/// The features of one view (a rest's sharpest frame).
struct SceneFeatures {
  double stamp_s = 0;  ///< the frame's stamp (camera clock, s)
  /// Pixels of the (distorted) image, pixel centres at integer coordinates (OpenCV's SIFT
  /// positions corrected for the quarter-pixel offset of its upsampled first octave).
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;                    ///< one row per keypoint (CV_32F, SIFT)
  std::vector<Eigen::Vector3d> bearings;  ///< unit vectors, camera frame, one per keypoint
  /// The full-resolution mono8 image the features came from (shared, not copied), for the
  /// matches' refinement; empty: the matches stay where the keypoints were detected.
  cv::Mat image;
};

/// Sharpness of a mono8 image (variance of its Laplacian; larger is sharper): picks a rest's
/// frame least blurred by residual motion.
double imageSharpness(const cv::Mat& mono8);

/// SIFT keypoints and descriptors of a mono8 image with their undistorted bearings. An unusable
/// image (empty, not mono8, intrinsics of another size) gives no features.
SceneFeatures extractSceneFeatures(const cv::Mat& mono8, const CameraIntrinsics& intrinsics,
                                   const SceneFeatureSettings& settings, double stamp_s);

enum class SceneMotionModel {
  kRotationOnly,  ///< rotation about the camera centre or a distant scene (homography at infinity)
  kGeneral        ///< rotation and translation (essential matrix)
};

struct SceneRotationSettings {
  double ratio_test = 0.8;  ///< Lowe's ratio of the best to the second-best descriptor distance
  /// Fewer inliers than this: no rotation (too little overlap, texture or a scene that moved).
  int min_inliers = 40;
  /// RANSAC gate on a match's transfer / epipolar error (pixels of the undistorted image). It only
  /// separates gross mismatches: the inliers are then re-selected at the chi-square 99.9 % bound of
  /// the noise estimated from them, and the covariance's sigma comes from their residuals.
  double ransac_threshold_px = 3.0;
  /// A gyro-predicted rotation further than this (deg) from the estimate fails the pair
  /// (a repetitive texture's wrong but consistent matches); 0: not checked.
  double max_prediction_difference_deg = 5.0;
  /// A near-planar view's other essential matrix is kept as an alternative (SceneRotation) when it
  /// holds at least this share of the chosen model's inliers.
  double alternative_inlier_share = 0.9;
  /// Each match's position in the `to` view refined at the full resolution: the `to` image warped
  /// into the `from` view by the matches' homography, then Lucas-Kanade on a window around the
  /// `from` keypoint (both views' images needed). What SIFT at a reduced image_scale loses in
  /// localisation, at a fraction of a full-resolution SIFT's cost. Off by default: on the robot's
  /// stops with moved objects it made the estimate worse (BENCHMARKS.md).
  bool refine_matches = false;
  /// A refinement that moves a match further than this (pixels of the full image) from where it was
  /// detected has locked onto other texture: the match keeps its detected position.
  double refine_max_shift_px = 2.0;
};

/// The natural scene's feature profiles (the setting scene_profile).
enum class SceneProfile {
  kFull,  ///< the defaults: SIFT on the full image, 1500 features, matches where detected
  /// SIFT on the image halved with 1000 features, each match refined at the full resolution
  /// (49 ms per view, 28 ms per pair on one core: the cost targets). Not the default:
  /// with objects moving in view 1.4-1.7x the static scene's error, and not always within 3
  /// sigma (BENCHMARKS.md, "Calibration without a board").
  kFast,
  kCustom,  ///< settings that are neither (sceneProfileOf only)
};
/// "full", "fast", "custom".
const char* toString(SceneProfile profile);
/// "full" or "fast" (not "custom"); false on any other word.
bool parseSceneProfile(const std::string& word, SceneProfile* profile);
/// Sets the settings that make up `profile` (image_scale, max_features, refine_matches); the
/// others keep their values. kCustom changes nothing.
void useSceneProfile(SceneProfile profile, SceneFeatureSettings* features,
                     SceneRotationSettings* rotation);
/// The profile the settings are, or kCustom.
SceneProfile sceneProfileOf(const SceneFeatureSettings& features,
                            const SceneRotationSettings& rotation);

/// Matches between two views' features.
struct SceneMatches {
  std::vector<std::pair<int, int>> indices;  ///< (index into `from`, index into `to`)
  /// Per match, its position in the `to` image (pixels; refined where `refined`, else the
  /// keypoint's). Empty: the keypoints' positions.
  std::vector<cv::Point2f> to_px;
  int refined = 0;  ///< matches whose `to` position was refined at the full resolution
  size_t size() const { return indices.size(); }
};

/// Another rotation that explains the matches about as well as the chosen one (a near-planar
/// view's second essential matrix): the joint estimate may take it instead when the IMU says so.
struct SceneRotationAlternative {
  Eigen::Matrix3d R_from_to = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d cov_rad2 = Eigen::Matrix3d::Zero();  ///< `to` camera axes, right perturbation
  int inliers = 0;
  double residual_rms_px = 0;
};

/// The camera's rotation between two views, with what the fit says about it.
struct SceneRotation {
  bool ok = false;
  std::string message;  ///< why not, with the counts (matches, inliers)
  Eigen::Matrix3d R_from_to = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d cov_rad2 = Eigen::Matrix3d::Zero();  ///< `to` camera axes, right perturbation
  SceneMotionModel model = SceneMotionModel::kRotationOnly;
  /// kGeneral: the unit direction of the `to` camera centre in the `from` camera frame.
  Eigen::Vector3d translation_direction = Eigen::Vector3d::Zero();
  int matches = 0;          ///< after the ratio test and the mutual check
  int refined_matches = 0;  ///< of them, placed at the full resolution (refine_matches)
  int inliers = 0;          ///< of the chosen model
  /// Of the inliers, those on a second motion that shares the rotation (an object slid between
  /// the views; estimateSceneRotationNear only): they measure the rotation too.
  int second_motion_inliers = 0;
  /// The inliers' noise per image coordinate under the chosen model (pixels): the RMS of their
  /// first-order geometric distances over the degrees of freedom; the sigma of cov_rad2.
  double residual_rms_px = 0;
  /// Other solutions holding at least SceneRotationSettings::alternative_inlier_share of the
  /// chosen model's inliers, more than 3 of its sigmas away from it.
  std::vector<SceneRotationAlternative> alternatives;
  /// The matches the fit started from (ratio test and mutual check), to fit the pair again
  /// without matching (estimateSceneRotationNear).
  SceneMatches matched;
};

/// The rotation between two views. `R_from_to_prediction` (e.g. the gyro's, through the current
/// R_cam_imu) seeds the refinement (one more hypothesis of the rotation-only RANSAC) and checks the
/// result (SceneRotationSettings); it may be absent. ok = false with a message naming the counts
/// (features and stamps of both views, matches, inliers) when the features, matches or inliers are
/// too few; a result too far from the prediction is ok = false with its rotation, model and counts
/// filled in. Deterministic: the same features give the same result. The method: doc/method.md,
/// "The camera's rotation from the natural scene".
SceneRotation estimateSceneRotation(const SceneFeatures& from, const SceneFeatures& to,
                                    const CameraIntrinsics& intrinsics,
                                    const std::optional<Eigen::Matrix3d>& R_from_to_prediction,
                                    const SceneRotationSettings& settings);

/// The rotation between two views with the rotation held near `R_from_to_near` while each model's
/// inliers are chosen (within `gate_px`, at most SceneRotationSettings::ransac_threshold_px), then
/// refined freely and chosen by GRIC: for a pair whose free fit the IMU contradicts. Two motions in
/// view that share the rotation (the room, and an object moved between the views) make a free fit
/// at a loose gate average them into a compromise; with the rotation held, the translation found
/// holds one of them, and either gives the camera's rotation. The matches outside that motion's
/// gate may hold a second translation with the same rotation: the two are then fitted together
/// (second_motion_inliers) when GRIC prefers them. The gate must cover the prediction's
/// error (pixels: focal length times its angle) and the image noise. Results as
/// estimateSceneRotation (no alternatives; no prediction check). `matched` (optional): the pair's
/// matches from an earlier fit (SceneRotation::matched), which saves matching them again.
SceneRotation estimateSceneRotationNear(const SceneFeatures& from, const SceneFeatures& to,
                                        const CameraIntrinsics& intrinsics,
                                        const Eigen::Matrix3d& R_from_to_near, double gate_px,
                                        const SceneRotationSettings& settings,
                                        const SceneMatches* matched = nullptr);

}  // namespace camera_imu_alignment
