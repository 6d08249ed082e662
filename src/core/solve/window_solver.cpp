// WindowSolver (window_solver.h): the stages in order, and the estimate's one-line message.
#include "camera_imu_alignment/solve/window_solver.h"

#include <memory>
#include <sstream>
#include <utility>

#include "window_stage.h"

namespace camera_imu_alignment {
namespace {

/// The stages, in the order they run. The consensus comes first: it works on the window as the
/// pipeline gave it, which the mount-change stage tests.
const std::vector<std::unique_ptr<WindowStage>>& stages() {
  static const std::vector<std::unique_ptr<WindowStage>> list = [] {
    std::vector<std::unique_ptr<WindowStage>> out;
    out.push_back(makeConsensusStage());
    out.push_back(makeMotionStage());
    out.push_back(makePairStage());
    out.push_back(makeJointStage());
    out.push_back(makeSceneRefitStage());
    out.push_back(makeMountChangeStage());
    return out;
  }();
  return list;
}

/// The natural scene's links as the solve used them: those taken as a near-planar view's other
/// solution by the gyro's consensus (WindowSnapshot::link_consensus) and by the joint estimate's
/// screening; those widened by the consensus; those fitted again with the rotation held
/// (JointResult::camera_links_refitted); those left out by the screening.
std::string sceneLinkNotes(const WindowSnapshot& window, const JointResult& joint) {
  const auto taken = [](const std::vector<int>& used) {
    return std::count_if(used.begin(), used.end(), [](int a) { return a >= 0; });
  };
  const auto by_gyro = taken(window.link_consensus.alternative_used);
  const auto by_screening = taken(joint.camera_link_alternative_used);
  std::vector<std::string> notes;
  if (by_gyro + by_screening > 0) {
    std::ostringstream s;
    s << by_gyro + by_screening << " of them the view's other solution: " << by_gyro
      << " by the gyro's consensus of " << window.link_consensus.consensus << " of "
      << window.link_consensus.links_judged << ", " << by_screening << " by the screening";
    notes.push_back(s.str());
  }
  if (window.link_consensus.undecided > 0) {
    notes.push_back(std::to_string(window.link_consensus.undecided) +
                    " widened to span two solutions the gyro could not tell apart");
  }
  if (!joint.camera_links_refitted.empty()) {
    const std::size_t two = joint.camera_links_second_motion.size();
    notes.push_back(
        std::to_string(joint.camera_links_refitted.size()) + " of " +
        std::to_string(window.joint.camera_links.size()) +
        " fitted again with the rotation held near the estimate's" +
        (two > 0 ? ", " + std::to_string(two) + " of them with a moved object as a second motion"
                 : ""));
  }
  if (!joint.camera_links_left_out.empty()) {
    notes.push_back(std::to_string(joint.camera_links_left_out.size()) +
                    " more left out: residual beyond chi-square(3) p 1e-4");
  }
  if (notes.empty()) return "";
  std::string out = " (";
  for (size_t k = 0; k < notes.size(); ++k) out += (k > 0 ? "; " : "") + notes[k];
  return out + ")";
}

/// The joint estimate into the result: its rotation and 1-sigma, the one-line message, the
/// motion's figures.
void takeJointEstimate(WindowSolveState* state) {
  AlignmentResult& result = state->result;
  const JointResult& joint = state->joint;
  const WindowSnapshot& window = state->window;
  const std::size_t links_dropped = joint.camera_links_left_out.size();
  const std::string sensors = state->settings.imu_orientation == ImuOrientationSource::kMagnetometer
                                  ? " (camera, accelerometer, magnetometer; gyro not used)"
                                  : "";
  if (joint.ok) {
    result.R_cam_imu = joint.R_cam_imu;
    result.quality.std_dev_deg = joint.std_dev_deg;
    result.quality.covariance_rad2 = joint.covariance_rad2;  // the two stay one estimate's
    const std::string motion = joint.motion_nodes > 0
                                   ? " and " + std::to_string(joint.motion_nodes) +
                                         " motion nodes (timeshift_cam_imu " +
                                         fixedText(1e3 * joint.timeshift_cam_imu_s, 2) + " +- " +
                                         fixedText(1e3 * joint.timeshift_sigma_s, 2) + " ms)"
                                   : "";
    const std::string scene =
        window.joint.camera_links.empty()
            ? ""
            : ", " + std::to_string(window.joint.camera_links.size() - links_dropped) +
                  " natural-scene rotations" + sceneLinkNotes(window, joint);
    result.message = "joint estimate" + sensors + " over " +
                     std::to_string(window.joint.poses.size()) + " poses" + motion + scene +
                     ": chi2/dof " + fixedText(joint.dof > 0 ? joint.chi2 / joint.dof : 0.0) +
                     ", 1-sigma [" + fixedText(joint.std_dev_deg.x(), 4) + " " +
                     fixedText(joint.std_dev_deg.y(), 4) + " " +
                     fixedText(joint.std_dev_deg.z(), 4) + "] deg; pairs: " + result.message;
  } else {
    result.message = "joint estimate failed (" + joint.message + "); pair solve: " + result.message;
  }
  result.joint = joint;
  if (joint.motion_nodes > 0) {  // the estimator's per-node residuals, the pipeline's curve
    MotionFigures figures = std::move(state->motion);
    figures.node_stamps_s = joint.motion.node_stamps_s;
    figures.node_residual_sigma = joint.motion.node_residual_sigma;
    figures.node_camera_residual_rad = joint.motion.node_camera_residual_rad;
    result.joint->motion = std::move(figures);
  }
}

}  // namespace

std::string fixedText(double value, int digits) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(digits);
  out << value;
  return out.str();
}

WindowSolver::WindowSolver(PipelineSettings settings) : settings_(std::move(settings)) {}

std::vector<std::string> WindowSolver::stageNames() {
  std::vector<std::string> names;
  for (const auto& stage : stages()) names.emplace_back(stage->name());
  return names;
}

WindowSolveOutput WindowSolver::solve(const WindowSnapshot& window,
                                      const WindowSolveRequest& request) const {
  WindowSolveState state(window, settings_, request);
  std::vector<std::string> notes;
  for (const auto& stage : stages()) {
    const std::string note = stage->run(&state);
    if (!note.empty()) notes.push_back(std::string(stage->name()) + ": " + note);
    if (state.done) break;
  }
  if (state.joint_solved) takeJointEstimate(&state);
  state.result.stage_notes = std::move(notes);
  WindowSolveOutput out = std::move(state.out);
  out.result = std::move(state.result);
  out.window = std::move(state.window);
  return out;
}

AlignmentResult solveWindow(const WindowSnapshot& window, const PipelineSettings& settings,
                            MountTestBasis* mount_test) {
  WindowSolveOutput out = WindowSolver(settings).solve(window);
  if (mount_test) *mount_test = std::move(out.basis);
  return std::move(out.result);
}

}  // namespace camera_imu_alignment
