// Simulator ground truth and sensor models (issue 3, IMU side): the simulated gyro integrates to
// the true relative rotations, at rest the accelerometer and magnetometer agree with the true
// attitude, and the same seed gives the same samples.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "camera_imu_alignment/rotation_math.h"
#include "camera_imu_alignment/simulation/imu_model.h"
#include "camera_imu_alignment/simulation/rig_trajectory.h"

namespace camera_imu_alignment {
namespace simulation {
namespace {

TEST(RigTrajectory, HoldsStillAtEachPoseAndMovesSmoothlyBetween) {
  TrajectoryOptions options;
  options.seed = 3;
  const RigTrajectory trajectory(options);
  ASSERT_EQ(trajectory.stationaryIntervals().size(), 12u);
  ASSERT_EQ(trajectory.poseOrientations().size(), 12u);
  for (size_t k = 0; k < trajectory.stationaryIntervals().size(); ++k) {
    const auto [start, end] = trajectory.stationaryIntervals()[k];
    EXPECT_GE(end - start, options.hold_min_s - 1e-9);
    EXPECT_LE(end - start, options.hold_max_s + 1e-9);
    const double mid = 0.5 * (start + end);
    EXPECT_TRUE(trajectory.isStationary(mid));
    EXPECT_EQ(trajectory.bodyRate(mid), Eigen::Vector3d::Zero());
    EXPECT_LT((trajectory.orientation(mid) - trajectory.poseOrientations()[k]).norm(), 1e-15);
    if (k > 0) {
      const double moving = 0.5 * (trajectory.stationaryIntervals()[k - 1].second + start);
      EXPECT_FALSE(trajectory.isStationary(moving));
      EXPECT_GT(trajectory.bodyRate(moving).norm(), 0.0);
    }
  }
  // Continuity at the interval ends (minimum-jerk profile starts and stops at rest).
  const double end0 = trajectory.stationaryIntervals()[0].second;
  EXPECT_LT((trajectory.orientation(end0 + 1e-6) - trajectory.orientation(end0)).norm(), 1e-9);
}

TEST(RigTrajectory, BodyRateIsTheDerivativeOfTheOrientation) {
  const RigTrajectory trajectory(TrajectoryOptions{});
  const double h = 1e-6;
  for (double t = 0.05; t < trajectory.durationS(); t += 0.37) {
    const Eigen::Vector3d numeric =
        logSO3(trajectory.orientation(t - h).transpose() * trajectory.orientation(t + h)) / (2 * h);
    EXPECT_LT((numeric - trajectory.bodyRate(t)).norm(), 1e-6) << "t = " << t;
  }
}

TEST(ImuModel, GyroMinusTrueBiasIntegratesToTheTrueRelativeRotations) {
  const RigTrajectory trajectory(TrajectoryOptions{});
  ImuSimulationOptions options;
  options.noise.scale = 0.0;  // white noise and random walk off, constant biases kept
  const auto samples = simulateImu(trajectory, options);
  const double dt = 1.0 / options.rate_hz;
  Eigen::Matrix3d R = trajectory.orientation(0.0);
  size_t next_pose = 1;
  for (size_t i = 0; i + 1 < samples.size() && next_pose < trajectory.poseOrientations().size();
       ++i) {
    // Midpoint rule on the bias-corrected rate.
    const Eigen::Vector3d w = 0.5 * (samples[i].gyro_rad_s - samples[i].true_gyro_bias +
                                     samples[i + 1].gyro_rad_s - samples[i + 1].true_gyro_bias);
    R = R * expSO3(w * dt);
    if (samples[i + 1].t_s >= trajectory.stationaryIntervals()[next_pose].first + 0.1) {
      const Eigen::Matrix3d truth = trajectory.poseOrientations()[next_pose];
      EXPECT_LT(rad2deg(geodesicDistance(R, truth)), 0.01) << "pose " << next_pose;
      ++next_pose;
    }
  }
  EXPECT_EQ(next_pose, trajectory.poseOrientations().size());
}

TEST(ImuModel, AtRestAccelerometerAndMagnetometerAgreeWithTheAttitude) {
  const RigTrajectory trajectory(TrajectoryOptions{});
  ImuSimulationOptions options;
  const auto samples = simulateImu(trajectory, options);
  for (size_t k = 0; k < trajectory.stationaryIntervals().size(); ++k) {
    const auto [start, end] = trajectory.stationaryIntervals()[k];
    Eigen::Vector3d accel = Eigen::Vector3d::Zero(), mag = Eigen::Vector3d::Zero(),
                    bias = Eigen::Vector3d::Zero();
    int n = 0;
    for (const auto& s : samples) {
      if (s.t_s < start || s.t_s > end) continue;
      accel += s.accel_m_s2;
      mag += s.mag_t;
      bias += s.true_accel_bias;
      ++n;
    }
    ASSERT_GT(n, 100);
    const Eigen::Matrix3d R = trajectory.poseOrientations()[k];
    const Eigen::Vector3d up_imu = R.transpose() * Eigen::Vector3d::UnitZ();
    // Specific force at rest: +9.81 along the IMU's "up" (REP-145), plus the accelerometer bias.
    EXPECT_LT(((accel - bias) / n - 9.81 * up_imu).norm(), 0.01) << "pose " << k;
    EXPECT_LT((mag / n - R.transpose() * options.earth_field_world_t).norm(), 2e-8) << "pose " << k;
  }
}

TEST(ImuModel, SameSeedSameSamples) {
  TrajectoryOptions t;
  t.num_poses = 3;
  ImuSimulationOptions o;
  const auto a = simulateImu(RigTrajectory(t), o);
  const auto b = simulateImu(RigTrajectory(t), o);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].gyro_rad_s, b[i].gyro_rad_s);
    ASSERT_EQ(a[i].accel_m_s2, b[i].accel_m_s2);
    ASSERT_EQ(a[i].mag_t, b[i].mag_t);
  }
  o.seed = 2;
  const auto c = simulateImu(RigTrajectory(t), o);
  EXPECT_NE(a[10].gyro_rad_s, c[10].gyro_rad_s);
}

TEST(RigTrajectory, SingleAxisOptionRotatesAboutOneWorldAxisOnly) {
  TrajectoryOptions options;
  options.single_axis_world = Eigen::Vector3d::UnitZ();
  const RigTrajectory trajectory(options);
  const auto& poses = trajectory.poseOrientations();
  for (size_t k = 1; k < poses.size(); ++k) {
    const Eigen::Vector3d rel = logSO3(poses[0].transpose() * poses[k]);
    if (rel.norm() > 1e-6) EXPECT_GT(std::abs(rel.normalized().z()), 1.0 - 1e-9);
  }
}

}  // namespace
}  // namespace simulation
}  // namespace camera_imu_alignment
