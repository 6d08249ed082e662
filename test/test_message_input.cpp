// The ROS boundary (src/ros/message_input.cpp; the clock-jump detector of src/core/pipeline): every
// kind of bad message the nodelet and calibrate_bag can receive is refused, counted under its
// reason and reported with the stream it came from; nothing non-finite gets through; frame ids are
// normalised; clock jumps are told apart from a camera's latency.
#include <gtest/gtest.h>

#include <tf2/buffer_core.h>

#include <cmath>
#include <limits>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <thread>
#include <vector>

#include "camera_imu_alignment/online/clock_jump.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/ros/message_conversion.h"
#include "camera_imu_alignment/ros/message_input.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/target_description.h"

namespace camera_imu_alignment {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TargetDescription checkerboard() {
  return parseTargetYaml(
      "target_type: 'checkerboard'\ntargetCols: 8\ntargetRows: 6\nrowSpacingMeters: 0.04\n"
      "colSpacingMeters: 0.04\n",
      "test target");
}

/// A pipeline with a MessageInput in front, recording every rejection and notice.
struct Boundary {
  explicit Boundary(PipelineSettings settings = {}) {
    PipelineCallbacks callbacks;
    callbacks.on_reject = [this](RejectReason reason, InputStream stream, const std::string& d) {
      rejects.push_back({reason, stream});
      details.push_back(d);
    };
    callbacks.on_pose = [this](const StationaryPose& p) { poses.push_back(p); };
    pipeline = std::make_unique<CalibrationPipeline>(checkerboard(), settings, callbacks);
    input = std::make_unique<MessageInput>(pipeline.get(),
                                           [this](const std::string& n) { notices.push_back(n); });
  }
  std::uint64_t count(RejectReason reason) const { return pipeline->rejections().count(reason); }

