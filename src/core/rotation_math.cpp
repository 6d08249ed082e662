#include "camera_imu_alignment/rotation_math.h"

#include <Eigen/SVD>
#include <cmath>

namespace camera_imu_alignment {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& rotvec) {
  const double angle = rotvec.norm();
  if (angle < 1e-12) {
    return Eigen::Matrix3d::Identity() + skew(rotvec);
  }
  return Eigen::AngleAxisd(angle, rotvec / angle).toRotationMatrix();
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);  // Shepperd-style branch on the largest diagonal: stable at 0 and pi.
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double sin_half = q.vec().norm();
  if (sin_half < 1e-12) {
    return 2.0 * q.vec();  // first order; exact limit at the identity
  }
  const double angle = 2.0 * std::atan2(sin_half, q.w());
  return q.vec() * (angle / sin_half);
}

double rotationAngle(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

double geodesicDistance(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  return rotationAngle(R_a.transpose() * R_b);
}

Eigen::Matrix3d projectToSO3(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

Eigen::Matrix3d leftJacobianInverse(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d Phi = skew(phi);
  if (angle < 1e-6) {
    return Eigen::Matrix3d::Identity() - 0.5 * Phi + Phi * Phi / 12.0;
  }
  const double half = 0.5 * angle;
  // Near pi, cot(half) -> 0 and the formula stays finite.
  const double coeff = (1.0 - half * std::cos(half) / std::sin(half)) / (angle * angle);
  return Eigen::Matrix3d::Identity() - 0.5 * Phi + coeff * Phi * Phi;
}

bool isRotationMatrix(const Eigen::Matrix3d& R, double tolerance) {
  if (!R.allFinite()) return false;
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > tolerance) return false;
  return R.determinant() > 0.0;
}

Eigen::Matrix3d uniformRotation(double u1, double u2, double u3) {
  // Shoemake's uniform random quaternion.
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const Eigen::Quaterniond q(a * std::sin(2 * kPi * u2), a * std::cos(2 * kPi * u2),
                             b * std::sin(2 * kPi * u3), b * std::cos(2 * kPi * u3));
  return q.normalized().toRotationMatrix();
}

}  // namespace camera_imu_alignment
