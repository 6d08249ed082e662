#include "camera_imu_alignment/offline/recording_outcome.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/io/atomic_file.h"
#include "camera_imu_alignment/io/calibration_report.h"
#include "camera_imu_alignment/io/csv_io.h"
#include "camera_imu_alignment/io/exit_codes.h"
#include "camera_imu_alignment/io/joint_yaml.h"

namespace camera_imu_alignment {
namespace {

const char* kNoCameraData =
    "no camera data (no sensor_msgs/Image or CompressedImage messages, no "
    "geometry_msgs/PoseStamped "
    "on camera_pose or --camera-pose-topic); the IMU alone cannot give R_cam_imu";

/// Two spellings of one file ("a/../b.yaml", "./b.yaml") compare equal; a file that does not exist
/// yet is compared by its normalised absolute path.
bool sameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (std::filesystem::exists(a, ec) && std::filesystem::exists(b, ec)) {
    return std::filesystem::equivalent(a, b, ec);
  }
  const auto normal = [](const std::string& p) {
    std::error_code ignored;
    return std::filesystem::absolute(p, ignored).lexically_normal();
  };
  return normal(a) == normal(b);
}

/// "--output / --imu-yaml": the result options given ("" when none).
std::string resultOptions(const RecordingOutputPaths& paths) {
  std::string options;
  if (!paths.output.empty()) options = "--output";
  if (!paths.imu_yaml.empty())
    options += (options.empty() ? "" : " / ") + std::string("--imu-yaml");
  return options;
}

/// No camera data or no camera info: the estimate cannot exist; nothing to summarise.
bool refuseWithoutCamera(const RecordingFacts& f, RecordingOutcome* o) {
  std::string why;
  if (f.camera_poses && f.camera_pose_messages == 0) {
    why = f.bag_path + ": no messages on " + f.camera_pose_topic + " (geometry_msgs/PoseStamped)" +
          (f.windowed ? " between --start and --end" : "") +
          "; the IMU alone cannot give R_cam_imu";
  } else if (!f.camera_poses && (f.image_topic.empty() || f.image_messages == 0)) {
    why = f.bag_path + ": " + kNoCameraData;
  } else if (!f.camera_poses && !f.has_intrinsics) {
    why = f.bag_path + ": no usable camera info (" +
          (f.camera_info_topic.empty() ? std::string("no sensor_msgs/CameraInfo topic")
                                       : f.camera_info_topic) +
          "); PnP needs the intrinsics";
  } else {
    return false;
  }
  o->summary = false;
  o->exit_code = kExitBadInput;
  o->err_lines.push_back(why);
  return true;
}

/// No solved estimate: what is missing (3), or the target file that does not fit the board (2).
void refuseUnsolved(const RecordingFacts& f, RecordingOutcome* o) {
  o->err_lines.push_back(f.message);
  if (!f.has_rests) {
    o->err_lines.push_back(
        f.bag_path + ": the recording has no stationary rests and " +
        std::to_string(f.motion_frames) +
        " camera orientation(s) during motion: the estimate needs several seconds of motion about "
        "every axis with the target in view, or rests of a few seconds at several orientations");
  }
  if (!f.target_diagnosis.empty()) {  // the target file, not the recording
    o->err_lines.push_back(f.target_path + ": " + f.target_diagnosis);
    o->exit_code = kExitBadInput;
    return;
  }
  o->exit_code = kExitNotEnoughInformation;  // the bag was read; it did not hold enough
}

/// --check: a check writes no result. Only an estimate that passed its gates can tell whether the
/// current calibration still holds.
void decideCheck(const RecordingFacts& f, bool passed, bool too_little, RecordingOutcome* o) {
  if (!f.check) {
    o->err_lines.push_back(
        "--check needs the joint estimate (--imu-orientation joint or magnetometer) with its "
        "covariance; " +
        f.joint_message);
    o->exit_code = kExitNotEnoughInformation;
    return;
  }
  if (passed) {
    o->out_lines.push_back("check: " + f.check_path + ": " + f.check->text);
    o->exit_code = f.check->consistent ? kExitOk : kExitQualityGate;
    return;
  }
  if (too_little) {
    o->out_lines.push_back(
        "check: " + f.check_path +
        ": not enough information in the bag to check it (see 'verdict:'): " + f.gate_why);
    o->exit_code = kExitNotEnoughInformation;
    return;
  }
  o->out_lines.push_back("check: " + f.check_path +
                         ": the new estimate FAILED its quality gates (see 'verdict:'), so it "
                         "cannot vouch for the current calibration");
  o->exit_code = kExitQualityGate;
}

/// The median of `v` (0 when empty).
double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

std::vector<std::pair<std::string, std::string>> RecordingOutputPaths::given() const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [option, path] : {std::pair<std::string, std::string>{"--output", output},
                                     {"--imu-yaml", imu_yaml},
                                     {"--report", report},
                                     {"--export-poses", export_poses}}) {
    if (!path.empty()) out.emplace_back(option, path);
  }
  return out;
}

