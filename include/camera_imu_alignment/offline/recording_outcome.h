// What calibrate_bag makes of a recording, ROS-free: its outputs checked before the bag is read
// (checkOutputPaths), the exit code (io/exit_codes.h), the closing messages and which files to
// write decided from what the run saw (decideRecordingOutcome), and those files written, each
// atomically (writeRecordingOutputs). The tool reads the bag and prints; every decision is here.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/io/calibration_summary.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/online/broadcast_gate.h"
#include "camera_imu_alignment/online/calibration_snapshot.h"
#include "camera_imu_alignment/solver/pose_window.h"

namespace camera_imu_alignment {

/// The files calibrate_bag writes, by option; "" where the option is not given.
struct RecordingOutputPaths {
  std::string output;        ///< --output: the result YAML
  std::string imu_yaml;      ///< --imu-yaml: Kalibr's imu.yaml with the calibrated intrinsics
  std::string report;        ///< --report: the one-page report (PNG)
  std::string export_poses;  ///< --export-poses: the window's poses CSV

  /// (option, path) of each one given, in the order above.
  std::vector<std::pair<std::string, std::string>> given() const;
};

/// Every problem with the outputs, one line each naming the option and the path, all of them (not
/// only the first): a file that cannot be written there (whyNotWritable, io/atomic_file.h), two
/// options naming the same file, an output that is one of `inputs` (the bag: it would be
/// overwritten). Empty when every output can be written. Checked before the bag is read, so that a
/// long run does not end in a file it cannot write.
std::vector<std::string> checkOutputPaths(const RecordingOutputPaths& paths,
                                          const std::vector<std::string>& inputs = {});

/// What the run saw, once the bag was read: everything the exit code and the closing messages
/// depend on.
struct RecordingFacts {
  std::string bag_path;
  // The camera source.
  bool camera_poses = false;      ///< camera poses (PoseStamped) instead of images
  std::string camera_pose_topic;  ///< with camera_poses
  std::uint64_t camera_pose_messages = 0;
  std::string image_topic;  ///< "" when the bag has none
  std::uint64_t image_messages = 0;
  std::string camera_info_topic;  ///< "" when the bag has none
  bool has_intrinsics = false;    ///< a usable camera_info arrived
  bool windowed = false;          ///< only a part of the bag was read (--start / --end)
  // The estimate.
  SolveStatus status = SolveStatus::kBadInput;
  std::string message;               ///< the estimate's own message
  bool has_rests = false;            ///< the IMU rested at least once
  std::size_t motion_frames = 0;     ///< camera orientations during motion
  std::string target_path;           ///< --target
  std::string target_diagnosis;      ///< "" unless the target file does not describe the board
  std::string camera_model_problem;  ///< "" unless camera_info's intrinsics do not fit the images
  /// The recording's verdict (none without a solved estimate).
  std::optional<CalibrationVerdict> verdict;
  /// The latest gate found enough data to judge (GateOutcome::enough_data), and why it did not.
  bool enough_data = true;
  std::string gate_why;
  bool remounted = false;  ///< a mount change was found
  // What was asked.
  std::string check_path;  ///< --check CURRENT.yaml; "" without
  /// The check of the current calibration by the estimate (none: no joint estimate with its
  /// covariance), and the joint estimate's message or why none ran.
  std::optional<CalibrationCheck> check;
  std::string joint_message;
  bool force = false;  ///< --force: write an estimate that failed its gates, marked FAILED
  RecordingOutputPaths outputs;
};

/// The decision: exit code, what to print after the summary, what to write.
struct RecordingOutcome {
  int exit_code = 0;
  /// The summary is printed and the report and the poses CSV written: the bag had camera data
  /// (without them there is nothing to show beyond the message).
  bool summary = true;
  /// --output and --imu-yaml are written, under `result_verdict` (the file's `verdict:` block).
  bool write_result = false;
  ResultVerdict result_verdict;
  std::vector<std::string> out_lines;  ///< stdout after the summary ("check: ...")
  std::vector<std::string> err_lines;  ///< stderr, the tool's name to be put before each
};

/// The exit code and the closing lines of a read recording, in order of precedence: no camera data
/// or no usable camera info (2, no summary); camera_info's intrinsics that do not fit the images
/// (2); no solved estimate (3, or 2 when the target file does not describe the board); --check
/// (0 still right, 4 not consistent or the new estimate FAILED its gates, 3 too little data or no
/// joint estimate to check with; nothing written); a FAILED verdict (3 too little data, else 4;
/// written, marked FAILED, only with --force); else 0 and the outputs written.
RecordingOutcome decideRecordingOutcome(const RecordingFacts& facts);

/// What the outputs are made of.
struct RecordingProducts {
  const ReportInput* report = nullptr;        ///< the summary's input: result, poses, rests
  std::vector<PoseOrientation> window_poses;  ///< --export-poses
  ResultMetadata meta;                        ///< --output's frames and poses (verdict: added)
  std::string imu_topic;                      ///< --imu-yaml's rostopic
  double imu_rate_hz = 0;  ///< the recording's mean IMU rate (when no rest gives one)
};

/// The Kalibr imu.yaml of the joint estimate (--imu-yaml): white noise densities from the rests
/// (the median over the rests of the per-sample scatter times sqrt(sample period)); `imu_rate_hz`
/// stands in for the rests' rate when there are none. Throws InputError naming `path` without a
/// successful joint estimate.
std::string imuYamlText(const std::string& path, const ReportInput& report,
                        const std::string& imu_topic, double imu_rate_hz);

/// Writes what `outcome` asks for, each file atomically: with the summary the report and the
/// poses CSV, with write_result the result YAML (its verdict block) and the imu.yaml (under a
/// FAILED verdict its first line a comment saying so: Kalibr's format has no such key). One line
/// per failure, naming the option and the path; empty when all were written.
std::vector<std::string> writeRecordingOutputs(const RecordingOutputPaths& paths,
                                               const RecordingOutcome& outcome,
                                               const RecordingProducts& products);

}  // namespace camera_imu_alignment
