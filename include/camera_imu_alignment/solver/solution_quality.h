// Residuals, uncertainty and observability of an R_cam_imu estimate.
//
// Residual of pair j at X = R_cam_imu:  r_j = Log(A_j X B_j^T X^T)  (rad, camera frame; zero when
// A_j X = X B_j). Perturbations are on the left, X <- Exp(delta) X, so delta, the covariance and
// the 1-sigma values are about the camera x, y, z axes. The error of an estimate against the truth
// is Log(X_est X_true^T) in the same frame.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "camera_imu_alignment/solver/rotation_pair.h"

namespace camera_imu_alignment {

struct QualityOptions {
  /// Not observable when the rotation about the least-excited direction (RMS over inlier pairs,
  /// deg) is below this floor ...
  double min_excitation_deg = 0.5;
  /// ... or below this many residual standard deviations: off-axis "excitation" at the noise level
  /// is noise, not information.
  double min_excitation_noise_ratio = 3.0;
};

/// Per-pair diagnostics.
struct PairDiagnostics {
  double residual_deg = 0.0;   ///< |r_j| at the estimate (deg)
  double angle_cam_deg = 0.0;  ///< rotation angle of A_j (deg)
  double angle_imu_deg = 0.0;  ///< rotation angle of B_j (deg)
  bool inlier = true;          ///< used in the final estimate
  std::string rejection;       ///< why it was dropped ("" for inliers)
};

struct SolutionQuality {
  bool observable = false;
  /// Human-readable verdict; when not observable it names the camera axis to rotate about.
  std::string observability_message;
  /// lambda_min / mean(lambda) of the information matrix, in [0, 1]: 1 = rotations spread evenly
  /// over all axes, 0 = a single rotation axis.
  double observability = 0.0;
  /// RMS rotation angle (deg) that constrains the least-constrained direction.
  double weakest_excitation_deg = 0.0;
  /// Unit direction (camera frame) about which R_cam_imu is least constrained.
  Eigen::Vector3d weak_axis_cam = Eigen::Vector3d::UnitZ();
  /// Unit direction (camera frame) to rotate the rig about to constrain weak_axis_cam:
  /// perpendicular to it, along the best-constrained direction.
  Eigen::Vector3d excite_axis_cam = Eigen::Vector3d::UnitX();
  int num_pairs = 0;
  int num_inliers = 0;
  double residual_rms_deg = 0.0;  ///< RMS of |r_j| over inliers (deg)
  /// Covariance of the left perturbation delta (rad^2, camera frame), from the Gauss-Newton
  /// information scaled by the residual variance (pairs sharing a pose handled as correlated),
  /// times dof / (dof - 2) for the noise scale estimated from few residuals (Student-t).
  Eigen::Matrix3d covariance_rad2 = Eigen::Matrix3d::Zero();
  /// 1-sigma about the camera x, y, z axes (deg); capped at 180 when not determined.
  Eigen::Vector3d std_dev_deg = Eigen::Vector3d::Constant(180.0);
  std::vector<PairDiagnostics> pairs;
};

/// Residual r = Log(A X B^T X^T) (rad, camera frame).
Eigen::Vector3d pairResidual(const RotationPair& pair, const Eigen::Matrix3d& R_cam_imu);

/// Jacobian d r / d delta for X <- Exp(delta) X, evaluated at residual r:
/// Jl^-1(r) A - Jr^-1(r).
Eigen::Matrix3d pairJacobian(const RotationPair& pair, const Eigen::Vector3d& residual);

/// Rotation angles (deg) of A and B of a pair.
void pairAnglesDeg(const RotationPair& pair, double* angle_cam_deg, double* angle_imu_deg);

/// Evaluates residuals, covariance and observability of R_cam_imu on the pairs; `inlier` marks the
/// pairs used (all when empty); `rejection` gives reasons for the others (may be empty);
/// `residuals`, when it has one entry per pair, holds r_j at R_cam_imu already (not recomputed);
/// `angles_rad`, when it has one entry per pair, holds the rotation angles (rad) of A_j and B_j
/// (as rotationAngle computes them; not recomputed).
SolutionQuality evaluateQuality(const RotationPairs& pairs, const Eigen::Matrix3d& R_cam_imu,
                                const std::vector<bool>& inlier = {},
                                const std::vector<std::string>& rejection = {},
                                const QualityOptions& options = {},
                                const std::vector<Eigen::Vector3d>& residuals = {},
                                const std::vector<Eigen::Vector2d>& angles_rad = {});

/// Name of the camera axis closest to `axis` ("x", "y" or "z").
std::string axisName(const Eigen::Vector3d& axis);

}  // namespace camera_imu_alignment
