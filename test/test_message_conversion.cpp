// ROS messages -> core structs (src/ros/message_conversion.cpp): every supported image encoding
// gives the same grey image, inconsistent messages are refused with a reason, CameraInfo fields
// map to the intrinsics.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera_imu_alignment/ros/message_conversion.h"

namespace camera_imu_alignment {
namespace {

/// A 37x23 grey ramp (odd sizes catch step/width mix-ups).
cv::Mat greyRamp() {
  cv::Mat grey(23, 37, CV_8UC1);
  for (int r = 0; r < grey.rows; ++r) {
    for (int c = 0; c < grey.cols; ++c) grey.at<std::uint8_t>(r, c) = (7 * r + 5 * c) % 256;
  }
  return grey;
}

sensor_msgs::Image imageMessage(const cv::Mat& m, const std::string& encoding, int padding = 0) {
  sensor_msgs::Image msg;
  msg.encoding = encoding;
  msg.width = m.cols;
  msg.height = m.rows;
  const std::size_t row = m.cols * m.elemSize();
  msg.step = static_cast<std::uint32_t>(row + padding);
  msg.data.assign(msg.step * m.rows, 0);
  for (int r = 0; r < m.rows; ++r) std::memcpy(&msg.data[r * msg.step], m.ptr(r), row);
  return msg;
}

double maxDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  double max = 0.0;
  cv::minMaxLoc(diff, nullptr, &max);
  return max;
}

TEST(MessageConversion, EverySupportedEncodingGivesTheGreyImage) {
  const cv::Mat grey = greyRamp();
  cv::Mat bgr, rgb, bgra, rgba, grey16;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  cv::cvtColor(grey, rgb, cv::COLOR_GRAY2RGB);
  cv::cvtColor(grey, bgra, cv::COLOR_GRAY2BGRA);
  cv::cvtColor(grey, rgba, cv::COLOR_GRAY2RGBA);
  grey.convertTo(grey16, CV_16U, 256.0);
  cv::Mat grey12;  // a 12-bit camera's mono16: values up to 4095
  grey.convertTo(grey12, CV_16U, 16.0);
  const std::pair<cv::Mat, std::string> cases[] = {
      {grey, "mono8"}, {grey, "8UC1"},     {bgr, "bgr8"},     {rgb, "rgb8"},     {bgra, "bgra8"},
      {rgba, "rgba8"}, {grey16, "mono16"}, {grey16, "16UC1"}, {grey12, "mono16"}};
  for (const auto& [image, encoding] : cases) {
    for (int padding : {0, 3}) {
      cv::Mat mono;
      std::string error;
      ASSERT_TRUE(toMono8(imageMessage(image, encoding, padding), &mono, &error))
          << encoding << ": " << error;
      ASSERT_EQ(mono.type(), CV_8UC1);
      ASSERT_EQ(mono.size(), grey.size());
      EXPECT_LE(maxDifference(mono, grey), 1.0) << encoding;
    }
  }
}

/// A smooth 38x24 ramp from 0 to 255, flat at 255 in a corner (Bayer demosaicing and yuv422 need
/// even sizes and no edges; the flat corner keeps the brightest value when demosaiced).
cv::Mat smoothRamp() {
  cv::Mat grey(24, 38, CV_8UC1);
  for (int r = 0; r < grey.rows; ++r) {
    for (int c = 0; c < grey.cols; ++c) {
      grey.at<std::uint8_t>(r, c) = cv::saturate_cast<std::uint8_t>(255.0 * (r + c) / 50.0);
    }
  }
  return grey;
}

/// `grey` as a Bayer mosaic: every filter colour sees the same grey, so demosaicing gives it back.
cv::Mat bayerOf(const cv::Mat& grey, int depth, double scale) {
  cv::Mat out;
  grey.convertTo(out, depth, scale);
  return out;
}

/// The largest difference inside a 2-pixel border (demosaicing guesses at the edges).
double interiorDifference(const cv::Mat& a, const cv::Mat& b) {
  const cv::Rect inside(2, 2, a.cols - 4, a.rows - 4);
  return maxDifference(a(inside), b(inside));
}

TEST(MessageConversion, BayerYuvSixteenBitColourAndFloatImagesThroughCvBridge) {
  const cv::Mat smooth = smoothRamp();
  for (const char* pattern : {"rggb", "bggr", "gbrg", "grbg"}) {
    for (const auto& [bits, scale] : {std::pair<int, double>{8, 1.0}, {16, 16.0}}) {
      const std::string encoding = "bayer_" + std::string(pattern) + std::to_string(bits);
      cv::Mat mono;
      std::string error;
      const cv::Mat mosaic = bayerOf(smooth, bits == 8 ? CV_8U : CV_16U, scale);
      ASSERT_TRUE(toMono8(imageMessage(mosaic, encoding), &mono, &error)) << encoding << error;
      ASSERT_EQ(mono.type(), CV_8UC1);
      ASSERT_EQ(mono.size(), smooth.size());
      EXPECT_LE(interiorDifference(mono, smooth), 2.0) << encoding;
    }
  }
  // yuv422 (UYVY): chroma 128 (grey), luma the image.
  cv::Mat uyvy(smooth.rows, smooth.cols, CV_8UC2);
  for (int r = 0; r < smooth.rows; ++r) {
    for (int c = 0; c < smooth.cols; ++c) {
      uyvy.at<cv::Vec2b>(r, c) = cv::Vec2b(128, smooth.at<std::uint8_t>(r, c));
    }
  }
  // 16-bit colour, a 12-bit Bayer camera, float intensities in [0, 1] (32 and 64 bit): stretched
  // by their actual range, so the ramp (0..255) comes back.
  const cv::Mat grey = greyRamp();
  cv::Mat rgb16, bgra16, grey_f32, grey_f64;
  cv::cvtColor(grey, rgb16, cv::COLOR_GRAY2RGB);
  rgb16.convertTo(rgb16, CV_16UC3, 256.0);
  cv::cvtColor(grey, bgra16, cv::COLOR_GRAY2BGRA);
  bgra16.convertTo(bgra16, CV_16UC4, 16.0);
  grey.convertTo(grey_f32, CV_32F, 1.0 / 255.0);
  grey.convertTo(grey_f64, CV_64F, 1.0 / 255.0);
  const std::pair<cv::Mat, std::string> cases[] = {{uyvy, "yuv422"},
                                                   {rgb16, "rgb16"},
                                                   {bgra16, "bgra16"},
                                                   {grey_f32, "32FC1"},
                                                   {grey_f64, "64FC1"}};
  for (const auto& [image, encoding] : cases) {
    const cv::Mat expected = image.size() == smooth.size() ? smooth : grey;
    for (int padding : {0, 3}) {
      cv::Mat mono;
      std::string error;
      ASSERT_TRUE(toMono8(imageMessage(image, encoding, padding), &mono, &error))
          << encoding << ": " << error;
      ASSERT_EQ(mono.type(), CV_8UC1);
      ASSERT_EQ(mono.size(), expected.size());
      EXPECT_LE(maxDifference(mono, expected), 1.0) << encoding << " padding " << padding;
    }
  }
  // A float image with a NaN pixel: the NaN becomes black, the rest keeps the range.
  cv::Mat with_nan = grey_f32.clone();
  with_nan.at<float>(3, 4) = std::numeric_limits<float>::quiet_NaN();
  cv::Mat mono;
  std::string error;
  ASSERT_TRUE(toMono8(imageMessage(with_nan, "32FC1"), &mono, &error)) << error;
  EXPECT_EQ(mono.at<std::uint8_t>(3, 4), 0);
  cv::Mat expected = grey.clone();
  expected.at<std::uint8_t>(3, 4) = 0;
  EXPECT_LE(maxDifference(mono, expected), 1.0);
}

TEST(MessageConversion, BigEndianSixteenBitImagesAreRead) {
  const cv::Mat grey = greyRamp();
  cv::Mat grey12;
  grey.convertTo(grey12, CV_16U, 16.0);
  sensor_msgs::Image msg = imageMessage(grey12, "mono16");
  for (std::size_t i = 0; i + 1 < msg.data.size(); i += 2) std::swap(msg.data[i], msg.data[i + 1]);
  msg.is_bigendian = 1;
  cv::Mat mono;
  std::string error;
  ASSERT_TRUE(toMono8(msg, &mono, &error)) << error;
  EXPECT_LE(maxDifference(mono, grey), 1.0);
}

TEST(MessageConversion, InconsistentImagesAreRefusedWithAReason) {
  const cv::Mat grey = greyRamp();
  std::string error;
  cv::Mat mono;
  sensor_msgs::Image msg = imageMessage(grey, "nonsense8");  // no such encoding
  EXPECT_FALSE(toMono8(msg, &mono, &error));
  EXPECT_NE(error.find("nonsense8"), std::string::npos) << error;
  cv::Mat three;
  cv::cvtColor(grey, three, cv::COLOR_GRAY2BGR);
  msg = imageMessage(three, "8UC3");  // three channels, but which is red?
  EXPECT_FALSE(toMono8(msg, &mono, &error));
  EXPECT_NE(error.find("no colour order"), std::string::npos) << error;
  msg = imageMessage(grey, "mono8");
  msg.data.resize(msg.data.size() - 1);  // truncated payload
  EXPECT_FALSE(toMono8(msg, &mono, &error));
  msg = imageMessage(grey, "rgb8");  // says rgb8, carries one byte per pixel
  EXPECT_FALSE(toMono8(msg, &mono, &error));
  msg = sensor_msgs::Image();  // empty
  msg.encoding = "mono8";
  EXPECT_FALSE(toMono8(msg, &mono, &error));
  msg = imageMessage(grey, "mono8");
  msg.step = 10;  // shorter than a row
  EXPECT_FALSE(toMono8(msg, &mono, &error));
}

TEST(MessageConversion, CompressedImagesDecodeAndGarbageIsRefused) {
  const cv::Mat grey = greyRamp();
  for (const char* ext : {".png", ".jpg"}) {
    sensor_msgs::CompressedImage msg;
    msg.format = ext + 1;
    ASSERT_TRUE(cv::imencode(ext, grey, msg.data));
    cv::Mat mono;
    std::string error;
    ASSERT_TRUE(toMono8(msg, &mono, &error)) << error;
    EXPECT_EQ(mono.size(), grey.size());
    EXPECT_LE(maxDifference(mono, grey), std::string(ext) == ".png" ? 0.0 : 12.0) << ext;
  }
  sensor_msgs::CompressedImage garbage;
  garbage.format = "jpeg";
  garbage.data = {1, 2, 3, 4, 5};
  cv::Mat mono;
  std::string error;
  EXPECT_FALSE(toMono8(garbage, &mono, &error));
  EXPECT_FALSE(error.empty());
  garbage.data.clear();
  EXPECT_FALSE(toMono8(garbage, &mono, &error));
}

TEST(MessageConversion, CameraInfoMapsToIntrinsicsAndBadOnesAreRefused) {
  sensor_msgs::CameraInfo info;
  info.width = 640;
  info.height = 480;
  info.K = {500.0, 0.0, 319.5, 0.0, 501.0, 239.5, 0.0, 0.0, 1.0};
  info.distortion_model = "plumb_bob";
  info.D = {0.1, -0.05, 0.001, 0.002, 0.0};
  CameraIntrinsics intrinsics;
  std::string error;
  ASSERT_TRUE(toCameraIntrinsics(info, &intrinsics, &error)) << error;
  EXPECT_EQ(intrinsics.width, 640);
  EXPECT_EQ(intrinsics.K(1, 1), 501.0);
  EXPECT_EQ(intrinsics.K(0, 2), 319.5);
  EXPECT_EQ(intrinsics.distortion, CameraIntrinsics::Distortion::kPlumbBob);
  EXPECT_EQ(intrinsics.D.size(), 5u);

  sensor_msgs::CameraInfo zero_k = info;
  zero_k.K.fill(0.0);
  EXPECT_FALSE(toCameraIntrinsics(zero_k, &intrinsics, &error));
  EXPECT_FALSE(error.empty());
  sensor_msgs::CameraInfo short_d = info;
  short_d.D = {0.1, 0.2, 0.3};
  EXPECT_FALSE(toCameraIntrinsics(short_d, &intrinsics, &error));
  EXPECT_NE(error.find("3"), std::string::npos) << error;
  sensor_msgs::CameraInfo unknown = info;
  unknown.distortion_model = "mystery";
  EXPECT_FALSE(toCameraIntrinsics(unknown, &intrinsics, &error));
  EXPECT_NE(error.find("mystery"), std::string::npos) << error;
}

TEST(MessageConversion, ImuAndMagneticFieldKeepStampsAndAxes) {
  sensor_msgs::Imu imu;
  imu.header.stamp = ros::Time(1700000000, 250000000);
  imu.angular_velocity.x = 0.1;
  imu.angular_velocity.y = -0.2;
  imu.angular_velocity.z = 0.3;
  imu.linear_acceleration.z = 9.81;
  const ImuSample sample = toImuSample(imu);
  EXPECT_DOUBLE_EQ(sample.stamp_s, 1700000000.25);
  EXPECT_EQ(sample.gyro_rad_s, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(sample.accel_m_s2, Eigen::Vector3d(0.0, 0.0, 9.81));
  sensor_msgs::MagneticField mag;
  mag.header.stamp = ros::Time(5, 0);
  mag.magnetic_field.y = 22e-6;
  const MagneticSample field = toMagneticSample(mag);
  EXPECT_EQ(field.stamp_s, 5.0);
  EXPECT_EQ(field.field_t, Eigen::Vector3d(0.0, 22e-6, 0.0));
}

TEST(MessageConversion, QuaternionsToRotationsAndBack) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  const geometry_msgs::Quaternion q = toQuaternionMsg(R);
  EXPECT_NEAR(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w, 1.0, 1e-12);
  const std::optional<Eigen::Matrix3d> back = toRotation(q);
  ASSERT_TRUE(back);
  EXPECT_LT((*back - R).norm(), 1e-12);
  geometry_msgs::Quaternion almost = q;  // a float-precision quaternion is renormalised
  almost.w *= 1.0 + 5e-4;
  ASSERT_TRUE(toRotation(almost));
  EXPECT_LT(((*toRotation(almost)).transpose() * *toRotation(almost) - Eigen::Matrix3d::Identity())
                .norm(),
            1e-12);
  geometry_msgs::Quaternion zero;  // all zeros, as a driver that never set it
  geometry_msgs::Quaternion twice = q, nan = q;
  twice.x *= 2.0, twice.y *= 2.0, twice.z *= 2.0, twice.w *= 2.0;
  nan.y = std::numeric_limits<double>::quiet_NaN();
  for (const auto& bad : {zero, twice, nan}) EXPECT_FALSE(toRotation(bad));
}

}  // namespace
}  // namespace camera_imu_alignment
