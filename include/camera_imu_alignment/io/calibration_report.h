// What a calibration run tells its user: the stdout summary with ready-to-paste blocks for other
// tools, and a one-page PNG report. Used by calibrate_bag (and the nodelet's save service).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/solver/alignment_solver.h"

namespace camera_imu_alignment {

struct ReportInput {
  AlignmentResult result;                   ///< the final solve (status, R_cam_imu, quality)
  RotationPairs pairs;                      ///< the pairs it was solved on (same order as
                                            ///< result.quality.pairs)
  std::vector<StationaryPose> poses;        ///< poses accepted
  std::vector<RejectedPose> rejected;       ///< rests that did not become poses, with reasons
  std::vector<StationarySegment> segments;  ///< every IMU rest
  RejectionCounts rejections;               ///< inputs rejected by reason
  double start_s = 0.0, end_s = 0.0;        ///< recording span (s), for the time axis
  std::string camera_frame = "camera_optical_frame";
  std::string imu_frame = "imu_link";
  std::string source;  ///< e.g. the bag path, shown in the title
};

/// The stdout summary: R_cam_imu as quaternion (xyzw), matrix and roll/pitch/yaw (deg, the
/// x-y-z fixed-axis convention of tf: R = Rz(yaw) Ry(pitch) Rx(roll)), 1-sigma about the camera
/// axes, RMS residual, observability (and the axis to rotate about when not observable), poses
/// used / rejected with reasons, inputs rejected by reason, then exportBlocks().
std::string formatSummary(const ReportInput& input);

/// Ready-to-paste blocks, each introduced by a comment line naming the tool and the convention:
///  - Kalibr camchain-imucam.yaml: T_cam_imu (4x4, zero translation),
///  - OpenVINS kalibr_imucam_chain.yaml: T_imu_cam (4x4, R_imu_cam = R_cam_imu^T),
///  - VINS-Mono / VINS-Fusion: extrinsicRotation (opencv-matrix, R_imu_cam: camera to body/IMU),
///  - `rosrun tf2_ros static_transform_publisher 0 0 0 qx qy qz qw <camera_frame> <imu_frame>`
///    (parent camera, child IMU: the transform maps IMU-frame points into the camera frame).
std::string exportBlocks(const Eigen::Matrix3d& R_cam_imu, const std::string& camera_frame,
                         const std::string& imu_frame);

/// Roll, pitch, yaw (deg) with R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d rollPitchYawDeg(const Eigen::Matrix3d& R);

/// One-page report (CV_8UC3, about 1200x900): per-pair residuals (inliers / outliers), the
/// coverage of rotation axes in the camera frame (which axes were excited), the stationary
/// segments over time (poses used, rejected rests with reasons), and the estimate with its
/// 1-sigma, observability and status.
cv::Mat renderReport(const ReportInput& input);

/// renderReport + cv::imwrite; false with `error` set when writing fails.
bool writeReportPng(const std::string& path, const ReportInput& input, std::string* error);

}  // namespace camera_imu_alignment
