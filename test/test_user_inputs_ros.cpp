// rostest of what a robot user meets around the inputs and the files (test/user_inputs.test, on
// wall time: no /use_sim_time): the launch files' save switch and defaults, the camera topic named
// when one of image / camera info is missing, camera_pose's camera frame, the diagnostics name of
// a nodelet, a loaded calibration replaced (said, the old file kept as .bak) and replay_bag.launch
// leaving /use_sim_time behind. The instances are nodelets (a manager each) or nodes, as the .test
// file's ~instance_kind says. Waits poll with wall-clock deadlines; no fixed sleep decides.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <nodelet/NodeletList.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>
#include <std_srvs/Trigger.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>

#include "camera_imu_alignment/AlignmentStatus.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "test_helpers.h"
#include "tool_runner.h"

namespace camera_imu_alignment {
namespace {

std::string g_instance_kind;  ///< "node" or "nodelet" (the .test file's ~instance_kind)

std::string temp(const std::string& name) { return test::processTempDir() + name; }

/// Polls `done` every 0.1 s (wall) until it holds or `timeout_s` passes.
bool waitFor(double timeout_s, const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline && ros::ok()) {
    if (done()) return true;
    ros::WallDuration(0.1).sleep();
  }
  return done();
}

/// An instance named `name` with private parameters and remaps `arguments`: an alignment_node, or
/// a manager `name`_manager with the AlignmentNodelet loaded into it. Stopped when destroyed.
/// log() is what it printed (the node's, or the manager's and the loader's output).
class Instance {
 public:
  Instance(const std::string& name, const std::string& arguments) : name_(name) {
    const std::string settings =
        " __name:=" + name + " _target_file:=" + TARGET_YAML + " " + arguments;
    std::string cmd;
    if (g_instance_kind == "nodelet") {
      // stdbuf: the INFO lines (stdout) reach the log at once, not when a buffer fills.
      cmd = "stdbuf -oL rosrun nodelet nodelet manager __name:=" + name + "_manager >" +
            path("log") + " 2>&1 & echo $! >" + path("pid") +
            "; rosrun nodelet nodelet load camera_imu_alignment/AlignmentNodelet " + name +
            "_manager" + settings + " >" + path("loader.log") + " 2>&1 & echo $! >" +
            path("loader.pid");
    } else {
      cmd = "stdbuf -oL " + std::string(ALIGNMENT_NODE_EXE) + settings + " >" + path("log") +
            " 2>&1 & echo $! >" + path("pid");
    }
    started_ = std::system(cmd.c_str()) == 0 &&
               ros::service::waitForService("/" + name + "/calibrate", ros::Duration(30.0));
  }
  ~Instance() { stop(); }
  void stop() const {
    std::string pids = "$(cat " + path("pid") + ")";
    if (g_instance_kind == "nodelet") pids += " $(cat " + path("loader.pid") + ")";
    std::system(("kill " + pids + " 2>/dev/null").c_str());
  }
  bool started() const { return started_; }
  std::string log() const {
    return test::readFile(path("log")) + test::readFile(path("loader.log"));
  }
  bool logged(const std::string& text) const { return log().find(text) != std::string::npos; }

