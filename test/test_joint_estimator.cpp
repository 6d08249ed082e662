// The joint maximum-likelihood estimator (estimation/joint_estimator.h) on problems generated from
// a known truth (joint_problem_simulation.h): exact without noise, accurate and consistent with
// noise for two IMU grades, robust to a bad camera pose, honest when the stated noise is too small.
// Degenerate shapes of input and bad input: test_joint_estimator_cases.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "joint_problem_simulation.h"
#include "joint_test_helpers.h"

namespace camera_imu_alignment {
namespace {

using test::allNotes;
using test::errorDeg;
using test::expectFinite;
using test::fractionWithin;
using test::hasNote;
using test::JointSimulation;
using test::JointSimulationOptions;
using test::maxNormalisedError;
using test::motionsAboutZ;
using test::perturbedRotation;
using test::rms;
using test::rotationError;
using test::simulateJointProblem;
using test::solveSimulation;

TEST(JointEstimator, NoiseFreeExactRecovery) {
  // Exact measurements; the stated noise and the priors are realistic except that the priors on
  // the IMU parameters are made 1000x wider (a prior would otherwise pull the estimate off the
  // truth). The soft iron is an isotropic scale: with |m_world| unknown that scale is set by its
  // prior alone, which moves no residual. The gyro bias is constant (its ramp between rests is
  // tested in test_gyro_preintegration; a bias step would be pulled by the walk prior).
  for (bool magnetometer : {true, false}) {
    for (uint64_t seed : {11u, 12u, 13u}) {
      JointSimulationOptions options;
      options.noise = false;
      options.with_magnetometer = magnetometer;
      options.soft_iron_isotropic = true;
      const JointSimulation sim = simulateJointProblem(options, seed);
      JointSettings settings;
      ImuModelPriors& p = settings.priors;
      for (double* sigma : {&p.gyro_scale, &p.gyro_cross_axis, &p.accel_scale, &p.accel_cross_axis,
                            &p.accel_bias_m_s2, &p.hard_iron_t}) {
        *sigma *= 1000.0;
      }
      settings.robust_loss = RobustLossKind::kNone;
      const JointResult r = JointEstimator(settings).solve(
          sim.problem, perturbedRotation(sim.R_cam_imu, deg2rad(2.0), seed));
      ASSERT_TRUE(r.ok) << r.message;
      EXPECT_LT(errorDeg(r, sim), 1e-6) << "seed " << seed << " magnetometer " << magnetometer;
      EXPECT_LT((r.intrinsics.gyro_matrix - sim.T_g).cwiseAbs().maxCoeff(), 1e-8);
      EXPECT_LT((r.intrinsics.accel_matrix - sim.T_a).cwiseAbs().maxCoeff(), 1e-8);
      EXPECT_LT((r.intrinsics.accel_bias_m_s2 - sim.accel_bias_m_s2).norm(), 1e-7);
      ASSERT_EQ(r.intrinsics.accel_bias_per_pose_m_s2.size(), sim.accel_bias_rest_mean.size());
      for (size_t k = 0; k < sim.accel_bias_rest_mean.size(); ++k) {
        EXPECT_LT((r.intrinsics.accel_bias_per_pose_m_s2[k] - sim.accel_bias_rest_mean[k]).norm(),
                  1e-7);
      }
      EXPECT_LT((r.intrinsics.gyro_bias_rad_s - sim.gyro_bias_rest_mean[0]).norm(), 1e-9);
      EXPECT_EQ(r.intrinsics.magnetometer_used, magnetometer);
      if (magnetometer) {
        EXPECT_LT((r.intrinsics.hard_iron_t - sim.hard_iron_t).norm(), 1e-11);
        EXPECT_NEAR(rad2deg(r.intrinsics.magnetic_dip_rad), 60.0, 1e-6);
      }
      EXPECT_LT(r.chi2, 1e-4);           // the priors' share: (truth / (1000 sigma))^2 ~ 1e-6 each
      EXPECT_GE(r.relinearisations, 2);  // the gyro model moved from I by ~1.5 %
      for (const EstimatedValue& v : r.parameters) {
        if (v.name.find("soft_iron") == std::string::npos) {
          EXPECT_EQ(v.estimated, v.name != "soft_iron_minus_identity" &&
                                     (magnetometer || v.name != "hard_iron_t"))
              << v.name;
        }
      }
    }
  }
}

struct GradeStatistics {
  std::vector<double> error_deg;
  std::vector<double> normalised;            // per axis, error / sigma
  std::vector<double> parameter_normalised;  // estimated IMU parameters, error / sigma
  int failures = 0;
};

/// Normalised errors of the estimated IMU parameters against the truth.
void addParameterErrors(const JointResult& r, const JointSimulation& sim,
                        std::vector<double>* out) {
  const ImuIntrinsics& in = r.intrinsics;
  for (int c = 0; c < 3; ++c) {
    if (!in.gyro_matrix_column_estimated[c]) continue;
    for (int row = 0; row < 3; ++row) {
      out->push_back((in.gyro_matrix(row, c) - sim.T_g(row, c)) / in.gyro_matrix_sigma(row, c));
    }
  }
  if (in.accel_matrix_estimated) {
    for (int row = 0; row < 3; ++row) {
      for (int c = 0; c <= row; ++c) {
        out->push_back((in.accel_matrix(row, c) - sim.T_a(row, c)) / in.accel_matrix_sigma(row, c));
      }
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (in.accel_bias_estimated) {
      out->push_back((in.accel_bias_m_s2(i) - sim.accel_bias_m_s2(i)) /
                     in.accel_bias_sigma_m_s2(i));
    }
    if (in.hard_iron_estimated) {
      out->push_back((in.hard_iron_t(i) - sim.hard_iron_t(i)) / in.hard_iron_sigma_t(i));
    }
  }
}

GradeStatistics runGrade(const JointSimulationOptions& options, const JointSettings& settings,
                         int seeds, uint64_t first_seed) {
  GradeStatistics stats;
  const JointEstimator estimator(settings);
  for (int i = 0; i < seeds; ++i) {
    const uint64_t seed = first_seed + i;
    const JointSimulation sim = simulateJointProblem(options, seed);
    const JointResult r =
        estimator.solve(sim.problem, perturbedRotation(sim.R_cam_imu, deg2rad(1.0), seed + 1000));
    if (!r.ok) {
      ++stats.failures;
      ADD_FAILURE() << "seed " << seed << ": " << r.message;
      continue;
    }
    const Eigen::Vector3d error = rotationError(r.R_cam_imu, sim.R_cam_imu);
    stats.error_deg.push_back(rad2deg(error.norm()));
    for (int axis = 0; axis < 3; ++axis) {
      stats.normalised.push_back(error(axis) / std::sqrt(r.covariance_rad2(axis, axis)));
    }
    addParameterErrors(r, sim, &stats.parameter_normalised);
  }
  return stats;
}

void expectConsistent(const GradeStatistics& stats, const std::string& grade) {
  const double normalised_std = rms(stats.normalised);
  std::printf(
      "%s: RMS error %.4f deg, max %.4f deg over %zu seeds; normalised error std %.2f, "
      "%.0f%% within 1 sigma, %.1f%% within 3; IMU parameters %.1f%% within 3 sigma "
      "(%zu, std %.2f)\n",
      grade.c_str(), rms(stats.error_deg),
      *std::max_element(stats.error_deg.begin(), stats.error_deg.end()), stats.error_deg.size(),
      normalised_std, 100.0 * fractionWithin(stats.normalised, 1.0),
      100.0 * fractionWithin(stats.normalised, 3.0),
      100.0 * fractionWithin(stats.parameter_normalised, 3.0), stats.parameter_normalised.size(),
      rms(stats.parameter_normalised));
  EXPECT_EQ(stats.failures, 0) << grade;
  EXPECT_GE(normalised_std, 0.7) << grade << ": the 1-sigma is too pessimistic";
  EXPECT_LE(normalised_std, 1.4) << grade << ": the 1-sigma does not cover the errors";
  EXPECT_GE(fractionWithin(stats.normalised, 1.0), 0.55) << grade;
  EXPECT_LE(fractionWithin(stats.normalised, 1.0), 0.82) << grade;
  EXPECT_GE(fractionWithin(stats.normalised, 3.0), 0.98) << grade;
  EXPECT_GE(fractionWithin(stats.parameter_normalised, 3.0), 0.98) << grade;
  const double parameter_std = rms(stats.parameter_normalised);
  EXPECT_GT(parameter_std, 0.6) << grade;
  EXPECT_LT(parameter_std, 1.4) << grade;
}

TEST(JointEstimator, ConsumerGradeAccurateAndConsistent) {
  // Consumer unit (the generator's defaults = the default priors): gyro 1.7e-4 rad/s/sqrt(Hz),
  // scale 1.5 %, cross-axis 1 %, bias up to 3 deg/s walking; accelerometer 0.02 m/s^2, bias
  // 0.2 m/s^2, scale 1 %; hard iron 15 uT, soft iron 5 %; camera 0.05 deg; 12 poses.
  const GradeStatistics stats = runGrade(JointSimulationOptions{}, JointSettings{}, 30, 100);
  expectConsistent(stats, "consumer");
  EXPECT_LE(rms(stats.error_deg), 0.06);
}

TEST(JointEstimator, NoisyGyroGradeConsistent) {
  // A noisy unit: gyro white noise 4e-3 rad/s/sqrt(Hz) (MPU-6050 class on a vibrating mount),
  // bias walk 3e-4 rad/s/sqrt(s), the same systematic errors.
  JointSimulationOptions options;
  options.gyro_noise_density = 4e-3;
  options.gyro_bias_walk = 3e-4;
  JointSettings settings;
  settings.priors.gyro_bias_walk_rad_s_sqrt_s = 3e-4;
  const GradeStatistics stats = runGrade(options, settings, 30, 200);
  expectConsistent(stats, "noisy");
  EXPECT_LE(rms(stats.error_deg), 0.1);
}

TEST(JointEstimator, RobustLossLimitsABadCameraPose) {
  const JointSimulation clean = simulateJointProblem(JointSimulationOptions{}, 100);
  JointSimulation sim = clean;
  sim.problem.poses[5].R_target_cam =
      sim.problem.poses[5].R_target_cam * expSO3(deg2rad(2.0) * Eigen::Vector3d(0.6, 0.0, 0.8));
  const JointResult huber = solveSimulation(sim);
  JointSettings plain;
  plain.robust_loss = RobustLossKind::kNone;
  const JointResult least_squares = solveSimulation(sim, plain);
  JointSettings cauchy;
  cauchy.robust_loss = RobustLossKind::kCauchy;
  const JointResult cauchy_result = solveSimulation(sim, cauchy);
  ASSERT_TRUE(huber.ok && least_squares.ok && cauchy_result.ok);
  std::printf(
      "2 deg camera outlier: error %.4f deg (Huber), %.4f (Cauchy), %.4f (none), clean "
      "%.4f\n",
      errorDeg(huber, sim), errorDeg(cauchy_result, sim), errorDeg(least_squares, sim),
      errorDeg(solveSimulation(clean), clean));
  EXPECT_LT(errorDeg(huber, sim), errorDeg(least_squares, sim));
  EXPECT_LT(errorDeg(cauchy_result, sim), errorDeg(least_squares, sim));
  // With the robust loss the 2 deg outlier costs little over the clean estimate (0.086 deg here).
  EXPECT_LT(errorDeg(huber, sim), errorDeg(solveSimulation(clean), clean) + 0.04);
  // The bad pose stands out in the per-pose residuals.
  const auto worst =
      std::max_element(huber.pose_residual_norm.begin(), huber.pose_residual_norm.end());
  EXPECT_EQ(worst - huber.pose_residual_norm.begin(), 5);
  EXPECT_GT(*worst, 3.0);
}

TEST(JointEstimator, UnderstatedNoiseScalesTheCovariance) {
  // The data's noise is 3x the stated one: chi2 / dof ~ 9 and the covariance is scaled by it.
  JointSimulationOptions options;
  options.camera_sigma_rad *= 3.0;
  options.accel_noise_m_s2 *= 3.0;
  options.gyro_noise_density *= 3.0;
  options.mag_noise_t *= 3.0;
  JointSimulation sim = simulateJointProblem(options, 110);
  for (JointPose& pose : sim.problem.poses) {
    pose.cov_cam_rad2 /= 9.0;
    pose.accel_mean_cov /= 9.0;
    pose.gyro_mean_cov /= 9.0;
    pose.mag_mean_cov /= 9.0;
  }
  for (GyroSegment& segment : sim.problem.segments) segment.noise_density_rad_s_sqrt_hz /= 3.0;
  const JointResult r = solveSimulation(sim);
  ASSERT_TRUE(r.ok) << r.message;
  // The camera's part is measured first (JointSettings::camera_excess_level): an isotropic
  // variance of (3^2 - 1) x the stated one per axis; the IMU's understated noise is left to the
  // chi2/dof scaling.
  const double stated_rad = options.camera_sigma_rad / 3.0;
  const double excess_ratio =
      std::sqrt(r.camera_excess_variance_rad2 / (8.0 * stated_rad * stated_rad));
  std::printf("camera excess %.2f x the true one, covariance scale %.2f\n", excess_ratio,
              r.covariance_scale);
  EXPECT_GT(excess_ratio, 0.5);
  EXPECT_LT(excess_ratio, 1.5);
  EXPECT_TRUE(hasNote(r, "scatter beyond their PnP covariance")) << allNotes(r);
  EXPECT_GT(r.covariance_scale, 1.5);
  EXPECT_LT(r.chi2_p_value, 1e-6);
  EXPECT_TRUE(hasNote(r, "covariances scaled by chi2/dof")) << allNotes(r);
  EXPECT_LT(maxNormalisedError(r, sim), 3.5);
}

TEST(JointEstimator, SameAnswerFromAFarInitialGuess) {
  const JointSimulation sim = simulateJointProblem(JointSimulationOptions{}, 120);
  const JointResult near = solveSimulation(sim, {}, 0.5, 1);
  const JointResult far = solveSimulation(sim, {}, 10.0, 2);
  ASSERT_TRUE(near.ok && far.ok);
  EXPECT_LT(rad2deg(geodesicDistance(near.R_cam_imu, far.R_cam_imu)), 1e-5);
  EXPECT_LT(errorDeg(far, sim), 0.1);
}

TEST(JointEstimator, SymmetricAccelerometerMatrixExact) {
  JointSimulationOptions options;
  options.noise = false;
  options.with_magnetometer = false;
  options.accel_matrix_form = AccelMatrixForm::kSymmetric;
  const JointSimulation sim = simulateJointProblem(options, 130);
  JointSettings settings;
  settings.accel_matrix_form = AccelMatrixForm::kSymmetric;
  settings.priors.accel_scale *= 1000.0;
  settings.priors.accel_cross_axis *= 1000.0;
  settings.priors.accel_bias_m_s2 *= 1000.0;
  settings.priors.gyro_scale *= 1000.0;
  settings.priors.gyro_cross_axis *= 1000.0;
  const JointResult r = solveSimulation(sim, settings, 2.0);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_LT(errorDeg(r, sim), 1e-6);
  EXPECT_LT((r.intrinsics.accel_matrix - sim.T_a).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LT((r.intrinsics.accel_matrix - r.intrinsics.accel_matrix.transpose()).norm(), 1e-15);
}

}  // namespace
}  // namespace camera_imu_alignment
