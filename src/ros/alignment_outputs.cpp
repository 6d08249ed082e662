// AlignmentWrapper, output side: quality gates, the static tf, ~status, ~stationary_poses, the
// saved calibration, services and diagnostics.
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "alignment_wrapper_impl.h"
#include "camera_imu_alignment/AlignmentStatus.h"
#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/io/default_frames.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/ros/message_conversion.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

void AlignmentWrapper::Impl::advertise() {
  status_pub = pnh.advertise<AlignmentStatus>("status", 10, true);
  poses_pub = pnh.advertise<geometry_msgs::PoseArray>("stationary_poses", 1, true);
  target_pose_pub = pnh.advertise<geometry_msgs::PoseStamped>("target_pose", 1, true);
  debug_pub = image_transport::ImageTransport(pnh).advertise("debug_image", 1);
  calibrate_srv = pnh.advertiseService("calibrate", &Impl::onCalibrate, this);
  reset_srv = pnh.advertiseService("reset", &Impl::onReset, this);
  save_srv = pnh.advertiseService("save", &Impl::onSave, this);
  capture_srv = pnh.advertiseService("capture_pose", &Impl::onCapturePose, this);
  // Wall time: status and diagnostics keep coming while a bag is paused or no clock runs (they
  // show that the node is alive), and not ten times as often when a bag plays at 10x.
  status_timer =
      pnh.createWallTimer(ros::WallDuration(settings.status_period_s), [this](const auto&) {
        publishStatus();
        diagnostics.force_update();
      });
  diagnostics.setHardwareID("camera_imu_alignment");
  diagnostics.add("calibration", this, &Impl::diagnose);
}

std::string AlignmentWrapper::Impl::cameraFrame() const {
  if (!settings.camera_frame.empty()) return settings.camera_frame;
  if (!input->cameraFrame().empty()) return input->cameraFrame();
  return frameOr(saved_camera_frame, kDefaultCameraFrame);
}

std::string AlignmentWrapper::Impl::imuFrame() const {
  if (!settings.imu_frame.empty()) return settings.imu_frame;
  if (!input->imuFrame().empty()) return input->imuFrame();
  return frameOr(saved_imu_frame, kDefaultImuFrame);
}

void AlignmentWrapper::Impl::onBroadcast(const BroadcastEstimate& estimate) {
  noteReplacedBroadcast(estimate);
  // A refined estimate (within min_change_deg) keeps the tf: only its 1-sigma and the file change.
  const bool refined = sent_R_cam_imu && sent_R_cam_imu->isApprox(estimate.R_cam_imu, 1e-12);
  if (!refined) {
    sendTransform(estimate.R_cam_imu);
    sent_R_cam_imu = estimate.R_cam_imu;
  }
  if (estimate.source != "estimated") {  // a loaded calibration: no solve reports it
    publishStatus();
    return;
  }
  // An estimate's status goes out once, from onEstimate, which follows.
  std::string error;
  const bool saved = !settings.output_file.empty() && save(estimate, &error);
  if (saved || settings.output_file.empty()) {
    save_error.clear();
  } else {
    save_error = error;
    ROS_ERROR_THROTTLE(10.0, "%s: %s", name.c_str(), error.c_str());
  }
  if (refined) {
    ROS_INFO("%s: the tf stays; %s the %d-pose estimate (1-sigma %.4f deg)", name.c_str(),
             saved                          ? "the saved calibration becomes"
             : settings.output_file.empty() ? "its 1-sigma becomes that of"
                                            : "not saved (see the error above): its 1-sigma "
                                              "becomes that of",
             estimate.poses, estimate.maxStdDevDeg());
  }
}

void AlignmentWrapper::Impl::sendTransform(const Eigen::Matrix3d& R_cam_imu) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  // A transform parent <- child maps child-frame points into the parent frame.
  if (settings.publish_inverse) {
    t.header.frame_id = imuFrame();
    t.child_frame_id = cameraFrame();
    t.transform.rotation = toQuaternionMsg(R_cam_imu.transpose());
  } else {
    t.header.frame_id = cameraFrame();
    t.child_frame_id = imuFrame();
    t.transform.rotation = toQuaternionMsg(R_cam_imu);
  }
  broadcaster.sendTransform(t);
  ROS_INFO("%s: broadcasting %s -> %s, R_cam_imu %s", name.c_str(), t.header.frame_id.c_str(),
           t.child_frame_id.c_str(), rollPitchYawText(R_cam_imu, 3).c_str());
}

