// The joint estimate's blocks of the result YAML (doc/CONVENTIONS.md): `joint` (consistency,
// 1-sigma, what was held at its prior and the rotation that would help) and `imu_intrinsics` (the
// IMU's errors, each with 1-sigma and whether it was estimated or held at its prior).
#pragma once

#include <string>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {

/// Which data the estimate used: "rests", "motion" (motion nodes only) or "both".
const char* dataUsed(const JointResult& joint);

/// The two blocks as YAML text (top level, no trailing blank line).
std::string jointToYaml(const JointResult& joint);

/// A Kalibr imu.yaml-style file (its four noise keys: as the recording measured them
/// (JointResult::noise), else the given rests' scatter, else the noise the estimate was given;
/// never 0; rostopic, update_rate) with the calibrated
/// intrinsics added as extra keys (T_g, T_a, biases, iron): what Kalibr and VIO configs read.
std::string kalibrImuYaml(const JointResult& joint, double gyro_noise_density_rad_s_sqrt_hz,
                          double accel_noise_density_m_s2_sqrt_hz, double update_rate_hz,
                          const std::string& rostopic);

}  // namespace camera_imu_alignment
