// The window solve's stages (window_solver.h): the state they pass along and their interface.
// Private to the solve room.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "camera_imu_alignment/solve/window_solver.h"

namespace camera_imu_alignment {

struct WindowSolveState {
  WindowSolveState(const WindowSnapshot& w, const PipelineSettings& s, const WindowSolveRequest& r)
      : window(w), settings(s), request(r) {}
  WindowSnapshot window;  ///< a copy the stages change (motion frames screened, links refitted)
  const PipelineSettings& settings;
  const WindowSolveRequest& request;
  AlignmentResult result;   ///< the pair estimate, then the joint one
  MotionFigures motion;     ///< the report's figures of the motion (motion stage)
  std::string motion_note;  ///< the motion stage's, for a message without pairs
  /// The window's problem as the consensus left it, before the motion stage screened its frames
  /// and set the time offset's start: what the mount-change stage tests (kept only when asked).
  JointProblem tested_problem;
  JointResult joint_as_measured;  ///< the joint estimate with the links as measured
  JointResult joint;              ///< the joint estimate (after the scene refit)
  bool joint_solved = false;
  WindowSolveOutput out;  ///< mount_test, basis, scene_refits
  bool done = false;      ///< a stage ended the solve
};

class WindowStage {
 public:
  virtual ~WindowStage() = default;
  virtual const char* name() const = 0;
  /// Runs on `state`; returns its note ("" when it has nothing to say).
  virtual std::string run(WindowSolveState* state) const = 0;
};

std::unique_ptr<WindowStage> makeMotionStage();
std::unique_ptr<WindowStage> makePairStage();
std::unique_ptr<WindowStage> makeConsensusStage();
std::unique_ptr<WindowStage> makeJointStage();
std::unique_ptr<WindowStage> makeSceneRefitStage();
std::unique_ptr<WindowStage> makeMountChangeStage();

/// "1.23" (for the result's message).
std::string fixedText(double value, int digits = 2);

}  // namespace camera_imu_alignment
