// The mount-change stage of the window solve (window_solver.h): the change-point test of the
// window's joint estimate (estimation/mount_change.h), asked for by WindowSolveRequest.
#include "window_stage.h"

#include <algorithm>

namespace camera_imu_alignment {
namespace {

class MountChangeStage : public WindowStage {
 public:
  const char* name() const override { return "mount change"; }
  std::string run(WindowSolveState* state) const override {
    const MountTestBasis& basis = state->out.basis;
    if (!state->request.test_mount_change || !state->joint_solved || !state->joint.ok ||
        !basis.as_measured.ok) {
      return "";
    }
    // A split whose first pose was never a candidate of a test (its windows were skipped) is
    // one: the splits with fewer than min_poses_after poses after them in the last tested window
    // were only pending, so the reach is the untested poses plus min_poses_after - 1.
    MountChangeSettings remount = state->request.remount;
    remount.max_poses_after = std::max(
        remount.max_poses_after, state->request.poses_not_yet_tested + remount.min_poses_after - 1);
    const JointSettings joint = jointSettingsOf(state->settings);
    // On the window as the pipeline gave it (the motion stage's screening aside: the test
    // expands its own problem), with the links as measured.
    MountChangeTest test =
        testMountChange(state->tested_problem, basis.as_measured, joint, remount);
    // With natural-scene links fitted again, a change must show on them too (MountTestBasis).
    if ((test.detected || test.pending) && !basis.refitted_problem.camera_links.empty() &&
        basis.refitted.ok) {
      const MountChangeTest again =
          testMountChange(basis.refitted_problem, basis.refitted, joint, remount);
      if (!again.detected && !again.pending) {
        test.detected = test.pending = false;
        test.message = "no mount change: the natural-scene rotations as measured show one (" +
                       test.message +
                       "), but not once fitted again with the rotation held near the estimate "
                       "(a moved object in view; " +
                       again.message + ")";
      }
    }
    state->out.mount_test = std::move(test);
    return state->out.mount_test->message;
  }
};

}  // namespace

std::unique_ptr<WindowStage> makeMountChangeStage() { return std::make_unique<MountChangeStage>(); }

}  // namespace camera_imu_alignment
