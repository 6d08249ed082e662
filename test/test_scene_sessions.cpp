// Calibration without a board (issue 26): the simulator's textured room (room_scene.h) rendered at
// the rests of a hand-held rig and of a ground robot, through the pipeline with no target, so that
// the camera's rotation between rests comes from the natural scene's features. R_cam_imu against
// the truth within its 1-sigma whenever the chi-square test passes; the worst measured rotation
// against the true one is printed.
#include <gtest/gtest.h>

#include <cstdint>

#include "scene_sessions.h"

namespace camera_imu_alignment {
namespace {

using test::runScene;
using test::SceneOutcome;

// Measured (2026-11-27, with the IMU's prediction seeding the two-view fit): seed 3 0.142 deg off
// (1-sigma norm 0.103, chi2/dof 0.94), 5 of 38 rotations left out as outliers; seed 4 inconsistent
// (chi2/dof 808): the general model's rotation is still 2-6 deg off on several near-planar views
// (a wall 1-3 m away), more than the screening removes. Either way no confident wrong answer; the
// accuracy target is not met.
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

// Measured (2026-11-27): 0.018 and 0.080 deg off, 1-sigma norm 0.176 and 0.241, chi2/dof 0.95 and
// 1.02; 1 of 32 rotations left out as an outlier in each.
TEST(SceneSessions, RobotStopsInATexturedRoom) {
  for (std::uint64_t seed : {3u, 4u}) {
    const SceneOutcome o = runScene("room_robot", seed);
    EXPECT_GE(o.links, 11);
    EXPECT_TRUE(o.consistent) << "seed " << seed;
    EXPECT_LT(o.error_deg, 0.2) << "seed " << seed;
    EXPECT_LT(o.error_deg, 3.0 * o.sigma_norm_deg) << "seed " << seed;
  }
}

TEST(SceneSessions, ATexturePoorRoomIsSaidRestByRest) { runScene("room_robot", 3, true); }

}  // namespace
}  // namespace camera_imu_alignment
