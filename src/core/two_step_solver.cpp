// The paper's two-step iteration, written in the paper's own terms. The issue references the
// paper's equations (11)-(19) for this part; each step below names the formula it implements:
//   stacked system     H1 R0 = H2V(R0 H2),  H1 = [A_1; ...; A_J] (3J x 3), H2 = [B_1 ... B_J] (3 x 3J)
//   right step         R^r_n = V2H(H1 R^l_{n-1}) pinv(H2)
//   left step          R^l_n = pinv(H1) H2V(R^r_n H2)
//   SVD projection     M = U S V^T -> U V^T, after negating M when det(M) < 0 (sign fix)
//   stopping rule      successive iterates closer than a tolerance
#include "camera_imu_alignment/two_step_solver.h"

#include <Eigen/Dense>

#include "camera_imu_alignment/rotation_math.h"

namespace camera_imu_alignment {
namespace {

using MatrixX3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;
using Matrix3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;

/// V2H: [M_1; ...; M_J] (3J x 3) -> [M_1 ... M_J] (3 x 3J).
Matrix3X verticalToHorizontal(const MatrixX3& V) {
  const Eigen::Index J = V.rows() / 3;
  Matrix3X H(3, 3 * J);
  for (Eigen::Index j = 0; j < J; ++j) H.middleCols<3>(3 * j) = V.middleRows<3>(3 * j);
  return H;
}

/// H2V: [M_1 ... M_J] (3 x 3J) -> [M_1; ...; M_J] (3J x 3).
MatrixX3 horizontalToVertical(const Matrix3X& H) {
  const Eigen::Index J = H.cols() / 3;
  MatrixX3 V(3 * J, 3);
  for (Eigen::Index j = 0; j < J; ++j) V.middleRows<3>(3 * j) = H.middleCols<3>(3 * j);
  return V;
}

/// The paper's projection with the determinant sign fix: negate M when det(M) < 0, then U V^T.
Eigen::Matrix3d projectWithSignFix(const Eigen::Matrix3d& M, bool* sign_fixed) {
  *sign_fixed = M.determinant() < 0.0;
  return projectToSO3(*sign_fixed ? Eigen::Matrix3d(-M) : M);
}

}  // namespace

TwoStepResult solveTwoStep(const RotationPairs& pairs, const TwoStepOptions& options) {
  TwoStepResult result;
  const Eigen::Index J = static_cast<Eigen::Index>(pairs.size());
  if (J < 1) return result;

  MatrixX3 H1(3 * J, 3);
  Matrix3X H2(3, 3 * J);
  for (Eigen::Index j = 0; j < J; ++j) {
    H1.middleRows<3>(3 * j) = pairs[j].A_cam;
    H2.middleCols<3>(3 * j) = pairs[j].B_imu;
  }
  if (!H1.allFinite() || !H2.allFinite()) return result;

  // Moore-Penrose pseudo-inverses. H1 has full column rank and H2 full row rank (they stack
  // rotations: H1^T H1 = H2 H2^T = J I), so pinv(H1) = (H1^T H1)^-1 H1^T, pinv(H2) = H2^T (H2 H2^T)^-1.
  const Eigen::Matrix<double, 3, Eigen::Dynamic> pinv_H1 = (H1.transpose() * H1).inverse() * H1.transpose();
  const Eigen::Matrix<double, Eigen::Dynamic, 3> pinv_H2 = H2.transpose() * (H2 * H2.transpose()).inverse();

  Eigen::Matrix3d R_left = options.initial_R_cam_imu.value_or(Eigen::Matrix3d::Identity());
  Eigen::Matrix3d R_right = R_left;
  for (int n = 1; n <= options.max_iterations; ++n) {
    TwoStepIterate it;
    it.iteration = n;
    // Right step: R^r_n = V2H(H1 R^l_{n-1}) pinv(H2), projected onto SO(3).
    const Eigen::Matrix3d M_right = verticalToHorizontal(H1 * R_left) * pinv_H2;
    it.R_right = projectWithSignFix(M_right, &it.right_sign_fixed);
    // Left step: R^l_n = pinv(H1) H2V(R^r_n H2), projected onto SO(3).
    const Eigen::Matrix3d M_left = pinv_H1 * horizontalToVertical(it.R_right * H2);
    it.R_left = projectWithSignFix(M_left, &it.left_sign_fixed);

    it.right_step_rad = n == 1 ? kPi : geodesicDistance(R_right, it.R_right);
    it.left_step_rad = geodesicDistance(R_left, it.R_left);
    R_right = it.R_right;
    R_left = it.R_left;
    result.iterations = n;
    if (options.record_trace) result.trace.push_back(it);
    if (it.right_step_rad < options.convergence_tolerance_rad &&
        it.left_step_rad < options.convergence_tolerance_rad) {
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
