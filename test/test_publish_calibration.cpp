// rostest of launch/publish_calibration.launch (test/publish_calibration.test): the saved result
// YAML test/data/result_example.yaml appears as the static tf, camera -> IMU with the file's
// frames, and IMU -> camera with renamed frames when publish_inverse is set; the rotation is the
// file's.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/transform_listener.h>

#include <Eigen/Geometry>
#include <chrono>

#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// The rotation parent <- child, polled for up to 60 s (wall).
std::optional<Eigen::Matrix3d> waitForRotation(tf2_ros::Buffer& buffer, const std::string& parent,
                                               const std::string& child) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline && ros::ok()) {
    if (buffer.canTransform(parent, child, ros::Time(0))) {
      const auto q = buffer.lookupTransform(parent, child, ros::Time(0)).transform.rotation;
      return Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
    }
    ros::WallDuration(0.1).sleep();
  }
  return std::nullopt;
}

TEST(PublishCalibration, TheSavedRotationAppearsAsTheStaticTf) {
  const StoredCalibration saved = readResultYaml(TEST_RESULT_YAML);
  ASSERT_EQ(saved.camera_frame, "example_camera_optical");
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const auto R = waitForRotation(buffer, "example_camera_optical", "example_imu");
  ASSERT_TRUE(R) << "no tf example_camera_optical -> example_imu";
  EXPECT_LT(rad2deg(geodesicDistance(*R, saved.R_cam_imu)), 1e-6);
  // publish_inverse: the IMU is the parent, the rotation R_imu_cam.
  const auto R_inverse = waitForRotation(buffer, "renamed_imu", "renamed_camera");
  ASSERT_TRUE(R_inverse) << "no tf renamed_imu -> renamed_camera";
  EXPECT_LT(rad2deg(geodesicDistance(*R_inverse, saved.R_cam_imu.transpose())), 1e-6);
  EXPECT_FALSE(buffer._frameExists("camera_optical_frame"));
}

}  // namespace
}  // namespace camera_imu_alignment

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "publish_calibration_test");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
