// SO(3) helpers shared by every solver: exponential and logarithm maps, projection onto SO(3),
// geodesic angles and the SO(3) Jacobians. Angles are in radians unless a name ends in _deg.
// Conventions (doc/CONVENTIONS.md): R_a_b maps vectors from frame b into frame a.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace camera_imu_alignment {

/// Skew-symmetric (cross-product) matrix: skew(v) * w == v.cross(w).
Eigen::Matrix3d skew(const Eigen::Vector3d& v);

/// Rotation matrix of the rotation vector `rotvec` (axis * angle, rad). Exact for all angles.
Eigen::Matrix3d expSO3(const Eigen::Vector3d& rotvec);

/// Rotation vector (axis * angle, angle in [0, pi]) of a rotation matrix. Computed through a
/// quaternion (largest-diagonal branch), so it stays accurate near 0 and near pi, where the
/// trace/acos formula loses the axis (the failure mode of OpenCV issues #17986 and #24871).
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R);

/// Rotation vector of a unit quaternion (q and -q give the same); equals logSO3 of its matrix.
Eigen::Vector3d logQuaternion(const Eigen::Quaterniond& q);

/// Rotation angle of R in [0, pi] (rad), accurate near 0 and pi.
double rotationAngle(const Eigen::Matrix3d& R);

/// Geodesic distance |Log(R_a^T R_b)| in rad.
double geodesicDistance(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);

/// Nearest rotation in the Frobenius norm: M = U S V^T -> U diag(1, 1, det(U V^T)) V^T (for
/// det(M) > 0 simply U V^T, the orthogonal polar factor, computed by Newton's polar iteration).
Eigen::Matrix3d projectToSO3(const Eigen::Matrix3d& M);

/// Inverse of the left Jacobian of SO(3): Log(Exp(d) Exp(phi)) ~ phi + Jl^-1(phi) d for small d.
/// The right-Jacobian inverse is leftJacobianInverse(-phi).
Eigen::Matrix3d leftJacobianInverse(const Eigen::Vector3d& phi);

/// c(theta) in Jl^-1(phi) = I - Phi/2 + c Phi^2 (Phi = skew(phi), theta = |phi|); 1/12 near 0.
double jacobianInverseCoefficient(double angle);

/// True when R is finite, orthonormal within `tolerance` (Frobenius) and has det +1.
bool isRotationMatrix(const Eigen::Matrix3d& R, double tolerance = 1e-6);

/// Random rotation uniformly distributed on SO(3), from three uniform numbers in [0, 1).
Eigen::Matrix3d uniformRotation(double u1, double u2, double u3);

/// Roll, pitch, yaw (deg) with R = Rz(yaw) Ry(pitch) Rx(roll): the x-y-z fixed-axis convention of
/// tf and of every output of this package. At pitch +-90 deg roll is reported as 0.
Eigen::Vector3d rollPitchYawDeg(const Eigen::Matrix3d& R);

/// rollPitchYawDeg as every tool, log line and summary prints it, the convention beside the
/// numbers: "roll, pitch, yaw (deg, R = Rz(yaw) Ry(pitch) Rx(roll)): [66.58, -61.35, -105.97]".
std::string rollPitchYawText(const Eigen::Matrix3d& R, int decimals);

/// Degrees <-> radians.
constexpr double kPi = 3.14159265358979323846;
constexpr double deg2rad(double deg) { return deg * kPi / 180.0; }
constexpr double rad2deg(double rad) { return rad * 180.0 / kPi; }

}  // namespace camera_imu_alignment
