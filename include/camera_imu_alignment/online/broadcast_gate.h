// When a new estimate replaces what the static tf says: the calibrator's quality gates as a pure
// function (no ROS, no state), unit-tested on its own.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "camera_imu_alignment/online/online_types.h"
#include "camera_imu_alignment/solver/alignment_solver.h"

namespace camera_imu_alignment {

enum class GateDecision {
  kReject,     ///< fails a quality gate: state collecting / not_observable
  kKeep,       ///< good, but not better than or not different from what is broadcast
  kBroadcast,  ///< broadcast (and save) it
};
/// "reject", "keep", "broadcast".
const char* toString(GateDecision decision);

struct GateOutcome {
  GateDecision decision = GateDecision::kReject;
  std::string why;  ///< for kReject and kKeep: the gate, with its numbers and parameter
  /// The verdicts every output prints (status, YAML, report, calibrate_bag), decided here once:
  /// consistent: a joint estimate that succeeded with chi-square p >= consistency_level (pair
  /// modes: always false, they have no such test);
  bool consistent = false;
  /// determined: solved, observable and finite with its largest 1-sigma <= max_std_dev_deg.
  bool determined = false;
  /// False when the window holds too little to judge (fewer than min_poses poses and too little
  /// motion, enoughMotion): not a failed quality gate but missing information (calibrate_bag's
  /// exit 3).
  bool enough_data = true;
  /// kKeep within min_change_deg, with a smaller 1-sigma than the broadcast estimate's: the tf
  /// stays, but the saved file and the broadcast 1-sigma become this estimate's.
  bool refines_broadcast = false;
};

/// The gates in order:
///   solved and observable; finite; at least min_poses in the window;
///   joint estimate (imu_orientation: joint or magnetometer): it succeeded and is consistent
///   (chi-square p-value
///     >= consistency_level); pair modes: RMS pair residual <= max_residual_deg;
///   largest 1-sigma <= max_std_dev_deg;
/// then against what is broadcast:
///   no silent regression: an estimate with a larger 1-sigma from no more poses and no more
///     camera orientations during motion than the broadcast one is kept back, unless `fresh_start`
///     (after a remount or a reset the old estimate is not a reference) or it differs significantly
///     from the broadcast one (the mount changed while nothing was watching: their difference is
///     judged against both covariances at remount.level);
///   min_change_deg: a change smaller than that is not re-broadcast (refines_broadcast when it is
///     more precise).
/// A joint estimate with motion stands in for min_poses when its window holds min_motion_s of
/// motion that turned the camera min_motion_rotation_deg about each of its axes (MotionFigures):
/// a recording without rests has no poses to count, and its statistical gates (consistency,
/// 1-sigma) decide once the motion has shown its noise.
bool enoughMotion(const JointResult& joint, const OnlineSettings& settings);

/// The camera axes the motion turned less than min_motion_rotation_deg about, as the status says
/// them ("camera z", "camera x and camera z"); "" when every axis turned enough.
std::string unexcitedAxes(const MotionFigures& motion, const OnlineSettings& settings);

GateOutcome judgeEstimate(const AlignmentResult& result, std::size_t window_poses,
                          const OnlineSettings& settings,
                          const std::optional<BroadcastEstimate>& broadcast, bool fresh_start);

/// Chi-square (3 dof) p-value of the difference between an estimate and the broadcast one under
/// their summed covariances; 1 when the broadcast one has no covariance.
double differenceSignificance(const AlignmentResult& result, const BroadcastEstimate& broadcast);

/// "Is my current calibration still right?": a new estimate against a current (broadcast or
/// saved) calibration.
struct CalibrationCheck {
  double error_deg = 0;  ///< angle between the two rotations
  /// Mahalanobis length of the difference, sqrt(chi2), under the new estimate's covariance plus
  /// the current calibration's (when it has one: a saved 1-sigma counts as independent per axis).
  double sigmas = 0;
  double chi2 = 0;         ///< 3 dof
  double p_value = 1;      ///< chi-square upper tail
  bool consistent = true;  ///< p_value >= consistency_level
  std::string text;        ///< one line with the figures and the verdict
};

/// The check of `current` by `estimate` (a solved joint estimate with its covariance; nullopt
/// otherwise) at `consistency_level`.
std::optional<CalibrationCheck> checkCalibration(const AlignmentResult& estimate,
                                                 const BroadcastEstimate& current,
                                                 double consistency_level);

/// A broadcast tf further than this many sigma (CalibrationCheck::sigmas) from the latest estimate
/// is warned about while the gates keep the estimate back (also below the check's
/// consistency_level: at 3 dof its default 0.001 is 4.0 sigma).
constexpr double kBroadcastWarningSigmas = 3.0;

/// "" unless the latest estimate (not the broadcast one) disagrees with the broadcast tf by more
/// than kBroadcastWarningSigmas or fails the check: then what is wrong, with the figures, and the
/// gate's reason why the tf stayed (`gate_why`). For the snapshot, the status and diagnostics
/// (WARN).
std::string broadcastWarning(const std::optional<CalibrationCheck>& check, bool latest_is_broadcast,
                             const std::string& gate_why);

}  // namespace camera_imu_alignment
