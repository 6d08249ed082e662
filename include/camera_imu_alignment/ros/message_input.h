// The ROS boundary of the calibration pipeline, shared by the nodelet and calibrate_bag so that
// both accept and refuse exactly the same messages.
//
// It checks what only a ROS message can get wrong, converts (message_conversion.h) and feeds the
// CalibrationPipeline, which checks the values (NaN/Inf, zero vectors, stamp order, magnetometer
// units). Refused here, each counted by reason in pipeline->rejections() and reported through the
// pipeline's on_reject callback like the pipeline's own refusals:
//   missing_stamp    header stamp zero (the driver never set it)
//   bad_camera_info  zero or non-finite K, D of a wrong length, unknown distortion model, no size
//   bad_image        unsupported encoding, empty or short data, a size other than the camera info's
//   non_finite       a camera_pose orientation that is not a unit quaternion
// Frame ids are kept without a leading slash (tf2 refuses "/imu"). A magnetometer whose frame_id
// differs from the IMU's is rotated into the IMU frame when the caller knows the rotation
// (setMagnetometerRotation, or looked up in tf: setTransforms), and otherwise assumed to share the
// IMU's axes, with a notice. With imu_orientation: message, Imu messages without an orientation
// (the pipeline then uses the gyro and accelerometer) are noted once, naming the topic.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>
#include <tf2/buffer_core.h>

#include <Eigen/Core>
#include <chrono>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "camera_imu_alignment/pipeline/sample_sink.h"

namespace camera_imu_alignment {

/// "/imu" -> "imu" (tf2 frame ids carry no leading slash).
std::string normalizeFrameId(const std::string& frame_id);

class MessageInput {
 public:
  /// `pipeline` must outlive this object. `notice` receives one-time remarks about the inputs
  /// (frame ids); may be empty.
  explicit MessageInput(SampleSink* pipeline, std::function<void(const std::string&)> notice = {});

  void addImu(const sensor_msgs::Imu& msg);
  void addMagnetic(const sensor_msgs::MagneticField& msg);
  /// Converts and hands the intrinsics to the pipeline when they differ from those in use.
  /// False (counted as bad_camera_info) when unusable; the previous intrinsics stay in use.
  bool setCameraInfo(const sensor_msgs::CameraInfo& msg);
  /// Converts an image to grey and, when `feed`, adds it to the pipeline as a frame. False
  /// (counted) for a missing stamp, a conversion failure or a size other than the camera info's.
  /// `mono8` (optional) receives the grey image, e.g. for a debug view.
  bool addImage(const sensor_msgs::Image& msg, bool feed = true, cv::Mat* mono8 = nullptr);
  bool addImage(const sensor_msgs::CompressedImage& msg, bool feed = true,
                cv::Mat* mono8 = nullptr);
  /// A camera orientation given by the user (the camera in the target frame): no detection. Its
  /// frame_id is the target's, so it does not name the camera frame.
  bool addCameraPose(const geometry_msgs::PoseStamped& msg, bool feed = true);
  /// False (counted as missing_stamp) when the header stamp is zero.
  bool checkStamp(const std_msgs::Header& header, InputStream stream);

  /// The topic each stream arrives on, to name it in notices (the nodelet's resolved topics,
  /// calibrate_bag's bag topics); without it notices name the stream ("imu").
  void setTopicNames(std::function<std::string(InputStream)> topic_of);

  /// R_imu_mag: maps magnetometer-frame vectors into the IMU frame (from tf, when frames differ).
  void setMagnetometerRotation(const Eigen::Matrix3d& R_imu_mag);
  bool hasMagnetometerRotation() const { return R_imu_mag_.has_value(); }
  /// True when the magnetometer's frame_id differs from the IMU's (both seen) and no rotation is
  /// set for these two frames (a changed frame id drops the old one): the caller may look one up.
  bool needsMagnetometerRotation() const;
  /// Where R_imu_mag is looked up (latest transform magnetometer frame -> IMU frame) when the two
  /// frames differ: from the first magnetometer message of a new pair of frames, every 0.1 s for
  /// `grace` of wall time, its samples dropped meanwhile (a live tf listener may still be
  /// receiving /tf_static; 0 when `tf` is complete, as a bag's), then at most once a second with
  /// the IMU's axes assumed (a notice says which). `tf` must outlive this object; nullptr: never.
  void setTransforms(const tf2::BufferCore* tf,
                     std::chrono::milliseconds grace = std::chrono::milliseconds(0));

  /// The latest frame id of each input (camera: the images'), without a leading slash ("" before
  /// the first).
  const std::string& imuFrame() const { return imu_frame_; }
  const std::string& magFrame() const { return mag_frame_; }
  const std::string& cameraFrame() const { return camera_frame_; }

 private:
  bool finishImage(const std_msgs::Header& header, bool converted, const std::string& error,
                   cv::Mat grey, bool feed, cv::Mat* mono8);
  void noteFrame(const std::string& frame_id, std::string* kept, const char* input);
  void checkMagFrame();
  /// imu_orientation: message and the Imu messages carry none: a notice once (again after
  /// messages with an orientation came in between), naming the topic.
  void checkMessageOrientation(const ImuSample& sample);
  std::string topicOf(InputStream stream) const;
  void lookUpMagnetometerRotation();
  bool waitingForRotation() const;

  SampleSink* pipeline_;
  std::function<void(const std::string&)> notice_;
  std::string imu_frame_, mag_frame_, camera_frame_;
  std::string noted_frame_pair_;  ///< IMU and magnetometer frames last noted as different
  std::optional<Eigen::Matrix3d> R_imu_mag_;
  const tf2::BufferCore* tf_ = nullptr;
  std::chrono::milliseconds grace_{0};                 ///< see setTransforms
  std::chrono::steady_clock::time_point last_lookup_;  ///< of R_imu_mag (throttled)
  std::optional<std::chrono::steady_clock::time_point> waiting_since_;  ///< first needed
  std::optional<sensor_msgs::CameraInfo> info_in_use_;  ///< the last accepted camera info
  std::function<std::string(InputStream)> topic_of_;
  bool noted_missing_orientation_ = false;
};

}  // namespace camera_imu_alignment