bool AlignmentWrapper::Impl::save(const BroadcastEstimate& estimate, std::string* error) {
  if (!estimate.result) {
    *error = "cannot save the calibration: the broadcast one was loaded, not estimated here";
    return false;
  }
  try {
    // The broadcast estimate with its own quality: the poses behind it, not the window's now.
    ResultMetadata meta{cameraFrame(), imuFrame(), estimate.poses};
    // A forced estimate is saved marked FAILED: no reader takes it for a good one.
    meta.verdict = estimate.forced_although.empty()
                       ? ResultVerdict{true, "PASSED (broadcast by the nodelet)", false}
                       : ResultVerdict{false, "FAILED: " + estimate.forced_although, true};
    backUpOutputOnce();
    writeResultYaml(settings.output_file, *estimate.result, meta);
    return true;
  } catch (const std::exception& e) {
    *error = std::string("cannot save the calibration: ") + e.what();
    return false;
  }
}

void AlignmentWrapper::Impl::loadSaved() {
  std::string warning;
  const std::optional<StoredCalibration> stored =
      loadSavedCalibration(settings.output_file, &warning);
  if (!warning.empty())
    ROS_WARN("%s: saved calibration not loaded: %s", name.c_str(), warning.c_str());
  if (!stored) return;
  saved_camera_frame = stored->camera_frame;
  saved_imu_frame = stored->imu_frame;
  const std::string failed = failedVerdictNote(*stored, settings.output_file);
  if (!failed.empty()) ROS_WARN("%s: %s; broadcast as loaded", name.c_str(), failed.c_str());
  const BroadcastEstimate loaded =
      storedBroadcast(*stored, "loaded: " + settings.output_file +
                                   (failed.empty() ? "" : " (FAILED its quality gates, forced)"));
  calibrator->loadBroadcast(loaded);
  ROS_INFO("%s: calibration loaded from %s (%d poses, 1-sigma %s deg)", name.c_str(),
           settings.output_file.c_str(), loaded.poses,
           stored->std_dev_deg ? std::to_string(loaded.maxStdDevDeg()).c_str() : "unknown");
}

