// calibrate_bag: R_cam_imu from a rosbag of a camera + IMU (+ magnetometer) rig, offline, without a
// roscore. Reads the bag with the rosbag C++ API (bag_reader.h, bag_topics.h) into the core's
// OnlineCalibrator (the class the nodelet drives); what the run's facts mean (exit code, closing
// messages, which files are written) is decided in the ROS-free core
// (offline/recording_outcome.h), which also checks every output before the bag is read and writes
// each atomically. Exit codes (io/exit_codes.h, doc/CONVENTIONS.md): 0 success; 2 bad input or
// usage (an output that cannot be written, an unreadable or truncated bag, a missing topic, no
// camera data, a bad target file, camera_info intrinsics that do not fit the images); 3 not enough
// information (too few poses, not observable: the message names the axis to rotate about); 4 the
// estimate fails the quality gates or the mount moved during the recording (--check: the current
// calibration is not consistent with the bag, or the bag's estimate failed its gates).
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bag_reader.h"
#include "bag_topics.h"
#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/config/online_config.h"
#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/io/calibration_summary.h"
#include "camera_imu_alignment/io/default_frames.h"
#include "camera_imu_alignment/io/exit_codes.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/offline/recording_outcome.h"
#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/ros/wrapper_settings.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/scene_rotation.h"
#include "camera_imu_alignment/vision/target_description.h"
#include "cli_args.h"

namespace cia = camera_imu_alignment;

