// Closed-form estimate of R_cam_imu from A_j X = X B_j: the leading eigenvector of the 9x9
// relaxation. sum_j ||A_j X - X B_j||_F^2 = 6J - 2 vec(X)^T S vec(X) with S = sum_j B_j (x) A_j
// (Kronecker product, column-major vec), so over ||vec X||^2 = 3 the minimiser is the eigenvector
// of the largest eigenvalue of (S + S^T)/2, reshaped and projected onto SO(3). Exact without noise
// for two pairs with non-parallel axes; no quaternion sign ambiguity, so it is safe near 180
// degrees.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "camera_imu_alignment/solver/rotation_pair.h"

namespace camera_imu_alignment {

/// Closed-form R_cam_imu from the pairs listed in `indices` (all pairs when empty).
/// Returns nothing when no pair is given or the input is not finite.
std::optional<Eigen::Matrix3d> solveClosedForm(const RotationPairs& pairs,
                                               const std::vector<int>& indices = {});

}  // namespace camera_imu_alignment
