// AlignmentWrapper, input side: settings, target, subscriptions, message conversion into the
// OnlineCalibrator, and its events.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <image_transport/camera_common.h>
#include <ros/master.h>

#include "alignment_wrapper_impl.h"
#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/ros/message_conversion.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/target_description.h"

namespace camera_imu_alignment {

AlignmentWrapper::AlignmentWrapper(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : impl_(std::make_unique<Impl>(nh, private_nh)) {}

AlignmentWrapper::~AlignmentWrapper() = default;

AlignmentWrapper::Impl::Impl(ros::NodeHandle nh_, ros::NodeHandle private_nh)
    : nh(nh_),
      pnh(private_nh),
      name(private_nh.getNamespace()),
      transport(nh_),
      // Named after this instance: a nodelet's ros::this_node is its manager.
      diagnostics(nh_, private_nh, private_nh.getNamespace()) {
  readSettings(pnh, &settings, &pipeline_settings);
  for (const std::string& notice : resolvePaths(&settings)) {
    ROS_WARN("%s: %s", name.c_str(), notice.c_str());
  }
  // No target_file: no board, the camera's rotation from the natural scene.
  const TargetDescription target =
      settings.target_file.empty() ? TargetDescription{} : loadTargetYaml(settings.target_file);
  OnlineCallbacks callbacks;
  callbacks.on_pose = [this](const StationaryPose& p) { onPose(p); };
  callbacks.on_pose_rejected = [this](const RejectedPose& r) { onPoseRejected(r); };
  callbacks.on_reject = [this](RejectReason reason, InputStream stream, const std::string& d) {
    onReject(reason, stream, d);
  };
  callbacks.on_estimate = [this](const EstimateEvent& e) { onEstimate(e); };
  callbacks.on_broadcast = [this](const BroadcastEstimate& b) { onBroadcast(b); };
  callbacks.on_remount = [this](const RemountEvent& e) { onRemount(e); };
  callbacks.on_state = [this](CalibrationState, const std::string&) { publishStatus(); };
  callbacks.on_clock_jump = [this](double jump_s, InputStream stream) {
    onClockJump(jump_s, stream);
  };
  settings.online.threaded = true;  // solves off the subscriber thread
  calibrator =
      std::make_unique<OnlineCalibrator>(target, pipeline_settings, settings.online, callbacks);
  input = std::make_unique<MessageInput>(calibrator.get(), [this](const std::string& notice) {
    ROS_WARN("%s: %s", name.c_str(), notice.c_str());
  });
  input->setTopicNames([this](InputStream stream) { return topicOf(stream); });
  debug_detector = std::make_unique<TargetDetector>(target, pipeline_settings.detector);
  if (settings.target_file.empty()) {
    ROS_INFO_STREAM(name << ": no target_file: the camera's rotation between rests from the "
                            "natural scene (features)");
  } else {
    ROS_INFO_STREAM(name << ": target " << target.describe() << " from " << settings.target_file);
  }

  advertise();
  if (settings.load_on_start) loadSaved();
  imu_sub = nh.subscribe("imu/data_raw", 2000, &Impl::onImu, this);
  mag_sub = nh.subscribe("imu/mag", 2000, &Impl::onMag, this);
  subscribeCamera();
  camera_pose_sub = nh.subscribe("camera_pose", 100, &Impl::onCameraPose, this);
  stale_timer = nh.createWallTimer(ros::WallDuration(0.5), [this](const auto&) { checkStale(); });
  // Finished solves are applied here too when no sample arrives (a paused bag).
  poll_timer =
      nh.createWallTimer(ros::WallDuration(0.05), [this](const auto&) { calibrator->poll(); });
  ROS_INFO_STREAM(name << ": listening on " << imu_sub.getTopic() << ", " << mag_sub.getTopic()
                       << ", " << topicOf(InputStream::kImage) << " (+ "
                       << topicOf(InputStream::kCameraInfo) << "), " << camera_pose_sub.getTopic());
}

void AlignmentWrapper::Impl::subscribeCamera() {
  // As image_transport names them: the remapped image topic ("/compressed" appended for
  // compressed); camera_info beside the image topic.
  const std::string image_topic = nh.resolveName("camera/image_raw");
  const std::string info_topic = image_transport::getCameraInfoTopic(image_topic);
  if (settings.image_transport != "compressed") {
    camera_sub = transport.subscribeCamera("camera/image_raw", 30, &Impl::onImage, this,
                                           image_transport::TransportHints("raw"));
    info_watch_sub = nh.subscribe<sensor_msgs::CameraInfo>(
        info_topic, 1, [this](const sensor_msgs::CameraInfoConstPtr&) {
          streams.seen(InputStream::kCameraInfo, ros::WallTime::now().toSec());
        });
    // Images without their camera info never reach onImage: seen here (the message is shared
    // with image_transport's subscription, not received twice).
    image_watch_sub =
        nh.subscribe<sensor_msgs::Image>(image_topic, 1, [this](const sensor_msgs::ImageConstPtr&) {
          streams.seen(InputStream::kImage, ros::WallTime::now().toSec());
        });
    return;
  }
  compressed_sub = nh.subscribe(image_topic + "/compressed", 30, &Impl::onCompressedImage, this);
  info_sub = nh.subscribe<sensor_msgs::CameraInfo>(
      info_topic, 10, [this](const sensor_msgs::CameraInfoConstPtr& info) {
        streams.seen(InputStream::kCameraInfo, ros::WallTime::now().toSec());
        latest_info = info;
      });
}

std::string AlignmentWrapper::Impl::topicOf(InputStream stream) const {
  switch (stream) {
    case InputStream::kImu:
      return imu_sub.getTopic();
    case InputStream::kMagnetometer:
      return mag_sub.getTopic();
    case InputStream::kImage:
      return compressed_sub ? compressed_sub.getTopic() : camera_sub.getTopic();
    case InputStream::kCameraInfo:
      return info_sub ? info_sub.getTopic() : camera_sub.getInfoTopic();
    case InputStream::kCameraPose:
      return camera_pose_sub.getTopic();
  }
  return toString(stream);
}

std::string AlignmentWrapper::Impl::otherTransportHint() const {
  const std::string raw_topic = nh.resolveName("camera/image_raw");
  const bool compressed = settings.image_transport == "compressed";
  const std::string other = compressed ? raw_topic : raw_topic + "/compressed";
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return "";
  for (const ros::master::TopicInfo& topic : topics) {
    if (topic.name == other) {
      return "; " + other + " is published: image_transport " +
             (compressed ? std::string("raw") : std::string("compressed")) +
             " (alignment.launch / replay_bag.launch image_transport:=" +
             (compressed ? "raw" : "compressed") + ")";
    }
  }
  return "";
}

std::string AlignmentWrapper::Impl::cameraInputHint() const {
  if (streams.everSeen(InputStream::kCameraPose)) return "";
  const bool images = streams.everSeen(InputStream::kImage);
  const bool info = streams.everSeen(InputStream::kCameraInfo);
  if (info && !images) {
    return "nothing on " + topicOf(InputStream::kImage) + " while camera info arrives on " +
           topicOf(InputStream::kCameraInfo) + ": wrong image topic?";
  }
  if (images && !info) {
    return "images arrive on " + topicOf(InputStream::kImage) + " but no camera info on " +
           topicOf(InputStream::kCameraInfo) +
           " (the image topic's sibling): frames are used only with their camera info";
  }
  if (!images && !info) {
    return "nothing on " + topicOf(InputStream::kImage) + ", " + topicOf(InputStream::kCameraInfo) +
           " or " + topicOf(InputStream::kCameraPose);
  }
  return "";
}

void AlignmentWrapper::Impl::noteReplacedBroadcast(const BroadcastEstimate& estimate) {
  if (previous_broadcast && previous_broadcast->first.rfind("loaded", 0) == 0 &&
      estimate.source == "estimated") {
    const double apart_deg =
        rad2deg(geodesicDistance(previous_broadcast->second, estimate.R_cam_imu));
    const std::string text = "the new estimate replaces the calibration " +
                             previous_broadcast->first + ", " + std::to_string(apart_deg) +
                             " deg from it" +
                             (settings.output_file.empty()
                                  ? std::string()
                                  : "; the old file is kept as " + settings.output_file + ".bak");
    if (apart_deg > 1.0) {
      ROS_WARN("%s: %s", name.c_str(), text.c_str());
    } else {
      ROS_INFO("%s: %s", name.c_str(), text.c_str());
    }
  }
  previous_broadcast = std::make_pair(estimate.source, estimate.R_cam_imu);
}

void AlignmentWrapper::Impl::backUpOutputOnce() {
  namespace fs = std::filesystem;
  if (output_backed_up || settings.output_file.empty()) return;
  std::error_code error;
  if (!fs::exists(settings.output_file, error)) return;
  output_backed_up = true;
  const std::string backup = settings.output_file + ".bak";
  fs::copy_file(settings.output_file, backup, fs::copy_options::overwrite_existing, error);
  if (error) {
    ROS_WARN("%s: could not keep the previous %s as %s (%s); it is overwritten", name.c_str(),
             settings.output_file.c_str(), backup.c_str(), error.message().c_str());
  } else {
    ROS_INFO("%s: the previous %s is kept as %s", name.c_str(), settings.output_file.c_str(),
             backup.c_str());
  }
}

void AlignmentWrapper::Impl::checkStale() {
  warnSilentStreams();
  if (input_stopped || (ros::WallTime::now() - last_imu_wall).toSec() < 2.0) return;
  input_stopped = true;
  ROS_INFO("%s: no IMU data for 2 s on %s: closing the rest in progress", name.c_str(),
           imu_sub.getTopic().c_str());
  calibrator->finish();
  publishStatus();
}

std::vector<InputStream> AlignmentWrapper::Impl::silentStreams() const {
  const bool magnetometer_expected =
      streams.everSeen(InputStream::kMagnetometer) ||
      pipeline_settings.imu_orientation == ImuOrientationSource::kMagnetometer;
  return streams.silent(ros::WallTime::now().toSec(), magnetometer_expected);
}

void AlignmentWrapper::Impl::warnSilentStreams() {
  const ros::WallTime now = ros::WallTime::now();
  for (InputStream stream : silentStreams()) {
    ros::WallTime& last = last_silent_warning[stream];
    if (!last.isZero() && (now - last).toSec() < 10.0) continue;
    last = now;
    if (stream == InputStream::kCameraInfo && streams.everSeen(InputStream::kImage)) {
      ROS_WARN(
          "%s: nothing on %s for 5 s while images arrive on %s: frames are used only with their "
          "camera info, published beside the image topic (the camera driver's camera_info)",
          name.c_str(), topicOf(stream).c_str(), topicOf(InputStream::kImage).c_str());
      continue;
    }
    ROS_WARN(
        "%s: nothing on %s for 5 s while other inputs flow: wrong topic name (remap it), or "
        "the driver stopped%s",
        name.c_str(), topicOf(stream).c_str(),
        stream == InputStream::kImage ? otherTransportHint().c_str() : "");
  }
  // A 6-axis IMU has no magnetometer: said once, not warned about.
  if (!mag_absence_noted && !streams.everSeen(InputStream::kMagnetometer) &&
      calibrator->inputCounts().imu_samples > 2000) {
    mag_absence_noted = true;
    ROS_WARN(
        "%s: nothing on %s while the IMU flows: the magnetometer is not used (fine for a 6-axis "
        "IMU; remap "
        "imu/mag if yours has one)",
        name.c_str(), mag_sub.getTopic().c_str());
  }
}

void AlignmentWrapper::Impl::onImu(const sensor_msgs::ImuConstPtr& msg) {
  streams.seen(InputStream::kImu, ros::WallTime::now().toSec());
  if (!input->checkStamp(msg->header, InputStream::kImu)) return;
  last_imu_wall = ros::WallTime::now();
  input_stopped = false;
  ++imu_count;
  input->addImu(*msg);
  const std::uint64_t gaps = calibrator->inputCounts().imu_gaps;
  if (gaps != imu_gaps_warned) {  // differs also after a reset clearing counts
    imu_gaps_warned = gaps;
    if (gaps > 0) {
      ROS_WARN_THROTTLE(5.0,
                        "%s: %s: gap in the IMU data (more than max_imu_gap_s = "
                        "%.2f s; %lu so far): a rest in progress ended there",
                        name.c_str(), imu_sub.getTopic().c_str(),
                        pipeline_settings.stationary.max_gap_s, static_cast<unsigned long>(gaps));
    }
  }
}

void AlignmentWrapper::Impl::onMag(const sensor_msgs::MagneticFieldConstPtr& msg) {
  streams.seen(InputStream::kMagnetometer, ros::WallTime::now().toSec());
  if (!input->checkStamp(msg->header, InputStream::kMagnetometer)) return;
  ++mag_count;
  if (!tf_buffer && !input->imuFrame().empty() &&
      normalizeFrameId(msg->header.frame_id) != input->imuFrame()) {
    // The magnetometer has a frame of its own: its rotation into the IMU frame comes from tf.
    tf_buffer = std::make_unique<tf2_ros::Buffer>();
    tf_listener = std::make_unique<tf2_ros::TransformListener>(*tf_buffer, nh);
    input->setTransforms(tf_buffer.get(), std::chrono::seconds(1));  // tf arriving
  }
  input->addMagnetic(*msg);
}

void AlignmentWrapper::Impl::onImage(const sensor_msgs::ImageConstPtr& image,
                                     const sensor_msgs::CameraInfoConstPtr& info) {
  streams.seen(InputStream::kImage, ros::WallTime::now().toSec());
  if (!input->checkStamp(image->header, InputStream::kImage)) return;
  handleImage(*image, *info);
}

void AlignmentWrapper::Impl::onCompressedImage(const sensor_msgs::CompressedImageConstPtr& image) {
  streams.seen(InputStream::kImage, ros::WallTime::now().toSec());
  if (!input->checkStamp(image->header, InputStream::kImage)) return;
  if (!latest_info) {
    ROS_WARN_THROTTLE(5.0, "%s: %s: images arrive but no camera info on %s yet; frames dropped",
                      name.c_str(), compressed_sub.getTopic().c_str(), info_sub.getTopic().c_str());
    return;
  }
  handleImage(*image, *latest_info);
}

template <typename ImageMessage>
void AlignmentWrapper::Impl::handleImage(const ImageMessage& image,
                                         const sensor_msgs::CameraInfo& info) {
  ++image_count;
  if (!input->setCameraInfo(info)) return;
  const bool wanted = calibrator->wantsFrames();  // manual_capture: poses only when armed
  const bool debug = debug_pub.getNumSubscribers() > 0;
  if (!wanted && !debug) return;
  cv::Mat mono8;
  if (!input->addImage(image, wanted, &mono8)) return;
  if (debug) publishDebugImage(mono8, image.header);
}

void AlignmentWrapper::Impl::onCameraPose(const geometry_msgs::PoseStampedConstPtr& msg) {
  streams.seen(InputStream::kCameraPose, ros::WallTime::now().toSec());
  if (!input->checkStamp(msg->header, InputStream::kCameraPose)) return;
  if (!camera_pose_frame_noted && settings.camera_frame.empty() && input->cameraFrame().empty()) {
    // A PoseStamped names only its parent frame (the target's): the camera's tf frame is not in
    // it, so the tf's camera end is a name chosen here, said once.
    camera_pose_frame_noted = true;
    ROS_INFO(
        "%s: %s gives the camera in frame '%s' but names no camera frame: the tf's camera "
        "frame is '%s' (set the camera_frame parameter to name it)",
        name.c_str(), camera_pose_sub.getTopic().c_str(), msg->header.frame_id.c_str(),
        cameraFrame().c_str());
  }
  ++image_count;
  input->addCameraPose(*msg, calibrator->wantsFrames());
}

void AlignmentWrapper::Impl::onPose(const StationaryPose& pose) {
  ROS_INFO("%s: stationary pose %d (%.1f s, %d frames, IMU from %s)", name.c_str(), pose.index,
           pose.end_s - pose.start_s, pose.num_frames, toString(pose.imu_source));
  publishPoses();
  publishStatus();
}

void AlignmentWrapper::Impl::onPoseRejected(const RejectedPose& rejected) {
  std::string reason = rejected.reason;
  const std::string hint = cameraInputHint();
  if (!hint.empty() && reason.rfind(kNoCameraDataReason, 0) == 0) reason += " (" + hint + ")";
  ROS_WARN_THROTTLE(2.0, "%s: rest %s-%s s not used: %s", name.c_str(),
                    formatStamp(rejected.start_s).c_str(), formatStamp(rejected.end_s).c_str(),
                    reason.c_str());
}

void AlignmentWrapper::Impl::onEstimate(const EstimateEvent& event) {
  const CalibrationProgress progress = progressOf(event, settings.online.max_std_dev_deg);
  // What the window held: poses at rest, camera orientations during motion, or both.
  const int nodes = event.result.joint ? event.result.joint->motion_nodes : 0;
  std::string from;
  if (event.window_poses > 0 || nodes == 0) from = std::to_string(event.window_poses) + " poses";
  if (nodes > 0) {
    from += (from.empty() ? "" : " and ") + std::to_string(nodes) +
            " camera orientations during motion";
  }
  ROS_INFO("%s: estimate from %s: %s", name.c_str(), from.c_str(), progressText(progress).c_str());
  if (event.gate.decision == GateDecision::kReject) {
    ROS_INFO_THROTTLE(2.0, "%s: estimate not broadcast: %s", name.c_str(), event.gate.why.c_str());
  } else if (event.gate.decision == GateDecision::kKeep) {
    ROS_INFO_THROTTLE(2.0, "%s: estimate kept back, the tf stays: %s", name.c_str(),
                      event.gate.why.c_str());
  }
  publishStatus();
}

void AlignmentWrapper::Impl::onRemount(const RemountEvent& event) {
  ROS_WARN("%s: %s", name.c_str(), event.message.c_str());
  publishPoses();
}

void AlignmentWrapper::Impl::onClockJump(double jump_s, InputStream stream) {
  ROS_WARN(
      "%s: %s: time jumped back by %.1f s (bag loop or restarted clock): buffers reset, the "
      "broadcast calibration is kept",
      name.c_str(), topicOf(stream).c_str(), jump_s);
}

void AlignmentWrapper::Impl::onReject(RejectReason reason, InputStream stream,
                                      const std::string& detail) {
  const ros::WallTime now = ros::WallTime::now();
  ros::WallTime& last = last_reject_warning[{stream, reason}];
  std::uint64_t& unwarned = unwarned_rejects[{stream, reason}];
  if (!last.isZero() && (now - last).toSec() < 5.0) {
    ++unwarned;
    return;
  }
  last = now;
  const std::string more =
      unwarned > 0 ? " (+" + std::to_string(unwarned) + " more since the last such warning)" : "";
  unwarned = 0;
  ROS_WARN("%s: %s: rejected (%s): %s%s", name.c_str(), topicOf(stream).c_str(), toString(reason),
           detail.c_str(), more.c_str());
}

}  // namespace camera_imu_alignment
