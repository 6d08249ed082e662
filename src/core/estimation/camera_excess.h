// The camera's noise as the recording shows it (JointSettings::camera_excess_level): the
// isotropic variance real PnP errors add to the rests' stated camera covariances.
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

}  // namespace joint
}  // namespace camera_imu_alignment
