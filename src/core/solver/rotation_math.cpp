#include "camera_imu_alignment/solver/rotation_math.h"

#include <Eigen/SVD>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace camera_imu_alignment {
namespace {

/// asin(s) / s for 0 <= s < 0.1 (truncation below 2e-18 relative).
double asinOverArgSeries(double s) {
  const double s2 = s * s;
  return 1.0 + s2 * (1.0 / 6.0 +
                     s2 * (3.0 / 40.0 +
                           s2 * (5.0 / 112.0 +
                                 s2 * (35.0 / 1152.0 +
                                       s2 * (63.0 / 2816.0 +
                                             s2 * (231.0 / 13312.0 + s2 * (143.0 / 10240.0)))))));
}

}  // namespace

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
  // R - R^T = 2 sin(theta) skew(axis) and tr(R) = 1 + 2 cos(theta).
  const Eigen::Vector3d half_vee =
      0.5 * Eigen::Vector3d(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  const double sin_angle = half_vee.norm();
  const double cos_angle = 0.5 * (R.trace() - 1.0);
  if (cos_angle > 0.0 && sin_angle < 0.1) {
    // Small angles (the residuals of a good fit): theta / sin(theta) = asin(s) / s as a series;
    // no transcendental call.
    return half_vee * asinOverArgSeries(sin_angle);
  }
  if (cos_angle > -0.9) {
    // Away from pi the skew part carries the axis accurately.
    return half_vee * (std::atan2(sin_angle, cos_angle) / sin_angle);
  }
  // Near pi the skew part vanishes: take the axis from a quaternion (largest-diagonal branch).
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double sin_half = q.vec().norm();
  return q.vec() * (2.0 * std::atan2(sin_half, q.w()) / sin_half);
}

Eigen::Vector3d logQuaternion(const Eigen::Quaterniond& q) {
  const double sign = q.w() < 0.0 ? -1.0 : 1.0;  // q and -q: the same rotation
  const Eigen::Vector3d v = sign * q.vec();
  const double s = v.norm();  // sin(theta / 2)
  if (s < 0.1) return v * (2.0 * asinOverArgSeries(s));
  return v * (2.0 * std::atan2(s, sign * q.w()) / s);
}

double rotationAngle(const Eigen::Matrix3d& R) {
  // sin(theta) from the skew part, cos(theta) from the trace: atan2 of both is accurate at 0 and
  // pi.
  const Eigen::Vector3d vee(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * vee.norm(), 0.5 * (R.trace() - 1.0));
}

double geodesicDistance(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  return rotationAngle(R_a.transpose() * R_b);
}