  std::unique_ptr<CalibrationPipeline> pipeline;
  std::unique_ptr<MessageInput> input;
  std::vector<std::pair<RejectReason, InputStream>> rejects;
  std::vector<std::string> details, notices;
  std::vector<StationaryPose> poses;
};

sensor_msgs::Imu imuAt(double t, const Eigen::Vector3d& accel = {0.0, 0.0, 9.81},
                       const Eigen::Vector3d& gyro = Eigen::Vector3d::Zero()) {
  sensor_msgs::Imu msg;
  msg.header.stamp = ros::Time(t);
  msg.header.frame_id = "imu_link";
  msg.angular_velocity.x = gyro.x();
  msg.angular_velocity.y = gyro.y();
  msg.angular_velocity.z = gyro.z();
  msg.linear_acceleration.x = accel.x();
  msg.linear_acceleration.y = accel.y();
  msg.linear_acceleration.z = accel.z();
  msg.orientation_covariance[0] = -1.0;
  return msg;
}

sensor_msgs::MagneticField magAt(double t, const Eigen::Vector3d& field_t = {2e-5, 0.0, -4e-5}) {
  sensor_msgs::MagneticField msg;
  msg.header.stamp = ros::Time(t);
  msg.header.frame_id = "imu_link";
  msg.magnetic_field.x = field_t.x();
  msg.magnetic_field.y = field_t.y();
  msg.magnetic_field.z = field_t.z();
  return msg;
}

sensor_msgs::CameraInfo cameraInfo(std::uint32_t width = 64, std::uint32_t height = 48) {
  sensor_msgs::CameraInfo info;
  info.width = width;
  info.height = height;
  info.K = {50.0, 0.0, width / 2.0, 0.0, 50.0, height / 2.0, 0.0, 0.0, 1.0};
  info.distortion_model = "plumb_bob";
  info.D = {0.0, 0.0, 0.0, 0.0, 0.0};
  return info;
}

sensor_msgs::Image monoImage(double t, std::uint32_t width = 64, std::uint32_t height = 48) {
  sensor_msgs::Image msg;
  msg.header.stamp = ros::Time(t);
  msg.header.frame_id = "camera_optical";
  msg.encoding = "mono8";
  msg.width = width;
  msg.height = height;
  msg.step = width;
  msg.data.assign(static_cast<std::size_t>(width) * height, 128);
  return msg;
}

geometry_msgs::PoseStamped cameraPose(double t, const Eigen::Quaterniond& q) {
  geometry_msgs::PoseStamped msg;
  msg.header.stamp = ros::Time(t);
  msg.header.frame_id = "calibration_target";
  msg.pose.orientation.w = q.w();
  msg.pose.orientation.x = q.x();
  msg.pose.orientation.y = q.y();
  msg.pose.orientation.z = q.z();
  return msg;
}

TEST(MessageInput, MessagesWithoutAStampAreCountedOnTheirStream) {
  Boundary b;
  b.input->addImu(imuAt(0.0));
  b.input->addMagnetic(magAt(0.0));
  EXPECT_FALSE(b.input->addImage(monoImage(0.0)));
  EXPECT_FALSE(b.input->addCameraPose(cameraPose(0.0, Eigen::Quaterniond::Identity())));
  EXPECT_EQ(b.count(RejectReason::kMissingStamp), 4u);
  EXPECT_EQ(b.pipeline->imuSamples(), 0u);
  EXPECT_EQ(b.pipeline->magneticSamples(), 0u);
  EXPECT_EQ(b.pipeline->frames(), 0u);
  const std::vector<InputStream> streams = {InputStream::kImu, InputStream::kMagnetometer,
                                            InputStream::kImage, InputStream::kCameraPose};
  ASSERT_EQ(b.rejects.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(b.rejects[i].second, streams[i]) << i;
  EXPECT_NE(b.details[0].find("stamp is zero"), std::string::npos) << b.details[0];
}

TEST(MessageInput, NonFiniteAndZeroVectorsAreRefusedField_by_field) {
  Boundary b;
  int expected_non_finite = 0;
  for (int field = 0; field < 6; ++field) {  // NaN or Inf in each gyro and accelerometer axis
    sensor_msgs::Imu msg = imuAt(1.0 + field);
    double* values[] = {&msg.angular_velocity.x,    &msg.angular_velocity.y,
                        &msg.angular_velocity.z,    &msg.linear_acceleration.x,
                        &msg.linear_acceleration.y, &msg.linear_acceleration.z};
    *values[field] = field % 2 == 0 ? kNaN : -kInf;
    b.input->addImu(msg);
    ++expected_non_finite;
  }
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Vector3d field(2e-5, 0.0, -4e-5);
    field(axis) = kNaN;
    b.input->addMagnetic(magAt(1.0 + axis, field));
    ++expected_non_finite;
  }
  EXPECT_EQ(b.count(RejectReason::kNonFinite), static_cast<std::uint64_t>(expected_non_finite));
  b.input->addImu(imuAt(10.0, Eigen::Vector3d::Zero()));
  b.input->addMagnetic(magAt(10.0, Eigen::Vector3d::Zero()));
  EXPECT_EQ(b.count(RejectReason::kZeroVector), 2u);
  EXPECT_EQ(b.pipeline->imuSamples(), 0u);
  EXPECT_EQ(b.pipeline->magneticSamples(), 0u);
  b.input->addImu(imuAt(11.0));  // a good sample after all that is taken
  EXPECT_EQ(b.pipeline->imuSamples(), 1u);
}

TEST(MessageInput, MagnetometerUnitsAreRecognisedAndMagScaleFixesThem) {
  Boundary tesla;
  const Eigen::Vector3d field_t(2e-5, 0.0, -4e-5);
  tesla.input->addMagnetic(magAt(1.0, field_t * 1e4));  // gauss
  tesla.input->addMagnetic(magAt(2.0, field_t * 1e6));  // microtesla
  EXPECT_EQ(tesla.count(RejectReason::kMagneticUnits), 2u);
  ASSERT_EQ(tesla.details.size(), 2u);
  EXPECT_NE(tesla.details[0].find("gauss"), std::string::npos) << tesla.details[0];
  EXPECT_NE(tesla.details[0].find("mag_scale: 1e-4"), std::string::npos) << tesla.details[0];
  EXPECT_NE(tesla.details[1].find("microtesla"), std::string::npos) << tesla.details[1];
  tesla.input->addMagnetic(magAt(3.0, field_t));
  EXPECT_EQ(tesla.pipeline->magneticSamples(), 1u);

  for (const double scale : {1e-4, 1e-6}) {
    PipelineSettings settings;
    settings.magnetometer.scale = scale;
    Boundary scaled(settings);
    scaled.input->addMagnetic(magAt(1.0, field_t / scale));
    EXPECT_EQ(scaled.count(RejectReason::kMagneticUnits), 0u) << scale;
    EXPECT_EQ(scaled.pipeline->magneticSamples(), 1u) << scale;
  }
}

TEST(MessageInput, DuplicateAndBackwardStampsAreCountedPerStream) {
  Boundary b;
  b.input->addImu(imuAt(5.0));
  b.input->addImu(imuAt(5.0));
  b.input->addImu(imuAt(4.0));
  b.input->addMagnetic(magAt(4.0));  // earlier than the IMU's newest: another stream, fine
  b.input->addMagnetic(magAt(3.5));
  EXPECT_EQ(b.count(RejectReason::kDuplicateStamp), 1u);
  EXPECT_EQ(b.count(RejectReason::kStampBackwards), 2u);
  EXPECT_EQ(b.pipeline->imuSamples(), 1u);
  EXPECT_EQ(b.pipeline->magneticSamples(), 1u);
  ASSERT_EQ(b.rejects.size(), 3u);
  EXPECT_EQ(b.rejects[2].second, InputStream::kMagnetometer);
}

TEST(MessageInput, OrientationCovarianceConventions) {
  sensor_msgs::Imu msg = imuAt(1.0);
  msg.orientation.w = 1.0;
  msg.orientation_covariance[0] = -1.0;  // REP-145: no orientation
  EXPECT_FALSE(toImuSample(msg).q_world_imu);
  msg.orientation_covariance[0] = 0.0;  // orientation with unknown covariance
  ASSERT_TRUE(toImuSample(msg).q_world_imu);
  EXPECT_NEAR(toImuSample(msg).q_world_imu->w(), 1.0, 1e-12);
  msg.orientation.w = 0.0;  // all zero: a driver without orientation that left cov[0] at 0
  EXPECT_FALSE(toImuSample(msg).q_world_imu);

  Boundary b;  // a non-unit orientation is dropped, the rates are kept
  msg.orientation.w = 0.8;
  b.input->addImu(msg);
  EXPECT_EQ(b.count(RejectReason::kNonFinite), 1u);
  EXPECT_EQ(b.pipeline->imuSamples(), 1u);
}

TEST(MessageInput, BadImagesAreCountedAndNamed) {
  Boundary b;
  ASSERT_TRUE(b.input->setCameraInfo(cameraInfo(64, 48)));
  sensor_msgs::Image unknown = monoImage(1.0);
  unknown.encoding = "nonsense8";  // no such encoding (cv_bridge reads every real one)
  EXPECT_FALSE(b.input->addImage(unknown));
  sensor_msgs::Image empty = monoImage(2.0);
  empty.data.clear();
  EXPECT_FALSE(b.input->addImage(empty));
  EXPECT_FALSE(b.input->addImage(monoImage(3.0, 32, 24)));  // not the camera info's size
  sensor_msgs::CompressedImage garbage;
  garbage.header.stamp = ros::Time(4.0);
  garbage.format = "jpeg";
  garbage.data = {0xff, 0xd8, 0x00};
  EXPECT_FALSE(b.input->addImage(garbage));
  sensor_msgs::CompressedImage small;  // decodes, but to another size
  small.header.stamp = ros::Time(5.0);
  small.format = "png";
  ASSERT_TRUE(cv::imencode(".png", cv::Mat(24, 32, CV_8UC1, cv::Scalar(9)), small.data));
  EXPECT_FALSE(b.input->addImage(small));
  EXPECT_EQ(b.count(RejectReason::kBadImage), 5u);
  EXPECT_EQ(b.pipeline->frames(), 0u);
  for (const auto& r : b.rejects) EXPECT_EQ(r.second, InputStream::kImage);
  EXPECT_NE(b.details[0].find("nonsense8"), std::string::npos) << b.details[0];
  EXPECT_NE(b.details[2].find("32x24"), std::string::npos) << b.details[2];
  EXPECT_NE(b.details[2].find("64x48"), std::string::npos) << b.details[2];

  cv::Mat grey;
  EXPECT_TRUE(b.input->addImage(monoImage(6.0), true, &grey));
  EXPECT_EQ(grey.cols, 64);
  EXPECT_EQ(b.pipeline->frames(), 1u);
  EXPECT_TRUE(b.input->addImage(monoImage(7.0), false, &grey));  // converted, not fed
  EXPECT_EQ(b.pipeline->frames(), 1u);
  EXPECT_EQ(b.input->cameraFrame(), "camera_optical");
}

TEST(MessageInput, ImuOrientationMessageWithoutOrientationsIsNotedOnceNamingTheTopic) {
  PipelineSettings settings;
  settings.imu_orientation = ImuOrientationSource::kMessage;
  Boundary b(settings);
  b.input->setTopicNames([](InputStream stream) {
    return stream == InputStream::kImu ? std::string("/rig/imu/data") : std::string("other");
  });
  for (int i = 0; i < 100; ++i) b.input->addImu(imuAt(1.0 + 0.01 * i));  // covariance[0] = -1
  ASSERT_EQ(b.notices.size(), 1u);
  EXPECT_NE(b.notices[0].find("/rig/imu/data"), std::string::npos) << b.notices[0];
  EXPECT_NE(b.notices[0].find("no orientation"), std::string::npos) << b.notices[0];
  EXPECT_NE(b.notices[0].find("gyro"), std::string::npos) << b.notices[0];
  // Orientations arrive, then stop again: said again.
  sensor_msgs::Imu with = imuAt(3.0);
  with.orientation_covariance[0] = 0.01;
  with.orientation.w = 1.0;
  b.input->addImu(with);
  b.input->addImu(imuAt(3.01));
  EXPECT_EQ(b.notices.size(), 2u);
  // Other sources never say it.
  Boundary automatic;
  for (int i = 0; i < 10; ++i) automatic.input->addImu(imuAt(1.0 + 0.01 * i));
  EXPECT_TRUE(automatic.notices.empty());
}

TEST(MessageInput, StampsInMessagesAreWrittenInFull) {
  // Frames at rest without the target, at today's epoch stamps: the reason gives the stamp in full.
  Boundary b;
  ASSERT_TRUE(b.input->setCameraInfo(cameraInfo(64, 48)));
  const double t0 = 1700000000.0;
  for (int i = 0; i <= 400; ++i) {
    const double t = t0 + 0.01 * i;
    b.input->addImu(imuAt(t));
    if (i >= 150 && i % 25 == 0) b.input->addImage(monoImage(t + 0.005));
  }
  ASSERT_GT(b.count(RejectReason::kTargetNotFound), 0u);
  bool found = false;
  for (const auto& d : b.details) {
    EXPECT_EQ(d.find("e+09"), std::string::npos) << d;
    found = found || d.find("image at 1700000001.505 s") != std::string::npos;
  }
  EXPECT_TRUE(found) << b.details.front();
  // Stamps going backwards, to the microsecond.
  b.input->addImu(imuAt(t0 + 3.000123));
  EXPECT_NE(b.details.back().find("1700000003.000123"), std::string::npos) << b.details.back();
}

TEST(MessageInput, BadCameraInfoIsCountedAndThePreviousOneStays) {
  Boundary b;
  sensor_msgs::CameraInfo zero_k = cameraInfo();
  zero_k.K.fill(0.0);
  EXPECT_FALSE(b.input->setCameraInfo(zero_k));
  EXPECT_FALSE(b.pipeline->hasIntrinsics());
  ASSERT_TRUE(b.input->setCameraInfo(cameraInfo()));
  sensor_msgs::CameraInfo short_d = cameraInfo();
  short_d.D = {0.1, 0.2};
  EXPECT_FALSE(b.input->setCameraInfo(short_d));
  sensor_msgs::CameraInfo nan_k = cameraInfo();
  nan_k.K[0] = kNaN;
  EXPECT_FALSE(b.input->setCameraInfo(nan_k));
  sensor_msgs::CameraInfo no_size = cameraInfo();
  no_size.width = 0;
  EXPECT_FALSE(b.input->setCameraInfo(no_size));
  EXPECT_EQ(b.count(RejectReason::kBadCameraInfo), 4u);
  for (const auto& r : b.rejects) EXPECT_EQ(r.second, InputStream::kCameraInfo);
  EXPECT_TRUE(b.pipeline->hasIntrinsics());
  EXPECT_TRUE(b.input->addImage(monoImage(1.0)));  // still checked against the good one
  EXPECT_FALSE(b.input->addImage(monoImage(2.0, 32, 24)));
}

TEST(MessageInput, CameraPosesMustBeUnitQuaternions) {
  Boundary b;
  EXPECT_TRUE(b.input->addCameraPose(cameraPose(1.0, Eigen::Quaterniond::Identity())));
  EXPECT_FALSE(b.input->addCameraPose(cameraPose(2.0, Eigen::Quaterniond(2.0, 0.0, 0.0, 0.0))));
  EXPECT_FALSE(b.input->addCameraPose(cameraPose(3.0, Eigen::Quaterniond(kNaN, 0.0, 0.0, 0.0))));
  EXPECT_FALSE(b.input->addCameraPose(cameraPose(4.0, Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0))));
  EXPECT_EQ(b.count(RejectReason::kNonFinite), 3u);
  EXPECT_EQ(b.pipeline->frames(), 1u);
  for (const auto& r : b.rejects) EXPECT_EQ(r.second, InputStream::kCameraPose);
  EXPECT_EQ(b.input->cameraFrame(), "");  // the pose's frame is the target's, not the camera's
}

