// Cost functors of the joint estimator (private to src/core/estimation), for ceres::AutoDiff.
//
// Parameter blocks (all Euclidean; rotations as increments relinearised between passes):
//   e_X (3)     R_cam_imu = Exp(e_X) X0              (rad, camera axes: left perturbation)
//   e_T (3)     R_world_target = Exp(e_T) T0         (rad, world axes; z held without magnetometer)
//   delta_k (3) R_target_cam_k' = R_target_cam_k Exp(delta_k)   (rad, camera axes)
//   accel_matrix (6)  T_a - I (AccelMatrixForm);  accel_bias_k (3) m/s^2, per pose
//   gyro_matrix (9)   T_g - I, row-major;         gyro_bias_k (3) rad/s, per pose
//   soft_iron (6)     S_m - I symmetric: [xx, yy, zz, xy, xz, yz]
//   hard_iron (3) uT;  field (2) uT: m_world = (0, field[0], field[1])
// Magnetic quantities are in microtesla inside the estimator (well-scaled for the solver).
// Every residual is whitened: r = L^-1 (measured - model) with L L^T the measurement covariance.
#pragma once

#include <ceres/rotation.h>

#include <Eigen/Core>
#include <array>

#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {
namespace joint {

template <typename T>
using Matrix3 = Eigen::Matrix<T, 3, 3>;
template <typename T>
using Vector3 = Eigen::Matrix<T, 3, 1>;

template <typename T>
Matrix3<T> expRotation(const T* rotvec) {
  Matrix3<T> R;
  ceres::AngleAxisToRotationMatrix(rotvec, ceres::ColumnMajorAdapter3x3(R.data()));
  return R;
}

template <typename T>
Vector3<T> logRotation(const Matrix3<T>& R) {
  Vector3<T> rotvec;
  ceres::RotationMatrixToAngleAxis(ceres::ColumnMajorAdapter3x3(R.data()), rotvec.data());
  return rotvec;
}

/// T_a = I + the 6 parameters in the chosen form.
template <typename T>
Matrix3<T> accelMatrix(const T* p, AccelMatrixForm form) {
  Matrix3<T> M = Matrix3<T>::Identity();
  M(0, 0) += p[0];
  M(1, 1) += p[1];
  M(2, 2) += p[2];
  M(1, 0) = p[3];
  M(2, 0) = p[4];
  M(2, 1) = p[5];
  if (form == AccelMatrixForm::kSymmetric) {
    M(0, 1) = p[3];
    M(0, 2) = p[4];
    M(1, 2) = p[5];
  } else {
    M(0, 1) = T(0.0);
    M(0, 2) = T(0.0);
    M(1, 2) = T(0.0);
  }
  return M;
}

/// S_m = I + symmetric [xx, yy, zz, xy, xz, yz].
template <typename T>
Matrix3<T> softIronMatrix(const T* p) {
  Matrix3<T> M;
  M << T(1.0) + p[0], p[3], p[4], p[3], T(1.0) + p[1], p[5], p[4], p[5], T(1.0) + p[2];
  return M;
}

/// T_g = I + the 9 row-major parameters.
template <typename T>
Matrix3<T> gyroMatrix(const T* p) {
  Matrix3<T> M;
  M << T(1.0) + p[0], p[1], p[2], p[3], T(1.0) + p[4], p[5], p[6], p[7], T(1.0) + p[8];
  return M;
}

/// R_world_imu_k^T v_world for R_world_imu_k = Exp(e_T) T0 R_target_cam_k Exp(delta_k) Exp(e_X) X0,
/// as a chain of vector rotations (cheaper with Jets than the matrix product).
template <typename T>
Vector3<T> imuFromWorld(const Eigen::Matrix3d& T0_target_cam, const Eigen::Matrix3d& X0,
                        const T* e_T, const T* delta, const T* e_X, const Vector3<T>& v_world) {
  const T minus_e_T[3] = {-e_T[0], -e_T[1], -e_T[2]};
  const T minus_delta[3] = {-delta[0], -delta[1], -delta[2]};
  const T minus_e_X[3] = {-e_X[0], -e_X[1], -e_X[2]};
  Vector3<T> a, b;
  ceres::AngleAxisRotatePoint(minus_e_T, v_world.data(), a.data());
  b = T0_target_cam.transpose().cast<T>() * a;
  ceres::AngleAxisRotatePoint(minus_delta, b.data(), a.data());
  ceres::AngleAxisRotatePoint(minus_e_X, a.data(), b.data());
  return X0.transpose().cast<T>() * b;
}

/// Accelerometer mean at a rest: a = T_a R_world_imu^T (0, 0, g) + b_a.
struct AccelResidual {
  Eigen::Matrix3d T0_target_cam, X0;  // T0 R_target_cam_k and X0
  Eigen::Vector3d accel_m_s2;
  Eigen::Matrix3d whitening;  // L^-1
  double gravity_m_s2;
  AccelMatrixForm form;

