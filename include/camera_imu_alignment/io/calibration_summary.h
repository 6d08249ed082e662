// What a calibration run tells its user in text: the stdout summary with ready-to-paste blocks for
// other tools. Used by calibrate_bag; the PNG page is calibration_report.h.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/alignment_result.h"
#include "camera_imu_alignment/io/default_frames.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"

namespace camera_imu_alignment {

/// A known R_cam_imu to compare the estimate with (calibrate_bag --truth, e.g. simulate_bag's).
struct KnownTruth {
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();
  std::string source;  ///< where it came from (the file), shown beside the error
};

/// A judgement of the run beyond the solver's status (quality gates, consistency, a remount),
/// e.g. {false, "FAILED: remount at pose 6"}. Shown in the summary ("verdict: ...") and at the top
/// of the report's estimate panel (red when !passed); set by the caller that made it.
struct ReportVerdict {
  bool passed = true;
  std::string text;
};

struct ReportInput {
  AlignmentResult result;             ///< the final solve (status, R_cam_imu, quality)
  RotationPairs pairs;                ///< the pairs it was solved on (same order as
                                      ///< result.quality.pairs)
  std::vector<StationaryPose> poses;  ///< poses accepted, in recording order
  /// The estimate used the newest `window_poses` of `poses` (the solver's window; the pairs' pose
  /// indices count within it). 0: inferred from the pairs' pose indices and the joint estimate.
  std::size_t window_poses = 0;
  std::vector<RejectedPose> rejected;       ///< rests that did not become poses, with reasons
  std::vector<StationarySegment> segments;  ///< every IMU rest
  RejectionCounts rejections;               ///< inputs rejected by reason
  double start_s = 0.0, end_s = 0.0;        ///< recording span (s), for the time axis
  std::string camera_frame = kDefaultCameraFrame;
  std::string imu_frame = kDefaultImuFrame;
  std::string source;                    ///< e.g. the bag path, shown in the title
  std::optional<KnownTruth> truth;       ///< when given: the error to it is shown
  std::optional<ReportVerdict> verdict;  ///< when given: shown above the estimate
};

/// The stdout summary: R_cam_imu as quaternion (xyzw), matrix and roll/pitch/yaw (deg, the
/// x-y-z fixed-axis convention of tf: R = Rz(yaw) Ry(pitch) Rx(roll)), 1-sigma about the camera
/// axes, RMS residual, observability (and the axis to rotate about when not observable), poses
/// used / rejected with reasons, inputs rejected by reason, the figures per pose and the error to
/// the truth when given (report_figures.h), then exportBlocks(). Without an estimate
/// (hasEstimate(): nothing was solved) it says "R_cam_imu: no estimate" and prints no rotation, no
/// quality of one and no blocks.
std::string formatSummary(const ReportInput& input);

/// T_cam_imu's translation for the export blocks: the IMU's position in the camera frame (m) with
/// its 1-sigma where the motion measured it, else zeros and the reason it was not measured.
struct ExportTranslation {
  bool measured = false;
  Eigen::Vector3d p_cam_imu_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_m = Eigen::Vector3d::Zero();
  std::string not_measured_reason = "not measured: keep your measured translation";
};
/// The result's (translationNotMeasuredReason, result_yaml.h).
ExportTranslation exportTranslationOf(const AlignmentResult& result);

/// Ready-to-paste blocks, each introduced by comment lines naming the tool, the convention and
/// whether the translation was measured (with its 1-sigma) or why not (then 0):
///  - Kalibr camchain-imucam.yaml: T_cam_imu (4x4; translation p_cam_imu),
///  - OpenVINS kalibr_imucam_chain.yaml: T_imu_cam (4x4, R_imu_cam = R_cam_imu^T,
///    t_imu_cam = -R_imu_cam p_cam_imu),
///  - VINS-Mono / VINS-Fusion: extrinsicRotation (opencv-matrix, R_imu_cam: camera to body/IMU)
///    and, when measured, extrinsicTranslation (t_imu_cam),
///  - `rosrun tf2_ros static_transform_publisher x y z qx qy qz qw <camera_frame> <imu_frame>`
///    (parent camera, child IMU: the transform maps IMU-frame points into the camera frame).
/// With timeshift_cam_imu_s (estimated from motion) Kalibr's block carries it as
/// timeshift_cam_imu (t_imu = t_cam + timeshift_cam_imu).
std::string exportBlocks(const Eigen::Matrix3d& R_cam_imu, const std::string& camera_frame,
                         const std::string& imu_frame,
                         std::optional<double> timeshift_cam_imu_s = std::nullopt,
                         const ExportTranslation& translation = ExportTranslation());

}  // namespace camera_imu_alignment
