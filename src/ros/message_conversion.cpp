#include "camera_imu_alignment/ros/message_conversion.h"

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_eigen/tf2_eigen.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

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
  Eigen::Quaterniond quat;
  tf2::fromMsg(q, quat);
  const double norm = quat.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) return std::nullopt;
  return quat.normalized().toRotationMatrix();
}

geometry_msgs::Quaternion toQuaternionMsg(const Eigen::Matrix3d& R) {
  return tf2::toMsg(Eigen::Quaterniond(R));
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

namespace enc = sensor_msgs::image_encodings;

const bool kHostIsBigEndian = [] {
  const std::uint16_t one = 1;
  std::uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 0;
}();

/// A one-channel image of any depth stretched to 8 bits by its actual range: 10- and 12-bit
/// cameras publish mono16 with values up to 1023 or 4095, float images have no fixed range.
/// Integer images map [min(0, darkest), brightest] to [0, 255] unless that range is narrower than
/// 255 (8-bit data in a wider type keeps its values); float images map [darkest, brightest] of
/// their finite pixels to [0, 255]. Non-finite pixels become 0.
cv::Mat stretchToMono8(const cv::Mat& grey) {
  if (grey.depth() == CV_8U) return grey.clone();
  cv::Mat values;
  grey.convertTo(values, CV_64F);
  const bool floating = grey.depth() == CV_32F || grey.depth() == CV_64F;
  const cv::Mat finite = values == values;  // NaN != NaN
  cv::Mat finite_mask = finite & (cv::abs(values) < std::numeric_limits<double>::infinity());
  values.setTo(0.0, ~finite_mask);
  double lo = 0.0, hi = 0.0;
  if (cv::countNonZero(finite_mask) > 0)
    cv::minMaxLoc(values, &lo, &hi, nullptr, nullptr, finite_mask);
  double range = hi - lo;
  if (!floating) {
    lo = std::min(lo, 0.0);
    range = std::max(hi - lo, 255.0);
  }
  cv::Mat mono8;
  if (!(range > 0.0)) {
    mono8 = cv::Mat::zeros(grey.size(), CV_8UC1);
  } else {
    values.convertTo(mono8, CV_8U, 255.0 / range, -lo * 255.0 / range);  // saturates
    mono8.setTo(0, ~finite_mask);
  }
  return mono8;
}

/// cv_bridge's image -> grey: colour, mono, Bayer and yuv422 encodings through cv_bridge's own
/// conversions (16-bit ones to mono16, then stretched), one-channel generic encodings (16UC1,
/// 32FC1, ...) stretched; multi-channel generic ones carry no channel order and are refused.
bool greyFromCvImage(const cv_bridge::CvImageConstPtr& image, cv::Mat* mono8, std::string* error) {
  const std::string& encoding = image->encoding;
  const bool has_colour_model = enc::isColor(encoding) || enc::isMono(encoding) ||
                                enc::isBayer(encoding) || encoding == enc::YUV422;
  if (has_colour_model) {
    if (enc::bitDepth(encoding) == 8) {
      *mono8 = cv_bridge::cvtColor(image, enc::MONO8)->image;
    } else {
      *mono8 = stretchToMono8(cv_bridge::cvtColor(image, enc::MONO16)->image);
    }
    return true;
  }
  if (image->image.channels() == 1) {
    *mono8 = stretchToMono8(image->image);
    return true;
  }
  *error = "encoding '" + encoding + "' has " + std::to_string(image->image.channels()) +
           " channels and no colour order: cannot make it grey (publish mono, rgb, bgr or Bayer)";
  return false;
}

}  // namespace

bool toMono8(const sensor_msgs::Image& msg, cv::Mat* mono8, std::string* error) {
  int channels = 0, bits = 0;
  try {
    channels = enc::numChannels(msg.encoding);
    bits = enc::bitDepth(msg.encoding);
  } catch (const std::runtime_error&) {
    *error = "unsupported encoding '" + msg.encoding +
             "' (every encoding of sensor_msgs/image_encodings is read)";
    return false;
  }
  const std::size_t bytes_per_channel = static_cast<std::size_t>(bits) / 8;
  const std::size_t row_bytes = static_cast<std::size_t>(msg.width) * channels * bytes_per_channel;
  if (msg.width == 0 || msg.height == 0 || msg.step < row_bytes ||
      msg.data.size() < static_cast<std::size_t>(msg.step) * msg.height) {
    std::ostringstream out;
    out << "image " << msg.width << "x" << msg.height << " " << msg.encoding << " with step "
        << msg.step << " needs " << static_cast<std::size_t>(msg.step) * msg.height
        << " bytes, has " << msg.data.size();
    *error = out.str();
    return false;
  }
  // OpenCV needs rows that start on a whole channel, and cv_bridge 1.16 returns the other byte
  // order's 16-bit pixels as byte pairs: such images are packed into host order first.
  const bool swap_bytes = bytes_per_channel > 1 && (msg.is_bigendian != 0) != kHostIsBigEndian;
  const sensor_msgs::Image* source = &msg;
  sensor_msgs::Image packed;
  if (msg.step % bytes_per_channel != 0 || swap_bytes) {
    packed.header = msg.header;
    packed.width = msg.width;
    packed.height = msg.height;
    packed.encoding = msg.encoding;
    packed.is_bigendian = kHostIsBigEndian;
    packed.step = static_cast<std::uint32_t>(row_bytes);
    packed.data.resize(row_bytes * msg.height);
    for (std::uint32_t r = 0; r < msg.height; ++r) {
      std::uint8_t* row = packed.data.data() + r * row_bytes;
      std::memcpy(row, msg.data.data() + static_cast<std::size_t>(r) * msg.step, row_bytes);
      if (!swap_bytes) continue;
      for (std::size_t i = 0; i < row_bytes; i += bytes_per_channel) {
        std::reverse(row + i, row + i + bytes_per_channel);
      }
    }
    source = &packed;
  }
  try {
    // Shares the message's (or the packed) pixels; the grey image is new.
    return greyFromCvImage(cv_bridge::toCvShare(*source, nullptr), mono8, error);
  } catch (const cv_bridge::Exception& e) {
    *error = "cannot convert the " + msg.encoding + " image to grey: " + e.what();
  } catch (const cv::Exception& e) {
    *error = "cannot convert the " + msg.encoding + " image to grey: " + e.what();
  }
  return false;
}

bool toMono8(const sensor_msgs::CompressedImage& msg, cv::Mat* mono8, std::string* error) {
  if (msg.data.empty()) {
    *error = "empty compressed image";
    return false;
  }
  try {
    const cv_bridge::CvImagePtr decoded = cv_bridge::toCvCopy(msg);
    if (decoded && !decoded->image.empty()) return greyFromCvImage(decoded, mono8, error);
    *error = "cannot decode the compressed image (format '" + msg.format + "')";
  } catch (const cv_bridge::Exception& e) {
    *error = std::string("cannot decode the compressed image: ") + e.what();
  } catch (const cv::Exception& e) {
    *error = std::string("cannot decode the compressed image: ") + e.what();
  }
  return false;
}

}  // namespace camera_imu_alignment
