// The joint estimator (estimation/joint_estimator.h) on degenerate shapes of input: motions that do
// not excite some IMU parameters (held at their priors, with notes), 3 poses, no magnetometer, no
// gyro, several groups, no rotation; and bad input (ok = false with a message, never a NaN).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

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

TEST(JointEstimator, RotationsAboutOneAxisHoldTheOtherGyroColumns) {
  // Every motion about IMU z but one of 25 deg about IMU x (rotations about a single axis leave
  // R_cam_imu undetermined about it): the gyro's y column is not excited. The one 25 deg motion
  // determines the x column (its posterior 1-sigma ~10 % of the prior's: 1.5 % of 25 deg is 0.4
  // deg against 0.05 deg of camera noise), which a 30 deg rule of accumulated rotation used to
  // hold.
  for (bool pin : {false, true}) {
    JointSimulationOptions options;
    options.motions_imu_rad = motionsAboutZ(11, 25.0);
    const JointSimulation sim = simulateJointProblem(options, 31);
    JointSettings settings;
    settings.pin_unexcited_parameters = pin;
    const JointResult r = solveSimulation(sim, settings);
    ASSERT_TRUE(r.ok) << r.message;
    expectFinite(r);
    const ImuIntrinsics& in = r.intrinsics;
    EXPECT_TRUE(in.gyro_matrix_column_estimated[0]);
    EXPECT_FALSE(in.gyro_matrix_column_estimated[1]);
    EXPECT_TRUE(in.gyro_matrix_column_estimated[2]);
    EXPECT_FALSE(hasNote(r, "gyro scale x")) << allNotes(r);
    EXPECT_TRUE(hasNote(r, "gyro scale y")) << allNotes(r);
    EXPECT_FALSE(hasNote(r, "gyro scale z")) << allNotes(r);
    EXPECT_TRUE(hasNote(r, "next, rotate about the IMU axis")) << allNotes(r);
    // The suggestion: a rotation axis perpendicular to IMU z.
    EXPECT_LT(std::abs(r.suggested_rotation_axis_imu.z()), 0.2)
        << r.suggested_rotation_axis_imu.transpose();
    EXPECT_NEAR(r.suggested_rotation_axis_imu.norm(), 1.0, 1e-9);
    // Held at the prior (I) when pinned; otherwise constrained by its prior and the little data
    // there is, and covered by its 1-sigma. The estimated column z is recovered.
    for (int row = 0; row < 3; ++row) {
      for (int c = 1; c < 2; ++c) {
        if (pin) {
          EXPECT_EQ(in.gyro_matrix(row, c), row == c ? 1.0 : 0.0);
          EXPECT_EQ(in.gyro_matrix_sigma(row, c), row == c ? 0.015 : 0.01);
        } else {
          EXPECT_LT(std::abs(in.gyro_matrix(row, c) - sim.T_g(row, c)),
                    3.0 * in.gyro_matrix_sigma(row, c));
        }
      }
      for (int c : {0, 2}) {
        EXPECT_LT(std::abs(in.gyro_matrix(row, c) - sim.T_g(row, c)),
                  3.0 * in.gyro_matrix_sigma(row, c));
        EXPECT_LT(in.gyro_matrix_sigma(row, c), 0.5 * (row == c ? 0.015 : 0.01));
      }
    }
    for (const EstimatedValue& v : r.parameters) {
      if (v.name == "gyro_matrix_column_y") EXPECT_FALSE(v.estimated) << v.name;
      if (v.name == "gyro_matrix_column_x" || v.name == "gyro_matrix_column_z") {
        EXPECT_TRUE(v.estimated);
      }
    }
    EXPECT_LT(maxNormalisedError(r, sim), 3.5) << "pin " << pin;
  }
}

