// The default estimator: least squares on SO(3) of the geodesic residuals |Log(A_j X B_j^T X^T)|^2,
// started from the paper's two-step iteration. When the two-step has not converged, its left and
// right iterates disagree, or its residuals are large for the noise level, the closed form is
// computed too and the better-fitting of the two starts Gauss-Newton. Gross outliers are rejected:
//  1. angle gate: the rotation angle is invariant under conjugation, so |angle(A_j) - angle(B_j)|
//     must be small; the gate is max(angle_gate_min_deg, angle_gate_sigmas * robust spread);
//  2. consensus: after a first least-squares fit, residuals above max(inlier_min_deg,
//     inlier_sigmas * robust sigma) mark outliers; when there are any, a Cauchy-loss refit from the
//     start and RANSAC over two-pair minimal solutions look for a larger consensus;
//  3. final Gauss-Newton (Levenberg-Marquardt safeguarded) on the inliers with the squared loss:
//     the maximum-likelihood estimator for independent Gaussian pairs (it reaches the Cramer-Rao
//     bound). Pairs formed from shared poses are fitted with equal weights; measured as accurate as
//     a pose-level maximum-likelihood fit and as OpenCV's PARK/HORAUD on the same poses.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "camera_imu_alignment/solver/rotation_pair.h"
#include "camera_imu_alignment/solver/two_step_solver.h"

namespace camera_imu_alignment {

/// Two-step options used as the optimal estimator's start: converged to 1e-6 rad within 20
/// iterations (the paper's setup needs about 10), else the closed form is the start: with 10-40 deg
/// motions the power method needs hundreds of iterations, which would dominate the solve time.
inline TwoStepOptions startTwoStepOptions() {
  TwoStepOptions options;
  options.convergence_tolerance_rad = 1e-6;
  options.max_iterations = 20;
  return options;
}

struct OptimalOptions {
  /// Gauss-Newton iteration limit per stage; convergence is tested, not assumed.
  int max_iterations = 100;
  /// Converged when the update is smaller than this (rad), or than 1% of the current 1-sigma.
  /// Without noise Gauss-Newton converges quadratically, so the answer is then exact to rounding.
  double step_tolerance_rad = 1e-9;
  /// Options of the two-step start. Its result is refined by Gauss-Newton, so it runs to 1e-6 rad
  /// (6e-5 deg, far below any sensor noise) rather than to the stand-alone 1e-10, with a budget of
  /// 20 iterations (the stand-alone method allows 1000).
  TwoStepOptions two_step = startTwoStepOptions();
  /// Reject pairs whose camera and IMU rotation angles differ by more than
  /// max(angle_gate_min_deg, angle_gate_sigmas * 1.4826 * median difference).
  double angle_gate_min_deg = 0.5;
  double angle_gate_sigmas = 5.0;
  /// Inlier threshold on |r_j|: max(inlier_min_deg, inlier_sigmas * sigma), sigma = robust per-axis
  /// residual standard deviation (median |r| / 1.538 for a 3-D Gaussian).
  double inlier_min_deg = 0.05;
  double inlier_sigmas = 4.5;
  /// Number of RANSAC hypotheses (two-pair minimal solutions) when outliers are suspected.
  int ransac_hypotheses = 300;
  /// Seed of the RANSAC sampler (results are deterministic).
  unsigned int seed = 1;
  /// Set false to fit all pairs (no gate, no consensus).
  bool reject_outliers = true;
};

struct OptimalResult {
  bool valid = false;
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();
  TwoStepResult two_step;  ///< the paper's solver, run on the gated pairs
  std::string start;       ///< "two_step" or "closed_form"
  bool converged = false;  ///< final Gauss-Newton stage converged
  int iterations = 0;      ///< Gauss-Newton iterations, all stages
  bool ransac_used = false;
  std::vector<bool> inlier;                ///< per input pair
  std::vector<std::string> rejection;      ///< per input pair, "" for inliers
  std::vector<Eigen::Vector3d> residuals;  ///< per input pair at R_cam_imu (rad, camera frame)
  /// Per input pair: rotation angles (rad) of A_j (x) and B_j (y), as rotationAngle gives them.
  std::vector<Eigen::Vector2d> pair_angles_rad;
};

/// Estimates R_cam_imu from the pairs (which must be rotation matrices).
OptimalResult solveOptimal(const RotationPairs& pairs, const OptimalOptions& options = {});

/// Settings of one Gauss-Newton / Levenberg-Marquardt refinement.
struct RefineSettings {
  double cauchy_scale_rad = 0.0;  ///< <= 0: squared loss; > 0: Cauchy loss of this scale
  int max_iterations = 100;
  double step_tolerance_rad = 1e-9;  ///< converged when the step is below this ...
  /// ... or (squared loss) below this fraction of the current 1-sigma of the estimate: further
  /// digits are statistically meaningless. Noise-free data reaches the absolute tolerance.
  double relative_step_tolerance = 0.01;
};

/// Refines R_cam_imu on the pairs in `indices`. `residuals`, when given, may hold the residuals at
/// the start (same order as indices; recomputed when the size differs) and receives those at the
/// result. Returns the iterations run; *converged tells whether a tolerance was met.
int refineRotation(const RotationPairs& pairs, const std::vector<int>& indices,
                   const RefineSettings& settings, Eigen::Matrix3d* R_cam_imu, bool* converged,
                   std::vector<Eigen::Vector3d>* residuals = nullptr);

}  // namespace camera_imu_alignment
