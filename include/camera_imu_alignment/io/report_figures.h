// The figures a calibration run's report shows beyond the solve itself: per stationary pose (how
// far it disagrees with the estimate, its reprojection error) and the error to a known truth.
// Computed once by reportFigures(); the PNG page (calibration_report.h) draws them and the text
// summary (calibration_summary.h) prints them, so both show the same numbers.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/io/calibration_summary.h"

namespace camera_imu_alignment {

/// One stationary pose against the estimate R_cam_imu. NaN where a figure does not apply.
struct PoseFigure {
  int index = 0;        ///< StationaryPose::index (0-based, recording order)
  int group = 0;        ///< StationaryPose::group
  double time_s = 0.0;  ///< middle of the rest, s from the recording start (ReportInput::start_s)
  bool in_window = false;            ///< the estimate used this pose
  int num_frames = 0;                ///< camera frames averaged into the pose
  double reprojection_rms_px = 0.0;  ///< the pose's own StationaryPose::reprojection_rms_px
  /// RMS over every pair with this pose (inliers and outliers) of |Log(A X B^T X^T)| at the
  /// estimate X (deg); window poses only.
  double pair_residual_rms_deg = 0.0;
  /// The mounting this pose implies, as a rotation from the estimate about the camera x, y, z axes
  /// (deg): Log(X_k X^T) with X_k = R_target_cam_k^T G R_world_imu_k, where G, the target's
  /// orientation in the world, is the chordal mean of R_target_cam_j X R_world_imu_j^T over the
  /// window poses j of the pose's group. Noise about 0 while the mount holds still; a mount that
  /// moved between two poses makes a step of the size and direction of the move. NaN when the
  /// window has no pose of this group.
  Eigen::Vector3d mount_offset_deg = Eigen::Vector3d::Zero();
  /// The joint estimator's RMS whitened residual of this pose (sigma units; about 1 when the pose
  /// fits its noise); NaN without a joint estimate or outside the window.
  double joint_residual_sigma = 0.0;
};

/// The estimate's error to a known truth. The error vector e is the left perturbation
/// R_est = Exp(e) R_true, about the camera axes, as the 1-sigma (quality.std_dev_deg) is.
struct TruthError {
  std::string source;                                   ///< KnownTruth::source
  double angle_deg = 0.0;                               ///< |Log(R_est^T R_true)|
  Eigen::Vector3d error_deg = Eigen::Vector3d::Zero();  ///< e about camera x, y, z
  Eigen::Vector3d sigma_deg = Eigen::Vector3d::Zero();  ///< the reported 1-sigma
  /// error_deg / sigma_deg per axis (NaN where the sigma is not a positive finite number).
  Eigen::Vector3d error_over_sigma = Eigen::Vector3d::Zero();
  /// Largest |error_over_sigma| (NaN when none is finite).
  double largestErrorInSigmas() const;
};

struct ReportFigures {
  std::vector<PoseFigure> poses;          ///< one per ReportInput::poses, same order
  std::size_t window_poses = 0;           ///< how many (the newest) are in the window
  std::optional<TruthError> truth_error;  ///< when ReportInput::truth is set
};

/// The figures of `input` (see PoseFigure, TruthError). Never throws; non-finite inputs give NaN
/// figures.
ReportFigures reportFigures(const ReportInput& input);

/// "chi2/dof 1.02 (150 dof, p 0.420: consistent)" for a successful joint estimate; the summary and
/// the report print it.
std::string jointConsistencyText(const JointResult& joint);

/// The truth line of the summary and the report: "truth (FILE): error 0.0400 deg, about camera x,
/// y, z [..] deg = [..] x 1-sigma", with " (beyond 3 sigma)" when an axis is.
std::string truthErrorText(const TruthError& error);

}  // namespace camera_imu_alignment
