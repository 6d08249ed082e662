// The camera's noise as the recording shows it (JointSettings::camera_excess_level): the
// isotropic variance real errors add to the stated covariances of the rests' camera orientations
// (PnP) and of the natural scene's rotations between rests (camera links).
#pragma once

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {
namespace joint {

/// The isotropic variance (rad^2) that, added to every rest's camera covariance, brings the
/// median rest's camera chi-square to chi-square(3)'s median; 0 when the rests' camera residuals
/// (result.camera_residual_rad, of a solve of `problem`) pass their chi-square test at
/// settings.camera_excess_level, or when the median rest already fits (the misfit is a few
/// poses': a remount or a bad pose, which the mount-change test judges).
double cameraExcessVariance(const JointProblem& problem, const JointResult& result,
                            const JointSettings& settings);

/// The same for the camera links (result.camera_link_residual_rad): features whose positions
/// shift with the viewpoint (a 20-60 deg turn changes a texture's look) err beyond the two-view
/// fit's covariance, which sees only their scatter.
double cameraLinkExcessVariance(const JointProblem& problem, const JointResult& result,
                                const JointSettings& settings);

}  // namespace joint

/// Adds `variance_rad2` x I to every camera link's covariance.
void addCameraLinkExcessVariance(double variance_rad2, JointProblem* problem);

}  // namespace camera_imu_alignment