void AlignmentWrapper::Impl::publishStatus() {
  const CalibrationSnapshot snap = calibrator->snapshot();
  AlignmentStatus s;
  s.header.stamp = snap.newest_stamp_s > 0 ? ros::Time(snap.newest_stamp_s) : ros::Time::now();
  s.header.frame_id = cameraFrame();
  s.state = toString(snap.state);
  s.message = snap.message;
  if (snap.state == CalibrationState::kWaitingForData) {
    if (snap.inputs.imu_samples == 0) {
      s.message = "waiting for IMU data on " + imu_sub.getTopic();
    } else {
      // Images without their camera info are not "nothing on the image topic".
      const std::string hint = cameraInputHint();
      s.message = "waiting for the camera: " +
                  (hint.empty() ? "nothing on " + topicOf(InputStream::kImage) + " / " +
                                      topicOf(InputStream::kCameraInfo) + " / " +
                                      camera_pose_sub.getTopic() + " yet"
                                : hint);
    }
  }
  s.poses_in_window = static_cast<std::uint32_t>(snap.window.size());
  s.poses_total = static_cast<std::uint32_t>(snap.poses_total);
  s.rests_total = static_cast<std::uint32_t>(snap.rests_total);
  s.remounts = static_cast<std::uint32_t>(snap.remounts);
  s.q_cam_imu.w = 1.0;
  s.q_broadcast.w = 1.0;
  const std::optional<BroadcastEstimate>& broadcast = snap.broadcast;
  if (snap.latest) {
    const AlignmentResult& r = snap.latest->result;
    s.pairs = static_cast<std::uint32_t>(r.quality.num_pairs);
    s.inliers = static_cast<std::uint32_t>(r.quality.num_inliers);
    s.has_estimate = true;
    s.q_cam_imu = toQuaternionMsg(r.R_cam_imu);
    s.residual_rms_deg = r.quality.residual_rms_deg;
    for (int i = 0; i < 3; ++i) s.std_dev_deg[i] = r.quality.std_dev_deg(i);
    s.observability = r.quality.observability;
    s.broadcast = snap.latest_is_broadcast;
    if (r.joint && r.joint->ok) {
      s.consistent = snap.latest->gate.consistent;
      s.chi2 = r.joint->chi2;
      s.dof = static_cast<std::uint32_t>(std::max(0, r.joint->dof));
      s.p_value = r.joint->chi2_p_value;
      s.motion_nodes = static_cast<std::uint32_t>(std::max(0, r.joint->motion_nodes));
      s.timeshift_estimated = r.joint->timeshift_estimated;
      s.timeshift_cam_imu_s = r.joint->timeshift_cam_imu_s;
      s.timeshift_sigma_s = r.joint->timeshift_sigma_s;
      if (r.joint->motion_nodes > 0) {
        for (int i = 0; i < 3; ++i)
          s.excitation_deg[i] = rad2deg(r.joint->motion.excitation_rad(i));
        s.excitation_missing = unexcitedAxes(r.joint->motion, settings.online);
      }
    }
  }
  s.poses_needed = snap.progress.poses_needed;
  if (snap.check) {
    s.has_check = true;
    s.check_error_deg = snap.check->error_deg;
    s.check_sigmas = snap.check->sigmas;
    s.check_consistent = snap.check->consistent;
  }
  const Eigen::Vector3d axis = snap.progress.rotate_about_cam;
  s.rotate_about_cam.x = axis.x();
  s.rotate_about_cam.y = axis.y();
  s.rotate_about_cam.z = axis.z();
  s.how_to_move = snap.progress.how_to_move;
  s.imu_guidance = snap.progress.imu_guidance;
  if (!s.imu_guidance.empty()) s.message += "; " + s.imu_guidance;
  if (broadcast) {
    s.has_broadcast = true;
    s.q_broadcast = toQuaternionMsg(broadcast->R_cam_imu);
    for (int i = 0; i < 3; ++i) s.broadcast_std_dev_deg[i] = broadcast->std_dev_deg(i);
    s.broadcast_source = broadcast->source;
    s.broadcast_poses = static_cast<std::uint32_t>(broadcast->poses);
  }
  if (const std::optional<StationaryPose>& last = snap.last_pose) {
    s.last_pose_start = ros::Time(last->start_s);
    s.last_pose_end = ros::Time(last->end_s);
    s.last_pose_frames = static_cast<std::uint32_t>(last->num_frames);
    s.last_pose_imu_source = toString(last->imu_source);
  }
  status_pub.publish(s);
}

void AlignmentWrapper::Impl::publishPoses() {
  // Camera orientations at the poses, in the target frame (rviz: fixed frame = the target).
  geometry_msgs::PoseArray out;
  const CalibrationSnapshot snap = calibrator->snapshot(SnapshotContents::kWithHistory);
  out.header.stamp = ros::Time(std::max(snap.newest_stamp_s, 0.0));
  out.header.frame_id = "calibration_target";
  for (const StationaryPose& p : snap.window) {
    geometry_msgs::Pose pose;
    pose.position.x = p.p_target_cam.x();
    pose.position.y = p.p_target_cam.y();
    pose.position.z = p.p_target_cam.z();
    pose.orientation = toQuaternionMsg(p.R_target_cam);
    out.poses.push_back(pose);
  }
  poses_pub.publish(out);
  if (snap.poses.empty()) return;
  // The target seen from the camera at the last pose: R_cam_target = R_target_cam^T.
  const StationaryPose& last = snap.poses.back();
  geometry_msgs::PoseStamped target;
  target.header.stamp = ros::Time(last.end_s);
  target.header.frame_id = cameraFrame();
  const Eigen::Vector3d p_cam_target = -(last.R_target_cam.transpose() * last.p_target_cam);
  target.pose.position.x = p_cam_target.x();
  target.pose.position.y = p_cam_target.y();
  target.pose.position.z = p_cam_target.z();
  target.pose.orientation = toQuaternionMsg(last.R_target_cam.transpose());
  target_pose_pub.publish(target);
  // The same as a tf frame, so that rviz can show camera, IMU and target together.
  geometry_msgs::TransformStamped t;
  t.header = target.header;
  t.child_frame_id = "calibration_target";
  t.transform.translation.x = p_cam_target.x();
  t.transform.translation.y = p_cam_target.y();
  t.transform.translation.z = p_cam_target.z();
  t.transform.rotation = target.pose.orientation;
  target_broadcaster.sendTransform(t);
}