namespace {

Eigen::Matrix3d projectToSO3BySvd(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

}  // namespace

namespace {

/// Cofactor matrix of X: its columns are the cross products of X's columns, and
/// X^-T = cof(X) / det(X). Returns det(X).
inline double cofactor(const Eigen::Matrix3d& X, Eigen::Matrix3d* C) {
  C->col(0) = X.col(1).cross(X.col(2));
  C->col(1) = X.col(2).cross(X.col(0));
  C->col(2) = X.col(0).cross(X.col(1));
  return X.col(0).dot(C->col(0));
}

}  // namespace

Eigen::Matrix3d projectToSO3(const Eigen::Matrix3d& M) {
  // For det(M) > 0 the nearest rotation is the orthogonal polar factor U V^T of M = U S V^T.
  // Higham's scaled Newton iteration X <- (g X + X^-T / g) / 2 converges to exactly that matrix,
  // quadratically. A 3x3 X^-T is its cofactor matrix (three cross products) over det(X), so an
  // iteration costs about 100 flops: several times cheaper than a 3x3 Jacobi SVD.
  // Near-singular or det <= 0 input goes through the SVD with the determinant fix.
  const double norm = M.norm();
  const double det = M.determinant();
  if (!(norm > 0.0) || !std::isfinite(norm) || det <= 1e-6 * norm * norm * norm) {
    return projectToSO3BySvd(M);
  }
  Eigen::Matrix3d X = M / norm;
  Eigen::Matrix3d C;
  for (int it = 0; it < 30; ++it) {
    const double det_X = cofactor(X, &C);  // X^-T = C / det_X, det_X > 0
    // Frobenius-norm scaling g = sqrt(|X^-1|_F / |X|_F) = (|C|^2 / (det^2 |X|^2))^(1/4).
    const double gamma = std::sqrt(std::sqrt(C.squaredNorm() / (det_X * det_X * X.squaredNorm())));
    const Eigen::Matrix3d X_next = (0.5 * gamma) * X + (0.5 / (gamma * det_X)) * C;
    const double change2 = (X_next - X).squaredNorm();
    X = X_next;
    // Each singular value s of X moves to s' = (g s + 1 / (g s)) / 2 (same singular vectors), and
    // g s -> 1. A change below 1e-6 (Frobenius) means X was within about 1e-6 of orthogonal, so
    // the new iterate is within about 1e-12; one unscaled step (quadratic convergence) takes that
    // to rounding level.
    if (change2 < 1e-12) {
      const double det_final = cofactor(X, &C);
      return 0.5 * X + (0.5 / det_final) * C;
    }
  }
  return projectToSO3BySvd(M);
}

double jacobianInverseCoefficient(double angle) {
  if (angle < 0.1) {
    // Series of (1 - (t/2) cot(t/2)) / t^2; the next term is below 2e-16 at t = 0.1.
    const double t2 = angle * angle;
    return 1.0 / 12.0 + t2 * (1.0 / 720.0 + t2 * (1.0 / 30240.0 + t2 / 1209600.0));
  }
  const double half = 0.5 * angle;
  // Near pi, cot(half) -> 0 and the coefficient stays finite.
  return (1.0 - half * std::cos(half) / std::sin(half)) / (angle * angle);
}

Eigen::Matrix3d leftJacobianInverse(const Eigen::Vector3d& phi) {
  const Eigen::Matrix3d Phi = skew(phi);
  return Eigen::Matrix3d::Identity() - 0.5 * Phi +
         jacobianInverseCoefficient(phi.norm()) * Phi * Phi;
}

bool isRotationMatrix(const Eigen::Matrix3d& R, double tolerance) {
  if (tolerance < 0.0) return false;
  // An infinite (or NaN) tolerance accepts any finite R with a positive determinant.
  if (!std::isfinite(tolerance)) return R.allFinite() && R.determinant() > 0.0;
  // With a finite tolerance the deviation test below fails for any non-finite entry (inf or NaN
  // make the deviation inf or NaN): no separate scan needed.
  // |R^T R - I|_F^2 from the six distinct entries of the symmetric R^T R (column dot products).
  const double* r = R.data();  // column-major: column k is r[3k .. 3k + 2]
  const double d0 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2] - 1.0;
  const double d1 = r[3] * r[3] + r[4] * r[4] + r[5] * r[5] - 1.0;
  const double d2 = r[6] * r[6] + r[7] * r[7] + r[8] * r[8] - 1.0;
  const double o01 = r[0] * r[3] + r[1] * r[4] + r[2] * r[5];
  const double o02 = r[0] * r[6] + r[1] * r[7] + r[2] * r[8];
  const double o12 = r[3] * r[6] + r[4] * r[7] + r[5] * r[8];
  const double deviation2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * (o01 * o01 + o02 * o02 + o12 * o12);
  if (!(deviation2 <= tolerance * tolerance)) return false;
  // det(R) = column 0 . (column 1 x column 2).
  const double det = r[0] * (r[4] * r[8] - r[5] * r[7]) + r[1] * (r[5] * r[6] - r[3] * r[8]) +
                     r[2] * (r[3] * r[7] - r[4] * r[6]);
  return det > 0.0;
}

Eigen::Matrix3d uniformRotation(double u1, double u2, double u3) {
  // Shoemake's uniform random quaternion.
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const Eigen::Quaterniond q(a * std::sin(2 * kPi * u2), a * std::cos(2 * kPi * u2),
                             b * std::sin(2 * kPi * u3), b * std::cos(2 * kPi * u3));
  return q.normalized().toRotationMatrix();
}

Eigen::Vector3d rollPitchYawDeg(const Eigen::Matrix3d& R) {
  // R = Rz(yaw) Ry(pitch) Rx(roll): R(2,0) = -sin(pitch), R(1,0)/R(0,0) = tan(yaw),
  // R(2,1)/R(2,2) = tan(roll).
  const double cos_pitch = std::hypot(R(0, 0), R(1, 0));
  const double pitch = std::atan2(-R(2, 0), cos_pitch);
  double roll = 0.0, yaw = 0.0;
  if (cos_pitch > 1e-9) {
    roll = std::atan2(R(2, 1), R(2, 2));
    yaw = std::atan2(R(1, 0), R(0, 0));
  } else {  // gimbal lock (pitch = +-90 deg): only yaw -+ roll is defined; report roll = 0
    yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  return Eigen::Vector3d(rad2deg(roll), rad2deg(pitch), rad2deg(yaw));
}

std::string rollPitchYawText(const Eigen::Matrix3d& R, int decimals) {
  const Eigen::Vector3d rpy = rollPitchYawDeg(R);
  std::ostringstream out;
  out << std::fixed << std::setprecision(decimals)
      << "roll, pitch, yaw (deg, R = Rz(yaw) Ry(pitch) "
      << "Rx(roll)): [" << rpy.x() << ", " << rpy.y() << ", " << rpy.z() << "]";
  return out.str();
}

}  // namespace camera_imu_alignment
