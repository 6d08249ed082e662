// The mount change-point test (estimation/mount_change.h) on joint problems generated from a known
// truth (joint_problem_simulation.h): a mount turned between two poses is found at the right pose
// with the right size once two poses follow it; an unchanged mount is not flagged, for an ideal,
// a consumer and a noisy IMU; the F tail matches tabulated values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/estimation/mount_change.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "joint_problem_simulation.h"

namespace camera_imu_alignment {
namespace {

using test::JointSimulation;
using test::JointSimulationOptions;
using test::simulateJointProblem;

enum class Grade { kIdeal, kTactical, kConsumer, kNoisy };

JointSimulationOptions optionsFor(Grade grade, int poses) {
  JointSimulationOptions options;  // defaults: a consumer MEMS unit
  options.num_poses = poses;
  if (grade == Grade::kIdeal) {
    options.gyro_scale = options.gyro_cross_axis = 0.0;
    options.accel_scale = options.accel_cross_axis = options.accel_bias_m_s2 = 0.0;
    options.hard_iron_t = options.soft_iron = 0.0;
    options.gyro_bias_max_rad_s = 0.0;
  } else if (grade == Grade::kTactical) {  // ADIS16495 class: 0.1 % scale, 0.05 deg axes
    options.gyro_scale = options.accel_scale = 0.001;
    options.gyro_cross_axis = options.accel_cross_axis = 0.001;
    options.accel_bias_m_s2 = 0.02;
    options.gyro_bias_max_rad_s = deg2rad(0.1);
    options.gyro_noise_density = 4e-5;
  } else if (grade == Grade::kNoisy) {
    options.gyro_noise_density = 0.004;  // MEMS gyro on a vibrating mount
    options.gyro_bias_max_rad_s = deg2rad(5.0);
    options.accel_noise_m_s2 = 0.05;
  }
  return options;
}

/// The camera measurements of poses `first_after`.. as seen after the mount turned by `turn`
/// (camera axes): R_cam_imu' = turn R_cam_imu, so R_target_cam' = R_target_cam turn^T.
void remount(JointSimulation* sim, int first_after, const Eigen::Matrix3d& turn) {
  for (std::size_t k = first_after; k < sim->problem.poses.size(); ++k) {
    sim->problem.poses[k].R_target_cam = sim->problem.poses[k].R_target_cam * turn.transpose();
  }
}

Eigen::Matrix3d turnAbout(const Eigen::Vector3d& axis, double angle_deg) {
  return expSO3(axis.normalized() * deg2rad(angle_deg));
}

MountChangeTest runTest(const JointSimulation& sim) {
  const JointSettings joint;
  const JointResult one = JointEstimator(joint).solve(sim.problem, sim.R_cam_imu);
  EXPECT_TRUE(one.ok) << one.message;
  return testMountChange(sim.problem, one, joint, MountChangeSettings{});
}

TEST(MountChange, FisherTailMatchesTables) {
  // Upper 5 % and 1 % points of F(3, 20): 3.10 and 4.94 (standard tables).
  EXPECT_NEAR(fisherUpperTail(3.098, 3, 20), 0.05, 5e-4);
  EXPECT_NEAR(fisherUpperTail(4.938, 3, 20), 0.01, 2e-4);
  EXPECT_EQ(fisherUpperTail(0.0, 3, 20), 1.0);
  EXPECT_EQ(fisherUpperTail(std::nan(""), 3, 20), 1.0);
  EXPECT_EQ(fisherUpperTail(2.0, 0, 20), 1.0);
}

TEST(MountChange, FoundAtTheRightPoseWithTwoPosesAfter) {
  // 2 deg (the smallest remount) about a different axis per seed, after pose 8 of 10.
  const Eigen::Vector3d axes[] = {{1, 0, 0}, {0, 1, 1}, {1, -1, 0.5}};
  for (Grade grade : {Grade::kIdeal, Grade::kTactical, Grade::kConsumer, Grade::kNoisy}) {
    for (int seed = 0; seed < 3; ++seed) {
      JointSimulation sim = simulateJointProblem(optionsFor(grade, 10), 300 + seed);
      remount(&sim, 8, turnAbout(axes[seed], 2.0));
      const MountChangeTest test = runTest(sim);
      ASSERT_TRUE(test.tested) << test.message;
      EXPECT_TRUE(test.detected) << "grade " << static_cast<int>(grade) << " seed " << seed << ": "
                                 << test.message;
      EXPECT_EQ(test.first_pose_after, 8) << test.message;
      EXPECT_NEAR(test.change_deg, 2.0, 0.3) << test.message;
      // The later mount's estimate is the turned truth.
      const Eigen::Matrix3d after_truth = turnAbout(axes[seed], 2.0) * sim.R_cam_imu;
      EXPECT_LT(rad2deg(rotationAngle(test.R_cam_imu_after.transpose() * after_truth)), 0.3)
          << test.message;
    }
  }
}

TEST(MountChange, NotFlaggedWithOnePoseAfter) {
  // One pose after the turn cannot be told from one bad pose: no candidate split has fewer than
  // min_poses_after (2) poses after it, so the change waits for the next pose.
  JointSimulation sim = simulateJointProblem(optionsFor(Grade::kConsumer, 10), 310);
  remount(&sim, 9, turnAbout({0, 0, 1}, 3.0));
  const MountChangeTest test = runTest(sim);
  // Nor at an earlier split that would take the changed pose with an unchanged one: the split
  // before the newest pose is the likeliest, but it only competes for the location.
  EXPECT_FALSE(test.detected) << test.message;
  EXPECT_TRUE(test.pending) << test.message;
  EXPECT_EQ(test.first_pose_after, 9) << test.message;
  for (const MountChangeCandidate& c : test.candidates) {
    EXPECT_EQ(c.declarable, c.first_pose_after <= 8) << "split " << c.first_pose_after;
  }
}

TEST(MountChange, AChangeBeforeTheNewestPoseIsNotSplitAPoseEarlyOnANoisyUnit) {
  // An MPU-6050 class unit with its own priors (3 % scale, 2 % cross-axis, 0.6 m/s^2 accelerometer
  // bias, 10 % soft iron): one pose 2 deg off is absorbed by the shared IMU model spread over every
  // pose, so the split a pose early (the changed pose with an unchanged one) fitted every pose and
  // was declared in 5 of these 10 recordings before the split before the newest pose took part.
  // Now nothing is declared with one pose after the change, and with two the split is exact.
  JointSimulationOptions options = optionsFor(Grade::kNoisy, 10);
  options.gyro_bias_max_rad_s = deg2rad(3.0);
  options.accel_noise_m_s2 = 0.2;
  options.gyro_scale = options.accel_scale = 0.03;
  options.gyro_cross_axis = options.accel_cross_axis = 0.02;
  options.accel_bias_m_s2 = 0.6;
  options.accel_bias_walk = 2e-3;
  options.hard_iron_t = 40e-6;
  options.soft_iron = 0.1;
  options.mag_noise_t = 1.5e-6;
  JointSettings joint;
  joint.priors.gyro_scale = joint.priors.accel_scale = 0.03;
  joint.priors.gyro_cross_axis = joint.priors.accel_cross_axis = 0.02;
  joint.priors.accel_bias_m_s2 = 1.2;
  joint.priors.accel_bias_walk_m_s2_sqrt_s = 2e-3;
  joint.priors.hard_iron_t = 40e-6;
  joint.priors.soft_iron_scale = joint.priors.soft_iron_cross = 0.1;
  const Eigen::Vector3d axes[] = {{1, 0, 0}, {0, 1, 1}, {1, -1, 0.5}, {0.6, -0.8, 0}};
  for (int seed = 0; seed < 10; ++seed) {
    for (int first_after : {9, 8}) {
      JointSimulation sim = simulateJointProblem(options, 500 + seed);
      remount(&sim, first_after, turnAbout(axes[seed % 4], 2.0));
      const JointResult one = JointEstimator(joint).solve(sim.problem, sim.R_cam_imu);
      ASSERT_TRUE(one.ok) << one.message;
      const MountChangeTest test = testMountChange(sim.problem, one, joint, MountChangeSettings{});
      const std::string what = "seed " + std::to_string(seed) + ", change before pose " +
                               std::to_string(first_after) + ": " + test.message;
      if (first_after == 9) {
        EXPECT_FALSE(test.detected) << what;
        EXPECT_TRUE(test.pending) << what;
      } else {
        EXPECT_TRUE(test.detected) << what;
        EXPECT_EQ(test.first_pose_after, 8) << what;
        EXPECT_EQ(test.first_pose_kept, 8) << what;
        EXPECT_NEAR(test.change_deg, 2.0, 0.3) << what;
      }
    }
  }
}

TEST(MountChange, OneBadPoseIsNotARemount) {
  // A camera orientation 1.5 deg off at one pose only (a bad PnP), newest or in between: no split
  // leaves every pose fitted, so no change is declared.
  for (int bad : {9, 8, 5}) {
    JointSimulation sim = simulateJointProblem(optionsFor(Grade::kConsumer, 10), 330 + bad);
    sim.problem.poses[bad].R_target_cam =
        sim.problem.poses[bad].R_target_cam * turnAbout({1, 1, 0}, 1.5);
    const MountChangeTest test = runTest(sim);
    EXPECT_FALSE(test.detected) << "bad pose " << bad << ": " << test.message;
  }
}

TEST(MountChange, NoFalseAlarmOnAnUnchangedMount) {
  // 20 recordings per grade, 12 poses each: the test at the last pose (3 candidate splits) must
  // not fire. At level 1e-4 the expected number of false alarms over all 80 is 0.008.
  for (Grade grade : {Grade::kIdeal, Grade::kTactical, Grade::kConsumer, Grade::kNoisy}) {
    int alarms = 0;
    double largest_statistic = 0.0;
    for (int seed = 0; seed < 20; ++seed) {
      const JointSimulation sim = simulateJointProblem(optionsFor(grade, 12), 400 + seed);
      const MountChangeTest test = runTest(sim);
      ASSERT_TRUE(test.tested) << test.message;
      if (test.detected) ++alarms;
      for (const MountChangeCandidate& c : test.candidates) {
        largest_statistic = std::max(largest_statistic, c.statistic);
      }
    }
    std::printf("grade %d: %d false alarms in 20, largest chi2 drop %.1f\n",
                static_cast<int>(grade), alarms, largest_statistic);
    EXPECT_EQ(alarms, 0) << "grade " << static_cast<int>(grade);
  }
}

TEST(MountChange, SettingsValidated) {
  MountChangeSettings s;
  EXPECT_EQ(s.validate(), "");
  s.min_poses_after = 1;
  EXPECT_NE(s.validate().find("remount_min_poses_after"), std::string::npos);
  s = MountChangeSettings{};
  s.level = 0.0;
  EXPECT_NE(s.validate().find("remount_level"), std::string::npos);
  s = MountChangeSettings{};
  s.max_poses_after = 1;
  EXPECT_NE(s.validate().find("remount_max_poses_after"), std::string::npos);
}

TEST(MountChange, TwoMountModelRecoversBothRotations) {
  // The estimator's two-mount model itself: the split given, both rotations recovered.
  JointSimulation sim = simulateJointProblem(optionsFor(Grade::kConsumer, 10), 320);
  const Eigen::Matrix3d turn = turnAbout({0.3, 1, 0}, 5.0);
  remount(&sim, 5, turn);
  sim.problem.mount_change_pose = 5;
  const JointResult r = JointEstimator().solve(sim.problem, sim.R_cam_imu);
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_TRUE(r.R_cam_imu_after_change.has_value());
  EXPECT_LT(rad2deg(rotationAngle(r.R_cam_imu.transpose() * sim.R_cam_imu)), 0.2);
  EXPECT_LT(rad2deg(rotationAngle(r.R_cam_imu_after_change->transpose() * turn * sim.R_cam_imu)),
            0.2);
  sim.problem.mount_change_pose = 10;  // no pose after it: refused, not a crash
  EXPECT_FALSE(JointEstimator().solve(sim.problem, sim.R_cam_imu).ok);
}

}  // namespace
}  // namespace camera_imu_alignment
