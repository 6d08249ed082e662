// Natural-scene sessions for the tests (test_scene_sessions, test_scene_monte_carlo): one of the
// simulator's room scenarios with a consumer IMU through the pipeline with no target (the camera's
// rotation between rests from the natural scene's features), solved, against the truth.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/simulation/imu_grades.h"
#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"

namespace camera_imu_alignment {
namespace test {

namespace sim = simulation;

/// A board's orientation noise per rest (deg per axis): the joint estimator's simulated problems'
/// camera noise (joint_problem_simulation.h), a board filling a third of the view 1-2 m away.
constexpr double kBoardSigmaDeg = 0.05;

struct SceneOutcome {
  double error_deg = 0;          ///< R_cam_imu against the truth
  double sigma_norm_deg = 0;     ///< its reported 1-sigma (norm over the axes)
  double worst_link_sigmas = 0;  ///< largest link error over its RMS 1-sigma per axis
  double worst_link_deg = 0;
  int links = 0;
  bool consistent = false;  ///< the joint estimate passed its chi-square test
  /// The same rests with a board seen at each (boardEquivalentErrorDeg): R_cam_imu's error.
  double board_error_deg = 0;
};

/// The board's error on the same motion: the window's joint problem with the camera's
/// orientation at every rest measured absolutely, as a board's PnP gives it (the truth with
/// `sigma_deg` of noise per axis, stated as such), and no natural-scene links; solved from the
/// same start. The simulator's room has no board in the hand-held views, so this stands in for one.
inline double boardEquivalentErrorDeg(const CalibrationPipeline& pipeline,
                                      const std::vector<simulation::StationaryPose>& rests,
                                      const Eigen::Matrix3d& R_cam_imu_true,
                                      const Eigen::Matrix3d& R_start, double sigma_deg,
                                      std::uint64_t seed) {
  const WindowSnapshot window = pipeline.snapshot();
  JointProblem board = window.joint;
  board.camera_links.clear();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, deg2rad(sigma_deg));
  for (size_t k = 0; k < board.poses.size(); ++k) {
    JointPose& pose = board.poses[k];
    const Eigen::Vector3d noise(normal(rng), normal(rng), normal(rng));
    pose.camera_absolute = true;
    pose.R_target_cam = rests[window.pose_indices[k]].R_world_cam * expSO3(noise);
    pose.cov_cam_rad2 = std::pow(deg2rad(sigma_deg), 2) * Eigen::Matrix3d::Identity();
  }
  const JointResult r = JointEstimator(jointSettingsOf(pipeline.settings())).solve(board, R_start);
  EXPECT_TRUE(r.ok) << r.message;
  return rad2deg(geodesicDistance(r.R_cam_imu, R_cam_imu_true));
}

/// CIA_SCENE_SEEDS=N: the Monte Carlo tests run seeds 100 .. 100 + N - 1 of each scene (20: the
/// issue's size, the figures in BENCHMARKS.md); unset: `default_count`, to keep the test command
/// short.
inline int sceneSeedCount(int default_count) {
  const char* text = std::getenv("CIA_SCENE_SEEDS");
  const int n = text ? std::atoi(text) : 0;
  return n > 0 ? n : default_count;
}

/// CIA_SCENE_PROFILE=fast (or full; the setting scene_profile's words): the features' fast profile
/// (SIFT on the image halved, 1000 features, each match refined at the full resolution;
/// BENCHMARKS.md, "Natural-scene rotation"); unset: the defaults.
inline PipelineSettings sceneProfileSettings() {
  PipelineSettings settings;
  const char* word = std::getenv("CIA_SCENE_PROFILE");
  SceneProfile profile = SceneProfile::kFull;
  if (word && parseSceneProfile(word, &profile)) {
    useSceneProfile(profile, &settings.scene_features, &settings.scene_rotation);
  }
  return settings;
}

inline SceneOutcome runScene(const std::string& scenario, std::uint64_t seed,
                             bool texture_poor = false) {
  sim::SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(sim::applyScenario(scenario, &c));
  c.texture_poor = texture_poor;
  // CIA_SCENE_ROBOT_TILT=MIN,MAX (deg): the robot's tilt at its stops (default 5,20), to measure
  // what more tilt gives.
  if (const char* tilt = std::getenv("CIA_SCENE_ROBOT_TILT")) {
    std::sscanf(tilt, "%lf,%lf", &c.robot_min_tilt_deg, &c.robot_max_tilt_deg);
  }
  sim::applyImuGrade(sim::ImuGrade::kConsumer, &c);
  // Each rest is rendered once (the harness caches it); frames only add noise draws.
  c.camera_rate_hz = 10.0;
  PipelineRun run = runPipeline(c, sceneProfileSettings());
  SceneOutcome out;
  const auto& poses = run.pipeline->poses();
  const auto& rests = run.run->trajectory.poses();
  if (texture_poor) {  // every rest refused, each naming its feature count; nothing to solve
    EXPECT_TRUE(poses.empty());
    EXPECT_EQ(run.pipeline->rejectedPoses().size(), rests.size());
    for (const RejectedPose& r : run.pipeline->rejectedPoses()) {
      EXPECT_NE(r.reason.find(" features in the sharpest frame at "), std::string::npos)
          << r.reason;
    }
    const AlignmentResult result = solveFinalWindow(*run.pipeline);
    EXPECT_NE(result.status, SolveStatus::kOk) << result.message;
    std::printf("%s seed %llu, texture-poor: %s\n", scenario.c_str(),
                static_cast<unsigned long long>(seed),
                run.pipeline->rejectedPoses().empty()
                    ? ""
                    : run.pipeline->rejectedPoses().front().reason.c_str());
    return SceneOutcome{};
  }
  EXPECT_EQ(poses.size(), rests.size()) << scenario << " seed " << seed;
  for (const RejectedPose& r : run.pipeline->rejectedPoses()) {
    ADD_FAILURE() << scenario << " seed " << seed << ": rest refused: " << r.reason;
  }
  for (const StationaryPose& pose : poses) {
    for (const SceneLinkSummary& link : pose.scene_links) {
      const Eigen::Matrix3d R_true =
          rests[link.from_pose].R_world_cam.transpose() * rests[pose.index].R_world_cam;
      const double error = rad2deg(geodesicDistance(link.R_from_to, R_true));
      out.worst_link_deg = std::max(out.worst_link_deg, error);
      // An angle over the RMS per-axis sigma: about sqrt(chi-square(3)), 3.4 at 95 %.
      out.worst_link_sigmas = std::max(out.worst_link_sigmas, error / link.sigma_deg);
      ++out.links;
    }
  }
  const AlignmentResult result = solveFinalWindow(*run.pipeline);
  EXPECT_EQ(result.status, SolveStatus::kOk) << result.message;
  out.error_deg = rad2deg(geodesicDistance(result.R_cam_imu, run.R_cam_imu_true()));
  out.board_error_deg = boardEquivalentErrorDeg(*run.pipeline, rests, run.R_cam_imu_true(),
                                                result.R_cam_imu, kBoardSigmaDeg, seed + 1000);
  out.sigma_norm_deg = result.quality.std_dev_deg.norm();
  out.consistent = result.joint && result.joint->consistent();
  std::printf(
      "%s seed %llu: %zu poses, %d links (worst %.3f deg, %.1f sigma); R_cam_imu %.4f deg "
      "off, 1-sigma norm %.4f (with a board at every rest: %.4f deg off); %s\n",
      scenario.c_str(), static_cast<unsigned long long>(seed), poses.size(), out.links,
      out.worst_link_deg, out.worst_link_sigmas, out.error_deg, out.sigma_norm_deg,
      out.board_error_deg, result.message.c_str());
  return out;
}

}  // namespace test
}  // namespace camera_imu_alignment