 private:
  std::string path(const std::string& what) const { return temp(name_ + "." + what); }
  std::string name_;
  bool started_ = false;
};

/// The node's input topics remapped under `prefix` ("from:=to" arguments).
std::string remapsUnder(const std::string& prefix) {
  std::string out;
  for (const char* topic :
       {"imu/data_raw", "imu/mag", "camera/image_raw", "camera/camera_info", "camera_pose"}) {
    out += std::string(" ") + topic + ":=" + prefix + "/" + topic;
  }
  return out;
}

bool connected(const ros::Publisher& pub) {
  return waitFor(30.0, [&] { return pub.getNumSubscribers() > 0; });
}

sensor_msgs::CameraInfo cameraInfo(double t) {
  sensor_msgs::CameraInfo info;
  info.header.stamp = ros::Time(t);
  info.header.frame_id = "cam";
  info.width = 64;
  info.height = 48;
  info.distortion_model = "plumb_bob";
  info.D = {0.0, 0.0, 0.0, 0.0, 0.0};
  info.K = {50.0, 0.0, 32.0, 0.0, 50.0, 24.0, 0.0, 0.0, 1.0};
  return info;
}

/// Publishes a still IMU (100 Hz) with images and / or camera info (10 Hz) for `seconds` of wall
/// time, message stamps from 100 s on. `image_topic` / `info_topic` empty: not published.
void publishRest(const std::string& imu_topic, const std::string& image_topic,
                 const std::string& info_topic, double seconds) {
  ros::NodeHandle nh;
  ros::Publisher imu_pub = nh.advertise<sensor_msgs::Imu>(imu_topic, 100);
  ros::Publisher image_pub, info_pub;
  ASSERT_TRUE(connected(imu_pub)) << imu_topic;
  if (!image_topic.empty()) image_pub = nh.advertise<sensor_msgs::Image>(image_topic, 10);
  if (!info_topic.empty()) {
    info_pub = nh.advertise<sensor_msgs::CameraInfo>(info_topic, 10);
    ASSERT_TRUE(connected(info_pub)) << info_topic;
  }
  for (int i = 0; i < static_cast<int>(seconds * 100.0); ++i) {
    const double t = 100.0 + 0.01 * i;
    sensor_msgs::Imu imu;
    imu.header.stamp = ros::Time(t);
    imu.header.frame_id = "imu";
    imu.linear_acceleration.z = 9.81;
    imu.orientation_covariance[0] = -1.0;
    imu_pub.publish(imu);
    if (i % 10 == 0) {
      const sensor_msgs::CameraInfo info = cameraInfo(t);
      if (info_pub) info_pub.publish(info);
      if (image_pub) {
        sensor_msgs::Image image;
        image.header = info.header;
        image.width = 64;
        image.height = 48;
        image.encoding = "mono8";
        image.step = 64;
        image.data.assign(64 * 48, 128);
        image_pub.publish(image);
      }
    }
    ros::WallDuration(0.01).sleep();
  }
}

class UserInputsRos : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    static ros::AsyncSpinner spinner(2);
    spinner.start();
  }
};

TEST_F(UserInputsRos, SaveFalseWritesAndLoadsNothingTheDriverPresetSetsTopicsDefaultsAgree) {
  // output:="" cannot switch saving off (roslaunch drops an empty command-line value and uses
  // the default); save:=false does: no output_file, nothing loaded, ~save says so.
  const std::string saved = temp("nosave.yaml");
  std::ofstream(saved) << test::readFile(RESULT_EXAMPLE_YAML);
  const std::string log = temp("nosave_launch.log"), pid = temp("nosave_launch.pid");
  const std::string launch =
      "roslaunch camera_imu_alignment alignment.launch name:=nosave manager:=nosave_manager "
      "node:=" +
      std::string(g_instance_kind == "node" ? "true" : "false") + " target:=" + TARGET_YAML +
      " output:=" + saved + " save:=false imu_driver:=vectornav " +
      "image_topic:=/nosave/camera/image_raw";
  std::system((launch + " >" + log + " 2>&1 & echo $! >" + pid).c_str());
  const bool up = ros::service::waitForService("/nosave/save", ros::Duration(60.0));
  // imu_driver:=vectornav: the driver's topics are subscribed.
  ros::NodeHandle driver_nh;
  const ros::Publisher imu_pub = driver_nh.advertise<sensor_msgs::Imu>("/vectornav/IMU", 1);
  const ros::Publisher mag_pub =
      driver_nh.advertise<sensor_msgs::MagneticField>("/vectornav/Mag", 1);
  EXPECT_TRUE(up && connected(imu_pub) && connected(mag_pub)) << test::readFile(log);
  std::string output_file = "unset";
  ros::param::get("/nosave/output_file", output_file);
  std_srvs::Trigger save;
  const bool called = up && ros::service::call("/nosave/save", save);
  std::optional<AlignmentStatus> status;
  ros::NodeHandle nh;
  auto sub = nh.subscribe<AlignmentStatus>(
      "/nosave/status", 1, [&](const AlignmentStatus::ConstPtr& m) { status = *m; });
  waitFor(10.0, [&] { return status.has_value(); });
  std::system(("kill -INT $(cat " + pid + ")").c_str());
  ASSERT_TRUE(up) << test::readFile(log);
  EXPECT_EQ(output_file, "");
  ASSERT_TRUE(called);
  EXPECT_FALSE(save.response.success) << save.response.message;
  ASSERT_TRUE(status);
  EXPECT_FALSE(status->has_estimate) << "the file was loaded: " << status->message;
  EXPECT_EQ(test::readFile(saved), test::readFile(RESULT_EXAMPLE_YAML));

  // replay_bag.launch and alignment.launch: the same default output.
  const auto output_param = [](const std::string& args) {
    const test::ToolRun r = test::runTool("roslaunch --dump-params camera_imu_alignment " + args);
    const std::size_t at = r.out.find("/output_file: ");
    return at == std::string::npos ? "(none) " + r.out + r.err
                                   : r.out.substr(at, r.out.find('\n', at) - at);
  };
  EXPECT_EQ(output_param("replay_bag.launch bag:=b.bag target:=t.yaml"),
            output_param("alignment.launch target:=t.yaml"));
}

