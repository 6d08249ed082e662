// Calibration without a board (issue 26): the simulator's textured room (room_scene.h) rendered at
// the rests of a hand-held rig and of a ground robot, through the pipeline with no target, so that
// the camera's rotation between rests comes from the natural scene's features. R_cam_imu against
// the truth within its 1-sigma whenever the chi-square test passes; the worst measured rotation
// against the true one is printed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "camera_imu_alignment/simulation/imu_grades.h"
#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;

struct SceneOutcome {
  double error_deg = 0;          ///< R_cam_imu against the truth
  double sigma_norm_deg = 0;     ///< its reported 1-sigma (norm over the axes)
  double worst_link_sigmas = 0;  ///< largest link error over its RMS 1-sigma per axis
  double worst_link_deg = 0;
  int links = 0;
  bool consistent = false;  ///< the joint estimate passed its chi-square test
};

SceneOutcome runScene(const std::string& scenario, std::uint64_t seed) {
  sim::SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(sim::applyScenario(scenario, &c));
  sim::applyImuGrade(sim::ImuGrade::kConsumer, &c);
  c.camera_rate_hz = 3.0;  // the sharpest frame of each rest is what counts
  test::PipelineRun run = test::runPipeline(c);
  SceneOutcome out;
  const auto& poses = run.pipeline->poses();
  const auto& rests = run.run->trajectory.poses();
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
  const AlignmentResult result = test::solveFinalWindow(*run.pipeline);
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

// Measured (2026-11-27, 3 Hz): seed 3 0.118 deg off (1-sigma norm 0.108, chi2/dof 1.07), 6 of 37
// rotations left out as outliers; seed 4 inconsistent (chi2/dof 1337): the general model's
// rotation is 2-9 deg off on several near-planar views (a wall 1-3 m away), more than the
// screening removes. Either way no confident wrong answer; the accuracy target is not met.
TEST(SceneSessions, HandHeldInATexturedRoomNeverConfidentlyWrong) {
  int consistent = 0;
  for (std::uint64_t seed : {3u, 4u}) {
    const SceneOutcome o = runScene("room_handheld", seed);
    EXPECT_GE(o.links, 11);
    if (!o.consistent) continue;  // flagged: the verdict fails, nothing is broadcast
    ++consistent;
    EXPECT_LT(o.error_deg, 0.2) << "seed " << seed;
    EXPECT_LT(o.error_deg, 3.0 * o.sigma_norm_deg) << "seed " << seed;
  }
  EXPECT_GE(consistent, 1);
}

// Measured (2026-11-27, 3 Hz): 0.049 and 0.087 deg off, 1-sigma norm 0.178 and 0.239, chi2/dof
// 1.02 and 0.83; 0 and 2 of 32 rotations left out as outliers.
TEST(SceneSessions, RobotStopsInATexturedRoom) {
  for (std::uint64_t seed : {3u, 4u}) {
    const SceneOutcome o = runScene("room_robot", seed);
    EXPECT_GE(o.links, 11);
    EXPECT_TRUE(o.consistent) << "seed " << seed;
    EXPECT_LT(o.error_deg, 0.2) << "seed " << seed;
    EXPECT_LT(o.error_deg, 3.0 * o.sigma_norm_deg) << "seed " << seed;
  }
}

}  // namespace
}  // namespace camera_imu_alignment
