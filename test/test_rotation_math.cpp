// SO(3) helpers against independent references (Eigen's AngleAxis, numerical derivatives, closed
// forms built in the test).
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

TEST(RotationMath, SkewIsTheCrossProduct) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d v = test::gaussianVector(rng, 2.0), w = test::gaussianVector(rng, 2.0);
    EXPECT_LT((skew(v) * w - v.cross(w)).norm(), 1e-14);
  }
}

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

TEST(RotationMath, ExpLogRoundTripForRandomRotationVectors) {
  // Rotation vectors uniform in the ball of radius pi (every rotation once, up to the pi sphere).
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3d v = test::uniformBall(rng, kPi);
    const Eigen::Matrix3d R = expSO3(v);
    ASSERT_TRUE(isRotationMatrix(R, 1e-13));
    const Eigen::Vector3d back = logSO3(R);
    ASSERT_TRUE(back.allFinite());
    // Rounding of R near pi costs ~eps / (pi - |v|) in the axis; far from pi it is ~1e-15.
    EXPECT_LT((back - v).norm(), 1e-13 + 1e-15 / std::max(kPi - v.norm(), 1e-3)) << v.transpose();
    // And the other way round: Exp(Log(R)) is R itself.
    EXPECT_LT((expSO3(back) - R).norm(), 1e-13);
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
  // Exact half turns written out by hand (no rounding in R at all): diag(1, -1, -1) etc.
  for (int i = 0; i < 3; ++i) {
    const Eigen::Matrix3d R =
        2.0 * Eigen::Vector3d::Unit(i) * Eigen::Vector3d::Unit(i).transpose() -
        Eigen::Matrix3d::Identity();
    const Eigen::Vector3d v = logSO3(R);
    ASSERT_TRUE(v.allFinite()) << i;
    EXPECT_NEAR(v.norm(), kPi, 1e-15) << i;
    EXPECT_NEAR(std::abs(v(i)), kPi, 1e-15) << i;
  }
  // Random axes at exactly pi and at pi - 1e-9: angle pi (resp. pi - 1e-9), axis up to sign.
  std::mt19937_64 rng(12);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d axis = test::randomUnitVector(rng);
    for (double angle : {kPi, kPi - 1e-9}) {
      const Eigen::Matrix3d R = expSO3(angle * axis);
      const Eigen::Vector3d v = logSO3(R);
      ASSERT_TRUE(v.allFinite()) << axis.transpose();
      EXPECT_NEAR(v.norm(), angle, 1e-12);
      EXPECT_NEAR(std::abs(v.normalized().dot(axis)), 1.0, 1e-12);
      EXPECT_NEAR(rotationAngle(R), angle, 1e-12);
      EXPECT_LT((expSO3(v) - R).norm(), 1e-13);
      const Eigen::Vector3d vq = logQuaternion(Eigen::Quaterniond(R));
      ASSERT_TRUE(vq.allFinite());
      EXPECT_NEAR(vq.norm(), angle, 1e-12);
      EXPECT_NEAR(std::abs(vq.normalized().dot(axis)), 1.0, 1e-12);
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

/// Rotation R1 * diag(s) * R2^T: singular values |s| and, for a negative entry, det -1.
Eigen::Matrix3d withSingularValues(const Eigen::Matrix3d& R1, const Eigen::Vector3d& s,
                                   const Eigen::Matrix3d& R2) {
  return R1 * s.asDiagonal() * R2.transpose();
}

TEST(RotationMath, ProjectionIsIdentityOnRotations) {
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d R = test::randomRotation(rng);
    EXPECT_LT((projectToSO3(R) - R).norm(), 1e-13);
  }
  EXPECT_EQ(projectToSO3(Eigen::Matrix3d::Identity()), Eigen::Matrix3d::Identity());
}

TEST(RotationMath, ProjectionReturnsThePolarFactorForPositiveDeterminant) {
  // M = R1 diag(a, b, c) R2^T with a, b, c > 0: the nearest rotation is R1 R2^T (known by
  // construction, no SVD in the test). Singular values from 1e-4 to 100 cover both code paths.
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> log_s(std::log(1e-4), std::log(100.0));
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Matrix3d R1 = test::randomRotation(rng), R2 = test::randomRotation(rng);
    const Eigen::Vector3d s(std::exp(log_s(rng)), std::exp(log_s(rng)), std::exp(log_s(rng)));
    const Eigen::Matrix3d P = projectToSO3(withSingularValues(R1, s, R2));
    ASSERT_TRUE(P.allFinite());
    EXPECT_NEAR(P.determinant(), 1.0, 1e-12);
    EXPECT_LT((P.transpose() * P - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    const double conditioning = s.maxCoeff() / s.minCoeff();
    EXPECT_LT((P - R1 * R2.transpose()).norm(), 1e-13 * conditioning + 1e-12) << s.transpose();
  }
}

TEST(RotationMath, ProjectionFixesNegativeDeterminantByFlippingTheSmallestDirection) {
  // Documented: U diag(1, 1, det(U V^T)) V^T. For M = R1 diag(a, b, -c) R2^T with c the smallest
  // singular value: U = R1, S = diag(a, b, c), V = R2 diag(1, 1, -1), det(U V^T) = -1, so the
  // answer is R1 diag(1, 1, -1) diag(1, 1, -1) R2^T = R1 R2^T.
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Matrix3d R1 = test::randomRotation(rng), R2 = test::randomRotation(rng);
    const double a = 1.0 + u(rng), b = 0.5 + 0.4 * u(rng), c = 0.4 * u(rng);
    const Eigen::Matrix3d M = withSingularValues(R1, Eigen::Vector3d(a, b, -c), R2);
    ASSERT_LT(M.determinant(), 0.0);
    const Eigen::Matrix3d P = projectToSO3(M);
    EXPECT_TRUE(isRotationMatrix(P, 1e-12));
    EXPECT_LT((P - R1 * R2.transpose()).norm(), 1e-9) << a << " " << b << " " << c;
  }
  // A pure reflection diag(1, 0.9, -0.1) becomes the identity; -I (all equal) a half turn.
  const Eigen::Matrix3d reflection = Eigen::Vector3d(1.0, 0.9, -0.1).asDiagonal();
  EXPECT_LT((projectToSO3(reflection) - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  const Eigen::Matrix3d half_turn = projectToSO3(-Eigen::Matrix3d::Identity());
  EXPECT_TRUE(isRotationMatrix(half_turn, 1e-12));
  EXPECT_NEAR(rotationAngle(half_turn), kPi, 1e-12);
  // Rank-deficient and zero input still give a rotation, never NaN.
  const Eigen::Matrix3d singular = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
  EXPECT_TRUE(isRotationMatrix(projectToSO3(singular), 1e-12));
  EXPECT_TRUE(isRotationMatrix(projectToSO3(Eigen::Matrix3d::Zero()), 1e-12));
}

TEST(RotationMath, JacobianInverseMatchesNumericalDerivativeOfLog) {
  std::mt19937_64 rng(3);
  for (double angle : {0.0, 1e-9, 1e-4, 0.05, 0.09, 0.1, 0.11, 1.0, 2.5, 3.0, kPi - 0.05}) {
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

TEST(RotationMath, JacobianCoefficientMatchesItsClosedForm) {
  // c(t) = (1 - (t/2) cot(t/2)) / t^2, evaluated in long double; 1/12 at 0, 1/pi^2 at pi.
  const auto closed = [](long double t) {
    return (1.0L - 0.5L * t * std::cos(0.5L * t) / std::sin(0.5L * t)) / (t * t);
  };
  EXPECT_DOUBLE_EQ(jacobianInverseCoefficient(0.0), 1.0 / 12.0);
  EXPECT_NEAR(jacobianInverseCoefficient(kPi), 1.0 / (kPi * kPi), 1e-15);
  for (double t : {1e-3, 0.05, 0.0999999, 0.1, 0.1000001, 0.5, 1.0, 2.0, 3.0, kPi - 1e-9}) {
    const double expected = static_cast<double>(closed(t));
    EXPECT_NEAR(jacobianInverseCoefficient(t), expected, 1e-12 * expected) << t;
  }
}

TEST(RotationMath, RotationAngleMatchesTraceFormulaAwayFromTheEnds) {
  std::mt19937_64 rng(4);
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d R = test::randomRotation(rng);
    const double trace_angle = std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0));
    if (trace_angle < 0.1 || trace_angle > kPi - 0.1) continue;
    ++compared;
    EXPECT_NEAR(rotationAngle(R), trace_angle, 1e-12);
    EXPECT_NEAR(geodesicDistance(Eigen::Matrix3d::Identity(), R), trace_angle, 1e-12);
  }
  EXPECT_GT(compared, 150);
  // Geodesic distance is the angle of R_a^T R_b, symmetric, and zero on equal rotations.
  const Eigen::Matrix3d Ra = test::randomRotation(rng), Rb = test::randomRotation(rng);
  const double expected = std::abs(Eigen::AngleAxisd(Eigen::Matrix3d(Ra.transpose() * Rb)).angle());
  EXPECT_NEAR(geodesicDistance(Ra, Rb), expected, 1e-12);
  EXPECT_NEAR(geodesicDistance(Rb, Ra), expected, 1e-12);
  EXPECT_LT(geodesicDistance(Ra, Ra), 1e-15);
}

TEST(RotationMath, IsRotationMatrixRejectsNonRotations) {
  EXPECT_TRUE(isRotationMatrix(Eigen::Matrix3d::Identity()));
  std::mt19937_64 rng(6);
  EXPECT_TRUE(isRotationMatrix(test::randomRotation(rng), 1e-12));
  Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
  nan(1, 1) = std::nan("");
  EXPECT_FALSE(isRotationMatrix(nan));
  Eigen::Matrix3d inf = Eigen::Matrix3d::Identity();
  inf(0, 2) = INFINITY;
  EXPECT_FALSE(isRotationMatrix(inf));
  EXPECT_FALSE(isRotationMatrix(1.01 * Eigen::Matrix3d::Identity()));
  // det +1 but not orthonormal (a shear).
  Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
  shear(0, 1) = 0.1;
  ASSERT_NEAR(shear.determinant(), 1.0, 1e-15);
  EXPECT_FALSE(isRotationMatrix(shear));
  // Orthonormal but det -1 (reflections, -I, a rotation times a reflection).
  EXPECT_FALSE(isRotationMatrix(Eigen::Vector3d(1, 1, -1).asDiagonal().toDenseMatrix()));
  EXPECT_FALSE(isRotationMatrix(-Eigen::Matrix3d::Identity()));
  EXPECT_FALSE(isRotationMatrix(-test::randomRotation(rng)));
  // The tolerance is on the Frobenius norm of R^T R - I.
  const Eigen::Matrix3d slightly_scaled = (1.0 + 1e-4) * test::randomRotation(rng);
  EXPECT_FALSE(isRotationMatrix(slightly_scaled, 1e-6));
  EXPECT_TRUE(isRotationMatrix(slightly_scaled, 1e-3));
}

TEST(RotationMath, UniformRotationGivesRotationsSpreadOverSO3) {
  // Haar measure: the mean of R is zero and the angle's density is (1 - cos t) / pi, whose mean
  // is pi/2 + 2/pi.
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
  double mean_angle = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = uniformRotation(u(rng), u(rng), u(rng));
    ASSERT_TRUE(isRotationMatrix(R, 1e-12));
    mean += R / n;
    mean_angle += rotationAngle(R) / n;
  }
  EXPECT_LT(mean.cwiseAbs().maxCoeff(), 0.02);
  EXPECT_NEAR(mean_angle, kPi / 2 + 2 / kPi, 0.02);
}

TEST(RotationMath, DegreeConversions) {
  EXPECT_DOUBLE_EQ(deg2rad(180.0), kPi);
  EXPECT_DOUBLE_EQ(rad2deg(kPi / 2), 90.0);
  EXPECT_NEAR(kPi, std::acos(-1.0), 0.0);
}

}  // namespace
}  // namespace camera_imu_alignment