TEST(MessageInput, FrameIdsLoseTheirLeadingSlashAndDifferentMagFramesAreNoted) {
  EXPECT_EQ(normalizeFrameId("/imu"), "imu");
  EXPECT_EQ(normalizeFrameId("//a/b"), "a/b");
  EXPECT_EQ(normalizeFrameId("imu_link"), "imu_link");
  EXPECT_EQ(normalizeFrameId(""), "");
  // The sparkfun_razor bag's frames: "/imu" and "/magnetometer".
  Boundary b;
  sensor_msgs::Imu imu = imuAt(1.0);
  imu.header.frame_id = "/imu";
  sensor_msgs::MagneticField mag = magAt(1.0);
  mag.header.frame_id = "/magnetometer";
  b.input->addImu(imu);
  EXPECT_FALSE(b.input->needsMagnetometerRotation());
  b.input->addMagnetic(mag);
  EXPECT_EQ(b.input->imuFrame(), "imu");
  EXPECT_EQ(b.input->magFrame(), "magnetometer");
  EXPECT_TRUE(b.input->needsMagnetometerRotation());
  ASSERT_EQ(b.notices.size(), 3u);  // each slash once, the different frames once
  EXPECT_NE(b.notices[0].find("'/imu'"), std::string::npos) << b.notices[0];
  EXPECT_NE(b.notices[1].find("'/magnetometer'"), std::string::npos) << b.notices[1];
  EXPECT_NE(b.notices[2].find("differs"), std::string::npos) << b.notices[2];
  for (int i = 2; i < 10; ++i) {
    imu.header.stamp = mag.header.stamp = ros::Time(i);
    b.input->addImu(imu);
    b.input->addMagnetic(mag);
  }
  EXPECT_EQ(b.notices.size(), 3u);   // not repeated
  imu.header.frame_id = "imu_link";  // a new IMU frame is taken, and compared again
  imu.header.stamp = ros::Time(20.0);
  b.input->addImu(imu);
  EXPECT_EQ(b.input->imuFrame(), "imu_link");
  ASSERT_EQ(b.notices.size(), 4u);
  EXPECT_NE(b.notices[3].find("'imu_link'"), std::string::npos) << b.notices[3];
  b.input->setMagnetometerRotation(Eigen::Matrix3d::Identity());
  EXPECT_FALSE(b.input->needsMagnetometerRotation());
}

