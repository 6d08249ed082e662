// What the online calibrator knows at one moment, as one ROS-free value (OnlineCalibrator::
// snapshot()): state, counts, the poses in the window, the latest estimate with its verdicts, the
// broadcast estimate, remounts, guidance and progress. Every output reads it (the nodelet's
// ~status, diagnostics and ~stationary_poses; calibrate_bag's summary, verdict, progress line,
// --export-poses, YAML and report), so that each verdict is decided once, in the core.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/inertial/stationary_detector.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/online/broadcast_gate.h"
#include "camera_imu_alignment/online/online_types.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/pipeline/input_rejections.h"

namespace camera_imu_alignment {

/// A solve of the window and what the gates made of it.
struct EstimateEvent {
  AlignmentResult result;
  GateOutcome gate;              ///< decision, why, and the consistent / determined verdicts
  std::size_t window_poses = 0;  ///< poses the estimate used
  bool forced = false;           ///< broadcast on request although a gate failed
  std::optional<MountChangeTest> mount_test;
  /// "" unless camera_info's model did not fit the images when it was judged
  /// (CameraModelCheck::message): the gate rejects it and the verdict names camera_info.
  std::string camera_model_problem;
};

/// A mount change found.
struct RemountEvent {
  int first_pose_index = 0;  ///< StationaryPose::index of the first pose of the new mount
  /// The window restarted from this pose (>= first_pose_index: a later split fitted as well, and
  /// an old-mount pose would bias the new estimate).
  int first_pose_kept = 0;
  double change_deg = 0;       ///< between the two mounts' estimates (0 when unknown: pair modes)
  std::size_t poses_kept = 0;  ///< poses of the new mount left in the window
  std::string message;
  /// A change during continuous motion: its stamp (s, camera clock; the pose indices then name
  /// the next pose, if any). NaN for a change between rests.
  double change_stamp_s = std::numeric_limits<double>::quiet_NaN();
};

/// Where a remount happened, for the verdicts: "before pose 7" or "during the motion at 30.21 s".
std::string remountPlace(const RemountEvent& event);

/// The recording's verdict (calibrate_bag's "verdict:" line; the nodelet's status): would the
/// estimate be broadcast, and was the mount one mount throughout.
struct CalibrationVerdict {
  bool passed = false;  ///< the gates passed (broadcast or kept) and no remount was found
  std::string text;     ///< "PASSED (...)" or "FAILED: <the gate or the remount>"
};

/// The verdict of a solved estimate (none when it is not solved and observable: the estimate's own
/// message says what is missing) given the remounts found since the start or the last reset. A
/// camera model that does not fit the images (EstimateEvent::camera_model_problem) fails it first,
/// naming camera_info: its poses are biased, and so is any remount or axis they suggest. With
/// `accept_last_mount` (calibrate_bag --accept-last-mount) a remount does not fail it: the estimate
/// is the last mount's, from the poses after the change, and the verdict names the change.
std::optional<CalibrationVerdict> recordingVerdict(const EstimateEvent& estimate,
                                                   const std::vector<RemountEvent>& remounts,
                                                   bool accept_last_mount = false);

/// How far the window is from a broadcast estimate of the required precision.
struct CalibrationProgress {
  /// Largest 1-sigma (deg) of the latest estimate; infinite before the first.
  double std_dev_deg = 0;
  double max_std_dev_deg = 0;  ///< the setting it must reach
  /// Poses still needed to reach max_std_dev_deg at the present rate (1-sigma falling as
  /// 1/sqrt(poses)); 0 when reached; -1 when unknown (no estimate yet).
  int poses_needed = -1;
  /// The camera axis to rotate about next (unit vector, camera frame).
  Eigen::Vector3d rotate_about_cam = Eigen::Vector3d::UnitX();
  /// Which IMU parameters are still held at their priors and how to excite them ("" when none).
  std::string imu_guidance;
  /// rotate_about_cam in the words of someone moving a rig or driving a robot, from its angle to
  /// the vertical at the newest rest: "turn in place (about the vertical)", "tilt about a
  /// horizontal axis (...)" or "turn and tilt"; "" when the vertical is not known.
  std::string how_to_move;
};

/// A saved calibration (a result YAML) as a broadcast estimate: its per-axis 1-sigma as a diagonal
/// covariance (the correlations are not saved), infinite 1-sigma when the file has none.
BroadcastEstimate storedBroadcast(const StoredCalibration& stored, const std::string& source);

/// "IMU parameters held at their priors: ...; to calibrate them, rotate about the camera axis
/// (x, y, z)" for a joint estimate that holds some ("" otherwise).
std::string imuGuidanceOf(const EstimateEvent& estimate);
/// The progress of the latest estimate towards max_std_dev_deg. With `up_cam` (the vertical, up,
/// in the camera frame at the newest rest; unit), how_to_move says how to rotate next.
CalibrationProgress progressOf(const std::optional<EstimateEvent>& estimate, double max_std_dev_deg,
                               const std::optional<Eigen::Vector3d>& up_cam = std::nullopt);
/// How to rotate about `axis_cam` given the vertical `up_cam` (both unit, camera frame): within 30
/// deg of the vertical "turn in place", beyond 60 deg "tilt", else "turn and tilt" (see
/// CalibrationProgress::how_to_move).
std::string howToMove(const Eigen::Vector3d& axis_cam, const Eigen::Vector3d& up_cam);

/// What OnlineCalibrator::snapshot() copies: the state alone (the status and diagnostics, published
/// every second and on every change), or also the histories of poses, rests and rejected rests (up
/// to CalibrationPipeline::kHistoryLimit each: the report, the progress line, the pose markers).
enum class SnapshotContents { kState, kWithHistory };

/// Input counters since the start (kept over a reset); cheap to read per sample.
struct InputCounts {
  std::uint64_t imu_samples = 0, magnetic_samples = 0, frames = 0;
  std::uint64_t frames_detected = 0;  ///< frames at rest on which detection ran
  std::uint64_t motion_frames = 0;    ///< frames during motion with a camera orientation
  std::uint64_t imu_gaps = 0;         ///< IMU stamp gaps that ended a rest
  bool has_intrinsics = false;
};
/// One line for the logs: "1-sigma 0.120 deg, max_std_dev_deg 0.050 reached" or "1-sigma 0.120
/// deg > max_std_dev_deg 0.050: about 9 more poses, rotating about the camera axis (0.10, 0.99,
/// 0.00)", with how_to_move after it when known ("...: turn in place (about the vertical)").
std::string progressText(const CalibrationProgress& progress);

struct CalibrationSnapshot {
  CalibrationState state = CalibrationState::kWaitingForData;
  std::string message;         ///< what the state means now, for the user
  double newest_stamp_s = -1;  ///< newest stamp on any input (s), -1 before the first

