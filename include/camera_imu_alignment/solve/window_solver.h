// The solve of one window, in named stages written once, in order (WindowSolver::stageNames):
//
//   motion        frames screened, the time offset's coarse value, motion pairs without rests
//   pairs         the pair estimators (the paper's two-step, the optimal solver): the start
//   consensus     the natural scene's two-fold rotations chosen by the gyro
//   joint         the joint estimate (model selection, magnetometer screening, the camera's noise
//                 as measured, the noise learned; estimation/joint_estimator.h) with the camera
//                 links screened (estimation/camera_link_screening.h)
//   scene refit   the natural scene's links fitted again near the estimate, solved again
//   mount change  the change-point test of the window (estimation/mount_change.h)
//
// Each stage takes the window's state and returns its note; the notes become
// AlignmentResult::stage_notes. A stage may end the solve (no pairs, no joint estimate). A new
// stage is one file in src/core/solve/ and one line in window_solver.cpp's list. Pure: the solver
// holds no state between solves; what a solve learns for the next (the scene refits) is returned.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/alignment_result.h"
#include "camera_imu_alignment/estimation/mount_change.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/pipeline/scene_link_refitter.h"

namespace camera_imu_alignment {

/// What the mount-change test compares its models on: the one-mount estimate of the window with
/// the natural-scene links as measured, and, when the scene refit took fitted links
/// (JointResult::camera_links_refitted), the problem with them as the estimate used them and that
/// estimate, its links' excess noise the larger of the two solves'. A change is declared only
/// when both show it (the mount-change stage): on the links as measured a moved object's
/// compromise rotations made the test see a 1 deg remount (simulated hand-held room, seed 104), on
/// the refitted ones a 0.19 deg misfit (seed 100, no moved object).
struct MountTestBasis {
  JointResult as_measured;
  JointProblem refitted_problem;  ///< empty camera_links when no link was fitted again
  JointResult refitted;
};

/// What the caller asks beyond the estimate.
struct WindowSolveRequest {
  bool test_mount_change = false;  ///< run the mount-change stage (joint estimates)
  MountChangeSettings remount;
  /// The window's newest poses that no earlier change-point test had among its poses: the test's
  /// candidate splits reach back to them (SolveJob::poses_not_yet_tested).
  int poses_not_yet_tested = 0;
};

struct WindowSolveOutput {
  /// The window as solved: motion frames screened, the consensus's link solutions
  /// (link_consensus), the links the scene refit took.
  WindowSnapshot window;
  AlignmentResult result;                     ///< its stage_notes: one per stage that ran
  std::optional<MountChangeTest> mount_test;  ///< when asked for and the estimate allowed it
  MountTestBasis basis;                       ///< what the change test compared (tests, benches)
  std::vector<SceneRefit> scene_refits;       ///< held fits this solve made (for the pipeline)
};

/// The state a window's stages pass along (window_stage.h for stage authors).
struct WindowSolveState;

class WindowSolver {
 public:
  explicit WindowSolver(PipelineSettings settings);
  WindowSolveOutput solve(const WindowSnapshot& window,
                          const WindowSolveRequest& request = {}) const;
  /// The stages' names, in the order they run.
  static std::vector<std::string> stageNames();

 private:
  PipelineSettings settings_;
};

/// WindowSolver(settings).solve(window).result; `mount_test` (optional) receives the basis.
AlignmentResult solveWindow(const WindowSnapshot& window, const PipelineSettings& settings,
                            MountTestBasis* mount_test = nullptr);

}  // namespace camera_imu_alignment
