// Private state of AlignmentWrapper, shared by its two source files (inputs: alignment_wrapper.cpp;
// tf, status, files, services, diagnostics: alignment_outputs.cpp). The policy (gates, remount,
// state) is the OnlineCalibrator's; this is the ROS side only. Not installed.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseStamped.h>
#include <image_transport/image_transport.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "camera_imu_alignment/Calibrate.h"
#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/ros/alignment_wrapper.h"
#include "camera_imu_alignment/ros/message_input.h"
#include "camera_imu_alignment/ros/stream_watch.h"
#include "camera_imu_alignment/ros/wrapper_settings.h"
#include "camera_imu_alignment/vision/target_detector.h"

namespace camera_imu_alignment {

struct AlignmentWrapper::Impl {
  Impl(ros::NodeHandle nh, ros::NodeHandle private_nh);

  ros::NodeHandle nh, pnh;
  /// The instance's name (its private namespace, e.g. "/camera_imu_alignment"): every log line
  /// starts with it, so that two instances in one manager can be told apart.
  std::string name;
  WrapperSettings settings;
  PipelineSettings pipeline_settings;
  std::unique_ptr<OnlineCalibrator> calibrator;

  // --- inputs
  // The magnetometer's frame differs from the IMU's: R_imu_mag from tf, looked up by MessageInput
  // (declared before the subscribers, so that it outlives their callbacks).
  std::unique_ptr<tf2_ros::Buffer> tf_buffer;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener;
  image_transport::ImageTransport transport;
  ros::Subscriber imu_sub, mag_sub, camera_pose_sub;
  image_transport::CameraSubscriber camera_sub;  ///< image_transport raw (image + camera info)
  // image_transport: compressed (Debian ships no compressed image_transport plugin): our own
  // subscriptions to <image topic>/compressed and the sibling camera_info, whose latest message
  // goes with each image.
  ros::Subscriber compressed_sub, info_sub;
  /// raw transport: the image and camera info topics each on their own as well, to tell a silent
  /// image topic from a silent camera info topic (image_transport only calls back with both).
  ros::Subscriber info_watch_sub, image_watch_sub;
  bool camera_pose_frame_noted = false;  ///< the camera frame camera_pose input uses was said
  sensor_msgs::CameraInfoConstPtr latest_info;
  std::unique_ptr<MessageInput> input;  ///< the checks and conversions calibrate_bag uses too
  ros::WallTime last_imu_wall;          ///< receipt time of the newest IMU message
  bool input_stopped = true;            ///< no IMU for a while: the rest in progress was closed
  ros::WallTimer stale_timer, poll_timer;
  std::uint64_t imu_gaps_warned = 0;  ///< imuGaps() when last warned about
  StreamWatch streams;                ///< silent topics while others flow
  std::map<InputStream, ros::WallTime> last_silent_warning;
  bool mag_absence_noted = false;
  /// IMU silent for 2 s of wall time (a bag ended, a driver stopped): close the rest in progress
  /// so that the last pose counts. Also warns about silent topics.
  void checkStale();
  void warnSilentStreams();
  std::vector<InputStream> silentStreams() const;
  void onImu(const sensor_msgs::ImuConstPtr& msg);
  void onMag(const sensor_msgs::MagneticFieldConstPtr& msg);
  void onImage(const sensor_msgs::ImageConstPtr& image,
               const sensor_msgs::CameraInfoConstPtr& info);
  void onCompressedImage(const sensor_msgs::CompressedImageConstPtr& image);
  /// The part of onImage and onCompressedImage after the stamp check (same conversion code as
  /// calibrate_bag: MessageInput::addImage for either message type).
  template <typename ImageMessage>
  void handleImage(const ImageMessage& image, const sensor_msgs::CameraInfo& info);
  /// Subscribes to the camera as settings.image_transport says.
  void subscribeCamera();
  /// camera_pose (geometry_msgs/PoseStamped, the camera in the target frame): orientations from
  /// the user's own detector or motion capture instead of images.
  void onCameraPose(const geometry_msgs::PoseStampedConstPtr& msg);
  /// The topic an input stream arrives on (resolved name), for messages.
  std::string topicOf(InputStream stream) const;
  /// Which camera topic is silent while the other flows ("" when both or neither flow, or camera
  /// poses come): appended to a rest's "no camera data" so that it names the topic to fix.
  std::string cameraInputHint() const;
  /// "" unless the image topic of the other transport (raw <-> compressed) is published: then
  /// "; <topic> is published: image_transport <other> (...)", for the silent-image warning.
  std::string otherTransportHint() const;