TEST(JointEstimator, SmallTiltsDetermineTheAccelerometerBiasAndCoverTheError) {
  // A rig that yaws (IMU z up) and tilts by 12 deg at most: gravity is seen within a narrow cone
  // (a coverage cut-off at ~9 deg of tilt used to hold the accelerometer's bias and matrix at
  // their prior here). The yaws carry the information: a world-fixed tilt of the target turns
  // with them in the IMU frame, a bias does not. So the bias is determined by the data (posterior
  // 1-sigma below 1/sqrt(2) of the prior's); T_a is not, and its prior uncertainty stays in the
  // covariance, so the 1-sigma of R_cam_imu covers the error.
  JointSimulationOptions options;
  options.initial_R_world_imu = Eigen::Matrix3d::Identity();
  std::vector<double> normalised;
  for (uint64_t seed = 40; seed < 50; ++seed) {
    // yaw, tilt out, tilt back, yaw, ...
    options.motions_imu_rad = motionsAboutZ(11, 0.0);
    for (int i : {1, 4, 7, 10}) {
      const Eigen::Vector3d axis = i % 2 == 1 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
      options.motions_imu_rad[i] = deg2rad(12.0) * axis;
      if (i + 1 < 11) options.motions_imu_rad[i + 1] = -deg2rad(12.0) * axis;
    }
    const JointSimulation sim = simulateJointProblem(options, seed);
    const JointResult r = solveSimulation(sim);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_TRUE(r.intrinsics.accel_bias_estimated);
    EXPECT_FALSE(hasNote(r, "accelerometer bias")) << allNotes(r);
    // Some entries of T_a need gravity from other directions: they rest on their prior.
    EXPECT_FALSE(r.intrinsics.accel_matrix_estimated);
    EXPECT_TRUE(hasNote(r, "accelerometer scale and non-orthogonality rests on its prior"))
        << allNotes(r);
    EXPECT_FALSE(hasNote(r, "spread")) << allNotes(r);
    const Eigen::Vector3d error = rotationError(r.R_cam_imu, sim.R_cam_imu);
    for (int axis = 0; axis < 3; ++axis) {
      normalised.push_back(error(axis) / std::sqrt(r.covariance_rad2(axis, axis)));
    }
  }
  std::printf("yaw and small tilts: normalised error std %.2f, %.0f%% within 3 sigma\n",
              rms(normalised), 100.0 * fractionWithin(normalised, 3.0));
  EXPECT_LT(rms(normalised), 1.4);
  EXPECT_GE(fractionWithin(normalised, 3.0), 0.95);

  // Pinned: T_a, which the data do not determine, is held at I; the bias, which they do, is
  // estimated (not left at the prior's mean).
  JointSettings pinned;
  pinned.pin_unexcited_parameters = true;
  const JointSimulation sim40 = simulateJointProblem(options, 40);
  const JointResult r = solveSimulation(sim40, pinned);
  const JointResult free = solveSimulation(sim40);
  ASSERT_TRUE(r.ok && free.ok) << r.message;
  EXPECT_EQ(r.intrinsics.accel_matrix, Eigen::Matrix3d::Identity());
  EXPECT_TRUE(free.intrinsics.accel_matrix != Eigen::Matrix3d::Identity());
  EXPECT_GT((r.intrinsics.accel_bias_m_s2 - Eigen::Vector3d::Zero()).norm(), 0.05);
  // Free, the bias estimate is within 3 of its 1-sigma of the truth.
  EXPECT_LT((free.intrinsics.accel_bias_m_s2 - sim40.accel_bias_m_s2).norm(),
            3.0 * free.intrinsics.accel_bias_sigma_m_s2.norm());
}

TEST(JointEstimator, ThreePoses) {
  JointSimulationOptions options;
  options.num_poses = 3;
  options.min_rotation_deg = 60.0;
  for (uint64_t seed = 50; seed < 55; ++seed) {
    const JointSimulation sim = simulateJointProblem(options, seed);
    const JointResult r = solveSimulation(sim);
    ASSERT_TRUE(r.ok) << r.message;
    expectFinite(r);
    EXPECT_FALSE(r.intrinsics.accel_matrix_estimated);  // 3 directions lie in a plane
    // Two motions cannot fix T_g and the accelerometer bias keeps its prior (0.2 m/s^2 ~ 1.2 deg
    // of tilt): errors of ~1 deg are the information limit here, and the 1-sigma says so.
    EXPECT_LT(maxNormalisedError(r, sim), 3.5) << seed;
    EXPECT_LT(r.std_dev_deg.maxCoeff(), 2.0) << seed;
    std::printf("3 poses, seed %d: error %.3f deg, 1-sigma [%.3f %.3f %.3f] deg\n",
                static_cast<int>(seed), errorDeg(r, sim), r.std_dev_deg(0), r.std_dev_deg(1),
                r.std_dev_deg(2));
  }
}