  template <typename T>
  bool operator()(const T* e_T, const T* e_X, const T* delta, const T* accel_matrix,
                  const T* accel_bias, T* residual) const {
    const Vector3<T> up_world(T(0.0), T(0.0), T(gravity_m_s2));
    const Vector3<T> specific_force = imuFromWorld(T0_target_cam, X0, e_T, delta, e_X, up_world);
    const Vector3<T> model =
        accelMatrix(accel_matrix, form) * specific_force + Eigen::Map<const Vector3<T>>(accel_bias);
    Eigen::Map<Vector3<T>> out(residual);
    out = whitening.cast<T>() * (accel_m_s2.cast<T>() - model);
    return true;
  }
};

/// Magnetometer mean at a rest (uT): m = S_m R_world_imu^T (0, f0, f1) + h.
struct MagResidual {
  Eigen::Matrix3d T0_target_cam, X0;
  Eigen::Vector3d mag_ut;
  Eigen::Matrix3d whitening;  // 1/uT

  template <typename T>
  bool operator()(const T* e_T, const T* e_X, const T* delta, const T* soft_iron,
                  const T* hard_iron_ut, const T* field_ut, T* residual) const {
    const Vector3<T> m_world(T(0.0), field_ut[0], field_ut[1]);
    const Vector3<T> m_imu = imuFromWorld(T0_target_cam, X0, e_T, delta, e_X, m_world);
    const Vector3<T> model =
        softIronMatrix(soft_iron) * m_imu + Eigen::Map<const Vector3<T>>(hard_iron_ut);
    Eigen::Map<Vector3<T>> out(residual);
    out = whitening.cast<T>() * (mag_ut.cast<T>() - model);
    return true;
  }
};

/// Hamilton quaternion [w, x, y, z] of a rotation matrix.
inline std::array<double, 4> quaternionOf(const Eigen::Matrix3d& R) {
  std::array<double, 4> q;
  ceres::RotationMatrixToQuaternion(ceres::ColumnMajorAdapter3x3(R.data()), q.data());
  return q;
}

/// Relative rotation between consecutive rests from the gyro vs from camera + R_cam_imu:
/// r = Log(DeltaR(theta)^T R_world_imu_k^T R_world_imu_k+1); R_world_target cancels. Evaluated
/// with quaternions (cheaper with Jets).
struct GyroResidual {
  std::array<double, 4> q_camera_relative;  // of R_target_cam_k^T R_target_cam_k+1
  std::array<double, 4> q_X0;
  std::array<double, 4> q_delta_R0;       // DeltaR preintegrated at theta0
  GyroPreintegrationJacobian jacobian;    // d Log / d theta
  GyroModelVector theta0_minus_identity;  // theta0 with I subtracted from T_g's entries
  Eigen::Matrix3d whitening;              // 1/rad

  template <typename T>
  static void multiply(const T* a, const T* b, T* ab) {
    ceres::QuaternionProduct(a, b, ab);
  }

  // Motion nodes (MotionGyroResidual): the calibrated body rates at the ends, rad/s, IMU frame.
  Eigen::Vector3d rate_from = Eigen::Vector3d::Zero(), rate_to = Eigen::Vector3d::Zero();
  double timeshift0 = 0;  // s, the preintegration's time offset
  /// ChangeGyroResidual: the second mount's linearisation point (pose k+1's R_cam_imu).
  std::array<double, 4> q_X0_to{1.0, 0.0, 0.0, 0.0};

  template <typename T>
  bool operator()(const T* e_X, const T* delta_from, const T* delta_to, const T* gyro_matrix,
                  const T* bias_from, const T* bias_to, T* residual) const {
    return evaluate<T, false>(e_X, nullptr, delta_from, delta_to, gyro_matrix, bias_from, bias_to,
                              nullptr, residual);
  }