std::vector<std::string> checkOutputPaths(const RecordingOutputPaths& paths,
                                          const std::vector<std::string>& inputs) {
  std::vector<std::string> problems;
  const auto given = paths.given();
  for (std::size_t i = 0; i < given.size(); ++i) {
    const auto& [option, path] = given[i];
    const std::string why = whyNotWritable(path);
    if (!why.empty()) problems.push_back(option + " " + why);
    for (std::size_t k = 0; k < i; ++k) {
      if (sameFile(given[k].second, path)) {
        problems.push_back(option + " " + path + ": the same file as " + given[k].first +
                           "; give each output its own file");
      }
    }
    for (const std::string& input : inputs) {
      if (!input.empty() && sameFile(input, path)) {
        problems.push_back(option + " " + path + ": is an input of the run (" + input +
                           "), it would be overwritten");
      }
    }
  }
  return problems;
}

RecordingOutcome decideRecordingOutcome(const RecordingFacts& f) {
  RecordingOutcome o;
  if (refuseWithoutCamera(f, &o)) return o;
  if (!f.camera_model_problem.empty()) {  // camera_info, not the recording: every pose is biased
    o.err_lines.push_back(
        (f.camera_info_topic.empty() ? std::string("camera info") : f.camera_info_topic) + ": " +
        f.camera_model_problem);
    o.exit_code = kExitBadInput;
    return o;
  }
  if (f.status != SolveStatus::kOk) {
    refuseUnsolved(f, &o);
    if (f.force) o.err_lines.push_back("--force: nothing written: there is no estimate to write");
    return o;
  }
  const bool passed = f.verdict && f.verdict->passed;
  // Too little data in the window (and no remount cut it): not enough information, not a failed
  // gate.
  const bool too_little = !passed && !f.enough_data && !f.remounted;
  if (!f.check_path.empty()) {
    decideCheck(f, passed, too_little, &o);
    return o;
  }
  o.result_verdict.passed = passed;
  o.result_verdict.text = f.verdict ? f.verdict->text : std::string();
  if (passed) {
    o.write_result = true;
    o.exit_code = kExitOk;
    return o;
  }
  const std::string options = resultOptions(f.outputs);
  const bool forced = f.force && !options.empty();
  o.write_result = forced;
  o.result_verdict.forced = forced;
  const std::string written = forced ? "; written to " + options + " marked FAILED (--force)" : "";
  if (too_little) {
    o.err_lines.push_back("not enough information (see 'verdict:'): " + f.gate_why +
                          (forced ? written : "; nothing written"));
    o.exit_code = kExitNotEnoughInformation;
    return o;
  }
  o.err_lines.push_back("the estimate fails the quality gates (see 'verdict:'); " +
                        (forced ? written.substr(2) : "not written to --output / --imu-yaml"));
  o.exit_code = kExitQualityGate;
  return o;
}

std::string imuYamlText(const std::string& path, const ReportInput& report,
                        const std::string& imu_topic, double imu_rate_hz) {
  if (!report.result.joint || !report.result.joint->ok) {
    throw InputError(path + ": no joint estimate (--imu-orientation joint) to write");
  }
  std::vector<double> gyro, accel, rate;
  for (const StationarySegment& s : report.segments) {
    if (s.num_samples < 10 || s.duration() <= 0.0) continue;
    const double dt = s.duration() / (s.num_samples - 1);
    gyro.push_back(s.gyro_std_rad_s / std::sqrt(3.0) * std::sqrt(dt));
    accel.push_back(s.accel_norm_std_m_s2 * std::sqrt(dt));
    rate.push_back(1.0 / dt);
  }
  return kalibrImuYaml(*report.result.joint, median(gyro), median(accel),
                       rate.empty() ? imu_rate_hz : median(rate), imu_topic);
}

std::vector<std::string> writeRecordingOutputs(const RecordingOutputPaths& paths,
                                               const RecordingOutcome& outcome,
                                               const RecordingProducts& products) {
  std::vector<std::string> errors;
  const auto attempt = [&](const std::string& option, const auto& write) {
    try {
      write();
    } catch (const InputError& e) {
      errors.push_back(option + " " + e.what());
    }
  };
  if (outcome.summary && !paths.report.empty() && products.report) {
    std::string error;
    if (!writeReportPng(paths.report, *products.report, &error)) {
      errors.push_back("--report " + paths.report + ": " + error);
    }
  }
  if (outcome.summary && !paths.export_poses.empty()) {
    attempt("--export-poses", [&] { writePosesCsv(paths.export_poses, products.window_poses); });
  }
  if (!outcome.write_result || !products.report) return errors;
  if (!paths.output.empty()) {
    attempt("--output", [&] {
      ResultMetadata meta = products.meta;
      meta.verdict = outcome.result_verdict;
      writeResultYaml(paths.output, products.report->result, meta);
    });
  }
  if (!paths.imu_yaml.empty()) {
    attempt("--imu-yaml", [&] {
      // Kalibr's format has no verdict key: a forced estimate says so in a comment at the top.
      const ResultVerdict& v = outcome.result_verdict;
      const std::string mark = v.passed ? ""
                                        : "# camera_imu_alignment: this estimate " + v.text +
                                              " (written with --force)\n";
      writeFileAtomically(paths.imu_yaml,
                          mark + imuYamlText(paths.imu_yaml, *products.report, products.imu_topic,
                                             products.imu_rate_hz));
    });
  }
  return errors;
}

}  // namespace camera_imu_alignment