TEST(JointEstimator, WithoutMagnetometer) {
  JointSimulationOptions options;
  options.with_magnetometer = false;
  const JointSimulation sim = simulateJointProblem(options, 60);
  const JointResult r = solveSimulation(sim);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_FALSE(r.intrinsics.magnetometer_used);
  EXPECT_FALSE(r.intrinsics.hard_iron_estimated);
  EXPECT_FALSE(hasNote(r, "magnetometer")) << allNotes(r);
  EXPECT_LT(errorDeg(r, sim), 0.1);
  EXPECT_LT(maxNormalisedError(r, sim), 3.5);
  // W's yaw is a gauge: R_world_target keeps the accelerometer's tilt but not the truth's yaw.
  const Eigen::Vector3d up_target_est = r.R_world_target.transpose().col(2);
  const Eigen::Vector3d up_target_true = sim.R_world_target.transpose().col(2);
  EXPECT_LT(rad2deg(std::acos(std::min(1.0, up_target_est.dot(up_target_true)))), 0.1);
}

TEST(JointEstimator, MagnetometerUseFollowsItsUsablePoses) {
  JointSimulationOptions options;
  options.unusable_mag_every = 3;  // poses 0, 3, 6, 9 unusable: 8 usable
  JointSimulation sim = simulateJointProblem(options, 70);
  JointResult r = solveSimulation(sim);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(r.intrinsics.magnetometer_used);
  EXPECT_TRUE(r.intrinsics.hard_iron_estimated);
  EXPECT_LT((r.intrinsics.hard_iron_t - sim.hard_iron_t).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_NEAR(r.intrinsics.magnetic_field_t, 50e-6 * sim.soft_iron.trace() / 3.0, 4e-6);
  EXPECT_LT(errorDeg(r, sim), 0.1);

  // Three usable poses: the hard iron is not excited, the magnetometer is not used (auto) ...
  for (size_t k = 3; k < sim.problem.poses.size(); ++k) sim.problem.poses[k].mag_mean_t.reset();
  r = solveSimulation(sim);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_FALSE(r.intrinsics.magnetometer_used);
  EXPECT_TRUE(hasNote(r, "magnetometer not used")) << allNotes(r);
  // ... unless forced on: then it is used, its iron resting on its prior (3 fields, 3 + 2 unknowns
  // of iron and field besides the soft iron).
  JointSettings forced;
  forced.use_magnetometer = MagnetometerUse::kOn;
  r = solveSimulation(sim, forced);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(r.intrinsics.magnetometer_used);
  EXPECT_FALSE(r.intrinsics.hard_iron_estimated);
  EXPECT_TRUE(hasNote(r, "magnetometer hard iron rests on its prior")) << allNotes(r);
  JointSettings off;
  off.use_magnetometer = MagnetometerUse::kOff;
  EXPECT_FALSE(solveSimulation(simulateJointProblem(JointSimulationOptions{}, 71), off)
                   .intrinsics.magnetometer_used);
}

TEST(JointEstimator, WithoutGyroSegmentsAccelerometerAndCameraOnly) {
  JointSimulationOptions options;
  options.with_gyro = false;
  std::vector<double> normalised;
  for (uint64_t seed = 80; seed < 90; ++seed) {
    const JointSimulation sim = simulateJointProblem(options, seed);
    ASSERT_TRUE(sim.problem.segments.empty());
    const JointResult r = solveSimulation(sim);
    ASSERT_TRUE(r.ok) << r.message;
    expectFinite(r);
    EXPECT_TRUE(hasNote(r, "no gyro segments")) << allNotes(r);
    for (bool estimated : r.intrinsics.gyro_matrix_column_estimated) EXPECT_FALSE(estimated);
    EXPECT_EQ(r.intrinsics.gyro_matrix, Eigen::Matrix3d::Identity());
    EXPECT_LT(errorDeg(r, sim), 0.15) << seed;
    const Eigen::Vector3d error = rotationError(r.R_cam_imu, sim.R_cam_imu);
    for (int axis = 0; axis < 3; ++axis) {
      normalised.push_back(error(axis) / std::sqrt(r.covariance_rad2(axis, axis)));
    }
  }
  EXPECT_LT(rms(normalised), 1.4);
}

TEST(JointEstimator, SeveralGroupsNeverPairedByTheGyro) {
  JointSimulationOptions options;
  options.num_poses = 15;
  options.groups = 3;  // the bias jumps between groups: a pairing across them would show
  for (uint64_t seed = 90; seed < 95; ++seed) {
    const JointSimulation sim = simulateJointProblem(options, seed);
    ASSERT_EQ(sim.problem.segments.size(), 12u);
    const JointResult r = solveSimulation(sim);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_LT(errorDeg(r, sim), 0.1) << seed;
    EXPECT_LT(maxNormalisedError(r, sim), 3.5) << seed;
    EXPECT_LT(r.chi2 / r.dof, 1.5) << seed;
  }
  // A segment across two groups is refused.
  JointSimulation sim = simulateJointProblem(options, 95);
  GyroSegment across = sim.problem.segments.front();
  across.from_pose = 4;
  across.to_pose = 5;  // pose 4 is in group 0, pose 5 in group 1
  sim.problem.segments.push_back(across);
  const JointResult r = solveSimulation(sim);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("different groups"), std::string::npos) << r.message;
}

