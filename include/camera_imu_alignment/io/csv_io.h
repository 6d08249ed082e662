// Readers for the pairs and poses CSV files of doc/CONVENTIONS.md. Columns are found by header
// name (any order, extra columns ignored); quaternions are Hamilton (w, x, y, z) and normalised on
// reading. Every problem is reported as an InputError naming the file and the line.
#pragma once

#include <string>
#include <vector>

#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/solver/pose_window.h"
#include "camera_imu_alignment/solver/rotation_pair.h"

namespace camera_imu_alignment {

/// Quaternions whose norm differs from 1 by more than this are input errors, not normalised.
constexpr double kQuaternionNormTolerance = 1e-2;

/// Pairs file: qa_w,qa_x,qa_y,qa_z (A, camera), qb_w,qb_x,qb_y,qb_z (B, IMU). Pairs are independent
/// (pose indices -1). Throws InputError.
RotationPairs readPairsCsv(const std::string& path);

/// Poses file: stamp, cam_qw..cam_qz (q_target_cam), imu_qw..imu_qz (q_world_imu), optional
/// group (an integer; poses of different groups are never paired; absent: one group). Throws
/// InputError.
std::vector<PoseOrientation> readPosesCsv(const std::string& path);

/// Writes a pairs file (header + one row per pair), atomically (io/atomic_file.h). Throws
/// InputError.
void writePairsCsv(const std::string& path, const RotationPairs& pairs);

/// Writes a poses file (header + one row per pose; a group column when the poses have several),
/// atomically (io/atomic_file.h). Throws InputError.
void writePosesCsv(const std::string& path, const std::vector<PoseOrientation>& poses);

}  // namespace camera_imu_alignment