  // --- inputs
  InputCounts inputs;
  RejectionCounts rejections;
  /// "" unless the target was never found at rest (CalibrationPipeline::targetNotFoundDiagnosis):
  /// what is wrong with the target file.
  std::string target_diagnosis;
  /// Does camera_info's model fit the images (CalibrationPipeline::cameraModelCheck)? When it does
  /// not (camera_model.wrong), `message` is its message and no remount is declared.
  CameraModelCheck camera_model;

  // --- poses
  std::size_t rests_total = 0, poses_total = 0;  ///< since the start or the last reset
  std::vector<StationaryPose> window;            ///< the poses the next solve uses, oldest first
  // With SnapshotContents::kWithHistory only (empty otherwise):
  std::vector<StationaryPose> poses;         ///< the newest kHistoryLimit poses
  std::vector<RejectedPose> rejected_poses;  ///< rests that became no pose (newest)
  std::vector<StationarySegment> rests;      ///< the newest kHistoryLimit IMU rests
  std::optional<StationaryPose> last_pose;

  // --- estimates
  std::optional<EstimateEvent> latest;  ///< the latest solve, as judged
  /// The latest estimate is what the static tf says now.
  bool latest_is_broadcast = false;
  std::optional<BroadcastEstimate> broadcast;  ///< what the static tf says
  std::optional<CalibrationVerdict> verdict;   ///< of the latest estimate (recordingVerdict)
  std::vector<RemountEvent> remount_events;    ///< since the start or the last reset (newest 100)
  /// The latest estimate against the broadcast one (when both exist): is the tf still right?
  std::optional<CalibrationCheck> check;
  /// "" unless the latest estimate disagrees with the broadcast tf beyond the check's level and
  /// the gates did not let it replace the tf: what is wrong and why it stayed (diagnostics WARN,
  /// and the status message says it).
  std::string broadcast_warning;
  int remounts = 0;
  CalibrationProgress progress;

  /// The window's poses as the poses CSV holds them (solve_rotation --poses): the stamp in the
  /// middle of the rest.
  std::vector<PoseOrientation> windowOrientations() const;
};

}  // namespace camera_imu_alignment
