// The paper's two-step iteration (Z.-Q. Zhang, "Cameras and Inertial/Magnetic Sensor Units
// Alignment Calibration", Sec. II), implemented literally: H1, H2, their pseudo-inverses and the
// V2H / H2V block reshapes, alternating a right and a left update, each projected onto SO(3).
//
// It is an SVD power method: pinv(H2) = H2^T / J, so each update applies X -> (1/J) sum A_j X B_j^T
// (or its adjoint) and converges to that operator's top singular vector, which is close to, but
// not, the least-squares optimum. Use OptimalSolver for the best estimate; this solver runs first
// at every solve and can be selected alone.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "camera_imu_alignment/solver/rotation_pair.h"

namespace camera_imu_alignment {

struct TwoStepOptions {
  /// Iteration limit. Small motions make the power method slow (about 200 iterations for 10-40 deg
  /// motions on real data), so the limit is generous and convergence is tested, never assumed.
  int max_iterations = 1000;
  /// Converged when both the left and the right iterate move by less than this (rad).
  double convergence_tolerance_rad = 1e-10;
  /// Initial left iterate R^l_0 (= R_cam_imu guess). Identity when empty.
  std::optional<Eigen::Matrix3d> initial_R_cam_imu;
  /// Keep every iterate in TwoStepResult::trace.
  bool record_trace = false;
};

/// One iteration n of the two-step scheme.
struct TwoStepIterate {
  int iteration = 0;
  Eigen::Matrix3d R_right;        ///< R^r_n (camera <- IMU)
  Eigen::Matrix3d R_left;         ///< R^l_n (camera <- IMU)
  double right_step_rad = 0.0;    ///< geodesic change of R^r from iteration n-1
  double left_step_rad = 0.0;     ///< geodesic change of R^l from iteration n-1
  bool right_sign_fixed = false;  ///< the right update had det < 0 and was negated
  bool left_sign_fixed = false;   ///< the left update had det < 0 and was negated
};

struct TwoStepResult {
  bool valid = false;      ///< false when fewer than one pair or non-finite input
  bool converged = false;  ///< both iterates moved less than the tolerance
  int iterations = 0;      ///< iterations run
  Eigen::Matrix3d R_cam_imu_left = Eigen::Matrix3d::Identity();   ///< last R^l: the answer
  Eigen::Matrix3d R_cam_imu_right = Eigen::Matrix3d::Identity();  ///< last R^r
  double left_right_disagreement_rad = 0.0;  ///< geodesic angle between R^l and R^r
  std::vector<TwoStepIterate> trace;         ///< filled when options.record_trace
};

/// Runs the two-step iteration on the pairs (A_j camera, B_j IMU) of A X = X B.
TwoStepResult solveTwoStep(const RotationPairs& pairs, const TwoStepOptions& options = {});

}  // namespace camera_imu_alignment
