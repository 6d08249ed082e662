#include "camera_imu_alignment/ros/message_conversion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace camera_imu_alignment {

ImuSample toImuSample(const sensor_msgs::Imu& msg) {
  ImuSample sample;
  sample.stamp_s = msg.header.stamp.toSec();
  sample.gyro_rad_s = {msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z};
  sample.accel_m_s2 = {msg.linear_acceleration.x, msg.linear_acceleration.y,
                       msg.linear_acceleration.z};
  // REP-145: orientation_covariance[0] = -1 says "no orientation"; many drivers send zeros.
  const auto& q = msg.orientation;
  const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (msg.orientation_covariance[0] != -1.0 && norm > 0.5) {
    sample.q_world_imu = Eigen::Quaterniond(q.w, q.x, q.y, q.z);  // the pipeline checks the norm
  }
  return sample;
}

std::optional<Eigen::Matrix3d> toRotation(const geometry_msgs::Quaternion& q) {
  const Eigen::Quaterniond quat(q.w, q.x, q.y, q.z);
  const double norm = quat.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) return std::nullopt;
  return quat.normalized().toRotationMatrix();
}

geometry_msgs::Quaternion toQuaternionMsg(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  geometry_msgs::Quaternion out;
  out.x = q.x(), out.y = q.y(), out.z = q.z(), out.w = q.w();
  return out;
}

MagneticSample toMagneticSample(const sensor_msgs::MagneticField& msg) {
  MagneticSample sample;
  sample.stamp_s = msg.header.stamp.toSec();
  sample.field_t = {msg.magnetic_field.x, msg.magnetic_field.y, msg.magnetic_field.z};
  return sample;
}

bool toCameraIntrinsics(const sensor_msgs::CameraInfo& msg, CameraIntrinsics* intrinsics,
                        std::string* error) {
  double K[9];
  for (int i = 0; i < 9; ++i) K[i] = msg.K[i];
  if (!CameraIntrinsics::fromCameraInfo(static_cast<int>(msg.width), static_cast<int>(msg.height),
                                        K, msg.distortion_model, msg.D, intrinsics, error)) {
    return false;
  }
  *error = intrinsics->validate();
  return error->empty();
}

namespace {

struct EncodingInfo {
  int cv_type;
  int channels;
  int bytes_per_channel;
};

bool encodingInfo(const std::string& encoding, EncodingInfo* info) {
  if (encoding == "mono8" || encoding == "8UC1") {
    *info = {CV_8UC1, 1, 1};
  } else if (encoding == "mono16" || encoding == "16UC1") {
    *info = {CV_16UC1, 1, 2};
  } else if (encoding == "rgb8" || encoding == "bgr8") {
    *info = {CV_8UC3, 3, 1};
  } else if (encoding == "rgba8" || encoding == "bgra8") {
    *info = {CV_8UC4, 4, 1};
  } else {
    return false;
  }
  return true;
}

}  // namespace

bool toMono8(const sensor_msgs::Image& msg, cv::Mat* mono8, std::string* error) {
  EncodingInfo info{};
  if (!encodingInfo(msg.encoding, &info)) {
    *error = "unsupported encoding '" + msg.encoding +
             "' (mono8, mono16, rgb8, bgr8, rgba8, bgra8 are read)";
    return false;
  }
  const std::size_t row_bytes =
      static_cast<std::size_t>(msg.width) * info.channels * info.bytes_per_channel;
  if (msg.width == 0 || msg.height == 0 || msg.step < row_bytes ||
      msg.data.size() < static_cast<std::size_t>(msg.step) * msg.height) {
    std::ostringstream out;
    out << "image " << msg.width << "x" << msg.height << " " << msg.encoding << " with step "
        << msg.step << " needs " << static_cast<std::size_t>(msg.step) * msg.height
        << " bytes, has " << msg.data.size();
    *error = out.str();
    return false;
  }
  if (info.bytes_per_channel == 2 && msg.is_bigendian) {
    *error = "big-endian 16-bit images are not supported";
    return false;
  }
  cv::Mat view(static_cast<int>(msg.height), static_cast<int>(msg.width), info.cv_type);
  if (msg.step % info.bytes_per_channel == 0) {  // wrap the message's rows where OpenCV can
    view = cv::Mat(static_cast<int>(msg.height), static_cast<int>(msg.width), info.cv_type,
                   const_cast<std::uint8_t*>(msg.data.data()), msg.step);
  } else {  // rows padded by an odd byte count: copy them
    for (std::uint32_t r = 0; r < msg.height; ++r) {
      std::memcpy(view.ptr(static_cast<int>(r)), msg.data.data() + r * msg.step, row_bytes);
    }
  }
  if (info.cv_type == CV_8UC1) {
    view.copyTo(*mono8);
  } else if (info.cv_type == CV_16UC1) {
    // 10- and 12-bit cameras publish mono16 too: stretch the brightest pixel to 255.
    double max_value = 0.0;
    cv::minMaxLoc(view, nullptr, &max_value);
    view.convertTo(*mono8, CV_8U, 255.0 / std::max(max_value, 255.0));
  } else if (msg.encoding == "rgb8") {
    cv::cvtColor(view, *mono8, cv::COLOR_RGB2GRAY);
  } else if (msg.encoding == "bgr8") {
    cv::cvtColor(view, *mono8, cv::COLOR_BGR2GRAY);
  } else if (msg.encoding == "rgba8") {
    cv::cvtColor(view, *mono8, cv::COLOR_RGBA2GRAY);
  } else {
    cv::cvtColor(view, *mono8, cv::COLOR_BGRA2GRAY);
  }
  return true;
}

bool toMono8(const sensor_msgs::CompressedImage& msg, cv::Mat* mono8, std::string* error) {
  if (msg.data.empty()) {
    *error = "empty compressed image";
    return false;
  }
  try {
    *mono8 = cv::imdecode(msg.data, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    *error = std::string("cannot decode the compressed image: ") + e.what();
    return false;
  }
  if (mono8->empty()) {
    *error = "cannot decode the compressed image (format '" + msg.format + "')";
    return false;
  }
  return true;
}

}  // namespace camera_imu_alignment
