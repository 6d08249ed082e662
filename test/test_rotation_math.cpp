// SO(3) helpers against independent references (Eigen's AngleAxis, numerical derivatives).
#include <gtest/gtest.h>

#include <Eigen/SVD>

#include "camera_imu_alignment/rotation_math.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

TEST(RotationMath, ExpLogRoundTripOverAllAngles) {
  std::mt19937_64 rng(1);
  for (double angle : {0.0, 1e-12, 1e-9, 1e-6, 0.01, 0.099, 0.1, 0.5, 1.0, 2.0, 2.7, 3.0,
                       kPi - 1e-6, kPi - 1e-9}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Vector3d axis = test::randomUnitVector(rng);
      const Eigen::Vector3d v = angle * axis;
      const Eigen::Matrix3d R = expSO3(v);
      EXPECT_LT((R - test::axisAngle(axis, angle)).norm(), 1e-14) << angle;
      const Eigen::Vector3d back = logSO3(R);
      ASSERT_TRUE(back.allFinite()) << angle;
      EXPECT_LT((back - v).norm(), 1e-12 + 1e-9 * angle) << "angle " << angle;
      EXPECT_NEAR(rotationAngle(R), angle, 1e-12 + 1e-9 * angle);
    }
  }
}

TEST(RotationMath, QuaternionLogEqualsMatrixLogForBothSigns) {
  std::mt19937_64 rng(5);
  for (double angle : {0.0, 1e-10, 1e-4, 0.05, 0.199, 0.2, 0.201, 1.0, 3.0, kPi - 1e-7}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Vector3d v = angle * test::randomUnitVector(rng);
      const Eigen::Quaterniond q(
          Eigen::AngleAxisd(angle, v.norm() > 0 ? v.normalized() : Eigen::Vector3d::UnitX()));
      const Eigen::Quaterniond minus_q(-q.w(), -q.x(), -q.y(), -q.z());
      EXPECT_LT((logQuaternion(q) - logSO3(q.toRotationMatrix())).norm(), 1e-12) << angle;
      EXPECT_LT((logQuaternion(minus_q) - logQuaternion(q)).norm(), 1e-15) << angle;
    }
  }
}

TEST(RotationMath, LogAtExactlyPiGivesTheAxisUpToSign) {
  for (const Eigen::Vector3d& axis :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1),
        Eigen::Vector3d(1.0 / 3, 2.0 / 3, -2.0 / 3)}) {
    const Eigen::Matrix3d R = test::axisAngle(axis, kPi);
    const Eigen::Vector3d v = logSO3(R);
    ASSERT_TRUE(v.allFinite());
    EXPECT_NEAR(v.norm(), kPi, 1e-12);
    EXPECT_NEAR(std::abs(v.normalized().dot(axis)), 1.0, 1e-12);
    EXPECT_NEAR(rotationAngle(R), kPi, 1e-12);
  }
}

TEST(RotationMath, ProjectionReturnsTheNearestRotation) {
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d R = test::randomRotation(rng);
    EXPECT_LT((projectToSO3(R) - R).norm(), 1e-13);
    // A perturbed rotation projects to U V^T of its SVD (computed here independently).
    const Eigen::Matrix3d M = R + 0.3 * Eigen::Matrix3d::Random();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant();
    const Eigen::Matrix3d expected = svd.matrixU() * D * svd.matrixV().transpose();
    const Eigen::Matrix3d P = projectToSO3(M);
    EXPECT_LT((P - expected).norm(), 1e-10);
    EXPECT_NEAR(P.determinant(), 1.0, 1e-12);
    EXPECT_LT((P.transpose() * P - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  }
  // A reflection (det -1) becomes the nearest proper rotation: flip the smallest singular
  // direction.
  const Eigen::Matrix3d reflection = Eigen::Vector3d(1.0, 0.9, -0.1).asDiagonal();
  const Eigen::Matrix3d P = projectToSO3(reflection);
  EXPECT_LT((P - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  // Rank-deficient input still gives a rotation, never NaN.
  const Eigen::Matrix3d singular = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
  EXPECT_TRUE(isRotationMatrix(projectToSO3(singular), 1e-12));
}

TEST(RotationMath, JacobianInverseMatchesNumericalDerivativeOfLog) {
  std::mt19937_64 rng(3);
  for (double angle : {1e-4, 0.05, 0.09, 0.11, 1.0, 2.5, 3.0}) {
    const Eigen::Vector3d phi = angle * test::randomUnitVector(rng);
    const Eigen::Matrix3d R = expSO3(phi);
    Eigen::Matrix3d numeric;
    const double h = 1e-6;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d d = h * Eigen::Vector3d::Unit(i);
      numeric.col(i) = (logSO3(expSO3(d) * R) - logSO3(expSO3(-d) * R)) / (2 * h);
    }
    EXPECT_LT((leftJacobianInverse(phi) - numeric).norm(), 1e-7) << "angle " << angle;
    // Right Jacobian inverse = left one at -phi: Log(R Exp(d)) ~ phi + Jr^-1 d.
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d d = h * Eigen::Vector3d::Unit(i);
      numeric.col(i) = (logSO3(R * expSO3(d)) - logSO3(R * expSO3(-d))) / (2 * h);
    }
    EXPECT_LT((leftJacobianInverse(-phi) - numeric).norm(), 1e-7) << "angle " << angle;
  }
}

TEST(RotationMath, RotationAngleMatchesTraceFormulaAwayFromTheEnds) {
  std::mt19937_64 rng(4);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d R = test::randomRotation(rng);
    const double trace_angle = std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0));
    if (trace_angle < 0.1 || trace_angle > kPi - 0.1) continue;
    EXPECT_NEAR(rotationAngle(R), trace_angle, 1e-12);
    EXPECT_NEAR(geodesicDistance(Eigen::Matrix3d::Identity(), R), trace_angle, 1e-12);
  }
}

TEST(RotationMath, IsRotationMatrixRejectsNonRotations) {
  EXPECT_TRUE(isRotationMatrix(Eigen::Matrix3d::Identity()));
  Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
  nan(1, 1) = std::nan("");
  EXPECT_FALSE(isRotationMatrix(nan));
  EXPECT_FALSE(isRotationMatrix(1.01 * Eigen::Matrix3d::Identity()));
  EXPECT_FALSE(isRotationMatrix(Eigen::Vector3d(1, 1, -1).asDiagonal().toDenseMatrix()));
  Eigen::Matrix3d inf = Eigen::Matrix3d::Identity();
  inf(0, 2) = INFINITY;
  EXPECT_FALSE(isRotationMatrix(inf));
}

}  // namespace
}  // namespace camera_imu_alignment