TEST(JointEstimator, BadInputIsRefusedWithAMessageAndNoNaN) {
  JointSimulationOptions options;
  options.num_poses = 5;
  const JointSimulation base = simulateJointProblem(options, 140);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    std::string name, expected;  // expected: part of the message
    std::function<void(JointProblem&, Eigen::Matrix3d&, JointSettings&)> spoil;
  };
  const std::vector<Case> cases = {
      {"two poses", "at least 3 poses",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses.resize(2);
         p.segments.resize(1);
       }},
      {"no poses", "at least 3 poses",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) { p = JointProblem{}; }},
      {"NaN accelerometer", "pose 2: accelerometer",
       [&](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses[2].accel_mean_m_s2.x() = nan;
       }},
      {"moving accelerometer", "not gravity",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses[1].accel_mean_m_s2 *= 3.0;
       }},
      {"zero accelerometer", "not gravity",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses[1].accel_mean_m_s2.setZero();
       }},
      {"camera not a rotation", "R_target_cam is not a rotation",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) { p.poses[3].R_target_cam *= 2.0; }},
      {"negative camera covariance", "cov_cam_rad2",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses[0].cov_cam_rad2 = -Eigen::Matrix3d::Identity();
       }},
      {"asymmetric covariance", "accel_mean_cov",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses[0].accel_mean_cov(0, 1) = 1.0;
       }},
      {"infinite gyro covariance", "gyro_mean_cov",
       [&](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses[4].gyro_mean_cov(2, 2) = inf;
       }},
      {"magnetometer in microtesla", "not in tesla",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses[1].mag_mean_t = Eigen::Vector3d(20.0, 5.0, -40.0);
       }},
      {"NaN magnetometer", "magnetometer mean",
       [&](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses[1].mag_mean_t->y() = nan;
       }},
      {"rest ends before it starts", "start_s <= end_s",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.poses[2].end_s = p.poses[2].start_s - 1.0;
       }},
      {"NaN gyro sample", "sample 7 is not finite",
       [&](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.segments[1].gyro_rad_s[7].z() = nan;
       }},
      {"stamps backwards", "strictly increasing",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         std::swap(p.segments[0].stamps_s[3], p.segments[0].stamps_s[4]);
       }},
      {"empty segment", "fewer than 2 gyro samples",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.segments[2].stamps_s.clear();
         p.segments[2].gyro_rad_s.clear();
       }},
      {"samples lost within a motion", "a gap of",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         for (size_t i = 200; i < p.segments[1].stamps_s.size(); ++i)
           p.segments[1].stamps_s[i] += 0.5;
       }},
      {"stamps and samples differ", "differ in length",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.segments[2].stamps_s.pop_back();
       }},
      {"segment skips a pose", "to_pose = from_pose + 1",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) { p.segments[0].to_pose = 2; }},
      {"segment out of range", "to_pose = from_pose + 1",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.segments[0].from_pose = 4;
         p.segments[0].to_pose = 5;
       }},
      {"segment twice", "a second segment",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.segments.push_back(p.segments[1]);
       }},
      {"negative noise density", "noise_density",
       [](JointProblem& p, Eigen::Matrix3d&, JointSettings&) {
         p.segments[1].noise_density_rad_s_sqrt_hz = -1.0;
       }},
      {"initial not a rotation", "R_cam_imu_initial",
       [](JointProblem&, Eigen::Matrix3d& R, JointSettings&) { R(0, 0) += 0.5; }},
      {"NaN initial", "R_cam_imu_initial",
       [&](JointProblem&, Eigen::Matrix3d& R, JointSettings&) { R(1, 2) = nan; }},
      {"zero prior sigma", "prior sigma",
       [](JointProblem&, Eigen::Matrix3d&, JointSettings& s) { s.priors.gyro_scale = 0.0; }},
      {"NaN gravity", "gravity_m_s2",
       [&](JointProblem&, Eigen::Matrix3d&, JointSettings& s) { s.gravity_m_s2 = nan; }},
      {"no iterations", "max_iterations",
       [](JointProblem&, Eigen::Matrix3d&, JointSettings& s) { s.max_iterations = 0; }},
  };
  for (const Case& c : cases) {
    JointProblem problem = base.problem;
    Eigen::Matrix3d R_initial = base.R_cam_imu;
    JointSettings settings;
    c.spoil(problem, R_initial, settings);
    const JointResult r = JointEstimator(settings).solve(problem, R_initial);
    EXPECT_FALSE(r.ok) << c.name;
    EXPECT_NE(r.message.find(c.expected), std::string::npos) << c.name << ": " << r.message;
    expectFinite(r);
  }
  // The untouched problem solves.
  EXPECT_TRUE(JointEstimator().solve(base.problem, base.R_cam_imu).ok);
}

