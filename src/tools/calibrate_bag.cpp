// calibrate_bag: R_cam_imu from a rosbag of a camera + IMU (+ magnetometer) rig, offline, without a
// roscore. Reads the bag with the rosbag C++ API and drives the core CalibrationPipeline (the same
// class the nodelet drives). Exit codes (doc/CONVENTIONS.md): 0 success; 2 bad input or usage
// (unreadable or truncated bag, missing topic, no camera data, bad target file, camera_info
// intrinsics that do not fit the images); 3 not enough
// information (too few poses, not observable: the message names the axis to rotate about); 4 the
// estimate fails the quality gates or the mount moved during the recording. The bag is read by
// bag_reader.h.
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bag_reader.h"
#include "bag_topics.h"
#include "camera_imu_alignment/config/online_config.h"
#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/io/calibration_report.h"
#include "camera_imu_alignment/io/csv_io.h"
#include "camera_imu_alignment/io/default_frames.h"
#include "camera_imu_alignment/io/input_error.h"
#include "camera_imu_alignment/io/joint_yaml.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/ros/message_input.h"
#include "camera_imu_alignment/ros/wrapper_settings.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/scene_rotation.h"
#include "camera_imu_alignment/vision/target_description.h"
#include "cli_args.h"

namespace cia = camera_imu_alignment;

