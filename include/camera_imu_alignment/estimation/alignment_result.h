// The window solve's answer (solve/window_solver.h): the pair solve (solver/alignment_solver.h)
// with the joint maximum-likelihood estimate beside it, and the notes of the solve's stages. What
// the online calibrator gates and broadcasts, the result YAML saves and the summary prints.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "camera_imu_alignment/estimation/joint_result.h"
#include "camera_imu_alignment/solver/alignment_solver.h"

namespace camera_imu_alignment {

struct AlignmentResult : PairSolveResult {
  AlignmentResult() = default;
  /// A pair solve alone (no joint estimate, no stage notes).
  AlignmentResult(PairSolveResult pair_solve)  // NOLINT(google-explicit-constructor)
      : PairSolveResult(std::move(pair_solve)) {}
  /// The joint estimate (pipeline with imu_orientation: joint): when present and ok, R_cam_imu and
  /// quality.std_dev_deg are its, the rest of `quality` is the pair solve's.
  std::optional<JointResult> joint;
  /// The window solve's stages that had something to say, "stage: note", in the order they ran
  /// (solve/window_solver.h); empty for a bare pair solve.
  std::vector<std::string> stage_notes;
};

}  // namespace camera_imu_alignment
