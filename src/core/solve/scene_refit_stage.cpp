// The scene-refit stage of the window solve (window_solver.h): the natural scene's links fitted
// again from their views with the rotation held near the joint estimate's
// (pipeline/scene_link_refitter.h), and the estimate solved again with them. Two motions in view
// that share the rotation (the room and an object moved between the rests) pull a free two-view
// fit into a compromise between them, a few tenths of a degree off; held, the fit follows one of
// them. A link whose views are gone or whose held fit fails keeps its rotation.
#include <algorithm>
#include <sstream>

#include "camera_imu_alignment/estimation/camera_link_screening.h"
#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "window_stage.h"

namespace camera_imu_alignment {
namespace {

class SceneRefitStage : public WindowStage {
 public:
  const char* name() const override { return "scene refit"; }
  std::string run(WindowSolveState* state) const override {
    const JointProblem& problem = state->window.joint;
    const SceneLinkRefitter* refitter = state->window.scene_links.get();
    const JointResult& joint = state->joint;
    if (!joint.ok || refitter == nullptr ||
        joint.camera_orientation_fit.size() != problem.poses.size()) {
      return "";
    }
    JointProblem refitted = problem;
    std::vector<int> changed, second_motion;
    for (std::size_t j = 0; j < refitted.camera_links.size(); ++j) {
      CameraLink& link = refitted.camera_links[j];
      const int index = static_cast<int>(j);
      const Eigen::Matrix3d R_fit =
          joint.camera_orientation_fit[static_cast<std::size_t>(link.from_pose)].transpose() *
          joint.camera_orientation_fit[static_cast<std::size_t>(link.to_pose)];
      std::optional<SceneRotation> again = refitter->remembered(index, R_fit);
      if (!again) {
        again = refitter->refit(index, R_fit);
        if (again) state->out.scene_refits.push_back({refitter->key(index), R_fit, *again});
      }
      if (!again || !again->ok || rotationAngle(again->R_from_to.transpose() * link.R_from_to) == 0)
        continue;
      link.alternatives.push_back({link.R_from_to, link.cov_rad2});
      link.R_from_to = again->R_from_to;
      link.cov_rad2 = again->cov_rad2 + link.undecided_rad2;
      changed.push_back(index);
      if (again->second_motion_inliers > 0) second_motion.push_back(index);
    }
    if (changed.empty()) return "";
    const JointEstimator estimator(jointSettingsOf(state->settings));
    JointResult second = solveScreeningCameraLinks(estimator, refitted, joint.R_cam_imu);
    if (!second.ok) return "the solve with the refitted links failed: " + second.message;
    second.camera_links_refitted = std::move(changed);
    second.camera_links_second_motion = std::move(second_motion);
    state->window.joint = std::move(refitted);
    state->joint = std::move(second);
    // The mount-change test's second basis: the links as the estimate used them, their excess
    // noise the larger of the two solves' (MountTestBasis).
    MountTestBasis& basis = state->out.basis;
    basis.refitted_problem = state->window.joint;
    basis.refitted = state->joint;
    basis.refitted.camera_link_excess_variance_rad2 =
        std::max(state->joint_as_measured.camera_link_excess_variance_rad2,
                 state->joint.camera_link_excess_variance_rad2);
    return std::to_string(state->joint.camera_links_refitted.size()) + " of " +
           std::to_string(problem.camera_links.size()) + " links taken from the held fit";
  }
};

}  // namespace

std::unique_ptr<WindowStage> makeSceneRefitStage() { return std::make_unique<SceneRefitStage>(); }

}  // namespace camera_imu_alignment
