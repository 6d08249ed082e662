// AlignmentWrapper, input side: settings, target, subscriptions, message conversion, the
// pipeline and its callbacks.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include <image_transport/camera_common.h>

#include "alignment_wrapper_impl.h"
#include "camera_imu_alignment/io/input_error.h"
#include "camera_imu_alignment/ros/message_conversion.h"
#include "camera_imu_alignment/solver/solution_quality.h"
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
      diagnostics(nh_, private_nh) {
  readSettings(pnh, &settings, &pipeline_settings);
  for (const std::string& notice : resolvePaths(&settings)) {
    ROS_WARN("%s: %s", name.c_str(), notice.c_str());
  }
  const TargetDescription target = loadTargetYaml(settings.target_file);
  PipelineCallbacks callbacks;
  callbacks.on_pose = [this](const StationaryPose& p) { onPose(p); };
  callbacks.on_pose_rejected = [this](const RejectedPose& r) { onPoseRejected(r); };
  callbacks.on_result = [this](const AlignmentResult& r) { onResult(r); };
  callbacks.on_reject = [this](RejectReason reason, InputStream stream, const std::string& d) {
    onReject(reason, stream, d);
  };
  pipeline = std::make_unique<CalibrationPipeline>(target, pipeline_settings, callbacks);
  input = std::make_unique<MessageInput>(pipeline.get(), [this](const std::string& notice) {
    ROS_WARN("%s: %s", name.c_str(), notice.c_str());
  });
  input->setTopicNames([this](InputStream stream) { return topicOf(stream); });
  debug_detector = std::make_unique<TargetDetector>(target, pipeline_settings.detector);
  ROS_INFO_STREAM(name << ": target " << target.describe() << " from " << settings.target_file);

  advertise();
  if (settings.load_on_start) loadSaved();
  imu_sub = nh.subscribe("imu/data_raw", 2000, &Impl::onImu, this);
  mag_sub = nh.subscribe("imu/mag", 2000, &Impl::onMag, this);
  subscribeCamera();
  camera_pose_sub = nh.subscribe("camera_pose", 100, &Impl::onCameraPose, this);
  stale_timer = nh.createWallTimer(ros::WallDuration(0.5), [this](const auto&) { checkStale(); });
  ROS_INFO_STREAM(name << ": listening on " << imu_sub.getTopic() << ", " << mag_sub.getTopic()
                       << ", " << topicOf(InputStream::kImage) << " (+ "
                       << topicOf(InputStream::kCameraInfo) << "), " << camera_pose_sub.getTopic());
}

