// Gyro preintegration (estimation/gyro_preintegration.h): analytic constant-rate cases, an
// independent quaternion integration, the bias ramp, and the 3 x 15 Jacobian against finite
// differences of a full re-integration.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

struct Samples {
  std::vector<double> stamps;
  std::vector<Eigen::Vector3d> gyro;
};

/// n samples at `rate_hz` from t0, rate(t) a smooth random function (rad/s).
Samples smoothSamples(int n, double rate_hz, double t0, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d a, b, c;
  for (int i = 0; i < 3; ++i) {
    a(i) = normal(rng);
    b(i) = 2.0 * normal(rng);
    c(i) = normal(rng);
  }
  Samples s;
  for (int i = 0; i < n; ++i) {
    const double t = t0 + i / rate_hz;
    s.stamps.push_back(t);
    s.gyro.push_back(a + (b * std::sin(3.0 * (t - t0)) + c * std::cos(1.7 * (t - t0))));
  }
  return s;
}

Eigen::Matrix3d nearIdentity(uint64_t seed, double size) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, size);
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 9; ++i) M(i / 3, i % 3) += normal(rng);
  return M;
}

TEST(GyroPreintegration, SampleIntervalsEndWithTheMedianPeriod) {
  const std::vector<double> dt = sampleIntervals({0.0, 0.01, 0.02, 0.05, 0.06});
  ASSERT_EQ(dt.size(), 5u);
  EXPECT_NEAR(dt[0], 0.01, 1e-15);
  EXPECT_NEAR(dt[2], 0.03, 1e-15);
  EXPECT_NEAR(dt[4], 0.01, 1e-15);  // median of 0.01, 0.01, 0.03, 0.01
  EXPECT_EQ(sampleIntervals({1.0}), std::vector<double>({0.0}));
}

TEST(GyroPreintegration, ConstantRateGivesTheExponential) {
  const Eigen::Matrix3d T_g = nearIdentity(1, 0.02);
  const Eigen::Vector3d bias(0.01, -0.02, 0.03);
  const Eigen::Vector3d true_rate(0.4, -0.9, 1.3);  // rad/s about a fixed axis
  std::vector<double> stamps;
  std::vector<Eigen::Vector3d> gyro;
  for (int i = 0; i < 400; ++i) {
    stamps.push_back(5.0 + i * 0.005);
    gyro.push_back(T_g * true_rate + bias);
  }
  const GyroPreintegration p = preintegrateGyro(stamps, gyro, 5.0, 7.0, T_g, bias, bias);
  EXPECT_NEAR(p.duration_s, 2.0, 1e-12);
  EXPECT_LT(geodesicDistance(p.delta_R, expSO3(true_rate * 2.0)), 1e-12);
}

TEST(GyroPreintegration, MatchesAPlainQuaternionIntegrationWithABiasRamp) {
  const Samples s = smoothSamples(600, 200.0, 10.0, 2);
  const Eigen::Matrix3d T_g = nearIdentity(3, 0.02);
  const Eigen::Vector3d b_from(0.02, 0.01, -0.03), b_to(-0.01, 0.04, 0.0);
  const double t_from = 10.0, t_to = 13.0;
  const GyroPreintegration p = preintegrateGyro(s.stamps, s.gyro, t_from, t_to, T_g, b_from, b_to);
  // Independent: quaternion product, bias interpolated at each stamp, fixed 5 ms steps.
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  const Eigen::Matrix3d T_inv = T_g.inverse();
  for (size_t i = 0; i < s.stamps.size(); ++i) {
    const double frac = (s.stamps[i] - t_from) / (t_to - t_from);
    const Eigen::Vector3d w = T_inv * (s.gyro[i] - (b_from + frac * (b_to - b_from)));
    const double angle = w.norm() * 0.005;
    q = q * Eigen::Quaterniond(Eigen::AngleAxisd(angle, w.normalized()));
  }
  EXPECT_LT(geodesicDistance(p.delta_R, q.toRotationMatrix()), 1e-11);
}