// replay_bag.launch passes the camera and frame args on (roslaunch ignored unknown ones silently:
// a compressed bag could not be replayed), and alignment.launch keeps the config's keys when they
// are not given (it set image_transport back to raw over the config's).
TEST_F(UserInputsRos, ReplayBagTakesTheTransportFramesAndDriverAndEmptyArgsKeepTheConfig) {
  const auto params = [](const std::string& args) {
    const test::ToolRun r = test::runTool("roslaunch --dump-params camera_imu_alignment " + args);
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    return r.out;
  };
  const auto value = [](const std::string& dump, const std::string& key) {
    const std::size_t at = dump.find("/camera_imu_alignment/" + key + ": ");
    if (at == std::string::npos) return std::string("(none)");
    const std::size_t from = dump.find(": ", at) + 2;
    return dump.substr(from, dump.find('\n', from) - from);
  };
  const std::string given = params(
      "replay_bag.launch bag:=b.bag image_transport:=compressed camera_frame:=cam "
      "imu_frame:=body publish_inverse:=true");
  EXPECT_EQ(value(given, "image_transport"), "compressed") << given;
  EXPECT_EQ(value(given, "camera_frame"), "cam") << given;
  EXPECT_EQ(value(given, "imu_frame"), "body") << given;
  EXPECT_EQ(value(given, "publish_inverse"), "true") << given;
  // Not given: the config's values (default.yaml: raw, '', '', false).
  const std::string config = test::tempPath("compressed_config.yaml");
  {
    std::string text = test::readFile(DEFAULT_CONFIG_YAML);
    const std::size_t at = text.find("\nimage_transport: raw");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, std::string("\nimage_transport: raw").size(), "\nimage_transport: compressed");
    std::ofstream(config) << text;
  }
  const std::string kept = params("replay_bag.launch bag:=b.bag config:=" + config);
  EXPECT_EQ(value(kept, "image_transport"), "compressed") << kept;
  EXPECT_EQ(value(kept, "publish_inverse"), "false") << kept;
}

// A nodelet that cannot start (a misspelt config key) stops its launch: the loader is required
// (it left a manager running that did nothing), as the node's exit 2 stops it.
TEST_F(UserInputsRos, ANodeletThatCannotStartStopsItsLaunch) {
  const std::string config = test::tempPath("misspelt_config.yaml");
  std::ofstream(config) << test::readFile(DEFAULT_CONFIG_YAML) << "\nmin_change_dge: 0.1\n";
  const auto start = std::chrono::steady_clock::now();
  // timeout's exit 124 would mean the launch kept running.
  const test::ToolRun r = test::runTool(
      "roslaunch camera_imu_alignment alignment.launch name:=misspelt manager:=misspelt_manager "
      "save:=false config:=" +
          config,
      90);
  const double took_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(r.exit_code, 124) << "the launch kept running after the failed load:\n"
                              << r.out << r.err;
  const std::string said = r.out + r.err;
  EXPECT_NE(said.find("min_change_dge"), std::string::npos) << said;
  EXPECT_NE(said.find("did you mean"), std::string::npos) << said;
  EXPECT_NE(said.find("REQUIRED process"), std::string::npos) << said;  // roslaunch names it
  std::cout << "[user_inputs] the misspelt launch stopped after " << took_s << " s\n";
}