/// One rest (IMU level, the field along `field_mag` in the magnetometer frame), then motion: the
/// pose's accelerometer + magnetometer attitude.
/// `mag_frame`: the magnetometer messages' frame_id; `tf`: where MessageInput may look up its
/// rotation into the IMU frame.
Eigen::Matrix3d accelMagAttitude(const Eigen::Vector3d& field_mag,
                                 const std::optional<Eigen::Matrix3d>& R_imu_mag,
                                 const std::string& mag_frame = "imu_link",
                                 const tf2::BufferCore* tf = nullptr,
                                 std::vector<std::string>* notices = nullptr) {
  Boundary b;
  if (R_imu_mag) b.input->setMagnetometerRotation(*R_imu_mag);
  b.input->setTransforms(tf);
  for (int i = 0; i < 1000; ++i) {  // 4 s at 200 Hz at rest, then 1 s turning
    const double t = 1.0 + i * 0.005;
    const bool moving = i >= 800;
    b.input->addImu(
        imuAt(t, {0.0, 0.0, 9.81}, moving ? Eigen::Vector3d(0, 0, 1.0) : Eigen::Vector3d::Zero()));
    if (i % 4 == 0) {
      sensor_msgs::MagneticField mag = magAt(t, field_mag);
      mag.header.frame_id = mag_frame;
      b.input->addMagnetic(mag);
    }
    if (i % 20 == 0) b.input->addCameraPose(cameraPose(t, Eigen::Quaterniond::Identity()));
  }
  b.pipeline->finish();
  if (notices) *notices = b.notices;
  EXPECT_GE(b.poses.size(), 1u) << b.pipeline->restsTotal() << " rests; "
                                << b.pipeline->rejections().summary() << " "
                                << (b.pipeline->rejectedPoses().empty()
                                        ? std::string("")
                                        : b.pipeline->rejectedPoses()[0].reason);
  if (b.poses.empty() || !b.poses[0].R_world_imu_accel_mag) {
    ADD_FAILURE() << "no accelerometer + magnetometer attitude";
    return Eigen::Matrix3d::Identity();
  }
  return *b.poses[0].R_world_imu_accel_mag;
}

