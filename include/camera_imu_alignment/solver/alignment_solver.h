// Entry point of the rotation solver: validates the pairs, runs the selected method and evaluates
// the quality of the answer. Used by solve_rotation, the offline pipeline and the nodelet.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/solver/optimal_solver.h"
#include "camera_imu_alignment/solver/rotation_pair.h"
#include "camera_imu_alignment/solver/solution_quality.h"
#include "camera_imu_alignment/solver/two_step_solver.h"

namespace camera_imu_alignment {

enum class SolverMethod {
  kOptimal,  ///< default: robust least squares on SO(3), started from the two-step
  kTwoStep,  ///< the paper's two-step iteration alone (its left iterate R^l), no outlier rejection
};

/// "optimal" / "two_step".
const char* toString(SolverMethod method);
/// Parses "optimal" / "two_step"; false on anything else.
bool parseSolverMethod(const std::string& text, SolverMethod* method);

struct SolverOptions {
  SolverMethod method = SolverMethod::kOptimal;
  OptimalOptions optimal;   ///< the default method (optimal.two_step: its two-step start)
  TwoStepOptions two_step;  ///< the two-step method run alone
  QualityOptions quality;
};

enum class SolveStatus {
  kOk,             ///< estimate observable
  kNotObservable,  ///< estimate computed but a direction is unconstrained; see quality
  kPoorFit,   ///< the two-step settled on a fixed point that fits far worse than the closed form
  kBadInput,  ///< no pairs, or a pair that is not a rotation
};

/// "ok", "not observable", "poor fit", "bad input" (as the summary and the report print it).
const char* toString(SolveStatus status);

/// The pair solve's answer. The window solve's answer (estimation/alignment_result.h) is this with
/// the joint estimate beside it.
struct PairSolveResult {
  SolveStatus status = SolveStatus::kBadInput;
  std::string message;  ///< one line for the user: what happened, what to do next
  SolverMethod method = SolverMethod::kOptimal;
  /// p_cam = R_cam_imu * p_imu. Meaningful only with status kOk (still filled with the best guess
  /// when kNotObservable, never NaN).
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();
  TwoStepResult two_step;  ///< the paper's solver: run at every solve
  std::string start;       ///< start of the optimal estimator ("two_step" / "closed_form")
  int iterations = 0;      ///< iterations of the selected method
  bool converged = false;  ///< the selected method met its convergence test
  SolutionQuality quality;
};

/// Whether `result` holds a rotation at all (the outputs show none otherwise): any status but
/// kBadInput, whose R_cam_imu is a placeholder (identity: no pairs, nothing solved), and finite.
/// A kNotObservable or kPoorFit estimate is a best guess, shown as such.
bool hasEstimate(const PairSolveResult& result);

/// Solves A_j X = X B_j for X = R_cam_imu.
PairSolveResult solveAlignment(const RotationPairs& pairs, const SolverOptions& options = {});

}  // namespace camera_imu_alignment