void AlignmentWrapper::Impl::publishDebugImage(const cv::Mat& mono8,
                                               const std_msgs::Header& header) {
  if (debug_pub.getNumSubscribers() == 0) return;
  const ros::WallTime now = ros::WallTime::now();
  if ((now - last_debug).toSec() < 0.2) return;
  last_debug = now;
  TargetObservation observation;
  const bool natural_scene = settings.target_file.empty();  // no board to look for
  const bool found = !natural_scene && debug_detector->detect(mono8, &observation);
  cv::Mat bgr;
  cv::cvtColor(mono8, bgr, cv::COLOR_GRAY2BGR);
  for (std::size_t i = 0; i < observation.image_points.size(); ++i) {
    const cv::Scalar colour = observation.point_ids[i] == 0 ? cv::Scalar(0, 0, 255)  // origin red
                                                            : cv::Scalar(0, 255, 0);
    cv::circle(bgr, observation.image_points[i], 3, colour, 1, cv::LINE_AA);
  }
  const std::string text = natural_scene ? "natural scene (no target)"
                           : found ? std::to_string(observation.image_points.size()) + " points"
                                   : "target not found";
  cv::putText(bgr, text, cv::Point(10, 25), cv::FONT_HERSHEY_SIMPLEX, 0.7,
              found ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 0, 255), 2, cv::LINE_AA);
  sensor_msgs::Image out;
  out.header = header;
  out.height = static_cast<std::uint32_t>(bgr.rows);
  out.width = static_cast<std::uint32_t>(bgr.cols);
  out.encoding = "bgr8";
  out.step = static_cast<std::uint32_t>(bgr.cols * 3);
  out.data.assign(bgr.data, bgr.data + bgr.total() * 3);
  debug_pub.publish(out);
}

bool AlignmentWrapper::Impl::onCalibrate(Calibrate::Request& req, Calibrate::Response& res) {
  const CalibrateOutcome outcome = calibrator->calibrateNow(req.force);
  const AlignmentResult& r = outcome.result;
  res.poses = static_cast<std::uint32_t>(outcome.window_poses);
  res.observable = r.quality.observable && r.status != SolveStatus::kBadInput;
  res.success = r.status == SolveStatus::kOk;
  res.broadcast = outcome.broadcast;
  res.not_broadcast_reason = outcome.not_broadcast_reason;
  res.message = r.message;
  res.has_estimate = r.status != SolveStatus::kBadInput && r.R_cam_imu.allFinite();
  if (res.has_estimate) {
    res.q_cam_imu = toQuaternionMsg(r.R_cam_imu);
    const Eigen::Vector3d rpy = rollPitchYawDeg(r.R_cam_imu);
    for (int i = 0; i < 3; ++i) {
      res.rpy_deg[i] = rpy(i);
      res.std_dev_deg[i] = r.quality.std_dev_deg(i);
    }
    res.residual_rms_deg = r.quality.residual_rms_deg;
  }  // else: all zeros, q_cam_imu included (has_estimate false)
  publishStatus();
  return true;
}

bool AlignmentWrapper::Impl::onReset(std_srvs::Trigger::Request&,
                                     std_srvs::Trigger::Response& res) {
  calibrator->reset();
  res.success = true;
  res.message = calibrator->stateMessage();
  publishPoses();
  publishStatus();
  return true;
}

