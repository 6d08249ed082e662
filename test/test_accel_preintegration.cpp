// The acceleration model's preintegration (joint_motion.h, integrateAccelLink) against analytic
// cases and against finite differences of itself: the velocity and position integrals of a
// constant acceleration without rotation, and the propagated derivative with respect to the gyro
// model (T_g and the biases at both ends) on a turning, accelerating recording.
#include <gtest/gtest.h>

#include <cmath>

#include "joint_motion.h"

namespace camera_imu_alignment {
namespace {

/// 1 s at 200 Hz: the gyro turning about all axes, the accelerometer varying.
GyroStream turningStream() {
  GyroStream stream;
  for (int i = 0; i <= 260; ++i) {
    const double t = -0.1 + 0.005 * i;
    stream.stamps_s.push_back(t);
    stream.gyro_rad_s.emplace_back(1.2 * std::sin(2.0 * t), 0.8 * std::cos(3.0 * t), 0.5 + t);
    stream.accel_m_s2.emplace_back(1.0 + std::sin(5.0 * t), -2.0 * t, 9.8 + 0.5 * std::cos(t));
  }
  return stream;
}

TEST(AccelPreintegration, ConstantAccelerationWithoutRotation) {
  GyroStream stream;
  const Eigen::Vector3d a(0.3, -1.2, 9.81);
  for (int i = 0; i <= 100; ++i) {
    stream.stamps_s.push_back(0.01 * i);
    stream.gyro_rad_s.emplace_back(Eigen::Vector3d::Zero());
    stream.accel_m_s2.push_back(a);
  }
  const joint::AccelLinkIntegral in =
      joint::integrateAccelLink(stream, 0.1, 0.85, Eigen::Matrix3d::Identity(),
                                Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  const double T = 0.75;
  EXPECT_NEAR(in.duration_s, T, 1e-12);
  EXPECT_LT((in.d0[0] - a * T).norm(), 1e-12);            // velocity change
  EXPECT_LT((in.d0[1] - a * T * T / 2.0).norm(), 1e-12);  // position change beyond v_from T
  EXPECT_LT((in.bias_jacobian[0] - T * Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(AccelPreintegration, GyroModelDerivativeMatchesFiniteDifferences) {
  const GyroStream stream = turningStream();
  Eigen::Matrix3d T_g;
  T_g << 1.02, 0.01, -0.015, 0.012, 0.985, 0.008, -0.01, 0.02, 1.01;
  const Eigen::Vector3d b_from(0.01, -0.02, 0.005), b_to(0.012, -0.018, 0.004);
  const double from = 0.02, to = 1.03;
  const joint::AccelLinkIntegral base =
      joint::integrateAccelLink(stream, from, to, T_g, b_from, b_to);
  constexpr double kStep = 1e-6;
  for (int i = 0; i < 15; ++i) {
    Eigen::Matrix3d T_plus = T_g, T_minus = T_g;
    Eigen::Vector3d bf_plus = b_from, bf_minus = b_from, bt_plus = b_to, bt_minus = b_to;
    if (i < 9) {
      T_plus(i / 3, i % 3) += kStep;
      T_minus(i / 3, i % 3) -= kStep;
    } else if (i < 12) {
      bf_plus(i - 9) += kStep;
      bf_minus(i - 9) -= kStep;
    } else {
      bt_plus(i - 12) += kStep;
      bt_minus(i - 12) -= kStep;
    }
    const auto plus = joint::integrateAccelLink(stream, from, to, T_plus, bf_plus, bt_plus);
    const auto minus = joint::integrateAccelLink(stream, from, to, T_minus, bf_minus, bt_minus);
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d numeric = (plus.d0[k] - minus.d0[k]) / (2.0 * kStep);
      const Eigen::Vector3d analytic = base.gyro_jacobian[k].col(i);
      // The derivative is of order |a| T^2 ~ 10; the propagation's second-order right Jacobian
      // leaves ~1e-5 of it.
      EXPECT_LT((analytic - numeric).norm(), 1e-4 * std::max(1.0, numeric.norm()))
          << "theta " << i << ", integral " << k << ": analytic " << analytic.transpose()
          << ", numeric " << numeric.transpose();
    }
  }
  EXPECT_NEAR(base.theta0_minus_identity(0), 0.02, 1e-12);
  EXPECT_NEAR(base.theta0_minus_identity(1), 0.01, 1e-12);
  EXPECT_NEAR(base.theta0_minus_identity(9), b_from(0), 1e-12);
  EXPECT_NEAR(base.theta0_minus_identity(14), b_to(2), 1e-12);
}

}  // namespace
}  // namespace camera_imu_alignment