TEST_F(UserInputsRos, TheMissingCameraTopicIsTheOneNamed) {
  // One instance gets images without their camera info, another the camera info while its image
  // topic is wrong; both get a still IMU, so that a rest ends when it stops.
  const Instance no_info("noinfo", "_load_on_start:=false" + remapsUnder("/noinfo"));
  const Instance wrong_image("wrongimg", "_load_on_start:=false" + remapsUnder("/wrongimg"));
  ASSERT_TRUE(no_info.started()) << no_info.log();
  ASSERT_TRUE(wrong_image.started()) << wrong_image.log();
  std::mutex mutex;
  std::set<std::string> diagnostic_names;
  ros::NodeHandle nh;
  auto sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const auto& s : m->status) diagnostic_names.insert(s.name);
      });
  std::thread other([] {
    publishRest("/wrongimg/imu/data_raw", "/wrongimg/camera/image_color",
                "/wrongimg/camera/camera_info", 7.0);
  });
  publishRest("/noinfo/imu/data_raw", "/noinfo/camera/image_raw", "", 7.0);
  other.join();
  // The rests end 2 s (wall) after the IMU stops.
  const std::string no_info_rest =
      "no camera data (images arrive on /noinfo/camera/image_raw but "
      "no camera info on /noinfo/camera/camera_info";
  const std::string wrong_image_rest =
      "no camera data (nothing on /wrongimg/camera/image_raw while camera info arrives on "
      "/wrongimg/camera/camera_info: wrong image topic?)";
  EXPECT_TRUE(waitFor(
      15.0, [&] { return no_info.logged(no_info_rest) && wrong_image.logged(wrong_image_rest); }))
      << no_info.log() << wrong_image.log();
  EXPECT_TRUE(
      no_info.logged("nothing on /noinfo/camera/camera_info for 5 s while images arrive "
                     "on /noinfo/camera/image_raw"))
      << no_info.log();
  EXPECT_FALSE(no_info.logged("nothing on /noinfo/camera/image_raw")) << no_info.log();
  EXPECT_FALSE(no_info.logged("nothing on /noinfo/camera_pose")) << no_info.log();
  EXPECT_FALSE(wrong_image.logged("no camera info received yet")) << wrong_image.log();
  EXPECT_TRUE(wrong_image.logged("nothing on /wrongimg/camera/image_raw for 5 s"))
      << wrong_image.log();
  // Diagnostics under the instance's own name (a nodelet's ros::this_node is its manager).
  std::lock_guard<std::mutex> lock(mutex);
  std::string names;
  for (const std::string& n : diagnostic_names) names += "'" + n + "' ";
  EXPECT_EQ(diagnostic_names.count("noinfo: calibration"), 1u) << names;
  EXPECT_EQ(diagnostic_names.count("noinfo_manager: calibration"), 0u) << names;
}

TEST_F(UserInputsRos, CameraPoseInputSaysWhichCameraFrameTheTfUses) {
  // A PoseStamped names the target frame only: the tf's camera frame is a name chosen by the
  // node, said once.
  const Instance posed("posein", "_load_on_start:=false" + remapsUnder("/posein"));
  ASSERT_TRUE(posed.started()) << posed.log();
  ros::NodeHandle nh;
  auto pub = nh.advertise<geometry_msgs::PoseStamped>("/posein/camera_pose", 10);
  ASSERT_TRUE(connected(pub));
  const std::string said =
      "/posein/camera_pose gives the camera in frame 'board' but names no camera frame: the tf's "
      "camera frame is 'camera_optical_frame' (set the camera_frame parameter to name it)";
  for (int i = 0; i < 50 && !posed.logged(said); ++i) {
    geometry_msgs::PoseStamped pose;
    pose.header.stamp = ros::Time(100.0 + 0.1 * i);
    pose.header.frame_id = "board";
    pose.pose.orientation.w = 1.0;
    pub.publish(pose);
    ros::WallDuration(0.1).sleep();
  }
  EXPECT_TRUE(posed.logged(said)) << posed.log();
  const std::string log = posed.log();
  EXPECT_EQ(log.find(said), log.rfind(said)) << "said more than once:\n" << log;
}

