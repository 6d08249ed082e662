// AlignmentWrapper, input side: settings, target, subscriptions, message conversion, the
// pipeline and its callbacks.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

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
    : nh(nh_), pnh(private_nh), transport(nh_), diagnostics(nh_, private_nh) {
  readSettings(pnh, &settings, &pipeline_settings);
  const TargetDescription target = loadTargetYaml(settings.target_file);
  PipelineCallbacks callbacks;
  callbacks.on_pose = [this](const StationaryPose& p) { onPose(p); };
  callbacks.on_pose_rejected = [this](const RejectedPose& r) { onPoseRejected(r); };
  callbacks.on_result = [this](const AlignmentResult& r) { onResult(r); };
  callbacks.on_reject = [this](RejectReason reason, InputStream stream, const std::string& d) {
    onReject(reason, stream, d);
  };
  pipeline = std::make_unique<CalibrationPipeline>(target, pipeline_settings, callbacks);
  input = std::make_unique<MessageInput>(pipeline.get(), [](const std::string& notice) {
    ROS_WARN("camera_imu_alignment: %s", notice.c_str());
  });
  debug_detector = std::make_unique<TargetDetector>(target, pipeline_settings.detector);
  ROS_INFO_STREAM("camera_imu_alignment: target " << target.describe() << " from "
                                                  << settings.target_file);

  advertise();
  if (settings.load_on_start) loadSaved();
  imu_sub = nh.subscribe("imu/data_raw", 2000, &Impl::onImu, this);
  mag_sub = nh.subscribe("imu/mag", 2000, &Impl::onMag, this);
  camera_sub = transport.subscribeCamera("camera/image_raw", 30, &Impl::onImage, this,
                                         image_transport::TransportHints(settings.image_transport));
  camera_pose_sub = nh.subscribe("camera_pose", 100, &Impl::onCameraPose, this);
  stale_timer = nh.createWallTimer(ros::WallDuration(0.5), [this](const auto&) { checkStale(); });
  ROS_INFO_STREAM("camera_imu_alignment: listening on "
                  << imu_sub.getTopic() << ", " << mag_sub.getTopic() << ", "
                  << camera_sub.getTopic() << " (+ " << camera_sub.getInfoTopic() << ")");
}

std::string AlignmentWrapper::Impl::topicOf(InputStream stream) const {
  switch (stream) {
    case InputStream::kImu:
      return imu_sub.getTopic();
    case InputStream::kMagnetometer:
      return mag_sub.getTopic();
    case InputStream::kImage:
      return camera_sub.getTopic();
    case InputStream::kCameraInfo:
      return camera_sub.getInfoTopic();
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
        "camera_imu_alignment: %s: time jumped back by %.1f s (bag loop or restarted "
        "clock): buffers reset, the broadcast calibration is kept",
        topicOf(stream).c_str(), jump_s);
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
  ROS_INFO("camera_imu_alignment: no IMU data for 2 s on %s: closing the rest in progress",
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
                        "camera_imu_alignment: %s: gap in the IMU data (more than max_imu_gap_s = "
                        "%.2f s; %lu so far): a rest in progress ended there",
                        imu_sub.getTopic().c_str(), pipeline_settings.stationary.max_gap_s,
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
  ++image_count;
  if (!input->setCameraInfo(*info)) return;
  const bool wanted = !settings.manual_capture || capture_armed;  // manual: poses only when asked
  const bool debug = debug_pub.getNumSubscribers() > 0;
  if (!wanted && !debug) return;
  cv::Mat mono8;
  if (!input->addImage(*image, wanted, &mono8)) return;
  if (wanted) applyPendingReset();
  if (debug) publishDebugImage(mono8, image->header);
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
  ROS_INFO("camera_imu_alignment: stationary pose %d (%.1f s, %d frames, IMU from %s)", pose.index,
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
          "camera_imu_alignment: pose %d disagrees with the calibration by %.2f deg RMS (%d "
          "in a row, %d restart the window)",
          pose.index, rms_deg, inconsistent_poses, settings.remount_poses);
    }
    if (inconsistent_poses >= settings.remount_poses) {
      pipeline->keepNewestPoses(static_cast<std::size_t>(settings.remount_poses));
      inconsistent_poses = 0;
      recalibrating = true;
      state = "recalibrating";
      state_message =
          "the last poses disagree with the calibration (mount moved?): window "
          "restarted from them";
      ROS_WARN("camera_imu_alignment: %s", state_message.c_str());
    }
  }
  publishPoses();
  publishStatus();
}

void AlignmentWrapper::Impl::onPoseRejected(const RejectedPose& rejected) {
  capture_armed = false;
  ROS_WARN_THROTTLE(2.0, "camera_imu_alignment: rest %.1f-%.1f s not used: %s", rejected.start_s,
                    rejected.end_s, rejected.reason.c_str());
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
  ROS_WARN("camera_imu_alignment: %s: rejected (%s): %s%s", topicOf(stream).c_str(),
           toString(reason), detail.c_str(), more.c_str());
}

}  // namespace camera_imu_alignment
