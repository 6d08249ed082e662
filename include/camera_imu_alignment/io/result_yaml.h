// The calibration result YAML of doc/CONVENTIONS.md (R_cam_imu as quaternion_xyzw and matrix,
// Kalibr-style T_cam_imu whose translation is the lever arm where the motion measured it, else
// zero, with the translation block saying which; quality block), plus extra keys: method,
// two_step, observability details, per-pair residuals, R_imu_cam.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "camera_imu_alignment/estimation/alignment_result.h"
#include "camera_imu_alignment/io/default_frames.h"

namespace camera_imu_alignment {

/// The quality gates' verdict a result was written under: the file's `verdict:` block. An estimate
/// that failed them is written only on request (calibrate_bag --force, the nodelet's ~calibrate
/// with force: true), and the block says so.
struct ResultVerdict {
  bool passed = true;
  std::string text;     ///< "PASSED (...)" or "FAILED: <the gate, with its numbers>"
  bool forced = false;  ///< written on request although it failed
};

struct ResultMetadata {
  std::string camera_frame = kDefaultCameraFrame;  ///< the tf frame of the camera
  std::string imu_frame = kDefaultImuFrame;        ///< the tf frame of the IMU
  int num_poses = 0;  ///< stationary poses behind the pairs (0: pairs given)
  /// When set, the `verdict:` block (solve_rotation has no gates and writes none).
  std::optional<ResultVerdict> verdict;
};

/// The result document as YAML text.
std::string resultToYaml(const AlignmentResult& result, const ResultMetadata& meta);

/// Why T_cam_imu's translation was not measured, for the outputs ("" when it was: the joint
/// estimate's lever arm, JointResult::lever_arm_measured): rests only, no camera positions during
/// the motion, or not determined by it. Ends with the advice to keep the user's measured one.
std::string translationNotMeasuredReason(const AlignmentResult& result);

/// Writes the YAML atomically (temporary file in the same folder + rename), so a reader never sees
/// a half-written file and a failed write leaves any previous file intact. Throws InputError.
void writeResultYaml(const std::string& path, const AlignmentResult& result,
                     const ResultMetadata& meta);

/// R_cam_imu and frames read back from a result (or truth) YAML.
struct StoredCalibration {
  std::string camera_frame;
  std::string imu_frame;
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();
  /// quality.std_dev_deg and quality.num_poses when the file has them (a result YAML does; a
  /// truth file does not).
  std::optional<Eigen::Vector3d> std_dev_deg;
  int num_poses = 0;
  std::optional<ResultVerdict> verdict;  ///< the `verdict:` block when the file has one
};

/// Reads R_cam_imu (quaternion_xyzw, else matrix) from a result YAML. Throws InputError naming the
/// file and the key on any problem (missing key, not finite, not a rotation, a `verdict:` block
/// without a boolean `passed`).
StoredCalibration readResultYaml(const std::string& path);

/// "" unless `stored` (read from `path`) was written under a FAILED verdict; then one line for its
/// reader to show: the file holds an estimate that failed its quality gates (written on request),
/// and the verdict. Every reader of a result file shows it: a FAILED estimate is never taken for a
/// good one silently.
std::string failedVerdictNote(const StoredCalibration& stored, const std::string& path);

/// For a node starting up: the calibration saved at `path`, nullopt when there is no file. A file
/// that cannot be read (corrupt, truncated, not a rotation) is renamed to `path + ".bad"`, kept for
/// inspection and never read again, and `warning` says so; the node then starts fresh.
std::optional<StoredCalibration> loadSavedCalibration(const std::string& path,
                                                      std::string* warning);

}  // namespace camera_imu_alignment
