// camera_pose bags end to end: simulate_bag --camera-pose --no-images writes the camera's
// orientation as geometry_msgs/PoseStamped (checked against SimulationRun: stamps with the offset,
// frame, noise); calibrate_bag reads it through MessageInput (no --target, no camera info) and
// calibrates from the rests as well as from images; a waving bag (no rests) is read and refused as
// not enough information; the camera source is chosen and said; bad stamps are refused, counted
// and named.
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <string>

#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "tool_runner.h"

namespace camera_imu_alignment {
namespace {

const std::string kCalibrate = CALIBRATE_BAG_EXE;
const std::string kSimulate = SIMULATE_BAG_EXE;

std::string simulate(const std::string& name, const std::string& options) {
  return test::simulateBag(kSimulate, name, options);
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(CameraPoseBag, RestsCalibrateFromCameraPosesAsFromImages) {
  for (const char* scenario : {"wall_board", "nominal"}) {
    const std::string bag =
        simulate(std::string("poses_") + scenario,
                 std::string("--scenario ") + scenario + " --seed 41 --camera-pose --no-images");
    const YAML::Node truth = YAML::LoadFile(test::bagStem(bag) + ".truth.yaml");
    EXPECT_EQ(truth["counts"]["images"].as<int>(), 0);
    const int poses = truth["counts"]["camera_poses"].as<int>();
    EXPECT_GT(poses, 100);
    const std::string output = test::tempPath("poses_result.yaml");
    std::filesystem::remove(output);
    const test::ToolRun run = test::runTool(kCalibrate + " --quiet --bag " + bag + " --truth " +
                                            test::bagStem(bag) + ".truth.yaml --output " + output);
    ASSERT_EQ(run.exit_code, 0) << scenario << "\n" << run.err << run.out;
    EXPECT_NE(run.err.find("camera source: camera poses on /camera_pose (the bag has no image "
                           "topic)"),
              std::string::npos)
        << run.err;
    EXPECT_NE(run.err.find(std::to_string(poses) + " camera poses; 12 stationary rests"),
              std::string::npos)
        << run.err;
    const Eigen::Matrix3d R_true = readResultYaml(test::bagStem(bag) + ".truth.yaml").R_cam_imu;
    const Eigen::Matrix3d R = readResultYaml(output).R_cam_imu;
    const auto sigma = YAML::LoadFile(output)["quality"]["std_dev_deg"].as<std::vector<double>>();
    const Eigen::Vector3d error = test::leftError(R, R_true);
    EXPECT_LT(rad2deg(error.norm()), 0.1) << scenario << "\n" << run.out;
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_LT(std::abs(rad2deg(error(axis))), 3.0 * sigma[axis] + 1e-3)
          << scenario << " axis " << axis;
    }
    std::printf("%s: error %.4f deg, 1-sigma %.4f %.4f %.4f deg\n", scenario, rad2deg(error.norm()),
                sigma[0], sigma[1], sigma[2]);
    std::filesystem::remove(bag);
  }
}

TEST(CameraPoseBag, AWavingBagIsCalibratedFromTheMotionAlone) {
  const std::string bag =
      simulate("waving",
               "--scenario waving --seed 1 --duration-s 10 --imu-grade consumer --camera-pose "
               "--no-images "
               "--camera-time-offset-s 0.015");
  const YAML::Node truth = YAML::LoadFile(test::bagStem(bag) + ".truth.yaml");
  EXPECT_DOUBLE_EQ(truth["timeshift_cam_imu_s"].as<double>(), -0.015);
  EXPECT_EQ(truth["stationary_intervals"].size(), 0u);
  EXPECT_EQ(truth["counts"]["camera_poses"].as<int>(), 51);  // 10 s at 5 Hz
  // The messages: the simulator's camera orientations (same seed, same noise), stamped at true
  // capture time + offset, in the target frame, at the camera rate.
  simulation::SimulationConfig config;
  config.seed = 1;
  ASSERT_TRUE(simulation::applyScenario("waving", &config));
  simulation::applyImuGrade(simulation::ImuGrade::kConsumer, &config);
  config.waving_duration_s = 10.0;
  config.camera_rate_hz = 5.0;
  config.camera_time_offset_s = 0.015;
  const simulation::SimulationRun sim(config);
  {
    rosbag::Bag in(bag, rosbag::bagmode::Read);
    std::size_t k = 0;
    for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery("/camera_pose"))) {
      const auto pose = m.instantiate<geometry_msgs::PoseStamped>();
      ASSERT_TRUE(pose);
      ASSERT_LT(k, sim.camera_orientations.size());
      const simulation::CameraOrientation& o = sim.camera_orientations[k++];
      EXPECT_NEAR(pose->header.stamp.toSec(), config.start_time_s + o.capture_s + 0.015, 1e-6);
      EXPECT_EQ(pose->header.frame_id, "calibration_target");
      const auto& q = pose->pose.orientation;
      const Eigen::Matrix3d R = Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix();
      EXPECT_LT(test::angleBetweenDeg(R, o.R_target_cam), 1e-6);
      const double noise_deg = test::angleBetweenDeg(R, o.R_target_cam_true);
      EXPECT_GT(noise_deg, 0.0);
      EXPECT_LT(noise_deg, 0.02 * 6.0);  // 0.02 deg per axis, far below 6 sigma
    }
    EXPECT_EQ(k, 51u);
  }
  // The motion alone (no rests) calibrates: R_cam_imu within its reported 3 sigma (the consumer
  // gyro's misalignment prior, ~0.4 deg per axis, without rests) and the time offset (Kalibr's
  // sign: the camera stamps are late by 15 ms, t_imu = t_cam - 0.015).
  // The bag holds 10 s of motion: below min_motion_s (15 s by default: exit 3, "not enough
  // information"); the setting lets a short recording through.
  const std::string stem = test::bagStem(bag);
  const std::string short_motion = test::writeTempFile("short_motion.yaml", "min_motion_s: 5\n");
  const test::ToolRun refused = test::runTool(kCalibrate + " --quiet --bag " + bag);
  EXPECT_EQ(refused.exit_code, 3) << refused.err << refused.out;
  EXPECT_NE(refused.err.find("(min_motion_s 15)"), std::string::npos) << refused.err;
  const test::ToolRun run =
      test::runTool(kCalibrate + " --quiet --bag " + bag + " --config " + short_motion +
                    " --truth " + stem + ".truth.yaml --output " + stem + ".out.yaml");
  EXPECT_EQ(run.exit_code, 0) << run.err << run.out;
  // Every pose but the first (stamped before the first IMU sample) is a motion frame.
  EXPECT_NE(run.err.find("51 camera poses; 0 stationary rests, 0 poses, 50 camera orientations "
                         "during motion"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(run.err.find("rejected"), std::string::npos) << run.err;
  EXPECT_NE(run.out.find("data used: motion (0 rest(s)"), std::string::npos) << run.out;
  const YAML::Node out = YAML::LoadFile(stem + ".out.yaml");
  EXPECT_NEAR(out["timeshift_cam_imu_s"].as<double>(), -0.015, 2e-3);
  const Eigen::Vector3d error = test::leftError(readResultYaml(stem + ".out.yaml").R_cam_imu,
                                                readResultYaml(stem + ".truth.yaml").R_cam_imu);
  const auto sigma = out["quality"]["std_dev_deg"].as<std::vector<double>>();
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LT(std::abs(rad2deg(error(axis))), 3.0 * sigma[axis]) << "axis " << axis << run.out;
    EXPECT_LT(sigma[axis], 1.0) << run.out;
  }
  std::printf(
      "waving, 10 s at 5 Hz, consumer: error %.4f deg, 1-sigma %.4f %.4f %.4f deg, "
      "timeshift %.5f s\n",
      rad2deg(error.norm()), sigma[0], sigma[1], sigma[2], out["timeshift_cam_imu_s"].as<double>());
  std::filesystem::remove(stem + ".out.yaml");
  std::filesystem::remove(bag);
}

TEST(CameraPoseBag, CameraSourceIsChosenAndSaid) {
  // Images and camera poses in one bag (tiny images: only the choice matters here).
  const std::string bag = simulate("both",
                                   "--num-poses 2 --hold-min-s 1 --hold-max-s 1 "
                                   "--width 64 --height 48 --camera-pose");
  const std::string stem = test::bagStem(bag);
  // Default: the images, without a target the natural scene's features (64x48 frames of a board
  // have too few: no pose); the note names the camera_pose topic.
  test::ToolRun run = test::runTool(kCalibrate + " --quiet --bag " + bag);
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("no --target: the natural scene's features"), std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("camera source: images on /camera/image_raw; the bag also has camera "
                         "poses on /camera_pose, not read"),
            std::string::npos)
      << run.err;
  // Chosen explicitly: the poses, no target needed; the images are not read.
  run = test::runTool(kCalibrate + " --quiet --bag " + bag + " --camera-pose-topic camera_pose");
  EXPECT_NE(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("camera source: camera poses on /camera_pose (--camera-pose-topic"),
            std::string::npos)
      << run.err;
  // Both sources given: refused, naming the options.
  run = test::runTool(kCalibrate + " --quiet --bag " + bag +
                      " --camera-pose-topic camera_pose --image-topic camera/image_raw --target " +
                      stem + ".target.yaml");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("give one camera source"), std::string::npos) << run.err;
  // A camera pose topic that is not in the bag, or not a PoseStamped.
  run = test::runTool(kCalibrate + " --quiet --bag " + bag + " --camera-pose-topic /nope");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--camera-pose-topic /nope: no such topic in the bag"), std::string::npos)
      << run.err;
  run = test::runTool(kCalibrate + " --quiet --bag " + bag + " --camera-pose-topic /imu/data_raw");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("geometry_msgs/PoseStamped"), std::string::npos) << run.err;
  std::filesystem::remove(bag);
}