TEST_F(UserInputsRos, ALoadedCalibrationThatIsReplacedIsSaidAndKeptAsBak) {
  const std::string bag = temp("replace.bag");
  const test::ToolRun sim =
      test::runTool(std::string(SIMULATE_BAG_EXE) + " --out " + bag +
                    " --camera-rate-hz 5 --scenario nominal --seed 43 --num-poses 5");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const Eigen::Matrix3d R_true = readResultYaml(temp("replace.truth.yaml")).R_cam_imu;
  // A saved calibration 60 deg off the mount in the bag.
  const std::string saved = temp("replace_result.yaml");
  AlignmentResult old_result;
  old_result.R_cam_imu =
      R_true * Eigen::AngleAxisd(M_PI / 3.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  writeResultYaml(saved, old_result, ResultMetadata{});
  const std::string old_text = test::readFile(saved);
  const Instance node("replace", "_load_on_start:=true _output_file:=" + saved +
                                     " _camera_frame:=rp_cam _imu_frame:=rp_imu" +
                                     remapsUnder("/replace"));
  ASSERT_TRUE(node.started()) << node.log();
  ASSERT_TRUE(waitFor(10.0, [&] { return node.logged("calibration loaded from " + saved); }))
      << node.log();
  // Played without --clock: the node runs on wall time (use_sim_time false), as a user may.
  const test::ToolRun play =
      test::runTool("rosbag play --quiet --delay 1 --rate 3 " + bag + remapsUnder("/replace"), 300);
  EXPECT_EQ(play.exit_code, 0) << play.err;
  EXPECT_TRUE(waitFor(30.0, [&] { return node.logged("replaces the calibration loaded: "); }))
      << node.log();
  EXPECT_TRUE(node.logged("deg from it; the old file is kept as " + saved + ".bak")) << node.log();
  EXPECT_EQ(test::readFile(saved + ".bak"), old_text);
  EXPECT_LT(rad2deg(geodesicDistance(readResultYaml(saved).R_cam_imu, R_true)), 0.3);
  // Wall time: the bag has ended, nothing flows; no input is called silent.
  ros::WallDuration(7.0).sleep();
  EXPECT_FALSE(node.logged("nothing on /replace/imu/mag")) << node.log();
}

TEST_F(UserInputsRos, ReplayBagLaunchDeletesUseSimTimeWhenItEnds) {
  // Last: it sets /use_sim_time on this master while it runs.
  const std::string bag = temp("sim_time.bag");
  const test::ToolRun sim = test::runTool(std::string(SIMULATE_BAG_EXE) + " --out " + bag +
                                          " --camera-rate-hz 1 --num-poses 3 --seed 3");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const std::string log = temp("replay_launch.log"), pid = temp("replay_launch.pid");
  std::system(("roslaunch camera_imu_alignment replay_bag.launch bag:=" + bag +
               " target:=" + TARGET_YAML + " save:=false >" + log + " 2>&1 & echo $! >" + pid)
                  .c_str());
  bool sim_time = false;
  EXPECT_TRUE(waitFor(60.0, [&] {
    return ros::param::get("/use_sim_time", sim_time) && sim_time &&
           ros::service::exists("/camera_imu_alignment/calibrate", false);
  })) << test::readFile(log);
  std::system(("kill -INT $(cat " + pid + ")").c_str());
  EXPECT_TRUE(waitFor(30.0, [&] {
    return std::system(("kill -0 $(cat " + pid + ") 2>/dev/null").c_str()) != 0;
  })) << "roslaunch did not end";
  EXPECT_FALSE(ros::param::has("/use_sim_time")) << test::readFile(log);
}

}  // namespace
}  // namespace camera_imu_alignment

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "user_inputs_test");
  ros::NodeHandle nh;
  std::string& kind = camera_imu_alignment::g_instance_kind;
  if (!ros::param::get("~instance_kind", kind) || (kind != "node" && kind != "nodelet")) {
    std::cerr << "test_user_inputs_ros: ~instance_kind must be node or nodelet\n";
    return 1;
  }
  return RUN_ALL_TESTS();
}
