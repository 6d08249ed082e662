// The pairs, consensus and joint stages of the window solve (window_solver.h).
#include "camera_imu_alignment/estimation/camera_link_consensus.h"
#include "camera_imu_alignment/estimation/camera_link_screening.h"
#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "window_stage.h"

namespace camera_imu_alignment {
namespace {

/// The pair estimators (the paper's two-step, the optimal solver) on the window's pairs: the
/// estimate without the joint model and its start. Ends the solve without pairs, without a usable
/// pair estimate, or when the settings ask for no joint estimate.
class PairStage : public WindowStage {
 public:
  const char* name() const override { return "pairs"; }
  std::string run(WindowSolveState* state) const override {
    const RotationPairs& pairs = state->window.pairs;
    AlignmentResult& result = state->result;
    if (pairs.empty()) {
      result.status = SolveStatus::kBadInput;
      result.message = "no pairs yet: " + std::to_string(state->window.pose_indices.size()) +
                       " stationary pose(s) in the window, at least 2 of one group needed" +
                       (state->motion_note.empty() ? "" : "; motion: " + state->motion_note);
      state->done = true;
      return result.message;
    }
    result = solveAlignment(pairs, state->settings.solver);
    state->done = !usesJointEstimate(state->settings.imu_orientation) ||
                  result.status == SolveStatus::kBadInput || !result.R_cam_imu.allFinite();
    return result.message;
  }
};

/// A near-planar view's two solutions (the natural scene): the one the gyro agrees with.
class ConsensusStage : public WindowStage {
 public:
  const char* name() const override { return "consensus"; }
  std::string run(WindowSolveState* state) const override {
    JointProblem& joint = state->window.joint;
    const bool links = !joint.camera_links.empty();
    if (links) state->window.link_consensus = chooseCameraLinkSolutions(&joint);
    if (state->request.test_mount_change) state->tested_problem = joint;
    if (!links) return "";
    const CameraLinkConsensus& consensus = state->window.link_consensus;
    return std::to_string(consensus.consensus) + " of " + std::to_string(consensus.links_judged) +
           " natural-scene links agree with the gyro" +
           (consensus.undecided > 0
                ? ", " + std::to_string(consensus.undecided) + " widened (undecided)"
                : "");
  }
};

/// The joint estimate started from the pair estimate, the natural scene's rotations screened (a
/// wrong one is left out: camera_link_screening.h).
class JointStage : public WindowStage {
 public:
  const char* name() const override { return "joint"; }
  std::string run(WindowSolveState* state) const override {
    const JointEstimator estimator(jointSettingsOf(state->settings));
    state->joint_as_measured =
        solveScreeningCameraLinks(estimator, state->window.joint, state->result.R_cam_imu);
    state->joint = state->joint_as_measured;
    state->joint_solved = true;
    state->out.basis.as_measured = state->joint_as_measured;
    const JointResult& joint = state->joint;
    if (!joint.ok) return "failed (" + joint.message + ")";
    return "chi2/dof " + fixedText(joint.dof > 0 ? joint.chi2 / joint.dof : 0.0) + " over " +
           std::to_string(joint.dof) + " dof, " + std::to_string(joint.iterations) +
           " iteration(s)" +
           (joint.camera_links_left_out.empty()
                ? ""
                : ", " + std::to_string(joint.camera_links_left_out.size()) +
                      " camera link(s) left out");
  }
};

}  // namespace

std::unique_ptr<WindowStage> makePairStage() { return std::make_unique<PairStage>(); }
std::unique_ptr<WindowStage> makeConsensusStage() { return std::make_unique<ConsensusStage>(); }
std::unique_ptr<WindowStage> makeJointStage() { return std::make_unique<JointStage>(); }

}  // namespace camera_imu_alignment
