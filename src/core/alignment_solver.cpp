#include "camera_imu_alignment/alignment_solver.h"

#include <sstream>

#include "camera_imu_alignment/rotation_math.h"

namespace camera_imu_alignment {

std::string toString(SolverMethod method) {
  return method == SolverMethod::kTwoStep ? "two_step" : "optimal";
}

bool parseSolverMethod(const std::string& text, SolverMethod* method) {
  if (text == "optimal") {
    *method = SolverMethod::kOptimal;
  } else if (text == "two_step") {
    *method = SolverMethod::kTwoStep;
  } else {
    return false;
  }
  return true;
}

AlignmentResult solveAlignment(const RotationPairs& pairs, const SolverOptions& options) {
  AlignmentResult result;
  result.method = options.method;
  if (pairs.empty()) {
    result.message = "no rotation pairs to solve";
    return result;
  }
  for (size_t j = 0; j < pairs.size(); ++j) {
    if (!isRotationMatrix(pairs[j].A_cam, 1e-6) || !isRotationMatrix(pairs[j].B_imu, 1e-6)) {
      result.message = "pair " + std::to_string(j) + " is not a pair of rotation matrices";
      return result;
    }
  }

  std::vector<bool> inlier;
  std::vector<std::string> rejection;
  if (options.method == SolverMethod::kTwoStep) {
    result.two_step = solveTwoStep(pairs, options.optimal.two_step);
    result.R_cam_imu = result.two_step.R_cam_imu_left;
    result.iterations = result.two_step.iterations;
    result.converged = result.two_step.converged;
    result.start = "identity";
    if (options.optimal.two_step.initial_R_cam_imu) result.start = "given";
  } else {
    const OptimalResult opt = solveOptimal(pairs, options.optimal);
    result.two_step = opt.two_step;
    result.R_cam_imu = opt.R_cam_imu;
    result.iterations = opt.iterations;
    result.converged = opt.converged;
    result.start = opt.start;
    inlier = opt.inlier;
    rejection = opt.rejection;
  }
  if (!result.R_cam_imu.allFinite()) {
    result.R_cam_imu.setIdentity();
    result.status = SolveStatus::kNotObservable;
    result.message = "the solver produced no finite estimate";
    return result;
  }
  result.quality = evaluateQuality(pairs, result.R_cam_imu, inlier, rejection, options.quality);
  result.status = result.quality.observable ? SolveStatus::kOk : SolveStatus::kNotObservable;
  std::ostringstream msg;
  msg.precision(3);
  if (result.quality.observable) {
    msg << "solved with " << toString(options.method) << ": " << result.quality.num_inliers << "/"
        << result.quality.num_pairs << " pairs, residual RMS " << result.quality.residual_rms_deg
        << " deg, 1-sigma [" << result.quality.std_dev_deg.transpose() << "] deg";
    if (!result.converged) msg << " (iteration limit reached before convergence)";
  } else {
    msg << result.quality.observability_message;
  }
  result.message = msg.str();
  return result;
}

}  // namespace camera_imu_alignment
