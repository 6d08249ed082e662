// The joint estimator with the camera measured relative to other poses only (the natural scene:
// JointProblem::camera_links, no target): problems generated from a known truth
// (joint_problem_simulation.h) whose absolute camera orientations are replaced by relative
// rotations between poses, with their own noise. Exact without noise; accurate and consistent
// with noise (the same information as a board for R_cam_imu: a board's frame is unknown too);
// poses in two camera groups that no link joins; bad links named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "joint_problem_simulation.h"
#include "joint_test_helpers.h"

namespace camera_imu_alignment {
namespace {

using test::errorDeg;
using test::fractionWithin;
using test::JointSimulation;
using test::JointSimulationOptions;
using test::perturbedRotation;
using test::rms;
using test::rotationError;
using test::simulateJointProblem;

/// The true camera orientation of pose k in the simulation's target frame.
Eigen::Matrix3d trueTargetCam(const JointSimulation& sim, size_t k) {
  return sim.R_world_target.transpose() * sim.R_world_imu[k] * sim.R_cam_imu.transpose();
}

/// The simulation with relative cameras: links between consecutive poses and every second pose
/// (noise `sigma_rad` per axis, stated as such), each pose's R_target_cam the consecutive links
/// chained from pose 0's (identity: the scene frame is the first camera's). `break_after` >= 0:
/// no link crosses from that pose to the next (two camera groups).
JointSimulation withCameraLinks(JointSimulation sim, double sigma_rad, uint64_t seed,
                                int break_after = -1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const size_t n = sim.problem.poses.size();
  const auto crosses = [&](size_t from, size_t to) {
    return break_after >= 0 && static_cast<int>(from) <= break_after &&
           static_cast<int>(to) > break_after;
  };
  std::vector<Eigen::Matrix3d> chained(n, Eigen::Matrix3d::Identity());
  for (size_t step : {1u, 2u}) {
    for (size_t from = 0; from + step < n; ++from) {
      const size_t to = from + step;
      if (crosses(from, to)) continue;
      CameraLink link;
      link.from_pose = static_cast<int>(from);
      link.to_pose = static_cast<int>(to);
      const Eigen::Vector3d noise(normal(rng), normal(rng), normal(rng));
      link.R_from_to =
          trueTargetCam(sim, from).transpose() * trueTargetCam(sim, to) * expSO3(sigma_rad * noise);
      link.cov_rad2 = sigma_rad * sigma_rad * Eigen::Matrix3d::Identity();
      sim.problem.camera_links.push_back(link);
      if (step == 1) chained[to] = chained[from] * link.R_from_to;
    }
  }
  for (size_t k = 0; k < n; ++k) {
    sim.problem.poses[k].camera_absolute = false;
    sim.problem.poses[k].R_target_cam = chained[k];
    sim.problem.poses[k].cov_cam_rad2.setZero();
  }
  return sim;
}

TEST(JointCameraLinks, NoiseFreeExactRecovery) {
  for (bool magnetometer : {true, false}) {
    JointSimulationOptions options;
    options.noise = false;
    options.with_magnetometer = magnetometer;
    options.soft_iron_isotropic = true;
    const JointSimulation sim = withCameraLinks(simulateJointProblem(options, 21), 0.0, 1);
    JointSettings settings;
    ImuModelPriors& p = settings.priors;
    for (double* sigma : {&p.gyro_scale, &p.gyro_cross_axis, &p.accel_scale, &p.accel_cross_axis,
                          &p.accel_bias_m_s2, &p.hard_iron_t}) {
      *sigma *= 1000.0;
    }
    settings.robust_loss = RobustLossKind::kNone;
    const JointResult r =
        JointEstimator(settings).solve(sim.problem, perturbedRotation(sim.R_cam_imu, 0.03, 2));
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_LT(errorDeg(r, sim), 1e-6) << "magnetometer " << magnetometer;
    EXPECT_LT((r.intrinsics.gyro_matrix - sim.T_g).cwiseAbs().maxCoeff(), 1e-8);
  }
}

struct Outcome {
  std::vector<double> error_deg, normalised;
};

void addOutcome(const JointResult& r, const JointSimulation& sim, Outcome* out) {
  const Eigen::Vector3d error = rotationError(r.R_cam_imu, sim.R_cam_imu);
  out->error_deg.push_back(rad2deg(error.norm()));
  for (int axis = 0; axis < 3; ++axis) {
    out->normalised.push_back(error(axis) / std::sqrt(r.covariance_rad2(axis, axis)));
  }
}

TEST(JointCameraLinks, ConsumerGradeAccurateAndConsistentAsWithABoard) {
  // Consumer unit (the generator's defaults); the relative rotations with 0.05 deg per axis, the
  // board's orientations with the same (the generator's camera noise).
  Outcome board, scene;
  const double sigma = deg2rad(0.05);
  for (uint64_t seed = 300; seed < 320; ++seed) {
    const JointSimulation sim = simulateJointProblem(JointSimulationOptions{}, seed);
    const JointSimulation relative = withCameraLinks(sim, sigma, seed + 7);
    const Eigen::Matrix3d start = perturbedRotation(sim.R_cam_imu, deg2rad(1.0), seed);
    const JointResult with_board = JointEstimator(JointSettings{}).solve(sim.problem, start);
    const JointResult r = JointEstimator(JointSettings{}).solve(relative.problem, start);
    ASSERT_TRUE(with_board.ok && r.ok) << r.message;
    addOutcome(with_board, sim, &board);
    addOutcome(r, relative, &scene);
  }
  std::printf(
      "20 seeds: relative cameras RMS %.4f deg (normalised std %.2f, %.0f%% within 3 sigma); "
      "board %.4f deg\n",
      rms(scene.error_deg), rms(scene.normalised), 100.0 * fractionWithin(scene.normalised, 3.0),
      rms(board.error_deg));
  EXPECT_LT(rms(scene.error_deg), 0.08);
  EXPECT_LT(rms(scene.error_deg), 1.5 * rms(board.error_deg));
  EXPECT_GT(rms(scene.normalised), 0.6);
  EXPECT_LT(rms(scene.normalised), 1.4);
  EXPECT_GE(fractionWithin(scene.normalised, 3.0), 0.98);
}

TEST(JointCameraLinks, TwoCameraGroupsJoinedByTheImu) {
  // No link between poses 5 and 6: the second group's scene frame is unrelated to the first's;
  // its rotation comes from the IMU (gravity, gyro, field), and both groups still count.
  const JointSimulation sim = simulateJointProblem(JointSimulationOptions{}, 330);
  const JointSimulation joined = withCameraLinks(sim, deg2rad(0.05), 5);
  JointSimulation split = withCameraLinks(sim, deg2rad(0.05), 5, 5);
  // The second group starts at an arbitrary frame: pose 6's chained orientation is identity.
  const Eigen::Matrix3d offset = split.problem.poses[6].R_target_cam.transpose();
  for (size_t k = 6; k < split.problem.poses.size(); ++k) {
    split.problem.poses[k].R_target_cam =
        expSO3(Eigen::Vector3d(0.3, -0.5, 0.2)) * offset * split.problem.poses[k].R_target_cam;
  }
  const Eigen::Matrix3d start = perturbedRotation(sim.R_cam_imu, deg2rad(1.0), 9);
  const JointResult one = JointEstimator(JointSettings{}).solve(joined.problem, start);
  const JointResult two = JointEstimator(JointSettings{}).solve(split.problem, start);
  ASSERT_TRUE(one.ok && two.ok) << two.message;
  std::printf("one camera group %.4f deg (1-sigma %.4f), two groups %.4f deg (1-sigma %.4f)\n",
              errorDeg(one, joined), one.std_dev_deg.norm(), errorDeg(two, split),
              two.std_dev_deg.norm());
  EXPECT_LT(errorDeg(two, split), 3.0 * two.std_dev_deg.norm());
  EXPECT_LT(errorDeg(two, split), 0.15);
  // The missing links cost information, never add it.
  EXPECT_GE(two.std_dev_deg.norm(), 0.99 * one.std_dev_deg.norm());
}

TEST(JointCameraLinks, BadLinksAreNamedAndAnUnlinkedPoseTellsNothing) {
  const JointSimulation sim =
      withCameraLinks(simulateJointProblem(JointSimulationOptions{}, 340), deg2rad(0.05), 3);
  const JointEstimator estimator{JointSettings{}};
  // Pose 11's links left (a sliding window): its camera says nothing, so wrong starting values
  // for it change nothing either.
  JointProblem unlinked = sim.problem;
  unlinked.camera_links.erase(
      std::remove_if(unlinked.camera_links.begin(), unlinked.camera_links.end(),
                     [](const CameraLink& l) { return l.from_pose == 11 || l.to_pose == 11; }),
      unlinked.camera_links.end());
  JointProblem unlinked_moved = unlinked;
  unlinked_moved.poses[11].R_target_cam =
      expSO3(Eigen::Vector3d(0.2, 0.1, -0.3)) * unlinked.poses[11].R_target_cam;
  JointResult r = estimator.solve(unlinked, sim.R_cam_imu);
  const JointResult moved = estimator.solve(unlinked_moved, sim.R_cam_imu);
  ASSERT_TRUE(r.ok && moved.ok) << r.message;
  EXPECT_LT(rad2deg(geodesicDistance(r.R_cam_imu, moved.R_cam_imu)), 1e-3);
  EXPECT_LT(errorDeg(r, sim), 3.0 * r.std_dev_deg.norm());

  JointProblem out_of_range = sim.problem;
  out_of_range.camera_links[2].to_pose = 40;
  r = estimator.solve(out_of_range, sim.R_cam_imu);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("camera link 2"), std::string::npos) << r.message;

  JointProblem not_finite = sim.problem;
  not_finite.camera_links[4].R_from_to(0, 0) = std::nan("");
  r = estimator.solve(not_finite, sim.R_cam_imu);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("camera link 4"), std::string::npos) << r.message;
  EXPECT_TRUE(r.R_cam_imu.allFinite());
}

}  // namespace
}  // namespace camera_imu_alignment
