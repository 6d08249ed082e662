// Natural-scene sessions for the tests (test_scene_sessions, test_scene_monte_carlo): one of the
// simulator's room scenarios with a consumer IMU through the pipeline with no target (the camera's
// rotation between rests from the natural scene's features), solved, against the truth.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "camera_imu_alignment/simulation/imu_grades.h"
#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"

namespace camera_imu_alignment {
namespace test {

namespace sim = simulation;

struct SceneOutcome {
  double error_deg = 0;          ///< R_cam_imu against the truth
  double sigma_norm_deg = 0;     ///< its reported 1-sigma (norm over the axes)
  double worst_link_sigmas = 0;  ///< largest link error over its RMS 1-sigma per axis
  double worst_link_deg = 0;
  int links = 0;
  bool consistent = false;  ///< the joint estimate passed its chi-square test
};

inline SceneOutcome runScene(const std::string& scenario, std::uint64_t seed,
                             bool texture_poor = false) {
  sim::SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(sim::applyScenario(scenario, &c));
  c.texture_poor = texture_poor;
  sim::applyImuGrade(sim::ImuGrade::kConsumer, &c);
  // Each rest is rendered once (the harness caches it); frames only add noise draws.
  c.camera_rate_hz = 10.0;
  PipelineRun run = runPipeline(c);
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
  out.sigma_norm_deg = result.quality.std_dev_deg.norm();
  out.consistent = result.joint && result.joint->consistent();
  std::printf(
      "%s seed %llu: %zu poses, %d links (worst %.3f deg, %.1f sigma); R_cam_imu %.4f deg "
      "off, 1-sigma norm %.4f; %s\n",
      scenario.c_str(), static_cast<unsigned long long>(seed), poses.size(), out.links,
      out.worst_link_deg, out.worst_link_sigmas, out.error_deg, out.sigma_norm_deg,
      result.message.c_str());
  return out;
}

}  // namespace test
}  // namespace camera_imu_alignment