TEST(CameraPoseBag, BadStampsAreRefusedCountedAndNamed) {
  const std::string bag = simulate("stamps", "--scenario few_poses --camera-pose --no-images");
  // Copy with three camera poses spoiled: a zero stamp, a duplicate, one out of order.
  const std::string spoiled = test::tempPath("stamps_spoiled.bag");
  {
    rosbag::Bag in(bag, rosbag::bagmode::Read), out(spoiled, rosbag::bagmode::Write);
    int k = 0;
    ros::Time previous;
    for (const rosbag::MessageInstance& m : rosbag::View(in)) {
      const auto pose = m.instantiate<geometry_msgs::PoseStamped>();
      if (!pose) {
        out.write(m.getTopic(), m.getTime(), m);
        continue;
      }
      geometry_msgs::PoseStamped p = *pose;
      ++k;
      if (k == 10) p.header.stamp = ros::Time(0);
      if (k == 20 || k == 30) p.header.stamp = previous;          // duplicate
      if (k == 40) p.header.stamp = previous - ros::Duration(1);  // backwards
      out.write(m.getTopic(), m.getTime(), p);
      previous = pose->header.stamp;
    }
  }
  const test::ToolRun run = test::runTool(kCalibrate + " --quiet --bag " + spoiled);
  EXPECT_EQ(count(run.err, "/camera_pose: rejected (missing_stamp)"), 1u) << run.err;
  EXPECT_EQ(count(run.err, "/camera_pose: rejected (duplicate_stamp)"), 2u) << run.err;
  EXPECT_EQ(count(run.err, "/camera_pose: rejected (stamp_backwards)"), 1u) << run.err;
  EXPECT_NE(run.exit_code, -1);
  std::filesystem::remove(bag);
  std::filesystem::remove(spoiled);
}

}  // namespace
}  // namespace camera_imu_alignment