  /// With kShifted, the ends at motion nodes move with the time offset: the gyro's rotation
  /// becomes Exp(-rate_from dt) DeltaR Exp(rate_to dt), dt = timeshift - timeshift0. With e_X_to
  /// (not null), pose k+1 has a mount of its own: Exp(e_X_to) q_X0_to.
  template <typename T, bool kShifted>
  bool evaluate(const T* e_X, const T* e_X_to, const T* delta_from, const T* delta_to,
                const T* gyro_matrix, const T* bias_from, const T* bias_to, const T* timeshift,
                T* residual) const {
    T q_e[4], q_X[4], q_X_inverse[4], q_from[4], q_to[4], a[4], b[4];
    const T q_X0_t[4] = {T(q_X0[0]), T(q_X0[1]), T(q_X0[2]), T(q_X0[3])};
    ceres::AngleAxisToQuaternion(e_X, q_e);
    multiply(q_e, q_X0_t, q_X);
    T q_X_to[4] = {q_X[0], q_X[1], q_X[2], q_X[3]};
    if (e_X_to != nullptr) {
      const T q_X0_to_t[4] = {T(q_X0_to[0]), T(q_X0_to[1]), T(q_X0_to[2]), T(q_X0_to[3])};
      ceres::AngleAxisToQuaternion(e_X_to, q_e);
      multiply(q_e, q_X0_to_t, q_X_to);
    }
    q_X_inverse[0] = q_X[0];
    for (int i = 1; i < 4; ++i) q_X_inverse[i] = -q_X[i];
    const T minus_delta_from[3] = {-delta_from[0], -delta_from[1], -delta_from[2]};
    ceres::AngleAxisToQuaternion(minus_delta_from, q_from);
    ceres::AngleAxisToQuaternion(delta_to, q_to);
    const T q_A[4] = {T(q_camera_relative[0]), T(q_camera_relative[1]), T(q_camera_relative[2]),
                      T(q_camera_relative[3])};
    // imu_relative = X^T Exp(-delta_from) A Exp(delta_to) X_to (X_to = X with one mount)
    multiply(q_X_inverse, q_from, a);
    multiply(a, q_A, b);
    multiply(b, q_to, a);
    T q_imu_relative[4];
    multiply(a, q_X_to, q_imu_relative);

    Eigen::Matrix<T, kGyroModelSize, 1> dtheta;
    for (int i = 0; i < 9; ++i) dtheta(i) = gyro_matrix[i] - T(theta0_minus_identity(i));
    for (int i = 0; i < 3; ++i) {
      dtheta(9 + i) = bias_from[i] - T(theta0_minus_identity(9 + i));
      dtheta(12 + i) = bias_to[i] - T(theta0_minus_identity(12 + i));
    }
    const Vector3<T> correction = jacobian.cast<T>() * dtheta;
    T q_correction[4], q_gyro[4];
    ceres::AngleAxisToQuaternion(correction.data(), q_correction);
    const T q_D0[4] = {T(q_delta_R0[0]), T(-q_delta_R0[1]), T(-q_delta_R0[2]), T(-q_delta_R0[3])};
    // gyro_relative^T = Exp(-correction) DeltaR0^T
    q_correction[1] = -q_correction[1];
    q_correction[2] = -q_correction[2];
    q_correction[3] = -q_correction[3];
    multiply(q_correction, q_D0, q_gyro);
    if constexpr (kShifted) {
      // gyro_relative^T = Exp(-rate_to dt) Exp(-correction) DeltaR0^T Exp(rate_from dt)
      const T dt = timeshift[0] - T(timeshift0);
      const T to_angle[3] = {-T(rate_to(0)) * dt, -T(rate_to(1)) * dt, -T(rate_to(2)) * dt};
      const T from_angle[3] = {T(rate_from(0)) * dt, T(rate_from(1)) * dt, T(rate_from(2)) * dt};
      T q_end[4], q_start[4];
      ceres::AngleAxisToQuaternion(to_angle, q_end);
      ceres::AngleAxisToQuaternion(from_angle, q_start);
      multiply(q_end, q_gyro, b);
      multiply(b, q_start, q_gyro);
    }
    multiply(q_gyro, q_imu_relative, a);
    Vector3<T> error;
    ceres::QuaternionToAngleAxis(a, error.data());
    Eigen::Map<Vector3<T>> out(residual);
    out = whitening.cast<T>() * error;
    return true;
  }
};

/// GyroResidual of a segment with a motion node at an end: the time offset is a parameter too.
struct MotionGyroResidual {
  GyroResidual gyro;

