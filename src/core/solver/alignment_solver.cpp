#include "camera_imu_alignment/solver/alignment_solver.h"

#include <cstdio>
#include <utility>

#include "camera_imu_alignment/solver/closed_form_solver.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

const char* toString(SolverMethod method) {
  return method == SolverMethod::kTwoStep ? "two_step" : "optimal";
}

const char* toString(SolveStatus status) {
  switch (status) {
    case SolveStatus::kOk:
      return "ok";
    case SolveStatus::kNotObservable:
      return "not observable";
    case SolveStatus::kPoorFit:
      return "poor fit";
    case SolveStatus::kBadInput:
      return "bad input";
  }
  return "unknown";
}

bool hasEstimate(const PairSolveResult& result) {
  return result.status != SolveStatus::kBadInput && result.R_cam_imu.allFinite();
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

PairSolveResult solveAlignment(const RotationPairs& pairs, const SolverOptions& options) {
  PairSolveResult result;
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
  std::vector<Eigen::Vector3d> residuals;
  std::vector<Eigen::Vector2d> angles_rad;
  if (options.method == SolverMethod::kTwoStep) {
    result.two_step = solveTwoStep(pairs, options.two_step);
    result.R_cam_imu = result.two_step.R_cam_imu_left;
    result.iterations = result.two_step.iterations;
    result.converged = result.two_step.converged;
    result.start = "identity";
    if (options.two_step.initial_R_cam_imu) result.start = "given";
  } else {
    OptimalResult opt = solveOptimal(pairs, options.optimal);
    result.two_step = std::move(opt.two_step);
    result.R_cam_imu = opt.R_cam_imu;
    result.iterations = opt.iterations;
    result.converged = opt.converged;
    result.start = opt.start;
    inlier = std::move(opt.inlier);
    rejection = std::move(opt.rejection);
    residuals = std::move(opt.residuals);
    angles_rad = std::move(opt.pair_angles_rad);
  }
  if (!result.R_cam_imu.allFinite()) {
    result.R_cam_imu.setIdentity();
    result.status = SolveStatus::kNotObservable;
    result.message = "the solver produced no finite estimate";
    return result;
  }
  result.quality = evaluateQuality(pairs, result.R_cam_imu, inlier, rejection, options.quality,
                                   residuals, angles_rad);
  result.status = result.quality.observable ? SolveStatus::kOk : SolveStatus::kNotObservable;
  if (options.method == SolverMethod::kTwoStep) {
    // The two-step can converge to a wrong fixed point (mountings far from its initial value) or
    // not converge at all; compare its fit with the closed form's so that this is never silent.
    const auto reference = solveClosedForm(pairs);
    if (reference) {
      const double reference_rms = evaluateQuality(pairs, *reference).residual_rms_deg;
      if (result.quality.residual_rms_deg > 2.0 * reference_rms + 1.0) {
        char msg[400];
        std::snprintf(
            msg, sizeof(msg),
            "the two-step %s at a rotation that does not fit the pairs (residual RMS %.3g deg; "
            "the closed form fits to %.3g deg, %.3g deg away): it is known to lock onto a wrong "
            "fixed point when the mounting is far from its initial value; use the optimal "
            "method or give an initial value",
            result.converged ? "converged" : "stopped", result.quality.residual_rms_deg,
            reference_rms, rad2deg(geodesicDistance(*reference, result.R_cam_imu)));
        result.status = SolveStatus::kPoorFit;
        result.message = msg;
        return result;
      }
    }
  }
  if (result.quality.observable) {
    char msg[256];
    const Eigen::Vector3d& sd = result.quality.std_dev_deg;
    std::snprintf(
        msg, sizeof(msg),
        "solved with %s: %d/%d pairs, residual RMS %.3g deg, 1-sigma [%.3g %.3g %.3g] deg%s",
        toString(options.method), result.quality.num_inliers, result.quality.num_pairs,
        result.quality.residual_rms_deg, sd.x(), sd.y(), sd.z(),
        result.converged ? "" : " (iteration limit reached before convergence)");
    result.message = msg;
  } else {
    result.message = result.quality.observability_message;
  }
  return result;
}

}  // namespace camera_imu_alignment