void AlignmentWrapper::Impl::subscribeCamera() {
  if (settings.image_transport != "compressed") {
    camera_sub = transport.subscribeCamera("camera/image_raw", 30, &Impl::onImage, this,
                                           image_transport::TransportHints("raw"));
    return;
  }
  // As image_transport names them: the remapped image topic, "/compressed" appended; camera_info
  // beside the image topic.
  const std::string image_topic = nh.resolveName("camera/image_raw");
  compressed_sub = nh.subscribe(image_topic + "/compressed", 30, &Impl::onCompressedImage, this);
  info_sub = nh.subscribe<sensor_msgs::CameraInfo>(
      image_transport::getCameraInfoTopic(image_topic), 10,
      [this](const sensor_msgs::CameraInfoConstPtr& info) { latest_info = info; });
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

bool AlignmentWrapper::Impl::acceptStamp(const std_msgs::Header& header, InputStream stream) {
  if (!input->checkStamp(header, stream)) return false;
  const double jump_s = clock.update(toString(stream), header.stamp.toSec());
  if (jump_s > 0.0) {
    ROS_WARN(
        "%s: %s: time jumped back by %.1f s (bag loop or restarted "
        "clock): buffers reset, the broadcast calibration is kept",
        name.c_str(), topicOf(stream).c_str(), jump_s);
    pipeline->reset();
    inconsistent_poses = 0;
  }
  return true;
}

void AlignmentWrapper::Impl::applyPendingReset() {
  if (!reset_requested) return;
  reset_requested = false;
  pipeline->reset();
}

void AlignmentWrapper::Impl::checkStale() {
  if (input_stopped || (ros::WallTime::now() - last_imu_wall).toSec() < 2.0) return;
  input_stopped = true;
  ROS_INFO("%s: no IMU data for 2 s on %s: closing the rest in progress", name.c_str(),
           imu_sub.getTopic().c_str());
  pipeline->finish();
  applyPendingReset();
  publishStatus();
}

void AlignmentWrapper::Impl::onImu(const sensor_msgs::ImuConstPtr& msg) {
  if (!acceptStamp(msg->header, InputStream::kImu)) return;
  last_imu_wall = ros::WallTime::now();
  input_stopped = false;
  ++imu_count;
  input->addImu(*msg);
  if (pipeline->imuGaps() != imu_gaps_warned) {  // differs also after a reset clearing counts
    imu_gaps_warned = pipeline->imuGaps();
    if (imu_gaps_warned > 0) {
      ROS_WARN_THROTTLE(5.0,
                        "%s: %s: gap in the IMU data (more than max_imu_gap_s = "
                        "%.2f s; %lu so far): a rest in progress ended there",
                        name.c_str(), imu_sub.getTopic().c_str(),
                        pipeline_settings.stationary.max_gap_s,
                        static_cast<unsigned long>(imu_gaps_warned));
    }
  }
  applyPendingReset();
}

void AlignmentWrapper::Impl::onMag(const sensor_msgs::MagneticFieldConstPtr& msg) {
  if (!acceptStamp(msg->header, InputStream::kMagnetometer)) return;
  ++mag_count;
  if (!tf_buffer && !input->imuFrame().empty() &&
      normalizeFrameId(msg->header.frame_id) != input->imuFrame()) {
    // The magnetometer has a frame of its own: its rotation into the IMU frame comes from tf.
    tf_buffer = std::make_unique<tf2_ros::Buffer>();
    tf_listener = std::make_unique<tf2_ros::TransformListener>(*tf_buffer, nh);
    input->setTransforms(tf_buffer.get(), std::chrono::seconds(1));  // tf arriving
  }
  input->addMagnetic(*msg);
  applyPendingReset();
}

void AlignmentWrapper::Impl::onImage(const sensor_msgs::ImageConstPtr& image,
                                     const sensor_msgs::CameraInfoConstPtr& info) {
  if (!acceptStamp(image->header, InputStream::kImage)) return;
  handleImage(*image, *info);
}

void AlignmentWrapper::Impl::onCompressedImage(const sensor_msgs::CompressedImageConstPtr& image) {
  if (!acceptStamp(image->header, InputStream::kImage)) return;
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
  const bool wanted = !settings.manual_capture || capture_armed;  // manual: poses only when asked
  const bool debug = debug_pub.getNumSubscribers() > 0;
  if (!wanted && !debug) return;
  cv::Mat mono8;
  if (!input->addImage(image, wanted, &mono8)) return;
  if (wanted) applyPendingReset();
  if (debug) publishDebugImage(mono8, image.header);
}

void AlignmentWrapper::Impl::onCameraPose(const geometry_msgs::PoseStampedConstPtr& msg) {
  if (!acceptStamp(msg->header, InputStream::kCameraPose)) return;
  ++image_count;
  input->addCameraPose(*msg, !settings.manual_capture || capture_armed);
  applyPendingReset();
}

void AlignmentWrapper::Impl::onPose(const StationaryPose& pose) {
  last_pose = pose;
  capture_armed = false;
  ROS_INFO("%s: stationary pose %d (%.1f s, %d frames, IMU from %s)", name.c_str(), pose.index,
           pose.end_s - pose.start_s, pose.num_frames, toString(pose.imu_source));
  // Remount check: the new pose's pairs with the rest of the window against the broadcast estimate.
  if (broadcast_R) {
    const RotationPairs pairs = pipeline->windowPairs();
    int newest = -1;
    for (const auto& p : pairs) newest = std::max(newest, p.pose_t);
    double sum_sq = 0.0;
    int count = 0;
    for (const auto& p : pairs) {
      if (p.pose_t != newest) continue;
      sum_sq += pairResidual(p, *broadcast_R).squaredNorm();
      ++count;
    }
    const double rms_deg = count > 0 ? std::sqrt(sum_sq / count) * 180.0 / M_PI : 0.0;
    inconsistent_poses = rms_deg > settings.remount_residual_deg ? inconsistent_poses + 1 : 0;
    if (inconsistent_poses > 0) {
      ROS_WARN(
          "%s: pose %d disagrees with the calibration by %.2f deg RMS (%d "
          "in a row, %d restart the window)",
          name.c_str(), pose.index, rms_deg, inconsistent_poses, settings.remount_poses);
    }
    if (inconsistent_poses >= settings.remount_poses) {
      pipeline->keepNewestPoses(static_cast<std::size_t>(settings.remount_poses));
      inconsistent_poses = 0;
      recalibrating = true;
      state = "recalibrating";
      state_message =
          "the last poses disagree with the calibration (mount moved?): window "
          "restarted from them";
      ROS_WARN("%s: %s", name.c_str(), state_message.c_str());
    }
  }
  publishPoses();
  publishStatus();
}

void AlignmentWrapper::Impl::onPoseRejected(const RejectedPose& rejected) {
  // manual_capture: a rest during which ~capture_pose was not called saw no camera data on
  // purpose; the pipeline's reason ("no camera data") would send the user looking for a fault.
  const std::string reason =
      settings.manual_capture && !capture_armed
          ? "not armed (manual_capture: call ~capture_pose during a rest to make it a pose)"
          : rejected.reason;
  capture_armed = false;
  ROS_WARN_THROTTLE(2.0, "%s: rest %s-%s s not used: %s", name.c_str(),
                    formatStamp(rejected.start_s).c_str(), formatStamp(rejected.end_s).c_str(),
                    reason.c_str());
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
