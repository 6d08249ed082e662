// calibrate_bag as a process on one small simulated bag (4 rests): what it writes and says at the
// edges. Outputs that cannot be written stop it before the bag is read; a truncated bag names
// `rosbag reindex`; --force writes a FAILED estimate marked so; --check under a FAILED verdict
// cannot vouch for the current calibration; a run without an estimate prints no rotation; a wrong
// topic lists the bag's topics of its type.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "camera_imu_alignment/io/result_yaml.h"
#include "tool_runner.h"

namespace camera_imu_alignment {
namespace {

const std::string kCalibrate = CALIBRATE_BAG_EXE;

std::string temp(const std::string& name) { return test::tempPath(name); }

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class CalibrateBagOutputs : public ::testing::Test {
 protected:
  /// One bag for every test: 4 rests about different axes, 25 s, the default camera.
  static void SetUpTestSuite() {
    bag_ = test::simulateBag(SIMULATE_BAG_EXE, "outputs",
                             "--scenario nominal --seed 29 "
                             "--num-poses 4");
    std::ofstream(strict_) << "max_std_dev_deg: 0.0001\n";  // no estimate of this bag passes
  }

  /// calibrate_bag on the bag with its target and `options`.
  static test::ToolRun calibrate(const std::string& options, const std::string& bag = bag_) {
    return test::runTool(kCalibrate + " --quiet --bag " + bag + " --target " + test::bagStem(bag_) +
                         ".target.yaml " + options);
  }

  static std::string bag_;
  static const std::string strict_;
};

std::string CalibrateBagOutputs::bag_;
const std::string CalibrateBagOutputs::strict_ = test::tempPath("strict.yaml");

TEST_F(CalibrateBagOutputs, UnwritableOutputsExitTwoBeforeTheBagIsRead) {
  // Before: the bag was read and solved, and the run ended on the first file it could not write.
  std::ofstream(temp("plain_file")) << "x";
  const std::string output = temp("no_such_folder/result.yaml");
  const std::string report = temp("plain_file/report.png");
  const std::string imu = temp("imu.yaml");
  const test::ToolRun r = calibrate("--output " + output + " --report " + report + " --imu-yaml " +
                                    imu + " --export-poses " + bag_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(has(r.err, "--output " + output + ": the folder ")) << r.err;
  EXPECT_TRUE(has(r.err, "--report " + report + ": ")) << r.err;
  EXPECT_TRUE(has(r.err, "--export-poses " + bag_ + ": is an input of the run")) << r.err;
  EXPECT_FALSE(has(r.err, "--imu-yaml")) << r.err;  // that one can be written
  EXPECT_FALSE(has(r.err, "] read ")) << r.err;     // the bag was not read
  EXPECT_FALSE(std::filesystem::exists(imu));
  EXPECT_GT(std::filesystem::file_size(bag_), 1000000u);  // and not overwritten
}

TEST_F(CalibrateBagOutputs, ATruncatedBagNamesTheFileAndRosbagReindex) {
  const std::string cut = temp("cut.bag");
  std::filesystem::copy_file(bag_, cut, std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(cut, std::filesystem::file_size(bag_) * 6 / 10);
  const test::ToolRun r = calibrate("", cut);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(has(r.err, "calibrate_bag: " + cut + ": cannot read the bag (")) << r.err;
  EXPECT_TRUE(has(r.err, "truncated")) << r.err;
  EXPECT_TRUE(has(r.err, "'rosbag reindex " + cut + "'")) << r.err;
  // The advice works: reindexed, the part that was recorded is read.
  if (std::system("command -v rosbag >/dev/null 2>&1") != 0) return;  // python3-rosbag absent
  ASSERT_EQ(test::runTool("rosbag reindex " + cut).exit_code, 0);
  const test::ToolRun repaired = calibrate("", cut);
  EXPECT_NE(repaired.exit_code, 2) << repaired.err;
  EXPECT_TRUE(has(repaired.err, "] read ")) << repaired.err;
}

TEST_F(CalibrateBagOutputs, ForceWritesAFailedEstimateMarkedFailed) {
  const std::string output = temp("forced.yaml"), imu = temp("forced_imu.yaml");
  std::filesystem::remove(output);
  const test::ToolRun refused = calibrate("--config " + strict_ + " --output " + output);
  EXPECT_EQ(refused.exit_code, 4) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(output));
  // Before: no --force (a usage error).
  const test::ToolRun forced =
      calibrate("--config " + strict_ + " --output " + output + " --imu-yaml " + imu + " --force");
  EXPECT_EQ(forced.exit_code, 4) << forced.err;  // forced, still a failure
  EXPECT_TRUE(has(forced.err, "written to --output / --imu-yaml marked FAILED (--force)"))
      << forced.err;
  ASSERT_TRUE(std::filesystem::exists(output)) << forced.err;
  const YAML::Node verdict = YAML::LoadFile(output)["verdict"];
  ASSERT_TRUE(verdict) << test::readFile(output);
  EXPECT_FALSE(verdict["passed"].as<bool>());
  EXPECT_TRUE(verdict["forced"].as<bool>());
  EXPECT_TRUE(has(verdict["text"].as<std::string>(), "FAILED: 1-sigma")) << verdict;
  EXPECT_TRUE(has(verdict["text"].as<std::string>(), "max_std_dev_deg 0.0001")) << verdict;
  EXPECT_EQ(test::readFile(imu).rfind("# camera_imu_alignment: this estimate FAILED: ", 0), 0u)
      << test::readFile(imu);
  // Read back by a reader, it is said to be what it is.
  const test::ToolRun check = calibrate("--check " + output);
  EXPECT_TRUE(has(check.err, "note: --check " + output +
                                 " holds an estimate that FAILED its quality gates, written on "
                                 "request (force)"))
      << check.err;
  // A check writes nothing: nothing to force.
  const test::ToolRun both = calibrate("--check " + output + " --force");
  EXPECT_EQ(both.exit_code, 2) << both.err;
  EXPECT_TRUE(has(both.err, "--force with --check")) << both.err;
}

TEST_F(CalibrateBagOutputs, CheckUnderAFailedVerdictExitsFour) {
  // The true calibration, checked by an estimate that fails its gates. Before: "still right",
  // exit 0.
  const std::string truth = test::bagStem(bag_) + ".truth.yaml";
  const test::ToolRun r = calibrate("--config " + strict_ + " --check " + truth);
  EXPECT_EQ(r.exit_code, 4) << r.err << r.out;
  EXPECT_TRUE(has(r.out, "verdict: FAILED")) << r.out;
  EXPECT_TRUE(has(r.out, "check: " + truth + ": the new estimate FAILED its quality gates"))
      << r.out;
  EXPECT_FALSE(has(r.out, "still right")) << r.out;
  // With the gates met, the same check holds.
  const test::ToolRun passed = calibrate("--check " + truth);
  EXPECT_EQ(passed.exit_code, 0) << passed.err << passed.out;
  EXPECT_TRUE(has(passed.out, "still right")) << passed.out;
}

TEST_F(CalibrateBagOutputs, NoEstimateMeansNoRotationInTheSummary) {
  // The first 6 s hold one rest: no pair, nothing solved. Before: the placeholder identity was
  // printed as R_cam_imu with blocks to paste and a static_transform_publisher line.
  const std::string page = temp("no_estimate.png");
  const test::ToolRun r = calibrate("--end 6 --report " + page);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_TRUE(has(r.out, "status: bad input")) << r.out;
  EXPECT_TRUE(has(r.out, "\nR_cam_imu: no estimate\n")) << r.out;
  for (const char* absent : {"quaternion xyzw", "roll, pitch, yaw", "T_cam_imu",
                             "static_transform_publisher", "extrinsicRotation"}) {
    EXPECT_FALSE(has(r.out, absent)) << absent << "\n" << r.out;
  }
  EXPECT_TRUE(std::filesystem::exists(page));  // the report still shows the rest and why
}

TEST_F(CalibrateBagOutputs, AWrongTopicListsTheBagsTopicsOfItsType) {
  const test::ToolRun imu = calibrate("--imu-topic /nope");
  EXPECT_EQ(imu.exit_code, 2) << imu.err;
  EXPECT_TRUE(has(imu.err,
                  "--imu-topic /nope: no such topic in the bag; the bag's "
                  "sensor_msgs/Imu topics: /imu/data_raw"))
      << imu.err;
  const test::ToolRun image = calibrate("--image-topic /imu/mag");
  EXPECT_EQ(image.exit_code, 2) << image.err;
  EXPECT_TRUE(has(image.err, "topic has type sensor_msgs/MagneticField")) << image.err;
  EXPECT_TRUE(has(image.err, "topics: /camera/image_raw (sensor_msgs/Image)")) << image.err;
  const test::ToolRun info = calibrate("--camera-info-topic /camera/info");
  EXPECT_EQ(info.exit_code, 2) << info.err;
  EXPECT_TRUE(has(info.err, "the bag's sensor_msgs/CameraInfo topics: /camera/camera_info"))
      << info.err;
  const test::ToolRun pose = calibrate("--camera-pose-topic /camera_pose");
  EXPECT_EQ(pose.exit_code, 2) << pose.err;
  EXPECT_TRUE(has(pose.err, "the bag has no geometry_msgs/PoseStamped topic")) << pose.err;
}

}  // namespace
}  // namespace camera_imu_alignment
