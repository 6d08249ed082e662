// simulate_bag end to end: usage and exit codes, the three files, same seed -> same bag bytes, and
// `rosbag info --yaml --freq` showing the expected topics, message counts and rates.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <utility>

#include "camera_imu_alignment/io/result_yaml.h"
#include "tool_runner.h"

namespace camera_imu_alignment {
namespace {

using RunResult = test::ToolRun;
using test::readFile;
RunResult run(const std::string& args) { return test::runTool(args, 120); }

const std::string kSim = SIMULATE_BAG_EXE;
// A short run: 3 poses of 1-1.5 s joined by 1-1.5 s motions.
const std::string kShort =
    " --num-poses 3 --hold-min-s 1 --hold-max-s 1.5 --move-min-s 1 --move-max-s 1.5";

std::string temp(const std::string& name) { return test::tempPath(name); }

TEST(SimulateBag, HelpListsEveryScenario) {
  const RunResult r = run(kSim + " --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* s :
       {"nominal", "wall_board", "aprilgrid", "circlegrid", "noisy_imu", "few_poses", "degenerate",
        "no_magnetometer", "magnetic_disturbance", "time_offset", "remount", "bad_input",
        "long_run", "tactical", "consumer", "noisy_consumer"}) {
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
  }
  for (const char* grade : {"ideal:", "tactical:", "consumer:", "noisy:"}) {
    EXPECT_NE(r.out.find(grade), std::string::npos) << grade;
  }
  EXPECT_NE(r.out.find("--imu-grade"), std::string::npos);
}

TEST(SimulateBag, OptionsAreCheckedAgainstTheirDeclaredRanges) {
  // The option table gives the usage line, the check and the message: one declaration.
  const RunResult help = run(kSim + " --help");
  EXPECT_NE(help.out.find("--gravity-m-s2 (a number within [9.5, 10.1], m/s^2)"), std::string::npos)
      << help.out;
  EXPECT_NE(help.out.find("--mag-disturbance-ut (a number within [0, 1000], uT)"),
            std::string::npos);
  const std::pair<std::string, std::string> cases[] = {
      {" --num-poses 2.5", "--num-poses = 2.5: must be an integer within [2, 1000]"},
      {" --gravity-m-s2 12", "--gravity-m-s2 = 12: must be a number within [9.5, 10.1]"},
      {" --motion wobble", "--motion = wobble: must be 'full', 'single_axis' or 'small_angle'"},
      {" --compression zip", "--compression = zip: must be 'none', 'lz4' or 'bz2'"},
      {" --earth-field-ut 1,x,3", "--earth-field-ut = 1,x,3: must be 3 numbers x,y,z"}};
  for (const auto& [options, expected] : cases) {
    const RunResult r = run(kSim + " --out " + temp("x.bag") + options);
    EXPECT_EQ(r.exit_code, 2) << options;
    EXPECT_NE(r.err.find(expected), std::string::npos) << options << " -> " << r.err;
  }
}

TEST(SimulateBag, BadUsageExitsTwoNamingTheOption) {
  RunResult r = run(kSim + " --out " + temp("x.bag") + " --imu-rate-hz -5");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--imu-rate-hz"), std::string::npos) << r.err;
  r = run(kSim + " --out " + temp("x.bag") + " --scenario nope");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--scenario"), std::string::npos) << r.err;
  std::remove(temp("x.truth.yaml").c_str());
  r = run(kSim + " --out " + temp("x.bag") + " --imu-grade military");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--imu-grade"), std::string::npos) << r.err;
  EXPECT_FALSE(std::ifstream(temp("x.truth.yaml")).good()) << "nothing written";
  r = run(kSim + " --seed 3");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
  r = run(kSim + " --out " + temp("x.txt"));
  EXPECT_EQ(r.exit_code, 2);
  r = run(kSim + " --out " + temp("x.bag") + " --distortion 1,2");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--distortion"), std::string::npos) << r.err;
}

TEST(SimulateBag, SameSeedGivesTheSameBag) {
  const std::string a = temp("a.bag"), b = temp("b.bag"), c = temp("c.bag");
  ASSERT_EQ(run(kSim + " --out " + a + " --seed 5" + kShort).exit_code, 0);
  ASSERT_EQ(run(kSim + " --out " + b + " --seed 5" + kShort).exit_code, 0);
  ASSERT_EQ(run(kSim + " --out " + c + " --seed 6" + kShort).exit_code, 0);
  const std::string bag_a = readFile(a);
  EXPECT_GT(bag_a.size(), 1000u);
  EXPECT_TRUE(bag_a == readFile(b)) << "same seed, different bags";
  EXPECT_FALSE(bag_a == readFile(c)) << "different seeds, same bag";
  EXPECT_EQ(readFile(temp("a.truth.yaml")), readFile(temp("b.truth.yaml")));
}

TEST(SimulateBag, FilesTopicsCountsAndRates) {
  const std::string bag = temp("nominal.bag");
  const RunResult r = run(kSim + " --out " + bag + " --seed 11" + kShort);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Truth readable by our result reader; target in Kalibr's format.
  const StoredCalibration truth = readResultYaml(temp("nominal.truth.yaml"));
  EXPECT_EQ(truth.camera_frame, "camera_optical_frame");
  EXPECT_EQ(truth.imu_frame, "imu_link");
  const YAML::Node target = YAML::LoadFile(temp("nominal.target.yaml"));
  EXPECT_EQ(target["target_type"].as<std::string>(), "checkerboard");
  const YAML::Node t = YAML::LoadFile(temp("nominal.truth.yaml"));
  EXPECT_EQ(t["stationary_intervals"].size(), 3u);

  const RunResult info = run("rosbag info --yaml --freq " + bag);
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const YAML::Node y = YAML::Load(info.out);
  std::map<std::string, YAML::Node> topics;
  for (const YAML::Node& n : y["topics"]) topics[n["topic"].as<std::string>()] = n;
  ASSERT_EQ(topics.size(), 4u) << info.out;
  const struct {
    const char* topic;
    const char* type;
    const char* count_key;
    double rate;
  } expected[] = {{"/imu/data_raw", "sensor_msgs/Imu", "imu", 200.0},
                  {"/imu/mag", "sensor_msgs/MagneticField", "magnetometer", 100.0},
                  {"/camera/image_raw", "sensor_msgs/Image", "images", 15.0},
                  {"/camera/camera_info", "sensor_msgs/CameraInfo", "images", 15.0}};
  for (const auto& e : expected) {
    ASSERT_TRUE(topics.count(e.topic)) << e.topic << "\n" << info.out;
    const YAML::Node& n = topics[e.topic];
    EXPECT_EQ(n["type"].as<std::string>(), e.type);
    EXPECT_EQ(n["messages"].as<long>(), t["counts"][e.count_key].as<long>()) << e.topic;
    EXPECT_NEAR(n["frequency"].as<double>(), e.rate, 0.02 * e.rate) << e.topic;
  }
}

TEST(SimulateBag, ScenariosChangeTopicsAndTruth) {
  const std::string bag = temp("nomag.bag");
  ASSERT_EQ(run(kSim + " --out " + bag + " --scenario no_magnetometer" + kShort).exit_code, 0);
  const RunResult info = run("rosbag info --yaml " + bag);
  ASSERT_EQ(info.exit_code, 0);
  EXPECT_EQ(info.out.find("imu/mag"), std::string::npos);

  const std::string bad = temp("bad.bag");
  const RunResult r = run(kSim + " --out " + bad + " --scenario bad_input" + kShort);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node t = YAML::LoadFile(temp("bad.truth.yaml"));
  EXPECT_EQ(t["bad_input"]["nan_imu_stamps_s"].size(), 5u);
  EXPECT_EQ(t["bad_input"]["empty_image_stamps_s"].size(), 2u);
  EXPECT_EQ(t["bad_input"]["zero_k_camera_info_stamps_s"].size(), 1u);
  const YAML::Node y = YAML::Load(run("rosbag info --yaml " + bad).out);
  for (const YAML::Node& n : y["topics"]) {
    if (n["topic"].as<std::string>() == "/imu/data_raw") {
      EXPECT_EQ(n["messages"].as<long>(), t["counts"]["imu"].as<long>() + 5);  // 5 duplicates
    }
  }

  const std::string offset = temp("offset.bag");
  ASSERT_EQ(run(kSim + " --out " + offset + " --scenario time_offset" + kShort).exit_code, 0);
  const YAML::Node to = YAML::LoadFile(temp("offset.truth.yaml"));
  EXPECT_DOUBLE_EQ(to["camera"]["time_offset_s"].as<double>(), 0.05);
}

TEST(SimulateBag, ImuGradeOverridesTheScenariosGradeAndNoiseOptionsOverrideTheGrade) {
  const std::string fast = kShort + " --camera-rate-hz 1";
  ASSERT_EQ(run(kSim + " --out " + temp("consumer.bag") + " --scenario consumer" + fast).exit_code,
            0);
  YAML::Node t = YAML::LoadFile(temp("consumer.truth.yaml"));
  EXPECT_EQ(t["imu_errors"]["grade"].as<std::string>(), "consumer");
  EXPECT_NE(t["imu_errors"]["T_g"][0][0].as<double>(), 1.0);

  const RunResult r = run(kSim + " --out " + temp("override.bag") +
                          " --scenario noisy_consumer --imu-grade tactical" + fast);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  t = YAML::LoadFile(temp("override.truth.yaml"));
  EXPECT_EQ(t["scenario"].as<std::string>(), "noisy_consumer");
  EXPECT_EQ(t["imu_errors"]["grade"].as<std::string>(), "tactical");
  EXPECT_NEAR(t["imu_errors"]["gyro_noise_density_rad_s_sqrt_hz"].as<double>(), 2.618e-5, 1e-8);

  ASSERT_EQ(run(kSim + " --out " + temp("graded.bag") +
                " --imu-grade noisy --gyro-noise-density 1e-3" + fast)
                .exit_code,
            0);
  t = YAML::LoadFile(temp("graded.truth.yaml"));
  EXPECT_EQ(t["imu_errors"]["grade"].as<std::string>(), "noisy");
  EXPECT_DOUBLE_EQ(t["imu_errors"]["gyro_noise_density_rad_s_sqrt_hz"].as<double>(), 1e-3);
  EXPECT_DOUBLE_EQ(t["imu_errors"]["sigmas"]["gyro_scale"].as<double>(), 0.03);
}

TEST(SimulateBag, PlaysWithRosbagPlay) {
  const std::string bag = temp("play.bag");
  ASSERT_EQ(run(kSim + " --out " + bag +
                " --num-poses 2 --hold-min-s 1 --hold-max-s 1"
                " --move-min-s 1 --move-max-s 1")
                .exit_code,
            0);
  // Own master on a port derived from the pid; every step bounded by timeout; the master is
  // stopped by its process id.
  const std::string port = std::to_string(20000 + ::getpid() % 20000);
  const std::string script =
      "export ROS_MASTER_URI=http://localhost:" + port +
      " ROS_HOSTNAME=localhost ROS_HOME=" + ::testing::TempDir() + "; timeout 60 roscore -p " +
      port + " >/dev/null 2>&1 & M=$!; " +
      "for i in $(seq 1 150); do rostopic list >/dev/null 2>&1 && break; sleep 0.2; done; " +
      "timeout 30 rosbag play -q " + bag + "; rc=$?; kill $M; wait $M; exit $rc";
  const RunResult r = run("sh -c '" + script + "'");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
}

}  // namespace
}  // namespace camera_imu_alignment
