// The window solve's stages (solve/window_solver.h): their order, the notes each writes, the
// mount-change stage only when asked, and a solve that ends at a stage, against the simulator's
// truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "camera_imu_alignment/solve/window_solver.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"

namespace camera_imu_alignment {
namespace {

bool hasNote(const AlignmentResult& result, const std::string& stage) {
  return std::any_of(result.stage_notes.begin(), result.stage_notes.end(),
                     [&](const std::string& note) { return note.rfind(stage + ": ", 0) == 0; });
}

TEST(WindowSolver, StagesRunInTheDocumentedOrder) {
  const std::vector<std::string> expected = {"consensus", "motion",      "pairs",
                                             "joint",     "scene refit", "mount change"};
  EXPECT_EQ(WindowSolver::stageNames(), expected);
}

TEST(WindowSolver, AWindowWithoutPairsEndsAtThePairStage) {
  WindowSnapshot window;
  window.pose_indices = {0};
  const WindowSolveOutput out = WindowSolver(PipelineSettings{}).solve(window);
  EXPECT_EQ(out.result.status, SolveStatus::kBadInput);
  EXPECT_FALSE(out.result.joint.has_value());
  EXPECT_FALSE(out.mount_test.has_value());
  ASSERT_EQ(out.result.stage_notes.size(), 1u);
  EXPECT_EQ(out.result.stage_notes[0].rfind("pairs: no pairs yet", 0), 0u)
      << out.result.stage_notes[0];
}

TEST(WindowSolver, ASimulatedWindowIsSolvedStageByStageAndTestedWhenAsked) {
  simulation::SimulationConfig c;
  c.seed = 5;
  simulation::applyScenario("nominal", &c);
  simulation::applyImuGrade(simulation::ImuGrade::kConsumer, &c);
  const simulation::SimulationRun run(c);
  PipelineSettings settings;
  settings.joint = test::jointSettingsFor(c);
  const WindowSnapshot window = test::feedWithoutImages(run, settings, 0.03)->snapshot();
  ASSERT_FALSE(window.joint.motion_frames.empty());

  const WindowSolver solver(settings);
  const WindowSolveOutput plain = solver.solve(window);
  ASSERT_EQ(plain.result.status, SolveStatus::kOk) << plain.result.message;
  ASSERT_TRUE(plain.result.joint && plain.result.joint->ok);
  EXPECT_LT(rad2deg(geodesicDistance(plain.result.R_cam_imu, run.trajectory.R_cam_imu_final())),
            0.1);
  EXPECT_TRUE(hasNote(plain.result, "motion"));
  EXPECT_TRUE(hasNote(plain.result, "pairs"));
  EXPECT_TRUE(hasNote(plain.result, "joint"));
  EXPECT_FALSE(hasNote(plain.result, "mount change"));
  EXPECT_FALSE(plain.mount_test.has_value());
  EXPECT_TRUE(plain.basis.as_measured.ok);

  WindowSolveRequest request;
  request.test_mount_change = true;
  const WindowSolveOutput tested = solver.solve(window, request);
  ASSERT_TRUE(tested.mount_test.has_value());
  EXPECT_TRUE(tested.mount_test->tested);
  EXPECT_FALSE(tested.mount_test->detected) << tested.mount_test->message;
  EXPECT_TRUE(hasNote(tested.result, "mount change"));
  // The test does not change the estimate; solveWindow is the same solve.
  EXPECT_TRUE(tested.result.R_cam_imu.isApprox(plain.result.R_cam_imu, 1e-12));
  EXPECT_TRUE(solveWindow(window, settings).R_cam_imu.isApprox(plain.result.R_cam_imu, 1e-12));
}

}  // namespace
}  // namespace camera_imu_alignment