TEST(MessageInput, AKnownMagnetometerRotationIsApplied) {
  // The magnetometer is mounted yawed by 30 deg: its x axis is the IMU's (cos 30, sin 30, 0).
  const Eigen::Matrix3d R_imu_mag = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).matrix();
  const Eigen::Vector3d field_imu(2e-5, 0.0, -4e-5);
  const Eigen::Vector3d field_mag = R_imu_mag.transpose() * field_imu;
  const Eigen::Matrix3d truth = accelMagAttitude(field_imu, std::nullopt);
  const Eigen::Matrix3d rotated = accelMagAttitude(field_mag, R_imu_mag);
  const Eigen::Matrix3d ignored = accelMagAttitude(field_mag, std::nullopt);
  EXPECT_LT(rad2deg(rotationAngle(truth.transpose() * rotated)), 1e-6);
  EXPECT_NEAR(rad2deg(rotationAngle(truth.transpose() * ignored)), 30.0, 1e-6);
}

TEST(MessageInput, AMagnetometerRotationIsLookedUpInTf) {
  // As a robot_state_publisher would say it: imu_link -> mag, the magnetometer yawed by 30 deg.
  const Eigen::Quaterniond q_imu_mag(Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()));
  tf2::BufferCore tf;
  geometry_msgs::TransformStamped t;
  t.header.frame_id = "imu_link";
  t.child_frame_id = "mag";
  t.transform.rotation = toQuaternionMsg(q_imu_mag.toRotationMatrix());
  ASSERT_TRUE(tf.setTransform(t, "test", true));
  const Eigen::Vector3d field_imu(2e-5, 0.0, -4e-5);
  const Eigen::Vector3d field_mag = q_imu_mag.conjugate() * field_imu;
  const Eigen::Matrix3d truth = accelMagAttitude(field_imu, std::nullopt);
  std::vector<std::string> notices;
  const Eigen::Matrix3d looked_up = accelMagAttitude(field_mag, std::nullopt, "mag", &tf, &notices);
  EXPECT_LT(rad2deg(rotationAngle(truth.transpose() * looked_up)), 1e-6);
  ASSERT_FALSE(notices.empty());
  EXPECT_NE(notices.back().find("rotated from 'mag' into 'imu_link' (tf)"), std::string::npos)
      << notices.back();
  // Unknown in tf (another frame): the IMU's axes, with the notice saying so.
  const Eigen::Matrix3d unknown =
      accelMagAttitude(field_mag, std::nullopt, "other_mag", &tf, &notices);
  EXPECT_NEAR(rad2deg(rotationAngle(truth.transpose() * unknown)), 30.0, 1e-6);
  ASSERT_FALSE(notices.empty());
  EXPECT_NE(notices.back().find("differs from the IMU's"), std::string::npos) << notices.back();
}