namespace {

using cia::kExitBadInput;
using cia::kExitOk;

const char* kUsage =
    "usage: calibrate_bag --bag FILE.bag [--target TARGET.yaml] [--config PARAMS.yaml]\n"
    "                     [--imu-topic T] [--mag-topic T] [--image-topic T]\n"
    "                     [--camera-info-topic T] [--camera-pose-topic T]\n"
    "                     [--method optimal|two_step]\n"
    "                     [--imu-orientation joint|auto|magnetometer|message]\n"
    "                     [--scene-profile full|fast]\n"
    "                     [--output RESULT.yaml] [--imu-yaml IMU.yaml] [--report REPORT.png]\n"
    "                     [--truth TRUTH.yaml] [--export-poses POSES.csv]\n"
    "                     [--check CURRENT.yaml] [--start S] [--end S]\n"
    "                     [--accept-last-mount] [--force] [--quiet]\n"
    "  --bag FILE.bag        ROS 1 bag: sensor_msgs/Imu, optional MagneticField, Image or\n"
    "                        CompressedImage and CameraInfo (topics found by type when not "
    "given),\n"
    "                        or geometry_msgs/PoseStamped camera poses instead of the images\n"
    "  --target TARGET.yaml  Kalibr target file (checkerboard, aprilgrid, circlegrid). Without\n"
    "                        it the camera's rotation between rests comes from the natural\n"
    "                        scene (features matched between the rests' views)\n"
    "  --camera-pose-topic T camera poses (geometry_msgs/PoseStamped, the camera in the target\n"
    "                        frame) as the camera source, images not read. Default: a topic\n"
    "                        named camera_pose when the bag has no image topic\n"
    "  --config PARAMS.yaml  settings, keys as in config/default.yaml\n"
    "  --method M            optimal (default) or two_step (the paper's iteration alone)\n"
    "  --imu-orientation S   joint (default: one estimate from every sensor with the IMU's errors\n"
    "                        calibrated), magnetometer (the paper's sensors: the same without\n"
    "                        the gyro, the iron calibrated), or pairs of poses with the IMU\n"
    "                        orientation from: auto (gyro between poses) or message (the Imu\n"
    "                        message's own)\n"
    "  --scene-profile P     without --target: full (default; SIFT on the full image) or fast\n"
    "                        (the image halved, each match refined at the full resolution:\n"
    "                        cheaper per rest; for a scene that holds still: less accurate\n"
    "                        with objects moving in view). As setting scene_profile\n"
    "  --output RESULT.yaml  write the result YAML there (see doc/CONVENTIONS.md in the package)\n"
    "                        Every output (--output, --imu-yaml, --report, --export-poses) is\n"
    "                        checked before the bag is read and written atomically\n"
    "  --imu-yaml IMU.yaml   with the joint estimate: a Kalibr imu.yaml (noise densities as the\n"
    "                        recording measured them) with the calibrated IMU intrinsics added\n"
    "  --report REPORT.png   write a one-page report: residuals per pair and per pose, axis\n"
    "                        coverage, rests, reprojection per pose, estimate (and its error to\n"
    "                        --truth)\n"
    "  --truth TRUTH.yaml    a YAML with R_cam_imu (e.g. simulate_bag's) to print (and draw) the\n"
    "                        error to\n"
    "  --export-poses POSES.csv  write the stationary poses the estimate used (the window) as the\n"
    "                        poses CSV that solve_rotation --poses reads (doc/CONVENTIONS.md)\n"
    "  --check CURRENT.yaml  is the current calibration (a result YAML) still right? Its\n"
    "                        difference to the bag's joint estimate in degrees and sigmas and the\n"
    "                        chi-square test at consistency_level: exit 0 when consistent, 4 when\n"
    "                        not or when the bag's estimate fails its quality gates (then it\n"
    "                        cannot vouch for it); nothing is written to --output / --imu-yaml\n"
    "  --start S, --end S    read only the part of the bag between them (seconds from its\n"
    "                        first message; as rosbag play --start / --duration)\n"
    "  --accept-last-mount   when the mount moved during the recording, write the estimate of the\n"
    "                        mount after the last change (named in the verdict) instead of\n"
    "                        exiting 4\n"
    "  --force               write an estimate that fails the quality gates to --output /\n"
    "                        --imu-yaml all the same, marked FAILED (the result YAML's verdict:\n"
    "                        block says why); the exit code stays 4 (3: too little data)\n"
    "  --quiet               no progress on stderr\n"
    "exit codes: 0 success, 2 bad input or usage (also: camera_info's intrinsics do not fit the\n"
    "images), 3 not enough information (the message says what\n"
    "motion is missing), 4 an estimate that fails the quality gates or a mount that moved during\n"
    "the recording (the verdict line says which; nothing is written unless --force)\n";

/// The run's settings and files, read and checked before the bag is opened.
struct RunInputs {
  cia::TargetDescription target;
  cia::PipelineSettings settings;
  cia::OnlineSettings online;  // the nodelet's quality gates and change detection
  std::optional<cia::StoredCalibration> current;  // --check
  std::optional<cia::StoredCalibration> truth;    // --truth
  cia::RecordingOutputPaths outputs;
};

/// Parses the value of `option` with `parse`; false after saying it must be one of `choices`.
template <typename T, typename Parse>
bool parseChoice(const cia::CliArgs& args, const char* option, const char* choices, T* value,
                 Parse parse) {
  if (!args.has(option) || parse(args.get(option), value)) return true;
  std::cerr << "calibrate_bag: " << option << " " << args.get(option) << ": must be " << choices
            << "\n";
  return false;
}

/// A result (or truth) YAML into `stored`; false after saying why. A file written under a FAILED
/// verdict is said to be one.
bool readStored(const cia::CliArgs& args, const char* option, const std::string& prefix,
                std::optional<cia::StoredCalibration>* stored) {
  if (!args.has(option)) return true;
  try {
    *stored = cia::readResultYaml(args.get(option));
  } catch (const cia::InputError& e) {
    std::cerr << "calibrate_bag: " << prefix << e.what() << "\n";
    return false;
  }
  const std::string failed = cia::failedVerdictNote(**stored, args.get(option));
  if (!failed.empty()) std::cerr << "[calibrate_bag] note: " << option << " " << failed << "\n";
  return true;
}

/// Target, settings, options, --check and --truth; every output checked (all of them said, not
/// only the first). False after saying what is wrong.
bool readInputs(const cia::CliArgs& args, RunInputs* in) {
  try {
    if (args.has("--target")) in->target = cia::loadTargetYaml(args.get("--target"));
    if (args.has("--config")) {
      cia::loadCalibrationConfig(args.get("--config"), &in->settings, &in->online,
                                 cia::wrapperKeys());
    }
  } catch (const cia::InputError& e) {
    std::cerr << "calibrate_bag: " << e.what() << "\n";
    return false;
  }
  cia::SceneProfile profile =
      cia::sceneProfileOf(in->settings.scene_features, in->settings.scene_rotation);
  if (!parseChoice(args, "--method", "optimal or two_step", &in->settings.solver.method,
                   cia::parseSolverMethod) ||
      !parseChoice(args, "--imu-orientation", "joint, auto, magnetometer or message",
                   &in->settings.imu_orientation, cia::parseImuOrientationSource) ||
      !parseChoice(args, "--scene-profile", "full or fast", &profile, cia::parseSceneProfile)) {
    return false;
  }
  if (args.has("--scene-profile")) {
    cia::useSceneProfile(profile, &in->settings.scene_features, &in->settings.scene_rotation);
  }
  if (args.has("--force") && args.has("--check")) {
    std::cerr << "calibrate_bag: --force with --check: a check writes no result; give one\n";
    return false;
  }
  if (!readStored(args, "--check", "--check ", &in->current) ||
      !readStored(args, "--truth", "", &in->truth)) {
    return false;
  }
  in->outputs = {args.get("--output"), args.get("--imu-yaml"), args.get("--report"),
                 args.get("--export-poses")};
  const std::vector<std::string> problems = cia::checkOutputPaths(in->outputs, {args.get("--bag")});
  for (const std::string& p : problems) std::cerr << "calibrate_bag: " << p << "\n";
  if (!problems.empty()) {
    std::cerr << "calibrate_bag: nothing read: the outputs above cannot be written\n";
  }
  return problems.empty();
}

/// Opens the bag, selects its topics and applies --start / --end; false after saying why (a bag
/// cut short: how to repair it).
bool openBag(const cia::CliArgs& args, rosbag::Bag* bag, cia::BagTopics* topics,
             cia::BagRunInfo* info) {
  const std::string bag_path = args.get("--bag");
  try {
    bag->open(bag_path, rosbag::bagmode::Read);
    cia::BagTopics requested{args.get("--imu-topic"),         args.get("--mag-topic"),
                             args.get("--image-topic"),       false,
                             args.get("--camera-info-topic"), args.get("--camera-pose-topic")};
    *topics = cia::selectBagTopics(*bag, requested);
    rosbag::View all(*bag);
    info->start_s = all.getBeginTime().toSec();
    info->end_s = all.getEndTime().toSec();
  } catch (const std::exception& e) {
    std::cerr << "calibrate_bag: " << cia::bagErrorMessage(bag_path, e) << "\n";
    return false;
  }
  return cia::readBagWindow(args, info);
}

/// The sources line: which topics (and target or scene profile) the run reads.
void printSources(const cia::CliArgs& args, const RunInputs& in, const cia::BagTopics& topics) {
  if (!topics.camera_source_note.empty()) {
    std::cerr << "[calibrate_bag] " << topics.camera_source_note << "\n";
  }
  std::cerr << "[calibrate_bag] " << args.get("--bag") << ": IMU " << topics.imu
            << ", magnetometer " << (topics.mag.empty() ? "(none)" : topics.mag);
  if (!topics.camera_pose.empty()) {
    std::cerr << ", camera poses " << topics.camera_pose << " (no target or camera info needed)\n";
    return;
  }
  std::cerr << ", images " << (topics.image.empty() ? "(none)" : topics.image) << ", camera info "
            << (topics.camera_info.empty() ? "(none)" : topics.camera_info)
            << (args.has("--target")
                    ? "; target " + in.target.describe()
                    : std::string("; no --target: the natural scene's features (scene_profile ") +
                          cia::toString(cia::sceneProfileOf(in.settings.scene_features,
                                                            in.settings.scene_rotation)) +
                          ")")
            << "\n";
}

/// The bag through the nodelet's calibrator, then its final solve.
struct RecordingRun {
  std::unique_ptr<cia::OnlineCalibrator> calibrator;
  cia::CalibrateOutcome outcome;
  cia::CalibrationSnapshot snap;
};

/// Reads the bag into a calibrator and solves the whole recording; false after saying why.
bool runRecording(const cia::CliArgs& args, RunInputs* in, const rosbag::Bag& bag,
                  const cia::BagTopics& topics, cia::BagRunInfo* info, RecordingRun* run) {
  const bool quiet = args.has("--quiet");
  cia::BagRejectLog reject_log(topics);
  cia::OnlineCallbacks callbacks;
  callbacks.on_reject = [&](cia::RejectReason r, cia::InputStream stream, const std::string& d) {
    reject_log(r, stream, d);
  };
  cia::solveAsRecording(&in->settings, &in->online);  // faster than real time, the same verdicts
  try {
    run->calibrator =
        std::make_unique<cia::OnlineCalibrator>(in->target, in->settings, in->online, callbacks);
  } catch (const std::invalid_argument& e) {
    std::cerr << "calibrate_bag: " << e.what() << "\n";
    return false;
  }
  cia::BagProgress progress(!quiet, info->start_s, info->end_s);
  try {
    readBag(bag, topics, run->calibrator.get(), &progress, info);
  } catch (const std::exception& e) {
    progress.done();
    std::cerr << "calibrate_bag: " << cia::bagErrorMessage(args.get("--bag"), e) << "\n";
    return false;
  }
  if (!quiet) std::cerr << "[calibrate_bag] final solve over the whole recording ..." << std::endl;
  const auto solve_start = std::chrono::steady_clock::now();
  run->outcome = run->calibrator->calibrateNow(false);
  if (!quiet) {
    std::ostringstream took;  // std::cerr's own format stays as it is
    took << std::fixed << std::setprecision(1)
         << std::chrono::duration<double>(std::chrono::steady_clock::now() - solve_start).count();
    std::cerr << "[calibrate_bag] final solve done in " << took.str() << " s" << std::endl;
  }
  run->snap = run->calibrator->snapshot(cia::SnapshotContents::kWithHistory);
  const cia::CalibrationSnapshot& snap = run->snap;
  const bool camera_poses = !topics.camera_pose.empty();
  std::cerr << "[calibrate_bag] read " << snap.inputs.imu_samples << " IMU, "
            << snap.inputs.magnetic_samples << " magnetometer samples, "
            << (camera_poses ? info->camera_pose_messages : info->image_messages)
            << (camera_poses ? " camera poses; " : " images; ") << snap.rests.size()
            << " stationary rests, " << snap.poses.size() << " poses, " << snap.inputs.motion_frames
            << " camera orientations during motion\n";
  return true;
}

/// The summary's and the report's input.
cia::ReportInput reportOf(const cia::CliArgs& args, const RunInputs& in, const RecordingRun& run,
                          const cia::BagRunInfo& info) {
  const cia::CalibrationSnapshot& snap = run.snap;
  cia::ReportInput report;
  report.result = run.outcome.result;
  report.poses = snap.poses;
  report.rejected = snap.rejected_poses;
  report.segments = snap.rests;
  report.rejections = snap.rejections;
  report.start_s = info.start_s;
  report.end_s = info.end_s;
  report.camera_frame = cia::frameOr(info.camera_frame, cia::kDefaultCameraFrame);
  report.imu_frame = cia::frameOr(info.imu_frame, cia::kDefaultImuFrame);
  report.source = args.get("--bag");
  report.pairs = cia::makeAllPairs(snap.windowOrientations());
  report.window_poses = snap.window.size();
  if (in.truth) report.truth = cia::KnownTruth{in.truth->R_cam_imu, args.get("--truth")};
  return report;
}

/// What the run saw, for decideRecordingOutcome.
cia::RecordingFacts factsOf(const cia::CliArgs& args, const RunInputs& in, const RecordingRun& run,
                            const cia::BagTopics& topics, const cia::BagRunInfo& info,
                            const std::optional<cia::CalibrationVerdict>& verdict) {
  const cia::CalibrationSnapshot& snap = run.snap;
  const cia::AlignmentResult& result = run.outcome.result;
  cia::RecordingFacts f;
  f.bag_path = args.get("--bag");
  f.camera_poses = !topics.camera_pose.empty();
  f.camera_pose_topic = topics.camera_pose;
  f.camera_pose_messages = info.camera_pose_messages;
  f.image_topic = topics.image;
  f.image_messages = info.image_messages;
  f.camera_info_topic = topics.camera_info;
  f.has_intrinsics = snap.inputs.has_intrinsics;
  f.windowed = info.windowed;
  f.status = result.status;
  f.message = result.message;
  f.has_rests = !snap.rests.empty();
  f.motion_frames = snap.inputs.motion_frames;
  f.target_path = args.get("--target");
  f.target_diagnosis = snap.target_diagnosis;
  if (snap.camera_model.wrong) f.camera_model_problem = snap.camera_model.message;
  f.verdict = verdict;
  if (snap.latest) {
    f.enough_data = snap.latest->gate.enough_data;
    f.gate_why = snap.latest->gate.why;
  }
  f.remounted = !snap.remount_events.empty();
  if (in.current) {
    f.check_path = args.get("--check");
    f.check = cia::checkCalibration(result, cia::storedBroadcast(*in.current, f.check_path),
                                    in.online.consistency_level);
    f.joint_message = result.joint ? result.joint->message : "none was run";
  }
  f.force = args.has("--force");
  f.outputs = in.outputs;
  return f;
}

/// The summary on stdout: the core's text, the error to --truth, the remounts, camera_info.
void printSummary(const cia::CliArgs& args, const cia::ReportInput& report,
                  const cia::CalibrationSnapshot& snap) {
  std::cout << cia::formatSummary(report);
  if (report.truth && cia::hasEstimate(report.result)) {
    std::cout << std::fixed << std::setprecision(4) << "error to " << args.get("--truth") << ": "
              << cia::rad2deg(
                     cia::geodesicDistance(report.result.R_cam_imu, report.truth->R_cam_imu))
              << " deg\n";
  }
  for (const cia::RemountEvent& e : snap.remount_events) {
    std::cout << "remount: " << e.message << "\n";
  }
  if (snap.camera_model.wrong) std::cout << "camera_info: " << snap.camera_model.message << "\n";
}

/// The whole job; returns the exit code (decided by decideRecordingOutcome).
int run(const cia::CliArgs& args) {
  RunInputs in;
  if (!readInputs(args, &in)) return kExitBadInput;
  rosbag::Bag bag;
  cia::BagTopics topics;
  cia::BagRunInfo info;
  if (!openBag(args, &bag, &topics, &info)) return kExitBadInput;
  printSources(args, in, topics);
  RecordingRun recording;
  if (!runRecording(args, &in, bag, topics, &info, &recording)) return kExitBadInput;

  const cia::CalibrateOutcome& solved = recording.outcome;
  cia::ReportInput report = reportOf(args, in, recording, info);
  // The nodelet's verdict (decided in the core): a remount during the recording, a failed gate.
  const std::optional<cia::CalibrationVerdict> verdict =
      args.has("--accept-last-mount")
          ? cia::recordingVerdict({solved.result, solved.gate, solved.window_poses},
                                  recording.snap.remount_events, true)
          : solved.verdict;
  if (verdict) report.verdict = cia::ReportVerdict{verdict->passed, verdict->text};
  const cia::RecordingOutcome outcome =
      cia::decideRecordingOutcome(factsOf(args, in, recording, topics, info, verdict));
  if (outcome.summary) printSummary(args, report, recording.snap);

  cia::RecordingProducts products;
  products.report = &report;
  products.window_poses = recording.snap.windowOrientations();
  products.meta = {report.camera_frame, report.imu_frame, static_cast<int>(solved.window_poses)};
  products.imu_topic = topics.imu;
  products.imu_rate_hz =
      info.end_s > info.start_s
          ? static_cast<double>(recording.snap.inputs.imu_samples) / (info.end_s - info.start_s)
          : 0.0;
  const std::vector<std::string> write_errors =
      cia::writeRecordingOutputs(in.outputs, outcome, products);
  for (const std::string& line : outcome.out_lines) std::cout << line << "\n";
  for (const std::string& line : outcome.err_lines) std::cerr << "calibrate_bag: " << line << "\n";
  for (const std::string& line : write_errors) std::cerr << "calibrate_bag: " << line << "\n";
  return write_errors.empty() ? outcome.exit_code : kExitBadInput;
}

}  // namespace

int main(int argc, char** argv) {
  cia::CliArgs args = [&] {
    try {
      return cia::CliArgs(
          argc, argv,
          {"--bag", "--target", "--config", "--imu-topic", "--mag-topic", "--image-topic",
           "--camera-info-topic", "--camera-pose-topic", "--method", "--imu-orientation",
           "--scene-profile", "--output", "--imu-yaml", "--report", "--truth", "--export-poses",
           "--check", "--start", "--end"},
          {"--help", "--quiet", "--accept-last-mount", "--force"});
    } catch (const cia::UsageError& e) {
      std::cerr << "calibrate_bag: " << e.what() << "\n" << kUsage;
      std::exit(kExitBadInput);
    }
  }();
  if (args.has("--help")) {
    std::cout << kUsage;
    return kExitOk;
  }
  if (!args.has("--bag")) {
    std::cerr << "calibrate_bag: --bag is required\n" << kUsage;
    return kExitBadInput;
  }
  return run(args);
}