TEST(JointEstimator, ZeroCovariancesUseTheFloors) {
  // Covariances of zero (a caller without scatter estimates) are usable: the floors apply.
  JointSimulationOptions options;
  options.noise = false;
  JointSimulation sim = simulateJointProblem(options, 150);
  for (JointPose& pose : sim.problem.poses) {
    pose.cov_cam_rad2.setZero();
    pose.accel_mean_cov.setZero();
    pose.gyro_mean_cov.setZero();
    pose.mag_mean_cov.setZero();
  }
  for (GyroSegment& segment : sim.problem.segments) segment.noise_density_rad_s_sqrt_hz = 0.0;
  const JointResult r = solveSimulation(sim);
  ASSERT_TRUE(r.ok) << r.message;
  expectFinite(r);
  EXPECT_LT(errorDeg(r, sim), 0.01);
}

TEST(JointEstimator, PosesWithoutRotationAreRefused) {
  // The same orientation at every pose: R_cam_imu about the vertical is not determined.
  JointSimulationOptions options;
  options.min_rotation_deg = 0.0;
  options.max_rotation_deg = 0.0;
  for (bool magnetometer : {false, true}) {
    options.with_magnetometer = magnetometer;
    const JointResult r = solveSimulation(simulateJointProblem(options, 160));
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.message.find("not determined"), std::string::npos) << r.message;
    expectFinite(r);
    EXPECT_TRUE(hasNote(r, "gyro scale x")) << allNotes(r);
    EXPECT_TRUE(hasNote(r, "accelerometer bias")) << allNotes(r);
  }
}

}  // namespace
}  // namespace camera_imu_alignment