  // --- the calibrator's events
  void onPose(const StationaryPose& pose);
  void onPoseRejected(const RejectedPose& rejected);
  void onEstimate(const EstimateEvent& event);
  void onBroadcast(const BroadcastEstimate& estimate);
  void onRemount(const RemountEvent& event);
  void onClockJump(double jump_s, InputStream stream);
  void onReject(RejectReason reason, InputStream stream, const std::string& detail);
  /// Warnings are throttled per input and reason: a flood of one kind hides no other.
  std::map<std::pair<InputStream, RejectReason>, ros::WallTime> last_reject_warning;
  std::map<std::pair<InputStream, RejectReason>, std::uint64_t> unwarned_rejects;

  // --- outputs (alignment_outputs.cpp)
  tf2_ros::StaticTransformBroadcaster broadcaster;
  tf2_ros::TransformBroadcaster target_broadcaster;  ///< camera -> calibration_target (rviz)
  ros::Publisher status_pub, poses_pub, target_pose_pub;
  image_transport::Publisher debug_pub;
  std::unique_ptr<TargetDetector> debug_detector;  ///< for ~debug_image only
  ros::WallTime last_debug;
  /// Draws the detected target points on `mono8` and publishes it, at most 5 per second and only
  /// while someone subscribes to ~debug_image.
  void publishDebugImage(const cv::Mat& mono8, const std_msgs::Header& header);
  // Input counts since the last diagnostics update (rates).
  std::uint64_t imu_count = 0, mag_count = 0, image_count = 0;
  ros::WallTime last_diagnostics = ros::WallTime::now();
  ros::ServiceServer calibrate_srv, reset_srv, save_srv, capture_srv;
  ros::WallTimer status_timer;
  diagnostic_updater::Updater diagnostics;
  std::string saved_camera_frame,
      saved_imu_frame;  ///< from the loaded file, until inputs name them

  void advertise();
  /// The static tf for R_cam_imu.
  void sendTransform(const Eigen::Matrix3d& R_cam_imu);
  /// Writes the broadcast estimate with its own quality (poses behind it, 1-sigma) to output_file.
  bool save(const BroadcastEstimate& estimate, std::string* error);
  std::optional<Eigen::Matrix3d> sent_R_cam_imu;  ///< what the static tf says (none before)
  std::string save_error;  ///< why the last save failed ("" after a good one): diagnostics
  void loadSaved();
  /// Called with every broadcast: says when an estimate replaces a calibration loaded from a file
  /// (WARN when more than 1 deg apart), naming the file and the angle.
  void noteReplacedBroadcast(const BroadcastEstimate& estimate);
  std::optional<std::pair<std::string, Eigen::Matrix3d>> previous_broadcast;  ///< source, R
  /// Before the first write of this run over an existing output_file: copies it to
  /// `<output_file>.bak` (said at INFO; a failed copy is warned about and the save goes on).
  void backUpOutputOnce();
  bool output_backed_up = false;
  void publishStatus();
  void publishPoses();  ///< ~stationary_poses and ~target_pose
  std::string cameraFrame() const;
  std::string imuFrame() const;
  bool onCalibrate(Calibrate::Request& req, Calibrate::Response& res);
  bool onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onSave(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onCapturePose(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
};

}  // namespace camera_imu_alignment