bool AlignmentWrapper::Impl::onSave(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  const std::optional<BroadcastEstimate>& broadcast = calibrator->broadcast();
  if (settings.output_file.empty()) {
    res.success = false;
    res.message = "no output_file parameter set";
  } else if (!broadcast || !broadcast->result) {
    res.success = false;
    res.message = broadcast ? "the broadcast calibration was loaded from a file, not estimated in "
                              "this run: nothing new to save"
                            : "no calibration has passed the quality gates yet";
  } else {
    std::string error;
    res.success = save(*broadcast, &error);
    res.message = res.success ? "saved to " + settings.output_file + " (" +
                                    std::to_string(broadcast->poses) + " poses)"
                              : error;
    save_error = error;
  }
  return true;
}

bool AlignmentWrapper::Impl::onCapturePose(std_srvs::Trigger::Request&,
                                           std_srvs::Trigger::Response& res) {
  if (!settings.online.manual_capture) {
    res.success = false;
    res.message = "manual_capture is false: every rest becomes a pose automatically";
    return true;
  }
  calibrator->armCapture();
  res.success = true;
  res.message = "armed: the current (or next) rest becomes a pose when the rig moves again";
  return true;
}

void AlignmentWrapper::Impl::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  const CalibrationSnapshot snap = calibrator->snapshot();
  const CalibrationState state = snap.state;
  std::vector<std::string> problems;  // each makes the summary WARN
  if (state == CalibrationState::kNotObservable || state == CalibrationState::kRecalibrating) {
    problems.push_back(snap.message);
  }
  for (InputStream stream : silentStreams()) {
    problems.push_back("nothing on " + topicOf(stream) + " while other inputs flow");
  }
  const std::uint64_t not_found = snap.rejections.count(RejectReason::kTargetNotFound);
  if (snap.inputs.frames_detected >= 10 && not_found >= snap.inputs.frames_detected) {
    problems.push_back("the target was not found in any of " +
                       std::to_string(snap.inputs.frames_detected) +
                       " frames at rest: does target_file describe the board in view?");
  }
  if (snap.camera_model.wrong) problems.push_back(snap.camera_model.message);
  if (snap.latest && snap.latest->result.joint && !snap.latest->result.joint->ok) {
    problems.push_back(
        "the joint estimate failed (" + snap.latest->result.joint->message + ")" +
        (snap.broadcast ? "; the broadcast calibration is from an earlier window" : std::string()));
  }
  if (!save_error.empty()) problems.push_back(save_error);
  if (!snap.broadcast_warning.empty()) problems.push_back(snap.broadcast_warning);
  std::string summary = std::string(toString(state)) + ": " + snap.message;
  for (const std::string& p : problems) {
    if (summary.find(p) == std::string::npos) summary += "; " + p;
  }
  status.summary(problems.empty() ? DiagnosticStatus::OK : DiagnosticStatus::WARN, summary);
  status.add("last save error", save_error.empty() ? "none" : save_error);
  const double elapsed = std::max(1e-3, (ros::WallTime::now() - last_diagnostics).toSec());
  last_diagnostics = ros::WallTime::now();
  status.add("imu rate (Hz)", imu_count / elapsed);
  status.add("magnetometer rate (Hz)", mag_count / elapsed);
  status.add("image rate (Hz)", image_count / elapsed);
  imu_count = mag_count = image_count = 0;
  status.add("imu samples", snap.inputs.imu_samples);
  status.add("magnetometer samples", snap.inputs.magnetic_samples);
  status.add("frames", snap.inputs.frames);
  status.add("frames detected", snap.inputs.frames_detected);
  status.add("poses in window", snap.window.size());
  status.add("remounts", snap.remounts);
  status.add("imu gaps", snap.inputs.imu_gaps);
  status.add("camera model", !snap.camera_model.tested ? std::string("not tested yet")
                             : snap.camera_model.wrong ? snap.camera_model.message
                                                       : std::string("fits the images"));
  // One key per reason, zeros included, so that monitors can track each.
  const RejectionCounts& rejections = snap.rejections;
  status.add("rejected inputs", rejections.summary());
  for (int i = 0; i < static_cast<int>(RejectReason::kCount); ++i) {
    const auto reason = static_cast<RejectReason>(i);
    status.add(std::string("rejected ") + toString(reason), rejections.count(reason));
  }
}

}  // namespace camera_imu_alignment
