// AlignmentWrapper, input side: settings, target, subscriptions, message conversion, the
// pipeline and its callbacks.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "alignment_wrapper_impl.h"
#include "camera_imu_alignment/csv_io.h"
#include "camera_imu_alignment/ros/message_conversion.h"
#include "camera_imu_alignment/solution_quality.h"
#include "camera_imu_alignment/target_description.h"

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
  callbacks.on_reject = [this](RejectReason reason, const std::string& d) { onReject(reason, d); };
  pipeline = std::make_unique<CalibrationPipeline>(target, pipeline_settings, callbacks);
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

bool AlignmentWrapper::Impl::acceptStamp(const ros::Time& stamp, const char* topic) {
  const double t = stamp.toSec();
  if (t <= 0.0) {
    ROS_WARN_THROTTLE(5.0, "camera_imu_alignment: %s: message without a stamp dropped", topic);
    return false;
  }
  // Per topic: a camera's stamps may lag the IMU's by its latency; only a topic going back on
  // itself is a jump.
  double& last = last_stamp_by_topic[topic];
  if (last > 0.0 && t < last - 1.0) {
    ROS_WARN(
        "camera_imu_alignment: %s: time jumped back by %.1f s (bag loop or restarted "
        "clock): buffers reset, the broadcast calibration is kept",
        topic, last - t);
    pipeline->reset();
    inconsistent_poses = 0;
    last_stamp_by_topic.clear();
    last_stamp_by_topic[topic] = t;
    last_stamp_s = t;
    return true;
  }
  last = std::max(last, t);
  last_stamp_s = std::max(last_stamp_s, t);
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
  ROS_INFO("camera_imu_alignment: no IMU data for 2 s: closing the rest in progress");
  pipeline->finish();
  applyPendingReset();
  publishStatus();
}

void AlignmentWrapper::Impl::onImu(const sensor_msgs::ImuConstPtr& msg) {
  if (!acceptStamp(msg->header.stamp, "imu")) return;
  imu_msg_frame = msg->header.frame_id;
  last_imu_wall = ros::WallTime::now();
  input_stopped = false;
  ++imu_count;
  pipeline->addImu(toImuSample(*msg));
  applyPendingReset();
}

void AlignmentWrapper::Impl::onMag(const sensor_msgs::MagneticFieldConstPtr& msg) {
  if (!acceptStamp(msg->header.stamp, "imu/mag")) return;
  ++mag_count;
  pipeline->addMagnetic(toMagneticSample(*msg));
  applyPendingReset();
}

void AlignmentWrapper::Impl::onImage(const sensor_msgs::ImageConstPtr& image,
                                     const sensor_msgs::CameraInfoConstPtr& info) {
  if (!acceptStamp(image->header.stamp, "camera")) return;
  image_frame = image->header.frame_id;
  ++image_count;
  if (info->K != last_info.K || info->D != last_info.D || info->width != last_info.width ||
      info->height != last_info.height || info->distortion_model != last_info.distortion_model) {
    CameraIntrinsics intrinsics;
    std::string error;
    if (!toCameraIntrinsics(*info, &intrinsics, &error)) {
      ROS_WARN_THROTTLE(5.0, "camera_imu_alignment: %s: unusable camera info: %s",
                        camera_sub.getInfoTopic().c_str(), error.c_str());
      return;
    }
    if (pipeline->setCameraIntrinsics(intrinsics)) last_info = *info;
  }
  const bool wanted = !settings.manual_capture || capture_armed;  // manual: poses only when asked
  if (!wanted && debug_pub.getNumSubscribers() == 0) return;
  cv::Mat mono8;
  std::string error;
  if (!toMono8(*image, &mono8, &error)) {
    ROS_WARN_THROTTLE(5.0, "camera_imu_alignment: %s: %s", camera_sub.getTopic().c_str(),
                      error.c_str());
    return;
  }
  if (wanted) {
    pipeline->addFrame({image->header.stamp.toSec(), mono8});
    applyPendingReset();
  }
  publishDebugImage(mono8, image->header);
}

void AlignmentWrapper::Impl::onCameraPose(const geometry_msgs::PoseStampedConstPtr& msg) {
  if (!acceptStamp(msg->header.stamp, "camera_pose")) return;
  if (image_frame.empty()) image_frame = msg->header.frame_id;  // until an image names the camera
  ++image_count;
  const auto& q = msg->pose.orientation;
  const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
    ROS_WARN_THROTTLE(5.0,
                      "camera_imu_alignment: %s: orientation is not a unit quaternion "
                      "(norm %g); pose dropped",
                      camera_pose_sub.getTopic().c_str(), norm);
    return;
  }
  if (settings.manual_capture && !capture_armed) return;
  CameraFrame frame;
  frame.stamp_s = msg->header.stamp.toSec();
  frame.R_target_cam = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
  pipeline->addFrame(frame);
  applyPendingReset();
}

void AlignmentWrapper::Impl::onPose(const StationaryPose& pose) {
  last_pose = pose;
  capture_armed = false;
  ROS_INFO("camera_imu_alignment: stationary pose %d (%.1f s, %d frames, IMU from %s)", pose.index,
           pose.end_s - pose.start_s, pose.num_frames, pose.imu_source.c_str());
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

void AlignmentWrapper::Impl::onReject(RejectReason reason, const std::string& detail) {
  ROS_WARN_THROTTLE(5.0, "camera_imu_alignment: %s: %s", rejectReasonName(reason), detail.c_str());
}

}  // namespace camera_imu_alignment
