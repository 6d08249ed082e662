#include "camera_imu_alignment/closed_form_solver.h"

#include <Eigen/Eigenvalues>

#include "camera_imu_alignment/rotation_math.h"

namespace camera_imu_alignment {

std::optional<Eigen::Matrix3d> solveClosedForm(const RotationPairs& pairs,
                                               const std::vector<int>& indices) {
  Eigen::Matrix<double, 9, 9> S = Eigen::Matrix<double, 9, 9>::Zero();
  const auto accumulate = [&S](const RotationPair& p) {
    // Kronecker product B (x) A: block (r, c) is B(r, c) * A.
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) S.block<3, 3>(3 * r, 3 * c) += p.B_imu(r, c) * p.A_cam;
  };
  if (indices.empty()) {
    for (const auto& p : pairs) accumulate(p);
  } else {
    for (int i : indices) accumulate(pairs.at(static_cast<size_t>(i)));
  }
  if ((indices.empty() && pairs.empty()) || !S.allFinite()) return std::nullopt;

  const Eigen::Matrix<double, 9, 9> S_sym = 0.5 * (S + S.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eig(S_sym);
  if (eig.info() != Eigen::Success) return std::nullopt;
  const Eigen::Matrix<double, 9, 1> v = eig.eigenvectors().col(8);  // largest eigenvalue
  Eigen::Matrix3d X = Eigen::Map<const Eigen::Matrix3d>(v.data());  // column-major vec^-1
  if (X.determinant() < 0.0) X = -X;  // the eigenvector's sign is arbitrary
  const Eigen::Matrix3d R = projectToSO3(X);
  if (!R.allFinite()) return std::nullopt;
  return R;
}

}  // namespace camera_imu_alignment
