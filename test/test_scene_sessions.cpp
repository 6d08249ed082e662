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

// Measured (2026-11-27, fifth session): seed 3 0.144 deg off (1-sigma norm 0.105, chi2/dof 0.89),
// all 38 rotations kept, 5 of them a near-planar view's other solution; seed 4 0.031 deg off
// (1-sigma norm 0.052), 10 of 21 its other solution, 1 left out (before the gyro's consensus it
// was inconsistent at chi2/dof 808: the general model 2-6 deg off on several views).
TEST(SceneSessions, HandHeldInATexturedRoom) {
  for (std::uint64_t seed : {3u, 4u}) {
    const SceneOutcome o = runScene("room_handheld", seed);
    EXPECT_GE(o.links, 11);
    EXPECT_TRUE(o.consistent) << "seed " << seed;
    EXPECT_LT(o.error_deg, 0.2) << "seed " << seed;
    EXPECT_LT(o.error_deg, 3.0 * o.sigma_norm_deg) << "seed " << seed;
  }
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

// The issue's texture-poor target: every rest refused with "N features in the sharpest frame at
// T s", no estimate (runScene asserts both per seed). Seeds 100-103 of each scene by default (about
// 2.5 s a session); CIA_SCENE_SEEDS=20 for the Monte Carlo size (all 40 said so, sixth
// session).
TEST(SceneSessions, ATexturePoorRoomIsSaidRestByRest) {
  const int seeds = test::sceneSeedCount(4);
  for (const char* scenario : {"room_robot", "room_handheld"}) {
    for (int k = 0; k < seeds; ++k) runScene(scenario, 100 + k, true);
  }
}

}  // namespace
}  // namespace camera_imu_alignment
