// MessageInput: the checks only ROS messages need, then conversion and the pipeline.
#include "camera_imu_alignment/ros/message_input.h"

#include <tf2/exceptions.h>

#include <cmath>
#include <sstream>

#include "camera_imu_alignment/ros/message_conversion.h"

namespace camera_imu_alignment {

std::string normalizeFrameId(const std::string& frame_id) {
  std::size_t start = 0;
  while (start < frame_id.size() && frame_id[start] == '/') ++start;
  return frame_id.substr(start);
}

MessageInput::MessageInput(SampleSink* pipeline, std::function<void(const std::string&)> notice)
    : pipeline_(pipeline), notice_(std::move(notice)) {}

bool MessageInput::checkStamp(const std_msgs::Header& header, InputStream stream) {
  if (!header.stamp.isZero()) return true;
  pipeline_->rejectInput(RejectReason::kMissingStamp, stream,
                         "header stamp is zero (the driver did not set it); message dropped");
  return false;
}

void MessageInput::noteFrame(const std::string& frame_id, std::string* kept, const char* input) {
  if (frame_id.empty() || frame_id == *kept) return;
  const std::string normalized = normalizeFrameId(frame_id);
  if (normalized == *kept) return;                 // the same frame, with and without the slash
  if (!kept->empty() && kept != &camera_frame_) {  // a rotation found for other frames is void
    R_imu_mag_.reset();
    last_lookup_ = std::chrono::steady_clock::time_point{};
    waiting_since_.reset();
  }
  *kept = normalized;
  if (normalized != frame_id && notice_) {
    notice_(std::string(input) + " frame_id '" + frame_id + "' starts with '/': used as '" +
            normalized + "' (tf2 frame ids have no leading slash)");
  }
}

bool MessageInput::needsMagnetometerRotation() const {
  return !R_imu_mag_ && !imu_frame_.empty() && !mag_frame_.empty() && imu_frame_ != mag_frame_;
}

void MessageInput::checkMagFrame() {
  const std::string pair = imu_frame_ + "\n" + mag_frame_;
  if (pair == noted_frame_pair_ || !needsMagnetometerRotation() || waitingForRotation()) return;
  noted_frame_pair_ = pair;
  if (notice_) {
    notice_("the magnetometer's frame_id '" + mag_frame_ + "' differs from the IMU's '" +
            imu_frame_ +
            "': its axes are taken to be the IMU's unless a rotation between the two frames is "
            "known (tf)");
  }
}

void MessageInput::setMagnetometerRotation(const Eigen::Matrix3d& R_imu_mag) {
  R_imu_mag_ = R_imu_mag;
}

void MessageInput::setTransforms(const tf2::BufferCore* tf, std::chrono::milliseconds grace) {
  tf_ = tf;
  grace_ = grace;
  last_lookup_ = std::chrono::steady_clock::time_point{};
  waiting_since_.reset();
}

bool MessageInput::waitingForRotation() const {
  return tf_ && needsMagnetometerRotation() && waiting_since_ &&
         std::chrono::steady_clock::now() - *waiting_since_ < grace_;
}

void MessageInput::lookUpMagnetometerRotation() {
  if (!tf_ || !needsMagnetometerRotation()) return;
  const auto now = std::chrono::steady_clock::now();
  if (!waiting_since_) waiting_since_ = now;
  const auto retry = now - *waiting_since_ < grace_ ? std::chrono::milliseconds(100)
                                                    : std::chrono::milliseconds(1000);
  if (now - last_lookup_ < retry) return;
  last_lookup_ = now;
  geometry_msgs::TransformStamped t;
  try {
    t = tf_->lookupTransform(imu_frame_, mag_frame_, ros::Time(0));
  } catch (const tf2::TransformException&) {
    return;  // not (yet) known
  }
  const std::optional<Eigen::Matrix3d> R_imu_mag = toRotation(t.transform.rotation);
  if (!R_imu_mag) return;  // not a rotation: as if unknown
  setMagnetometerRotation(*R_imu_mag);
  if (notice_) {
    notice_("the magnetometer's field is rotated from '" + mag_frame_ + "' into '" + imu_frame_ +
            "' (tf)");
  }
}

void MessageInput::setTopicNames(std::function<std::string(InputStream)> topic_of) {
  topic_of_ = std::move(topic_of);
}

std::string MessageInput::topicOf(InputStream stream) const {
  return topic_of_ ? topic_of_(stream) : toString(stream);
}

void MessageInput::checkMessageOrientation(const ImuSample& sample) {
  if (pipeline_->imuOrientationSource() != ImuOrientationSource::kMessage) return;
  if (sample.q_world_imu) {
    noted_missing_orientation_ = false;
    return;
  }
  if (noted_missing_orientation_) return;
  noted_missing_orientation_ = true;
  if (notice_) {
    notice_(topicOf(InputStream::kImu) +
            ": imu_orientation is 'message' but the Imu messages carry no orientation "
            "(orientation_covariance[0] = -1 or a zero quaternion): the gyro and accelerometer "
            "give the IMU's orientation instead (imu_orientation: auto)");
  }
}

void MessageInput::addImu(const sensor_msgs::Imu& msg) {
  if (!checkStamp(msg.header, InputStream::kImu)) return;
  noteFrame(msg.header.frame_id, &imu_frame_, "the IMU's");
  lookUpMagnetometerRotation();
  checkMagFrame();
  const ImuSample sample = toImuSample(msg);
  checkMessageOrientation(sample);
  pipeline_->addImu(sample);
}

void MessageInput::addMagnetic(const sensor_msgs::MagneticField& msg) {
  if (!checkStamp(msg.header, InputStream::kMagnetometer)) return;
  noteFrame(msg.header.frame_id, &mag_frame_, "the magnetometer's");
  lookUpMagnetometerRotation();
  if (waitingForRotation()) return;  // not in the IMU's axes yet: held back, not counted
  checkMagFrame();
  MagneticSample sample = toMagneticSample(msg);
  if (R_imu_mag_) sample.field_t = *R_imu_mag_ * sample.field_t;
  pipeline_->addMagnetic(sample);
}

bool MessageInput::setCameraInfo(const sensor_msgs::CameraInfo& msg) {
  if (info_in_use_ && msg.K == info_in_use_->K && msg.D == info_in_use_->D &&
      msg.width == info_in_use_->width && msg.height == info_in_use_->height &&
      msg.distortion_model == info_in_use_->distortion_model) {
    return true;
  }
  CameraIntrinsics intrinsics;
  std::string error;
  if (!toCameraIntrinsics(msg, &intrinsics, &error)) {
    pipeline_->rejectInput(RejectReason::kBadCameraInfo, InputStream::kCameraInfo,
                           error + "; ignored");
    return false;
  }
  if (!pipeline_->setCameraIntrinsics(intrinsics)) return false;  // counted by the pipeline
  info_in_use_ = msg;
  return true;
}

bool MessageInput::addImage(const sensor_msgs::Image& msg, bool feed, cv::Mat* mono8) {
  if (!checkStamp(msg.header, InputStream::kImage)) return false;
  cv::Mat grey;
  std::string error;
  bool converted = true;
  if (info_in_use_ && (msg.width != info_in_use_->width || msg.height != info_in_use_->height)) {
    std::ostringstream out;
    out << "image is " << msg.width << "x" << msg.height << ", the camera info says "
        << info_in_use_->width << "x" << info_in_use_->height
        << " (binning / ROI are not supported); frame dropped";
    error = out.str();
    converted = false;
  } else {
    converted = toMono8(msg, &grey, &error);
  }
  return finishImage(msg.header, converted, error, grey, feed, mono8);
}

bool MessageInput::addImage(const sensor_msgs::CompressedImage& msg, bool feed, cv::Mat* mono8) {
  if (!checkStamp(msg.header, InputStream::kImage)) return false;
  cv::Mat grey;
  std::string error;
  bool converted = toMono8(msg, &grey, &error);
  if (converted && info_in_use_ &&
      (grey.cols != static_cast<int>(info_in_use_->width) ||
       grey.rows != static_cast<int>(info_in_use_->height))) {
    std::ostringstream out;
    out << "image decodes to " << grey.cols << "x" << grey.rows << ", the camera info says "
        << info_in_use_->width << "x" << info_in_use_->height << "; frame dropped";
    error = out.str();
    converted = false;
  }
  return finishImage(msg.header, converted, error, grey, feed, mono8);
}

bool MessageInput::finishImage(const std_msgs::Header& header, bool converted,
                               const std::string& error, cv::Mat grey, bool feed, cv::Mat* mono8) {
  noteFrame(header.frame_id, &camera_frame_, "the camera's");
  if (!converted) {
    pipeline_->rejectInput(RejectReason::kBadImage, InputStream::kImage, error);
    return false;
  }
  if (feed) pipeline_->addFrame({header.stamp.toSec(), grey});
  if (mono8) *mono8 = grey;
  return true;
}

bool MessageInput::addCameraPose(const geometry_msgs::PoseStamped& msg, bool feed) {
  if (!checkStamp(msg.header, InputStream::kCameraPose)) return false;
  const auto& q = msg.pose.orientation;
  const std::optional<Eigen::Matrix3d> R_target_cam = toRotation(q);
  if (!R_target_cam) {
    const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    std::ostringstream out;
    out << "orientation is not a unit quaternion (norm " << norm << "); pose dropped";
    pipeline_->rejectInput(RejectReason::kNonFinite, InputStream::kCameraPose, out.str());
    return false;
  }
  if (!feed) return true;
  CameraFrame frame;
  frame.stamp_s = msg.header.stamp.toSec();
  frame.R_target_cam = *R_target_cam;
  const auto& p = msg.pose.position;
  const Eigen::Vector3d position(p.x, p.y, p.z);
  if (position.allFinite()) frame.p_target_cam_m = position;
  pipeline_->addFrame(frame);
  return true;
}

}  // namespace camera_imu_alignment
