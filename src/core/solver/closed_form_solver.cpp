#include "camera_imu_alignment/solver/closed_form_solver.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

using Matrix9 = Eigen::Matrix<double, 9, 9>;
using Vector9 = Eigen::Matrix<double, 9, 1>;

/// Unit eigenvector of the largest eigenvalue of the symmetric S. The eigenvalues come from
/// Eigen's symmetric QR (no eigenvector accumulation); when the largest is well separated, its
/// eigenvector is computed by inverse iteration with a Cholesky factor of sigma I - S (sigma just
/// above it) and verified by its residual. Otherwise (near-degenerate, or the check fails) the full
/// eigendecomposition is used. Both give the same eigenvector to rounding (its sign is arbitrary).
bool topEigenvector(const Matrix9& S, Vector9* v) {
  Eigen::SelfAdjointEigenSolver<Matrix9> values(S, Eigen::EigenvaluesOnly);
  if (values.info() != Eigen::Success) return false;
  const Vector9& lambda = values.eigenvalues();  // ascending
  const double scale = std::max(std::abs(lambda(0)), std::abs(lambda(8)));
  const double gap = lambda(8) - lambda(7);
  if (scale > 0.0 && gap > 1e-3 * scale) {
    // Each step shrinks the other components by (sigma - lambda_8) / (sigma - lambda_i) <= 1e-6.
    const double sigma = lambda(8) + 1e-6 * gap;
    const Eigen::LLT<Matrix9> llt(sigma * Matrix9::Identity() - S);
    if (llt.info() == Eigen::Success) {
      Vector9 x = Vector9::Constant(1.0 / 3.0);
      for (int step = 0; step < 4; ++step) {
        x = llt.solve(x);
        x.normalize();
      }
      const double rayleigh = x.dot(S * x);
      // sin(angle to the true eigenvector) <= |S x - rayleigh x| / gap.
      if (x.allFinite() && std::abs(rayleigh - lambda(8)) <= 1e-12 * scale &&
          (S * x - rayleigh * x).norm() <= 1e-13 * scale) {
        *v = x;
        return true;
      }
    }
  }
  Eigen::SelfAdjointEigenSolver<Matrix9> eig(S);
  if (eig.info() != Eigen::Success) return false;
  *v = eig.eigenvectors().col(8);  // largest eigenvalue
  return true;
}

}  // namespace

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
  Eigen::Matrix<double, 9, 1> v;  // unit eigenvector of the largest eigenvalue
  if (!topEigenvector(S_sym, &v)) return std::nullopt;
  Eigen::Matrix3d X = Eigen::Map<const Eigen::Matrix3d>(v.data());  // column-major vec^-1
  if (X.determinant() < 0.0) X = -X;  // the eigenvector's sign is arbitrary
  const Eigen::Matrix3d R = projectToSO3(X);
  if (!R.allFinite()) return std::nullopt;
  return R;
}

}  // namespace camera_imu_alignment
