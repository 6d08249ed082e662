// The camera's pose relative to the target from one observation of it: planar PnP with its
// ambiguity test and reprojection check.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "camera_imu_alignment/vision/camera_model.h"
#include "camera_imu_alignment/vision/target_description.h"
#include "camera_imu_alignment/vision/target_detector.h"

namespace camera_imu_alignment {

struct PoseSettings {
  double max_reprojection_rms_px = 1.0;  ///< poses above are rejected
  /// Planar PnP has two solutions (IPPE); the pose is rejected as ambiguous when the second one's
  /// reprojection RMS is within this factor of the first (they explain the image equally well).
  double min_ambiguity_ratio = 1.5;
};

/// Camera pose relative to the target (doc/CONVENTIONS.md: R_target_cam; p_target = R_target_cam
/// p_cam + p_target_cam).
struct CameraPose {
  Eigen::Matrix3d R_target_cam = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_target_cam =
      Eigen::Vector3d::Zero();  ///< camera centre in the target frame (m)
  double reprojection_rms_px = 0.0;
  double reprojection_mean_px = 0.0;  ///< mean reprojection distance (px)
  double ambiguity_ratio = 0.0;  ///< second-best / best reprojection RMS of the planar solutions
  int num_points = 0;
  /// Covariance of R_target_cam (rad^2, camera axes, right perturbation R Exp(delta)) that the
  /// reprojection residuals imply: sigma^2 (J^T J)^-1 of the pinhole PnP, sigma^2 the sum of the
  /// squared residual coordinates over 2N - 6. What the image says about this frame's orientation,
  /// errors of the camera model included (a lens distortion missing from camera_info shows here,
  /// not in the scatter of the frames of one rest, which see the same lens).
  Eigen::Matrix3d cov_rotation_rad2 = Eigen::Matrix3d::Zero();
};

/// PnP (IPPE on undistorted points, then Levenberg-Marquardt refinement). Returns nullopt with the
/// reason in `why` when there are too few points, PnP fails, the reprojection RMS is above the
/// limit or the solution is ambiguous.
std::optional<CameraPose> estimateCameraPose(const TargetObservation& observation,
                                             const TargetDescription& target,
                                             const CameraIntrinsics& intrinsics,
                                             const PoseSettings& settings, std::string* why);

}  // namespace camera_imu_alignment