  template <typename T>
  bool operator()(const T* e_X, const T* delta_from, const T* delta_to, const T* gyro_matrix,
                  const T* bias_from, const T* bias_to, const T* timeshift, T* residual) const {
    return gyro.evaluate<T, true>(e_X, nullptr, delta_from, delta_to, gyro_matrix, bias_from,
                                  bias_to, timeshift, residual);
  }
};

/// GyroResidual of the motion during which the mount changed (JointProblem::mount_change_pose):
/// the gyro measures the IMU's turn whenever the mount moved, from the first mount's orientation
/// at the rest before to the second's at the rest after: X^T Exp(-delta_from) A Exp(delta_to)
/// X_after.
struct ChangeGyroResidual {
  GyroResidual gyro;  ///< with q_X0_to the second mount's

  template <typename T>
  bool operator()(const T* e_X, const T* e_X_after, const T* delta_from, const T* delta_to,
                  const T* gyro_matrix, const T* bias_from, const T* bias_to, T* residual) const {
    return gyro.evaluate<T, false>(e_X, e_X_after, delta_from, delta_to, gyro_matrix, bias_from,
                                   bias_to, nullptr, residual);
  }
};

/// R_world_imu v for R_world_imu = Exp(e_T) T0 R_target_cam Exp(delta) Exp(e_X) X0 (the inverse
/// chain of imuFromWorld).
template <typename T>
Vector3<T> worldFromImu(const Eigen::Matrix3d& T0_target_cam, const Eigen::Matrix3d& X0,
                        const T* e_T, const T* delta, const T* e_X, const Vector3<T>& v_imu) {
  Vector3<T> a = X0.cast<T>() * v_imu, b;
  ceres::AngleAxisRotatePoint(e_X, a.data(), b.data());
  ceres::AngleAxisRotatePoint(delta, b.data(), a.data());
  b = T0_target_cam.cast<T>() * a;
  ceres::AngleAxisRotatePoint(e_T, b.data(), a.data());
  return a;
}

/// The accelerometer between two keyframes (AccelLink), preintegrated from `from`: with R_w the
/// world-from-IMU rotation at `from`, f_k = int w_k DeltaR T_a^-1 (a - b) dt (k = 0 velocity,
/// k = 1 position), the residuals per axis are
///   r_v = R_w f_0 - g z T - R_world_target (v_to - v_from)
///   r_p = R_w f_1 - g z T^2 / 2 - R_world_target (p_to - p_from - v_from T)
/// with v the IMU's velocity and p = p_cam + R_target_cam l the IMU's position (target frame; l the
/// IMU's position in the camera frame, p_cam the keyframe's camera centre state), whitened per axis
/// by the 2x2 covariance of [r_v, r_p]. Parameter blocks: e_T, e_X, delta_from, accel_matrix,
/// accel_bias, lever_arm, gyro_matrix, gyro_bias_from, gyro_bias_to, pv_from, pv_to (p_cam, v).
struct AccelLinkResidual {
  Eigen::Matrix3d T0_target_cam_from, X0, T0;  // T0 R_target_cam_from, X0, T0 = R_world_target_0
  Eigen::Vector3d d0[2];
  Eigen::Matrix3d bias_jacobian[2];
  Eigen::Matrix<double, 3, 9> per_entry[2];
  Eigen::Matrix<double, 3, 15> gyro_jacobian[2];  // d d0[k] / d theta (T_g, bias from, bias to)
  Eigen::Matrix<double, 15, 1> theta0_minus_identity;
  Eigen::Matrix3d R_tc_from, R_tc_to;  // the keyframes' measured camera orientations
  double gravity_m_s2, duration_s;
  Eigen::Matrix2d whitening;  // L^-1 of each axis' [r_v, r_p] covariance
  AccelMatrixForm form;

  static constexpr int kBlocks = 11;
  static constexpr int kBlockSizes[kBlocks] = {3, 3, 3, 6, 3, 3, 9, 3, 3, 6, 6};