namespace {

using cia::kExitBadInput;
using cia::kExitNotEnoughInformation;
using cia::kExitOk;
using cia::kExitQualityGate;

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
    "                     [--accept-last-mount] [--quiet]\n"
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
    "                        not (nothing is written to --output / --imu-yaml)\n"
    "  --start S, --end S    read only the part of the bag between them (seconds from its\n"
    "                        first message; as rosbag play --start / --duration)\n"
    "  --accept-last-mount   when the mount moved during the recording, write the estimate of the\n"
    "                        mount after the last change (named in the verdict) instead of\n"
    "                        exiting 4\n"
    "  --quiet               no progress on stderr\n"
    "exit codes: 0 success, 2 bad input or usage (also: camera_info's intrinsics do not fit the\n"
    "images), 3 not enough information (the message says what\n"
    "motion is missing), 4 an estimate that fails the quality gates or a mount that moved during\n"
    "the recording (the verdict line says which; nothing is written)\n";

const char* kNoCameraData =
    "no camera data (no sensor_msgs/Image or CompressedImage messages, no "
    "geometry_msgs/PoseStamped "
    "on camera_pose or --camera-pose-topic); the IMU alone cannot give R_cam_imu";

/// --imu-yaml: the Kalibr imu.yaml of the joint estimate. White noise densities from the rests:
/// the median over the rests of the per-sample scatter times sqrt(sample period).
/// `imu_rate_hz` (the recording's mean rate) stands in for the rests' when there are none.
bool writeImuYaml(const std::string& path, const cia::ReportInput& report,
                  const std::string& imu_topic, double imu_rate_hz) {
  if (!report.result.joint || !report.result.joint->ok) {
    std::cerr << "calibrate_bag: --imu-yaml " << path
              << ": no joint estimate (--imu-orientation joint) to write\n";
    return false;
  }
  std::vector<double> gyro, accel, rate;
  for (const cia::StationarySegment& s : report.segments) {
    if (s.num_samples < 10 || s.duration() <= 0.0) continue;
    const double dt = s.duration() / (s.num_samples - 1);
    gyro.push_back(s.gyro_std_rad_s / std::sqrt(3.0) * std::sqrt(dt));
    accel.push_back(s.accel_norm_std_m_s2 * std::sqrt(dt));
    rate.push_back(1.0 / dt);
  }
  const auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  std::ofstream out(path);
  out << cia::kalibrImuYaml(*report.result.joint, median(gyro), median(accel),
                            rate.empty() ? imu_rate_hz : median(rate), imu_topic);
  if (!out) {
    std::cerr << "calibrate_bag: --imu-yaml " << path << ": cannot write the file\n";
    return false;
  }
  return true;
}

/// The whole job; returns the exit code.
int run(const cia::CliArgs& args) {
  // --- Inputs: target, settings, bag, topics. Each failure names its file, option or topic.
  cia::TargetDescription target;
  cia::PipelineSettings settings;
  cia::OnlineSettings online;  // the nodelet's quality gates and change detection
  try {
    if (args.has("--target")) target = cia::loadTargetYaml(args.get("--target"));
    if (args.has("--config")) {
      cia::loadCalibrationConfig(args.get("--config"), &settings, &online, cia::wrapperKeys());
    }
  } catch (const cia::InputError& e) {
    std::cerr << "calibrate_bag: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (args.has("--method") &&
      !cia::parseSolverMethod(args.get("--method"), &settings.solver.method)) {
    std::cerr << "calibrate_bag: --method " << args.get("--method")
              << ": must be optimal or two_step\n";
    return kExitBadInput;
  }
  if (args.has("--imu-orientation") &&
      !cia::parseImuOrientationSource(args.get("--imu-orientation"), &settings.imu_orientation)) {
    std::cerr << "calibrate_bag: --imu-orientation " << args.get("--imu-orientation")
              << ": must be joint, auto, magnetometer or message\n";
    return kExitBadInput;
  }
  if (args.has("--scene-profile")) {
    cia::SceneProfile profile = cia::SceneProfile::kFull;
    if (!cia::parseSceneProfile(args.get("--scene-profile"), &profile)) {
      std::cerr << "calibrate_bag: --scene-profile " << args.get("--scene-profile")
                << ": must be full or fast\n";
      return kExitBadInput;
    }
    cia::useSceneProfile(profile, &settings.scene_features, &settings.scene_rotation);
  }
  std::optional<cia::StoredCalibration> current;
  if (args.has("--check")) {
    try {
      current = cia::readResultYaml(args.get("--check"));
    } catch (const cia::InputError& e) {
      std::cerr << "calibrate_bag: --check " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  std::optional<cia::StoredCalibration> truth;
  if (args.has("--truth")) {
    try {
      truth = cia::readResultYaml(args.get("--truth"));
    } catch (const cia::InputError& e) {
      std::cerr << "calibrate_bag: " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  const std::string bag_path = args.get("--bag");
  rosbag::Bag bag;
  cia::BagTopics topics;
  cia::BagRunInfo info;
  try {
    bag.open(bag_path, rosbag::bagmode::Read);
    cia::BagTopics requested{args.get("--imu-topic"),         args.get("--mag-topic"),
                             args.get("--image-topic"),       false,
                             args.get("--camera-info-topic"), args.get("--camera-pose-topic")};
    topics = cia::selectBagTopics(bag, requested);
    rosbag::View all(bag);
    info.start_s = all.getBeginTime().toSec();
    info.end_s = all.getEndTime().toSec();
    if (!cia::readBagWindow(args, &info)) return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "calibrate_bag: " << bag_path << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  const bool camera_poses = !topics.camera_pose.empty();
  if (!topics.camera_source_note.empty()) {
    std::cerr << "[calibrate_bag] " << topics.camera_source_note << "\n";
  }
  std::cerr << "[calibrate_bag] " << bag_path << ": IMU " << topics.imu << ", magnetometer "
            << (topics.mag.empty() ? "(none)" : topics.mag);
  if (camera_poses) {
    std::cerr << ", camera poses " << topics.camera_pose << " (no target or camera info needed)\n";
  } else {
    std::cerr << ", images " << (topics.image.empty() ? "(none)" : topics.image) << ", camera info "
              << (topics.camera_info.empty() ? "(none)" : topics.camera_info)
              << (args.has("--target")
                      ? "; target " + target.describe()
                      : std::string("; no --target: the natural scene's "
                                    "features (scene_profile ") +
                            cia::toString(cia::sceneProfileOf(settings.scene_features,
                                                              settings.scene_rotation)) +
                            ")")
              << "\n";
  }

  // --- Run the pipeline over the bag.
  // The nodelet's calibrator (poses, solves, change detection, gates), solving as poses arrive.
  cia::BagRejectLog reject_log(topics);
  cia::OnlineCallbacks callbacks;
  callbacks.on_reject = [&](cia::RejectReason r, cia::InputStream stream, const std::string& d) {
    reject_log(r, stream, d);
  };
  cia::solveAsRecording(&settings, &online);  // faster than real time, the same verdicts
  std::unique_ptr<cia::OnlineCalibrator> calibrator;
  try {
    calibrator = std::make_unique<cia::OnlineCalibrator>(target, settings, online, callbacks);
  } catch (const std::invalid_argument& e) {
    std::cerr << "calibrate_bag: " << e.what() << "\n";
    return kExitBadInput;
  }
  cia::BagProgress progress(!args.has("--quiet"), info.start_s, info.end_s);
  try {
    readBag(bag, topics, calibrator.get(), &progress, &info);
  } catch (const std::exception& e) {
    progress.done();
    std::cerr << "calibrate_bag: " << bag_path << ": cannot read the bag to the end (" << e.what()
              << "); truncated or corrupt? 'rosbag reindex' may repair it\n";
    return kExitBadInput;
  }

  // --- Verdict.
  if (!args.has("--quiet")) {
    std::cerr << "[calibrate_bag] final solve over the whole recording ..." << std::endl;
  }
  const auto solve_start = std::chrono::steady_clock::now();
  const cia::CalibrateOutcome outcome = calibrator->calibrateNow(false);
  if (!args.has("--quiet")) {
    std::ostringstream took;  // std::cerr's own format stays as it is
    took << std::fixed << std::setprecision(1)
         << std::chrono::duration<double>(std::chrono::steady_clock::now() - solve_start).count();
    std::cerr << "[calibrate_bag] final solve done in " << took.str() << " s" << std::endl;
  }
  const cia::CalibrationSnapshot snap = calibrator->snapshot(cia::SnapshotContents::kWithHistory);
  std::cerr << "[calibrate_bag] read " << snap.inputs.imu_samples << " IMU, "
            << snap.inputs.magnetic_samples << " magnetometer samples, "
            << (camera_poses ? info.camera_pose_messages : info.image_messages)
            << (camera_poses ? " camera poses; " : " images; ") << snap.rests.size()
            << " stationary rests, " << snap.poses.size() << " poses, " << snap.inputs.motion_frames
            << " camera orientations during motion\n";
  if (camera_poses && info.camera_pose_messages == 0) {
    std::cerr << "calibrate_bag: " << bag_path << ": no messages on " << topics.camera_pose
              << " (geometry_msgs/PoseStamped)"
              << (info.windowed ? " between --start and --end" : "")
              << "; the IMU alone cannot give R_cam_imu\n";
    return kExitBadInput;
  }
  if (!camera_poses && (topics.image.empty() || info.image_messages == 0)) {
    std::cerr << "calibrate_bag: " << bag_path << ": " << kNoCameraData << "\n";
    return kExitBadInput;
  }
  if (!camera_poses && !snap.inputs.has_intrinsics) {
    std::cerr << "calibrate_bag: " << bag_path << ": no usable camera info ("
              << (topics.camera_info.empty() ? "no sensor_msgs/CameraInfo topic"
                                             : topics.camera_info)
              << "); PnP needs the intrinsics\n";
    return kExitBadInput;
  }
  cia::ReportInput report;
  report.result = outcome.result;
  report.poses = snap.poses;
  report.rejected = snap.rejected_poses;
  report.segments = snap.rests;
  report.rejections = snap.rejections;
  report.start_s = info.start_s;
  report.end_s = info.end_s;
  report.camera_frame = cia::frameOr(info.camera_frame, cia::kDefaultCameraFrame);
  report.imu_frame = cia::frameOr(info.imu_frame, cia::kDefaultImuFrame);
  report.source = bag_path;
  report.pairs = cia::makeAllPairs(snap.windowOrientations());
  report.window_poses = snap.window.size();
  if (truth) report.truth = cia::KnownTruth{truth->R_cam_imu, args.get("--truth")};
  // The nodelet's verdict (decided in the core): a remount during the recording, a failed gate.
  const std::optional<cia::CalibrationVerdict> verdict =
      args.has("--accept-last-mount")
          ? cia::recordingVerdict({outcome.result, outcome.gate, outcome.window_poses},
                                  snap.remount_events, true)
          : outcome.verdict;
  const bool gates_passed = verdict && verdict->passed;
  if (verdict) report.verdict = cia::ReportVerdict{gates_passed, verdict->text};
  std::cout << cia::formatSummary(report);
  if (truth && report.result.status != cia::SolveStatus::kBadInput) {  // else: no estimate
    std::cout << std::fixed << std::setprecision(4) << "error to " << args.get("--truth") << ": "
              << cia::rad2deg(cia::geodesicDistance(report.result.R_cam_imu, truth->R_cam_imu))
              << " deg\n";
  }
  for (const cia::RemountEvent& e : snap.remount_events) {
    std::cout << "remount: " << e.message << "\n";
  }
  if (snap.camera_model.wrong) std::cout << "camera_info: " << snap.camera_model.message << "\n";
  if (args.has("--report")) {
    std::string error;
    if (!cia::writeReportPng(args.get("--report"), report, &error)) {
      std::cerr << "calibrate_bag: --report " << args.get("--report") << ": " << error << "\n";
      return kExitBadInput;
    }
  }
  if (args.has("--export-poses")) {
    try {
      cia::writePosesCsv(args.get("--export-poses"), snap.windowOrientations());
    } catch (const cia::InputError& e) {
      std::cerr << "calibrate_bag: --export-poses " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  if (snap.camera_model.wrong) {  // camera_info, not the recording: every pose is biased by it
    std::cerr << "calibrate_bag: "
              << (topics.camera_info.empty() ? std::string("camera info") : topics.camera_info)
              << ": " << snap.camera_model.message << "\n";
    return kExitBadInput;
  }
  const cia::SolveStatus status = report.result.status;
  if (status != cia::SolveStatus::kOk) {
    std::cerr << "calibrate_bag: " << report.result.message << "\n";
    if (snap.rests.empty()) {
      std::cerr << "calibrate_bag: " << bag_path << ": the recording has no stationary rests and "
                << snap.inputs.motion_frames
                << " camera orientation(s) during motion: the estimate needs several seconds of "
                   "motion about every axis with the target in view, or rests of a few seconds at "
                   "several orientations\n";
    }
    const std::string target_problem = snap.target_diagnosis;
    if (!target_problem.empty()) {  // the target file, not the recording
      std::cerr << "calibrate_bag: " << args.get("--target") << ": " << target_problem << "\n";
      return kExitBadInput;
    }
    return kExitNotEnoughInformation;  // the bag was read; it did not hold enough information
  }
  if (current) {
    const std::optional<cia::CalibrationCheck> check =
        cia::checkCalibration(report.result, cia::storedBroadcast(*current, args.get("--check")),
                              online.consistency_level);
    if (!check) {
      std::cerr << "calibrate_bag: --check needs the joint estimate (--imu-orientation joint or "
                   "magnetometer) with its covariance; "
                << (report.result.joint ? report.result.joint->message : "none was run") << "\n";
      return kExitNotEnoughInformation;
    }
    std::cout << "check: " << args.get("--check") << ": " << check->text << "\n";
    return check->consistent ? kExitOk : kExitQualityGate;  // a check writes no result
  }
  if (!gates_passed) {
    // Too little data in the window (and no remount cut it): not enough information, not a
    // failed gate.
    if (snap.latest && !snap.latest->gate.enough_data && snap.remount_events.empty()) {
      std::cerr << "calibrate_bag: not enough information (see 'verdict:'): "
                << snap.latest->gate.why << "; nothing written\n";
      return kExitNotEnoughInformation;
    }
    std::cerr << "calibrate_bag: the estimate fails the quality gates (see 'verdict:'); not "
                 "written to --output / --imu-yaml\n";
    return kExitQualityGate;
  }
  if (args.has("--output")) {
    try {
      cia::ResultMetadata meta{report.camera_frame, report.imu_frame,
                               static_cast<int>(outcome.window_poses)};
      cia::writeResultYaml(args.get("--output"), report.result, meta);
    } catch (const cia::InputError& e) {
      std::cerr << "calibrate_bag: " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  if (args.has("--imu-yaml") &&
      !writeImuYaml(args.get("--imu-yaml"), report, topics.imu,
                    info.end_s > info.start_s
                        ? static_cast<double>(snap.inputs.imu_samples) / (info.end_s - info.start_s)
                        : 0.0)) {
    return kExitBadInput;
  }
  return kExitOk;
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
          {"--help", "--quiet", "--accept-last-mount"});
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
