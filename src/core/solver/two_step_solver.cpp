// The paper's two-step iteration, written in the paper's own terms. The issue references the
// paper's equations (11)-(19) for this part; each step below names the formula it implements:
//   stacked system     H1 R0 = H2V(R0 H2),  H1 = [A_1; ...; A_J] (3J x 3), H2 = [B_1 ... B_J] (3 x
//   3J) right step         R^r_n = V2H(H1 R^l_{n-1}) pinv(H2) left step          R^l_n = pinv(H1)
//   H2V(R^r_n H2) SVD projection     M = U S V^T -> U V^T, after negating M when det(M) < 0 (sign
//   fix) stopping rule      successive iterates closer than a tolerance
// H1, H2 are kept as their 3x3 blocks, the pseudo-inverses through their closed forms
// pinv(H1) = (H1^T H1)^-1 H1^T and pinv(H2) = H2^T (H2 H2^T)^-1, and each step is applied as the
// 9x9 linear map it is (built once per solve) followed by the 3x3 inverse factor;
// test_two_step_solver checks the iterates against the formulas evaluated with explicitly stacked
// H1, H2 and Eigen's own pseudo-inverses.
#include "camera_imu_alignment/solver/two_step_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// The paper's projection with the determinant sign fix: negate M when det(M) < 0, then U V^T.
Eigen::Matrix3d projectWithSignFix(const Eigen::Matrix3d& M, bool* sign_fixed) {
  *sign_fixed = M.determinant() < 0.0;
  return projectToSO3(*sign_fixed ? Eigen::Matrix3d(-M) : M);
}

/// Geodesic angle between two rotations from their Frobenius distance, |R1 - R2|_F = 2 sqrt(2)
/// sin(theta / 2): exact, and cheaper than a logarithm.
double stepAngle(double frobenius_distance) {
  const double s = std::min(1.0, frobenius_distance / (2.0 * std::sqrt(2.0)));
  return 2.0 * std::asin(s);
}

}  // namespace

TwoStepResult solveTwoStep(const RotationPairs& pairs, const TwoStepOptions& options) {
  TwoStepResult result;
  const size_t J = pairs.size();
  if (J < 1) return result;

  // H1 = [A_1; ...; A_J] (3J x 3) and H2 = [B_1 ... B_J] (3 x 3J), kept as their 3x3 blocks.
  // Moore-Penrose pseudo-inverses: H1 has full column rank and H2 full row rank (they stack
  // rotations, H1^T H1 = H2 H2^T = J I up to rounding), so
  //   pinv(H1) = (H1^T H1)^-1 H1^T = [P1_1 ... P1_J],  P1_j = (H1^T H1)^-1 A_j^T
  //   pinv(H2) = H2^T (H2 H2^T)^-1 = [P2_1; ...; P2_J], P2_j = B_j^T (H2 H2^T)^-1
  Eigen::Matrix3d H1tH1 = Eigen::Matrix3d::Zero(), H2H2t = Eigen::Matrix3d::Zero();
  for (const auto& p : pairs) {
    H1tH1.noalias() += p.A_cam.transpose() * p.A_cam;
    H2H2t.noalias() += p.B_imu * p.B_imu.transpose();
  }
  if (!H1tH1.allFinite() || !H2H2t.allFinite()) return result;
  const Eigen::Matrix3d H1tH1_inv = H1tH1.inverse(), H2H2t_inv = H2H2t.inverse();
  // Both steps are linear in R before the projection. With column-major vec and
  // vec(L R M) = (M^T (x) L) vec(R), both go through one 9x9 matrix S = sum_j B_j (x) A_j:
  //   right: V2H(H1 R) pinv(H2) = sum_j A_j R P2_j = (sum_j A_j R B_j^T) (H2 H2^T)^-1,
  //          vec(sum_j A_j R B_j^T) = S vec(R);
  //   left:  pinv(H1) H2V(R H2) = sum_j P1_j R B_j = (H1^T H1)^-1 (sum_j A_j^T R B_j),
  //          vec(sum_j A_j^T R B_j) = S^T vec(R)   ((B (x) A)^T = B^T (x) A^T).
  // S is built once per solve (81 products per pair), so each iteration costs two 9x9
  // matrix-vector and two 3x3 products instead of 4J 3x3 products (same numbers, J-independent).
  using Matrix9 = Eigen::Matrix<double, 9, 9>;
  using Vector9 = Eigen::Matrix<double, 9, 1>;
  Matrix9 S = Matrix9::Zero();
  for (const auto& p : pairs) {
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) S.block<3, 3>(3 * r, 3 * c) += p.B_imu(r, c) * p.A_cam;
    }
  }

  // Stopping rule on the geodesic step angle theta, tested through the Frobenius distance
  // |R1 - R2|_F = 2 sqrt(2) sin(theta / 2) (monotone in theta): the same test without an asin.
  const double tolerance = options.convergence_tolerance_rad;
  const double frobenius_tolerance =
      tolerance > kPi ? INFINITY : 2.0 * std::sqrt(2.0) * std::sin(0.5 * tolerance);
  Eigen::Matrix3d R_left = options.initial_R_cam_imu.value_or(Eigen::Matrix3d::Identity());
  Eigen::Matrix3d R_right = R_left;
  for (int n = 1; n <= options.max_iterations; ++n) {
    TwoStepIterate it;
    it.iteration = n;
    // Right step: R^r_n = V2H(H1 R^l_{n-1}) pinv(H2), projected onto SO(3).
    Eigen::Matrix3d N_right;
    Eigen::Map<Vector9>(N_right.data()) = S.lazyProduct(Eigen::Map<const Vector9>(R_left.data()));
    const Eigen::Matrix3d M_right = N_right.lazyProduct(H2H2t_inv);
    it.R_right = projectWithSignFix(M_right, &it.right_sign_fixed);
    // Left step: R^l_n = pinv(H1) H2V(R^r_n H2), projected onto SO(3).
    Eigen::Matrix3d N_left;
    Eigen::Map<Vector9>(N_left.data()) =
        S.transpose().lazyProduct(Eigen::Map<const Vector9>(it.R_right.data()));
    const Eigen::Matrix3d M_left = H1tH1_inv.lazyProduct(N_left);
    it.R_left = projectWithSignFix(M_left, &it.left_sign_fixed);

    const double right_distance = (R_right - it.R_right).norm();
    const double left_distance = (R_left - it.R_left).norm();
    // The first right step has no predecessor: its step counts as pi (never converged at n = 1
    // unless the tolerance exceeds pi).
    const bool right_small = n == 1 ? kPi < tolerance : right_distance < frobenius_tolerance;
    const bool converged = right_small && left_distance < frobenius_tolerance;
    R_right = it.R_right;
    R_left = it.R_left;
    result.iterations = n;
    if (options.record_trace) {
      it.right_step_rad = n == 1 ? kPi : stepAngle(right_distance);
      it.left_step_rad = stepAngle(left_distance);
      result.trace.push_back(it);
    }
    if (converged) {
      result.converged = true;
      break;
    }
  }
  result.valid = R_left.allFinite() && R_right.allFinite();
  result.R_cam_imu_left = R_left;
  result.R_cam_imu_right = R_right;
  result.left_right_disagreement_rad = geodesicDistance(R_left, R_right);
  return result;
}

}  // namespace camera_imu_alignment