  template <typename T>
  bool operator()(T const* const* parameters, T* residual) const {
    const T* e_T = parameters[0];
    const T* e_X = parameters[1];
    const T* delta = parameters[2];
    const Matrix3<T> P = accelMatrix(parameters[3], form) - Matrix3<T>::Identity();
    const Eigen::Map<const Vector3<T>> b(parameters[4]);
    const Eigen::Map<const Vector3<T>> l(parameters[5]);
    Eigen::Matrix<T, 15, 1> dtheta;
    for (int i = 0; i < 9; ++i) dtheta(i) = parameters[6][i] - T(theta0_minus_identity(i));
    for (int i = 0; i < 3; ++i) {
      dtheta(9 + i) = parameters[7][i] - T(theta0_minus_identity(9 + i));
      dtheta(12 + i) = parameters[8][i] - T(theta0_minus_identity(12 + i));
    }
    const T* pv_from = parameters[9];
    const T* pv_to = parameters[10];
    const Vector3<T> v_from(pv_from[3], pv_from[4], pv_from[5]);
    const Vector3<T> v_to(pv_to[3], pv_to[4], pv_to[5]);
    const Vector3<T> p_from =
        Vector3<T>(pv_from[0], pv_from[1], pv_from[2]) + R_tc_from.cast<T>() * l;
    const Vector3<T> p_to = Vector3<T>(pv_to[0], pv_to[1], pv_to[2]) + R_tc_to.cast<T>() * l;
    const T dt(duration_s);
    const Vector3<T> change[2] = {v_to - v_from, p_to - p_from - v_from * dt};
    const T gravity[2] = {T(gravity_m_s2) * dt, T(0.5 * gravity_m_s2) * dt * dt};
    Vector3<T> r[2];
    for (int k = 0; k < 2; ++k) {
      Vector3<T> f =
          d0[k].cast<T>() + gyro_jacobian[k].cast<T>() * dtheta - bias_jacobian[k].cast<T>() * b;
      for (int s = 0; s < 3; ++s) {
        for (int u = 0; u < 3; ++u) f -= P(s, u) * per_entry[k].col(3 * s + u).cast<T>();
      }
      Vector3<T> predicted = worldFromImu(T0_target_cam_from, X0, e_T, delta, e_X, f);
      predicted(2) -= gravity[k];
      const Vector3<T> rotated = T0.cast<T>() * change[k];
      Vector3<T> measured;
      ceres::AngleAxisRotatePoint(e_T, rotated.data(), measured.data());
      r[k] = predicted - measured;
    }
    for (int i = 0; i < 3; ++i) {
      residual[i] = T(whitening(0, 0)) * r[0](i) + T(whitening(0, 1)) * r[1](i);
      residual[3 + i] = T(whitening(1, 0)) * r[0](i) + T(whitening(1, 1)) * r[1](i);
    }
    return true;
  }
};

/// A camera rotation measured between two poses without a target (JointProblem::camera_links):
/// r = L^-1 Log(R_meas^T Exp(-delta_from) C Exp(delta_to)), C = R_target_cam_from^T R_target_cam_to
/// of the poses' starting orientations (right perturbation in the `to` camera's axes).
struct CameraLinkResidual {
  Eigen::Matrix3d R_measured_transpose, C;
  Eigen::Matrix3d whitening;  // L^-1

  template <typename T>
  bool operator()(const T* delta_from, const T* delta_to, T* residual) const {
    const T minus_from[3] = {-delta_from[0], -delta_from[1], -delta_from[2]};
    const Matrix3<T> model = expRotation(minus_from) * C.cast<T>() * expRotation(delta_to);
    const Matrix3<T> error = R_measured_transpose.cast<T>() * model;
    Eigen::Map<Vector3<T>> out(residual);
    out = whitening.cast<T>() * logRotation(error);
    return true;
  }
};

/// Bias random walk (gyro or accelerometer) between consecutive rests: r = (b_to - b_from) / sigma.
struct BiasWalkResidual {
  double inverse_sigma;  // 1 / (walk * sqrt(dt)), in the bias' inverse units

  template <typename T>
  bool operator()(const T* bias_from, const T* bias_to, T* residual) const {
    for (int i = 0; i < 3; ++i) residual[i] = (bias_to[i] - bias_from[i]) * T(inverse_sigma);
    return true;
  }
};

}  // namespace joint
}  // namespace camera_imu_alignment