TEST(GyroPreintegration, BiasRampIsClampedOutsideTheMotion) {
  // Samples before t_from use b_from, after t_to b_to.
  std::vector<double> stamps = {0.0, 0.1, 0.2, 0.3};
  std::vector<Eigen::Vector3d> gyro(4, Eigen::Vector3d(1.0, 0.0, 0.0));
  const Eigen::Vector3d b_from(0.5, 0.0, 0.0), b_to(0.9, 0.0, 0.0);
  const GyroPreintegration p =
      preintegrateGyro(stamps, gyro, 5.0, 6.0, Eigen::Matrix3d::Identity(), b_from, b_to);
  EXPECT_NEAR(logSO3(p.delta_R).x(), 0.5 * 0.4, 1e-12);
  const GyroPreintegration q =
      preintegrateGyro(stamps, gyro, -6.0, -5.0, Eigen::Matrix3d::Identity(), b_from, b_to);
  EXPECT_NEAR(logSO3(q.delta_R).x(), 0.1 * 0.4, 1e-12);
}

TEST(GyroPreintegration, JacobianMatchesFiniteDifferences) {
  const Samples s = smoothSamples(400, 200.0, 0.0, 4);
  const Eigen::Matrix3d T_g = nearIdentity(5, 0.02);
  const Eigen::Vector3d b_from(0.02, 0.01, -0.03), b_to(-0.01, 0.04, 0.0);
  const GyroPreintegration p = preintegrateGyro(s.stamps, s.gyro, 0.0, 2.0, T_g, b_from, b_to);
  const double h = 1e-6;
  for (int j = 0; j < kGyroModelSize; ++j) {
    GyroModelVector plus = p.theta0, minus = p.theta0;
    plus(j) += h;
    minus(j) -= h;
    auto integrate = [&](const GyroModelVector& theta) {
      Eigen::Matrix3d M;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) M(r, c) = theta(3 * r + c);
      }
      return preintegrateGyro(s.stamps, s.gyro, 0.0, 2.0, M, theta.segment<3>(9),
                              theta.segment<3>(12))
          .delta_R;
    };
    const Eigen::Vector3d numeric = (logSO3(p.delta_R.transpose() * integrate(plus)) -
                                     logSO3(p.delta_R.transpose() * integrate(minus))) /
                                    (2.0 * h);
    EXPECT_LT((numeric - p.jacobian.col(j)).norm(), 1e-6 * (1.0 + numeric.norm()))
        << "parameter " << j << ": numeric " << numeric.transpose() << " analytic "
        << p.jacobian.col(j).transpose();
  }
}

TEST(GyroPreintegration, FirstOrderCorrectionErrorIsQuadratic) {
  const Samples s = smoothSamples(400, 200.0, 0.0, 6);
  const GyroPreintegration p =
      preintegrateGyro(s.stamps, s.gyro, 0.0, 2.0, Eigen::Matrix3d::Identity(),
                       Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  GyroModelVector direction;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int j = 0; j < kGyroModelSize; ++j) direction(j) = normal(rng);
  double previous_error = 0.0;
  for (double size : {1e-2, 5e-3}) {
    const GyroModelVector theta = p.theta0 + size * direction;
    Eigen::Matrix3d M;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) M(r, c) = theta(3 * r + c);
    }
    const Eigen::Matrix3d exact =
        preintegrateGyro(s.stamps, s.gyro, 0.0, 2.0, M, theta.segment<3>(9), theta.segment<3>(12))
            .delta_R;
    const double error = geodesicDistance(correctedDeltaR(p, theta), exact);
    const double uncorrected = geodesicDistance(p.delta_R, exact);
    EXPECT_LT(error, 0.05 * uncorrected) << size;
    if (previous_error > 0.0) {
      EXPECT_NEAR(previous_error / error, 4.0, 0.8);
    }
    previous_error = error;
  }
}

TEST(GyroPreintegration, RightJacobianMatchesFiniteDifferences) {
  for (const Eigen::Vector3d& phi :
       {Eigen::Vector3d(0.3, -1.2, 0.5), Eigen::Vector3d(1e-7, 2e-7, 0.0),
        Eigen::Vector3d(0.0, 0.0, 0.0)}) {
    const Eigen::Matrix3d Jr = rightJacobianSO3(phi);
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d d = 1e-6 * Eigen::Vector3d::Unit(j);
      const Eigen::Vector3d numeric = (logSO3(expSO3(phi).transpose() * expSO3(phi + d)) -
                                       logSO3(expSO3(phi).transpose() * expSO3(phi - d))) /
                                      2e-6;
      EXPECT_LT((numeric - Jr.col(j)).norm(), 1e-8);
    }
  }
}

}  // namespace
}  // namespace camera_imu_alignment