TEST(MessageInput, MagnetometerSamplesWaitForTheirRotationAShortWhile) {
  // A live tf listener has just started: samples are held back (not fed, not counted) until the
  // rotation is known or the grace period is over; then the IMU's axes are assumed, with a notice.
  const auto sleep = [](int ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); };
  sensor_msgs::MagneticField mag = magAt(1.0);
  mag.header.frame_id = "mag";
  tf2::BufferCore tf;
  Boundary arrives;
  arrives.input->setTransforms(&tf, std::chrono::milliseconds(400));
  arrives.input->addImu(imuAt(1.0));
  arrives.input->addMagnetic(mag);
  EXPECT_EQ(arrives.pipeline->magneticSamples(), 0u);
  geometry_msgs::TransformStamped t;
  t.header.frame_id = "imu_link";
  t.child_frame_id = "mag";
  t.transform.rotation.w = 1.0;
  ASSERT_TRUE(tf.setTransform(t, "test", true));
  sleep(150);  // retried every 0.1 s during the grace period
  mag.header.stamp = ros::Time(1.1);
  arrives.input->addMagnetic(mag);
  EXPECT_EQ(arrives.pipeline->magneticSamples(), 1u);
  EXPECT_TRUE(arrives.input->hasMagnetometerRotation());
  EXPECT_TRUE(arrives.rejects.empty());

  tf2::BufferCore empty;
  Boundary never;
  never.input->setTransforms(&empty, std::chrono::milliseconds(200));
  never.input->addImu(imuAt(1.0));
  mag.header.stamp = ros::Time(1.0);
  never.input->addMagnetic(mag);
  EXPECT_EQ(never.pipeline->magneticSamples(), 0u);
  EXPECT_TRUE(never.notices.empty());
  sleep(250);
  mag.header.stamp = ros::Time(1.1);
  never.input->addMagnetic(mag);
  EXPECT_EQ(never.pipeline->magneticSamples(), 1u);
  EXPECT_FALSE(never.input->hasMagnetometerRotation());
  ASSERT_FALSE(never.notices.empty());
  EXPECT_NE(never.notices.back().find("differs from the IMU's"), std::string::npos);
}

