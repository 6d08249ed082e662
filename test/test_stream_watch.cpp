// StreamWatch (ros/stream_watch.h): which input topics are silent while others flow (a wrong remap)
// and which are merely absent (nothing flows at all, or a stream that is not expected).
#include <gtest/gtest.h>

#include <algorithm>

#include "camera_imu_alignment/ros/stream_watch.h"

namespace camera_imu_alignment {
namespace {

bool has(const std::vector<InputStream>& streams, InputStream s) {
  return std::find(streams.begin(), streams.end(), s) != streams.end();
}

TEST(StreamWatch, AWrongImuTopicIsSilentWhileTheCameraFlows) {
  StreamWatch watch(5.0);
  for (double t = 0.0; t <= 10.0; t += 0.1) {
    watch.seen(InputStream::kImage, t);
    watch.seen(InputStream::kCameraInfo, t);
  }
  const auto silent = watch.silent(10.0, false);
  EXPECT_TRUE(has(silent, InputStream::kImu));
  EXPECT_FALSE(has(silent, InputStream::kImage));
  EXPECT_FALSE(has(silent, InputStream::kCameraInfo));
  EXPECT_FALSE(has(silent, InputStream::kCameraPose));    // images flow: camera_pose not expected
  EXPECT_FALSE(has(silent, InputStream::kMagnetometer));  // not expected
}

TEST(StreamWatch, AWrongImageTopicIsNamedAndNotTheFlowingCameraInfo) {
  StreamWatch watch(5.0);
  for (double t = 0.0; t <= 10.0; t += 0.1) {
    watch.seen(InputStream::kImu, t);
    watch.seen(InputStream::kCameraInfo, t);
  }
  const auto silent = watch.silent(10.0, false);
  EXPECT_TRUE(has(silent, InputStream::kImage));
  EXPECT_FALSE(has(silent, InputStream::kCameraInfo));
  EXPECT_FALSE(has(silent, InputStream::kImu));
}

TEST(StreamWatch, CameraPoseInsteadOfImagesAndAMagnetometerThatStopped) {
  StreamWatch watch(5.0);
  for (double t = 0.0; t <= 10.0; t += 0.1) {
    watch.seen(InputStream::kImu, t);
    watch.seen(InputStream::kCameraPose, t);
    if (t < 3.0) watch.seen(InputStream::kMagnetometer, t);
  }
  const auto silent = watch.silent(10.0, true);
  EXPECT_FALSE(has(silent, InputStream::kImage));  // camera_pose flows: images not expected
  EXPECT_FALSE(has(silent, InputStream::kCameraInfo));
  EXPECT_TRUE(has(silent, InputStream::kMagnetometer));
  EXPECT_TRUE(watch.everSeen(InputStream::kMagnetometer));
}

TEST(StreamWatch, NothingIsSilentWhileNothingFlowsOrAtTheStart) {
  StreamWatch watch(5.0);
  EXPECT_TRUE(watch.silent(100.0, true).empty());  // nothing ever came
  watch.seen(InputStream::kImu, 0.0);
  EXPECT_TRUE(watch.silent(2.0, true).empty());  // too early to tell
  watch.seen(InputStream::kImu, 20.0);
  EXPECT_TRUE(watch.silent(30.0, true).empty());    // everything stopped (a bag ended)
  EXPECT_FALSE(watch.silent(21.0, false).empty());  // the IMU flows, the camera does not
}

}  // namespace
}  // namespace camera_imu_alignment