TEST(MessageInput, ARotationFoundForOtherFramesIsDropped) {
  Boundary b;
  b.input->addImu(imuAt(1.0));
  sensor_msgs::MagneticField mag = magAt(1.0);
  mag.header.frame_id = "mag";
  b.input->addMagnetic(mag);
  EXPECT_TRUE(b.input->needsMagnetometerRotation());
  b.input->setMagnetometerRotation(Eigen::Matrix3d::Identity());
  EXPECT_FALSE(b.input->needsMagnetometerRotation());
  mag.header.frame_id = "mag2";  // a different sensor now
  mag.header.stamp = ros::Time(1.1);
  b.input->addMagnetic(mag);
  EXPECT_TRUE(b.input->needsMagnetometerRotation());
  EXPECT_FALSE(b.input->hasMagnetometerRotation());
}

TEST(MessageInput, ImuGapsAreCountedAndEndTheRestAndRateDropsAreFine) {
  Boundary b;
  for (int i = 0; i < 800; ++i) b.input->addImu(imuAt(1.0 + i * 0.005));       // 4 s at 200 Hz
  const double after_gap = 1.0 + 799 * 0.005 + 0.5;                            // 0.5 s without data
  for (int i = 0; i < 100; ++i) b.input->addImu(imuAt(after_gap + i * 0.04));  // 4 s at 25 Hz
  b.pipeline->finish();
  EXPECT_EQ(b.pipeline->imuGaps(), 1u);
  EXPECT_EQ(b.pipeline->restsTotal(), 2u);  // the gap split the rest; the slow part is a rest too
  ASSERT_EQ(b.pipeline->segments().size(), 2u);
  EXPECT_NEAR(b.pipeline->segments()[1].end_s, after_gap + 99 * 0.04, 0.6);
}

TEST(ClockJumpDetector, ACameraLaggingTheImuIsNotAJump) {
  ClockJumpDetector clock(1.0);
  for (int i = 0; i < 100; ++i) {
    const double t = 100.0 + 0.01 * i;
    EXPECT_EQ(clock.update("imu", t), 0.0);
    EXPECT_EQ(clock.update("image", t - 0.8), 0.0) << "camera 0.8 s behind the IMU";
  }
  EXPECT_EQ(clock.update("imu", 100.5), 0.0);  // small disorder: the pipeline's business
  EXPECT_NEAR(clock.newest(), 100.99, 1e-9);
}

TEST(ClockJumpDetector, AJumpBackOnOneInputRestartsAll) {
  ClockJumpDetector clock(1.0);
  clock.update("imu", 200.0);
  clock.update("image", 199.9);
  EXPECT_NEAR(clock.update("imu", 150.0), 50.0, 1e-9);  // a bag loop
  EXPECT_NEAR(clock.newest(), 150.0, 1e-9);
  // The camera follows the loop: its first stamp after it is no second jump.
  EXPECT_EQ(clock.update("image", 149.9), 0.0);
  EXPECT_EQ(clock.update("imu", 150.01), 0.0);
  EXPECT_NEAR(clock.update("image", 100.0), 49.9, 1e-9);
}

}  // namespace
}  // namespace camera_imu_alignment
