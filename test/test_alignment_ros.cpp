// rostest of the nodelet and of alignment_node (one source, two .test files): simulated bags are
// played with --clock under use_sim_time; the static tf, the services, a remount and a restart
// from the saved file are checked against the simulator's truth. Waits poll with wall-clock
// deadlines (the sim clock stops with the bag); no fixed sleeps decide anything. The further
// instances some tests start are of the kind the .test file names (~instance_kind): nodelets in
// alignment_nodelet.test, nodes in alignment_node.test.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <nodelet/NodeletList.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <tuple>

#include "camera_imu_alignment/AlignmentStatus.h"
#include "camera_imu_alignment/Calibrate.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "test_helpers.h"
#include "tool_runner.h"

namespace camera_imu_alignment {
namespace {

const std::string kNode = "/camera_imu_alignment";

std::string temp(const std::string& name) { return test::tempPath(name); }

/// Simulates a bag (5 Hz camera) and checks that its target is the one the node was started with.
std::string simulate(const std::string& name, const std::string& options) {
  const std::string bag = test::simulateBag(SIMULATE_BAG_EXE, name, options);
  EXPECT_EQ(test::readFile(test::bagStem(bag) + ".target.yaml"), test::readFile(TARGET_YAML))
      << "the simulator's target changed: update test/data/sim_checkerboard_8x6.yaml";
  return bag;
}

/// Plays a bag with --clock (blocking, in the background through std::async); `remaps` are
/// rosbag play's "from:=to" arguments.
std::future<int> play(const std::string& bag, double rate, const std::string& remaps = "") {
  const std::string cmd = "rosbag play --clock --quiet --delay 1 --rate " + std::to_string(rate) +
                          " " + bag + " " + remaps + " >/dev/null 2>&1";
  return std::async(std::launch::async, [cmd] { return std::system(cmd.c_str()); });
}

/// R_cam_imu broadcast from `camera` to `imu` (parent camera), polled until `timeout_s` (wall).
/// `accept` decides whether a seen value is the awaited one.
std::optional<Eigen::Matrix3d> waitForTf(
    tf2_ros::Buffer& buffer, const std::string& camera, const std::string& imu, double timeout_s,
    const std::function<bool(const Eigen::Matrix3d&)>& accept = [](const auto&) { return true; }) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::optional<Eigen::Matrix3d> last;
  while (std::chrono::steady_clock::now() < deadline && ros::ok()) {
    if (buffer.canTransform(camera, imu, ros::Time(0))) {
      const auto t = buffer.lookupTransform(camera, imu, ros::Time(0)).transform.rotation;
      last = Eigen::Quaterniond(t.w, t.x, t.y, t.z).toRotationMatrix();
      if (accept(*last)) return last;
    }
    ros::WallDuration(0.2).sleep();
  }
  return last;
}

Eigen::Matrix3d toMatrix(const geometry_msgs::Quaternion& q) {
  return Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
}

template <typename Srv>
bool call(const std::string& name, Srv* srv) {
  if (!ros::service::waitForService(kNode + "/" + name, ros::Duration(30.0))) return false;
  return ros::service::call(kNode + "/" + name, *srv);
}

/// The latest ~status of `node`, polled until `pred` holds or `timeout_s` (wall) passes.
std::optional<AlignmentStatus> waitForStatus(
    double timeout_s, const std::function<bool(const AlignmentStatus&)>& pred,
    const std::string& node = kNode) {
  ros::NodeHandle nh;
  std::optional<AlignmentStatus> last;
  auto sub = nh.subscribe<AlignmentStatus>(node + "/status", 10,
                                           [&](const AlignmentStatus::ConstPtr& m) { last = *m; });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline && ros::ok()) {
    if (last && pred(*last)) return last;
    ros::WallDuration(0.1).sleep();
  }
  return last;
}

/// The node's input topics remapped under `prefix` ("from:=to" arguments).
std::string remapsUnder(const std::string& prefix) {
  std::string out;
  for (const char* topic :
       {"imu/data_raw", "imu/mag", "camera/image_raw", "camera/camera_info", "camera_pose"}) {
    out += std::string(" ") + topic + ":=" + prefix + "/" + topic;
  }
  return out;
}

/// The key/values of `node`'s /diagnostics status, polled until `pred` holds or `timeout_s` (wall).
std::map<std::string, std::string> waitForDiagnostics(
    const std::string& node, double timeout_s,
    const std::function<bool(const std::map<std::string, std::string>&)>& pred) {
  ros::NodeHandle nh;
  std::map<std::string, std::string> last;
  std::mutex mutex;
  auto sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& status : m->status) {
          if (status.name.find(node) == std::string::npos) continue;
          std::lock_guard<std::mutex> lock(mutex);
          last.clear();
          for (const auto& kv : status.values) last[kv.key] = kv.value;
          last["summary"] = status.message;
          last["level"] = std::to_string(static_cast<int>(status.level));
        }
      });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline && ros::ok()) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (!last.empty() && pred(last)) return last;
    }
    ros::WallDuration(0.1).sleep();
  }
  std::lock_guard<std::mutex> lock(mutex);
  return last;
}

/// A diagnostics value as a count (-1 when missing).
long countOf(const std::map<std::string, std::string>& values, const std::string& key) {
  const auto it = values.find(key);
  return it == values.end() ? -1 : std::stol(it->second);
}

/// Waits until `pub` has a subscriber (the node under test connected).
bool connected(const ros::Publisher& pub) {
  for (int i = 0; i < 300 && pub.getNumSubscribers() == 0; ++i) ros::WallDuration(0.1).sleep();
  return pub.getNumSubscribers() > 0;
}

/// The duration of a bag (s), from rosbag info.
double bagDuration(const std::string& bag) {
  const test::ToolRun r = test::runTool("rosbag info -y -k duration " + bag);
  return r.exit_code == 0 ? std::stod(r.out) : 0.0;
}

/// The kind of instance this run tests, from the .test file's ~instance_kind: "node"
/// (alignment_node.test) or "nodelet" (alignment_nodelet.test). Set in main.
std::string g_instance_kind;

/// Scenarios whose outcome the shared AlignmentWrapper and the core decide (remounts followed
/// over minutes of replay) run in the nodelet's file only: alignment_node is a shell over the same
/// wrapper (src/ros/alignment_node.cpp). The node's file runs what differs between the kinds:
/// starting and failing to start, parameters, the launch file, the spinner's callbacks.
#define SKIP_IN_THE_NODE_FILE()  \
  if (g_instance_kind == "node") \
  GTEST_SKIP() << "run in alignment_nodelet.test only: the node shares the nodelet's wrapper"

/// A further instance of the kind under test, named `name`, with `arguments` (private parameters
/// and remaps); stopped when it goes out of scope, also when an assertion ends the test early.
/// node: an alignment_node process. nodelet: a nodelet manager `name`_manager and
/// `nodelet load camera_imu_alignment/AlignmentNodelet` into it, as alignment.launch does (the
/// loader sets the private parameters and passes the remaps on to the manager); started() then
/// also means that the manager lists the nodelet as loaded. log() is what the instance printed:
/// the node's output, or the manager's (where the nodelet writes) and the loader's.
class ExtraNode {
 public:
  ExtraNode(const std::string& name, const std::string& arguments) : name_(name) {
    const std::string settings =
        " __name:=" + name + " _target_file:=" + TARGET_YAML + " " + arguments;
    std::string cmd;
    if (g_instance_kind == "nodelet") {
      const std::string manager = name + "_manager";
      cmd = "rosrun nodelet nodelet manager __name:=" + manager + " >" + path("log") +
            " 2>&1 & echo $! >" + path("pid") +
            "; rosrun nodelet nodelet load camera_imu_alignment/AlignmentNodelet " + manager +
            settings + " >" + path("loader.log") + " 2>&1 & echo $! >" + path("loader.pid");
    } else {
      cmd = std::string(ALIGNMENT_NODE_EXE) + settings + " >" + path("log") + " 2>&1 & echo $! >" +
            path("pid");
    }
    started_ = std::system(cmd.c_str()) == 0;
    if (started_ && g_instance_kind == "nodelet") started_ = loadedInto(name + "_manager");
  }
  ~ExtraNode() { stop(); }
  void stop() const { std::system(("kill " + pids() + " 2>/dev/null").c_str()); }
  bool started() const { return started_; }
  /// Every process of the instance is running (a nodelet's crash ends its manager).
  bool alive() const {
    std::string cmd = "kill -0 $(cat " + path("pid") + ") 2>/dev/null";
    if (g_instance_kind == "nodelet") cmd += " && kill -0 $(cat " + path("loader.pid") + ")";
    return std::system((cmd + " 2>/dev/null").c_str()) == 0;
  }
  std::string log() const {
    std::string out = test::readFile(path("log"));
    if (g_instance_kind == "nodelet") out += test::readFile(path("loader.log"));
    return out;
  }

 private:
  std::string path(const std::string& what) const { return temp(name_ + "." + what); }
  /// True once `manager` lists this nodelet as loaded (polled for up to 30 s, wall clock).
  bool loadedInto(const std::string& manager) const {
    const std::string service = "/" + manager + "/list";
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    if (!ros::service::waitForService(service, ros::Duration(30.0))) return false;
    while (std::chrono::steady_clock::now() < deadline && ros::ok()) {
      nodelet::NodeletList list;
      if (ros::service::call(service, list)) {
        const auto& loaded = list.response.nodelets;
        if (std::find(loaded.begin(), loaded.end(), "/" + name_) != loaded.end()) return true;
      }
      ros::WallDuration(0.1).sleep();
    }
    return false;
  }
  std::string pids() const {
    std::string out = "$(cat " + path("pid") + ")";
    if (g_instance_kind == "nodelet") out += " $(cat " + path("loader.pid") + ")";
    return out;
  }
  std::string name_;
  bool started_ = false;
};

class AlignmentRos : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    static ros::AsyncSpinner spinner(2);  // after ros::init (main)
    spinner.start();
  }
  tf2_ros::Buffer buffer_;
  tf2_ros::TransformListener listener_{buffer_};
};

TEST_F(AlignmentRos, ReplayBroadcastsTheTruthAndTheServicesWork) {
  const std::string bag = simulate("nominal", "--scenario nominal --seed 41 --num-poses 7");
  const Eigen::Matrix3d R_true =
      readResultYaml(bag.substr(0, bag.size() - 4) + ".truth.yaml").R_cam_imu;
  auto player = play(bag, 3.0);
  const auto R = waitForTf(buffer_, "camera_optical_frame", "imu_link", 180.0);
  ASSERT_TRUE(R) << "no tf camera_optical_frame -> imu_link";
  EXPECT_LT(test::angleBetweenDeg(*R, R_true), 0.2);
  EXPECT_EQ(player.get(), 0);

  // The last rest is closed 2 s (wall) after the IMU stops: then all 7 poses are in.
  const auto status = waitForStatus(
      30.0, [](const AlignmentStatus& s) { return s.has_estimate && s.poses_total == 7u; });
  ASSERT_TRUE(status);
  EXPECT_EQ(status->poses_total, 7u);
  EXPECT_EQ(status->state, AlignmentStatus::CALIBRATED) << status->message;
  EXPECT_GE(status->poses_in_window, 3u);
  // The latest estimate is broadcast, or kept back because it is less precise than the broadcast
  // one (no silent regression, test_broadcast_gate), or because the broadcast one already equals
  // it within min_change_deg.
  EXPECT_TRUE(status->broadcast || status->message.find("regression") != std::string::npos ||
              status->message.find("within min_change_deg") != std::string::npos)
      << status->message;

  Calibrate calibrate;
  ASSERT_TRUE(call("calibrate", &calibrate));
  EXPECT_TRUE(calibrate.response.success) << calibrate.response.message;
  EXPECT_TRUE(calibrate.response.has_estimate);
  // Whether it is what the tf says, and why not when it is not.
  EXPECT_EQ(calibrate.response.not_broadcast_reason.empty(), calibrate.response.broadcast)
      << calibrate.response.not_broadcast_reason;
  Calibrate forced;
  forced.request.force = true;
  ASSERT_TRUE(call("calibrate", &forced));
  EXPECT_TRUE(forced.response.broadcast) << forced.response.not_broadcast_reason;
  EXPECT_TRUE(calibrate.response.observable);
  EXPECT_LT(test::angleBetweenDeg(toMatrix(calibrate.response.q_cam_imu), R_true), 0.2);
  EXPECT_GT(calibrate.response.std_dev_deg[0], 0.0);
  // calibrate_bag drives the same pipeline: the same poses, the same answer.
  const std::string offline = temp("offline.yaml");
  const test::ToolRun tool =
      test::runTool(std::string(CALIBRATE_BAG_EXE) + " --quiet --bag " + bag + " --target " +
                    TARGET_YAML + " --output " + offline);
  ASSERT_EQ(tool.exit_code, 0) << tool.err;
  EXPECT_LT(test::angleBetweenDeg(readResultYaml(offline).R_cam_imu,
                                  toMatrix(calibrate.response.q_cam_imu)),
            0.01);

  std_srvs::Trigger save;
  ASSERT_TRUE(call("save", &save));
  ASSERT_TRUE(save.response.success) << save.response.message;
  std::string output;
  ASSERT_TRUE(ros::param::get(kNode + "/output_file", output));
  EXPECT_LT(test::angleBetweenDeg(readResultYaml(output).R_cam_imu, R_true), 0.2);
  // What is saved is the broadcast estimate with its own quality: its poses, not the window's.
  const auto broadcast_status =
      waitForStatus(10.0, [](const AlignmentStatus& s) { return s.has_broadcast; });
  ASSERT_TRUE(broadcast_status);
  EXPECT_EQ(readResultYaml(output).num_poses, static_cast<int>(broadcast_status->broadcast_poses));
  EXPECT_EQ(broadcast_status->broadcast_source, "estimated");
  const std::string saved = temp("saved.yaml");
  std::filesystem::copy_file(output, saved, std::filesystem::copy_options::overwrite_existing);

  std_srvs::Trigger capture;
  ASSERT_TRUE(call("capture_pose", &capture));
  EXPECT_FALSE(capture.response.success);  // automatic mode
  EXPECT_NE(capture.response.message.find("manual_capture"), std::string::npos);

  std_srvs::Trigger reset;
  ASSERT_TRUE(call("reset", &reset));
  EXPECT_TRUE(reset.response.success);
  // ~reset resets: the window and the counts are empty, the broadcast calibration stays.
  const auto after = waitForStatus(10.0, [](const AlignmentStatus& s) {
    return s.poses_in_window == 0u && s.poses_total == 0u && !s.has_estimate;
  });
  ASSERT_TRUE(after);
  EXPECT_EQ(after->poses_in_window, 0u);
  EXPECT_FALSE(after->has_estimate);
  EXPECT_TRUE(after->has_broadcast);
  // ~save after the reset still writes the broadcast estimate with its own pose count.
  std_srvs::Trigger save_after_reset;
  ASSERT_TRUE(call("save", &save_after_reset));
  EXPECT_TRUE(save_after_reset.response.success) << save_after_reset.response.message;
  EXPECT_EQ(readResultYaml(output).num_poses, static_cast<int>(broadcast_status->broadcast_poses));
  Calibrate after_reset;
  ASSERT_TRUE(call("calibrate", &after_reset));
  EXPECT_FALSE(after_reset.response.success);
  EXPECT_EQ(after_reset.response.poses, 0u);
  // Nothing solved: no rotation is answered (not an identity that reads as an estimate).
  EXPECT_FALSE(after_reset.response.has_estimate);
  const auto& q = after_reset.response.q_cam_imu;
  EXPECT_EQ(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w, 0.0);

  // A restarted node (another name and frames) broadcasts the saved calibration at once.
  const ExtraNode restarted(
      "restarted",
      "_output_file:=" + saved + " _camera_frame:=restored_cam _imu_frame:=restored_imu");
  ASSERT_TRUE(restarted.started());
  const auto restored = waitForTf(buffer_, "restored_cam", "restored_imu", 30.0);
  ASSERT_TRUE(restored) << restarted.log();
  EXPECT_LT(test::angleBetweenDeg(*restored, R_true), 0.2);
  // Its status shows the loaded rotation and where it came from.
  const auto loaded = waitForStatus(
      15.0, [](const AlignmentStatus& s) { return s.has_broadcast; }, "/restarted");
  ASSERT_TRUE(loaded) << restarted.log();
  EXPECT_EQ(loaded->state, AlignmentStatus::CALIBRATED) << loaded->message;
  EXPECT_EQ(loaded->broadcast_source, "loaded: " + saved);
  EXPECT_LT(test::angleBetweenDeg(toMatrix(loaded->q_broadcast), R_true), 0.2);
  EXPECT_GT(loaded->broadcast_poses, 0u);
}

TEST_F(AlignmentRos, AConsumerUnitsRemountBeforeTheFirstBroadcastIsFollowed) {
  SKIP_IN_THE_NODE_FILE();
  // A consumer-grade IMU (scale, cross-axis, biases, iron) whose mount turns by 3 deg after its
  // fifth pose (30.2 s: between the holds of poses 4 and 5 for this seed); min_poses 6 keeps
  // anything from being broadcast before the turn. The change is found although nothing was
  // broadcast, and the new mount is broadcast within 0.2 deg from its 11 poses.
  const std::string bag = simulate("consumer_remount",
                                   "--scenario consumer --seed 61 --num-poses 16 --remount "
                                   "--remount-deg 0,3,0 --remount-time-s 30.2");
  const Eigen::Matrix3d R_after =
      readResultYaml(bag.substr(0, bag.size() - 4) + ".truth.yaml").R_cam_imu;
  const ExtraNode consumer("consumer",
                           "_min_poses:=6 _load_on_start:=false _camera_frame:=consumer_cam "
                           "_imu_frame:=consumer_imu" +
                               remapsUnder("consumer"));
  ASSERT_TRUE(consumer.started()) << consumer.log();
  auto player = play(bag, 3.0, remapsUnder("consumer"));
  const auto R =
      waitForTf(buffer_, "consumer_cam", "consumer_imu", 240.0,
                [&](const Eigen::Matrix3d& r) { return test::angleBetweenDeg(r, R_after) < 0.2; });
  EXPECT_EQ(player.get(), 0);
  ASSERT_TRUE(R) << consumer.log();
  EXPECT_LT(test::angleBetweenDeg(*R, R_after), 0.2);
  const auto status = waitForStatus(
      10.0, [](const AlignmentStatus& s) { return s.remounts >= 1u; }, "/consumer");
  ASSERT_TRUE(status) << consumer.log();
  EXPECT_GE(status->remounts, 1u) << consumer.log();
  EXPECT_NE(consumer.log().find("mount changed before pose"), std::string::npos);
}

TEST_F(AlignmentRos, RemountReconvergesToTheNewMounting) {
  SKIP_IN_THE_NODE_FILE();
  // The mount turns by 10 deg about the camera y axis halfway: the window restarts from the poses
  // that disagree and the tf follows.
  std_srvs::Trigger reset;
  ASSERT_TRUE(call("reset", &reset));
  const std::string bag = simulate("remount", "--scenario remount --seed 43");
  const std::string stem = bag.substr(0, bag.size() - 4);
  const Eigen::Matrix3d R_after = readResultYaml(stem + ".truth.yaml").R_cam_imu;
  auto player = play(bag, 3.0);
  const auto R =
      waitForTf(buffer_, "camera_optical_frame", "imu_link", 240.0,
                [&](const Eigen::Matrix3d& r) { return test::angleBetweenDeg(r, R_after) < 0.3; });
  EXPECT_EQ(player.get(), 0);
  ASSERT_TRUE(R);
  EXPECT_LT(test::angleBetweenDeg(*R, R_after), 0.3);
}

TEST_F(AlignmentRos, ManualCaptureTakesOnlyTheArmedRest) {
  // A second node on its own topics with manual_capture: armed once before the bag, so the first
  // rest becomes a pose and the later ones do not.
  const std::string bag = simulate("manual", "--scenario nominal --seed 47 --num-poses 4");
  const ExtraNode manual("manual",
                         "_manual_capture:=true _load_on_start:=false" + remapsUnder("manual"));
  ASSERT_TRUE(manual.started());
  ASSERT_TRUE(ros::service::waitForService("/manual/capture_pose", ros::Duration(30.0)));
  std_srvs::Trigger capture;
  ASSERT_TRUE(ros::service::call("/manual/capture_pose", capture));
  EXPECT_TRUE(capture.response.success) << capture.response.message;
  // Beside it, an instance listening to the same camera but to a wrong IMU topic.
  const ExtraNode deaf(
      "deaf", "_load_on_start:=false" + remapsUnder("manual") + " imu/data_raw:=/deaf/wrong_imu");
  ASSERT_TRUE(deaf.started()) << deaf.log();
  // And one told of the wrong target (an AprilGrid while the bag shows a checkerboard).
  const std::string wrong_target = temp("wrong_target.yaml");
  std::ofstream(wrong_target) << "target_type: aprilgrid\ntagCols: 6\ntagRows: 6\n"
                                 "tagSize: 0.088\ntagSpacing: 0.3\n";
  const ExtraNode blind(
      "blind", "_load_on_start:=false _target_file:=" + wrong_target + remapsUnder("manual"));
  ASSERT_TRUE(blind.started()) << blind.log();
  EXPECT_EQ(play(bag, 3.0, remapsUnder("manual")).get(), 0);
  // All rests but the last are judged while the bag plays (the last one, unarmed, would not count
  // either); the status is latched.
  const auto last = waitForStatus(
      15.0, [](const AlignmentStatus& s) { return s.poses_total >= 1; }, "/manual");
  ASSERT_TRUE(last) << manual.log();
  EXPECT_EQ(last->poses_total, 1u) << manual.log();
  // A wrong IMU topic: said, naming the topic, while the camera flows; diagnostics WARN.
  const auto deaf_diagnostics = waitForDiagnostics("deaf", 20.0, [](const auto& v) {
    return v.count("summary") && v.at("summary").find("nothing on") != std::string::npos;
  });
  EXPECT_NE(deaf.log().find("nothing on /deaf/wrong_imu"), std::string::npos) << deaf.log();
  ASSERT_TRUE(deaf_diagnostics.count("level"));
  EXPECT_EQ(deaf_diagnostics.at("level"), "1") << deaf_diagnostics.at("summary");  // WARN
  // The wrong target: never found, said in diagnostics (WARN).
  const auto blind_diagnostics = waitForDiagnostics("blind", 20.0, [](const auto& v) {
    return v.count("summary") && v.at("summary").find("target was not found") != std::string::npos;
  });
  ASSERT_TRUE(blind_diagnostics.count("summary")) << blind.log();
  EXPECT_NE(blind_diagnostics.at("summary").find("target was not found"), std::string::npos)
      << blind_diagnostics.at("summary");
  EXPECT_EQ(blind_diagnostics.at("level"), "1");
  // The later rests were not armed: said so, not "no camera data".
  EXPECT_NE(manual.log().find("not used: not armed"), std::string::npos) << manual.log();
  EXPECT_EQ(manual.log().find("no camera data"), std::string::npos) << manual.log();
}

TEST_F(AlignmentRos, AnInstanceThatCannotStartSaysWhyAndItsStartFails) {
  // A bad value and a relative target path. The node exits 2 printing the reason; the nodelet
  // logs it under its own name and its load fails, so `nodelet load` exits with an error (before,
  // it stayed loaded as an empty shell and the loader never returned).
  const std::string target = " _target_file:=" + std::string(TARGET_YAML);
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {target + " _window_poses:=-1", {"window_poses = -1: must be an integer within [2, 200]"}},
      {" _target_file:=no_such_board.yaml",
       {"target_file 'no_such_board.yaml': no such file: tried /", "/no_such_board.yaml",
        "~/.ros"}}};
  int n = 0;
  for (const auto& [arguments, expected] : cases) {
    const std::string name = "cannot_start_" + std::to_string(n++);
    std::string log;
    if (g_instance_kind == "node") {
      const test::ToolRun run =
          test::runTool(std::string(ALIGNMENT_NODE_EXE) + " __name:=" + name + arguments, 60);
      EXPECT_EQ(run.exit_code, 2) << run.out << run.err;
      log = run.out + run.err;
    } else {
      const std::string manager = name + "_manager", manager_log = temp(manager + ".log");
      std::system(("rosrun nodelet nodelet manager __name:=" + manager + " >" + manager_log +
                   " 2>&1 & echo $! >" + temp(manager + ".pid"))
                      .c_str());
      ASSERT_TRUE(ros::service::waitForService("/" + manager + "/list", ros::Duration(30.0)));
      const test::ToolRun load =
          test::runTool("rosrun nodelet nodelet load camera_imu_alignment/AlignmentNodelet " +
                            manager + " __name:=" + name + arguments,
                        60);
      EXPECT_NE(load.exit_code, 0) << "the load did not fail";
      EXPECT_NE(load.exit_code, 124) << "the loader kept waiting on a nodelet that did not start";
      nodelet::NodeletList list;
      ASSERT_TRUE(ros::service::call("/" + manager + "/list", list));
      EXPECT_TRUE(list.response.nodelets.empty()) << "an empty shell stayed loaded";
      std::system(("kill $(cat " + temp(manager + ".pid") + ")").c_str());
      log = test::readFile(manager_log) + load.out + load.err;
    }
    EXPECT_NE(log.find("/" + name + ": cannot start: "), std::string::npos) << log;
    for (const std::string& text : expected) {
      EXPECT_NE(log.find(text), std::string::npos) << text << "\n" << log;
    }
    EXPECT_FALSE(ros::service::exists("/" + name + "/calibrate", false));
  }
}

TEST_F(AlignmentRos, TheLaunchFileClearsParametersLeftByAnEarlierRun) {
  // An earlier run left a typo key on the parameter server; alignment.launch (the kind under
  // test) starts all the same, and the stale key is gone.
  ros::param::set("/stale/min_pose", 3);
  ros::param::set("/stale/window_poses", -1);
  const std::string log = temp("stale_launch.log"), pid = temp("stale_launch.pid");
  const std::string command =
      "roslaunch camera_imu_alignment alignment.launch name:=stale manager:=stale_manager "
      "node:=" +
      std::string(g_instance_kind == "node" ? "true" : "false") + " target:=" + TARGET_YAML +
      " output:=" + temp("stale_result.yaml") +
      " load_on_start:=false camera_frame:=stale_cam imu_frame:=stale_imu "
      "imu_topic:=/stale/imu/data_raw mag_topic:=/stale/imu/mag "
      "image_topic:=/stale/camera/image_raw";
  std::system((command + " >" + log + " 2>&1 & echo $! >" + pid).c_str());
  const auto status = waitForStatus(
      60.0, [](const AlignmentStatus&) { return true; }, "/stale");
  const bool stale_key_left = ros::param::has("/stale/min_pose");
  std::system(("kill -INT $(cat " + pid + ")").c_str());
  ros::WallDuration(3.0).sleep();
  EXPECT_TRUE(status) << test::readFile(log);
  EXPECT_FALSE(stale_key_left);
  EXPECT_EQ(test::readFile(log).find("unknown key"), std::string::npos) << test::readFile(log);
}

TEST_F(AlignmentRos, CompressedImagesThroughItsOwnSubscription) {
  // image_transport: compressed without image_transport's compressed plugin (Debian has none):
  // the instance subscribes to <image topic>/compressed itself and decodes like calibrate_bag.
  ExtraNode node("compressed",
                 "_image_transport:=compressed _load_on_start:=false" + remapsUnder("compressed"));
  ASSERT_TRUE(node.started()) << node.log();
  ros::NodeHandle nh;
  auto info_pub = nh.advertise<sensor_msgs::CameraInfo>("/compressed/camera/camera_info", 10);
  auto image_pub =
      nh.advertise<sensor_msgs::CompressedImage>("/compressed/camera/image_raw/compressed", 10);
  ASSERT_TRUE(connected(info_pub)) << node.log();
  ASSERT_TRUE(connected(image_pub)) << node.log();
  sensor_msgs::CameraInfo info;
  info.header.frame_id = "compressed_cam";
  info.width = 64;
  info.height = 48;
  info.distortion_model = "plumb_bob";
  info.D = {0.0, 0.0, 0.0, 0.0, 0.0};
  info.K = {50.0, 0.0, 32.0, 0.0, 50.0, 24.0, 0.0, 0.0, 1.0};
  info.header.stamp = ros::Time(200.0);
  info_pub.publish(info);
  ros::WallDuration(0.5).sleep();
  for (int i = 0; i < 4; ++i) {
    sensor_msgs::CompressedImage image;
    image.header = info.header;
    image.header.stamp = ros::Time(200.0 + 0.2 * i);
    image.format = "png";
    if (i < 3) {
      ASSERT_TRUE(cv::imencode(".png", cv::Mat(48, 64, CV_8UC1, cv::Scalar(40 * i)), image.data));
    } else {
      image.data = {1, 2, 3, 4};  // not an image: bad_image
    }
    image_pub.publish(image);
    ros::WallDuration(0.05).sleep();
  }
  const auto values = waitForDiagnostics("compressed", 30.0, [](const auto& v) {
    return countOf(v, "frames") == 3 && countOf(v, "rejected bad_image") == 1;
  });
  EXPECT_EQ(countOf(values, "frames"), 3) << node.log();
  EXPECT_EQ(countOf(values, "rejected bad_image"), 1) << node.log();
  EXPECT_TRUE(node.alive()) << node.log();
}

TEST_F(AlignmentRos, RealImuOnlyBagsKeepItWaitingForTheCameraWithoutATf) {
  SKIP_IN_THE_NODE_FILE();  // the input handling is the wrapper both share (test budget)
  // CIA_REALDATA_DIR/imu_tools_bags (no camera; skipped when absent): a phidgets IMU lying upside
  // down with NaN magnetometer samples, an AR.Drone, a SparkFun Razor with leading-slash frame ids.
  // Played one after the other (their clocks jump back) into a node of its own.
  const std::string dir = std::string(CIA_REALDATA_DIR) + "/imu_tools_bags/";
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << dir << " not found";
  ExtraNode real("real", "_load_on_start:=false _camera_frame:=real_cam _imu_frame:=real_imu" +
                             remapsUnder("real"));
  ASSERT_TRUE(real.started());
  ASSERT_TRUE(ros::service::waitForService("/real/calibrate", ros::Duration(30.0)));
  ros::NodeHandle nh;
  std::optional<AlignmentStatus> last;
  std::uint32_t most_rests = 0;
  auto sub =
      nh.subscribe<AlignmentStatus>("/real/status", 100, [&](const AlignmentStatus::ConstPtr& m) {
        last = *m;
        most_rests = std::max(most_rests, m->rests_total);
      });
  for (const auto& [bag, imu, mag] :
       {std::tuple<std::string, std::string, std::string>{"phidgets_imu_upside_down.bag",
                                                          "/imu/data_raw", "/imu/mag"},
        {"ardrone_imu.bag", "/ardrone/imu", "/ardrone/mag"},
        {"sparkfun_razor.bag", "/imu/data_raw", "/imu/mag"}}) {
    EXPECT_EQ(play(dir + bag, 8.0, imu + ":=/real/imu/data_raw " + mag + ":=/real/imu/mag").get(),
              0)
        << bag;
  }
  // The phidgets bag's NaN magnetometer samples are counted, not used.
  const auto values = waitForDiagnostics(
      "real", 10.0, [](const auto& v) { return countOf(v, "rejected non_finite") > 0; });
  EXPECT_GT(countOf(values, "rejected non_finite"), 0);
  // Still running, still waiting for the camera, rests seen, no tf ever.
  const bool alive = real.alive();
  real.stop();
  const std::string log = real.log();
  EXPECT_TRUE(alive) << log;
  ASSERT_TRUE(last) << log;
  EXPECT_EQ(last->state, AlignmentStatus::WAITING_FOR_DATA) << last->message;
  EXPECT_NE(last->message.find("camera"), std::string::npos) << last->message;
  EXPECT_GT(most_rests, 0u) << log;
  EXPECT_EQ(last->poses_total, 0u);
  EXPECT_FALSE(buffer_.canTransform("real_cam", "real_imu", ros::Time(0)));
  EXPECT_EQ(log.find("nan"), std::string::npos) << log;
  // The sparkfun_razor's frame ids "/imu" and "/magnetometer" were noticed.
  EXPECT_NE(log.find("starts with '/'"), std::string::npos) << log;
  EXPECT_NE(log.find("'magnetometer'"), std::string::npos) << log;
}

TEST_F(AlignmentRos, ACorruptSavedFileIsSetAsideAndTheNodeStartsFresh) {
  // A truncated result file (a power cut while an older version wrote it) at start: a warning,
  // the file kept as .bad for the user, no tf from it, the node waiting for data.
  const std::string saved = temp("corrupt_result.yaml");
  std::filesystem::remove(saved + ".bad");
  {
    std::ofstream out(saved);
    out << "R_cam_imu:\n  rows: 3\n  cols: 3\n  data: [0.9, 0.1,";
  }
  ExtraNode node("corrupt", "_output_file:=" + saved +
                                " _camera_frame:=corrupt_cam _imu_frame:=corrupt_imu" +
                                remapsUnder("corrupt"));
  ASSERT_TRUE(node.started());
  const auto status = waitForStatus(
      30.0, [](const AlignmentStatus&) { return true; }, "/corrupt");
  ASSERT_TRUE(status) << node.log();
  EXPECT_EQ(status->state, AlignmentStatus::WAITING_FOR_DATA) << status->message;
  EXPECT_FALSE(status->has_estimate);
  EXPECT_TRUE(node.alive());
  node.stop();
  const std::string log = node.log();
  EXPECT_NE(log.find("saved calibration not loaded"), std::string::npos) << log;
  EXPECT_NE(log.find(saved + ".bad"), std::string::npos) << log;
  EXPECT_TRUE(std::filesystem::exists(saved + ".bad"));
  EXPECT_FALSE(std::filesystem::exists(saved));
  EXPECT_FALSE(buffer_.canTransform("corrupt_cam", "corrupt_imu", ros::Time(0)));
}

TEST_F(AlignmentRos, HostileInputsAreCountedByReasonAndNothingBreaks) {
  // Every kind of bad message, sent to a node of its own; each is refused, counted under its
  // reason in /diagnostics and warned about naming the topic; the node keeps running.
  ExtraNode node("hostile", "_load_on_start:=false" + remapsUnder("hostile"));
  ASSERT_TRUE(node.started());
  ros::NodeHandle nh;
  auto imu_pub = nh.advertise<sensor_msgs::Imu>("/hostile/imu/data_raw", 100);
  auto mag_pub = nh.advertise<sensor_msgs::MagneticField>("/hostile/imu/mag", 100);
  auto image_pub = nh.advertise<sensor_msgs::Image>("/hostile/camera/image_raw", 100);
  auto info_pub = nh.advertise<sensor_msgs::CameraInfo>("/hostile/camera/camera_info", 100);
  auto pose_pub = nh.advertise<geometry_msgs::PoseStamped>("/hostile/camera_pose", 100);
  for (const ros::Publisher* pub : {&imu_pub, &mag_pub, &image_pub, &info_pub, &pose_pub}) {
    ASSERT_TRUE(connected(*pub)) << pub->getTopic() << "\n" << node.log();
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto pause = [] { ros::WallDuration(0.02).sleep(); };
  const auto imu = [&](double t, double ax, double ay, double az, double gx = 0.0) {
    sensor_msgs::Imu m;
    m.header.stamp = ros::Time(t);
    m.header.frame_id = "/imu";  // leading slash, as the sparkfun_razor bag
    m.linear_acceleration.x = ax;
    m.linear_acceleration.y = ay;
    m.linear_acceleration.z = az;
    m.angular_velocity.x = gx;
    m.orientation_covariance[0] = -1.0;
    imu_pub.publish(m);
    pause();
  };
  imu(100.00, 0.0, 0.0, 9.81, nan);                                    // non_finite
  imu(100.01, std::numeric_limits<double>::infinity(), 0.0, 9.81);     // non_finite
  imu(100.02, 0.0, 0.0, nan);                                          // non_finite
  imu(100.03, 0.0, 0.0, 0.0);                                          // zero_vector
  imu(0.0, 0.0, 0.0, 9.81);                                            // missing_stamp
  for (int i = 0; i < 20; ++i) imu(101.0 + 0.01 * i, 0.0, 0.0, 9.81);  // good
  imu(101.19, 0.0, 0.0, 9.81);                                         // duplicate_stamp
  imu(100.70, 0.0, 0.0, 9.81);                                         // stamp_backwards
  const auto mag = [&](double t, double x, double z) {
    sensor_msgs::MagneticField m;
    m.header.stamp = ros::Time(t);
    m.header.frame_id = "/magnetometer";  // another frame than the IMU's
    m.magnetic_field.x = x;
    m.magnetic_field.z = z;
    mag_pub.publish(m);
    pause();
  };
  // The magnetometer's frame is the IMU's turned by 90 deg about z (as a URDF would say).
  tf2_ros::StaticTransformBroadcaster static_tf;
  geometry_msgs::TransformStamped imu_to_mag;
  imu_to_mag.header.stamp = ros::Time(100.0);
  imu_to_mag.header.frame_id = "imu";
  imu_to_mag.child_frame_id = "magnetometer";
  imu_to_mag.transform.rotation.z = imu_to_mag.transform.rotation.w = std::sqrt(0.5);
  static_tf.sendTransform(imu_to_mag);
  // The first sample starts the node's tf listener and is held back while the rotation arrives.
  mag(100.9, 2e-5, -4e-5);
  ros::WallDuration(1.2).sleep();
  mag(101.0, 0.2, -0.4);    // gauss: magnetic_units
  mag(101.1, 20.0, -40.0);  // microtesla: magnetic_units
  mag(101.2, 0.0, 0.0);     // zero_vector
  mag(101.3, 2e-5, -4e-5);  // good
  const auto camera = [&](double t, std::uint32_t w, std::uint32_t h, const std::string& encoding,
                          bool zero_k, std::size_t bytes) {
    sensor_msgs::CameraInfo info;
    info.header.stamp = ros::Time(t);
    info.header.frame_id = "camera_optical";
    info.width = 64;
    info.height = 48;
    info.distortion_model = "plumb_bob";
    info.D = {0.0, 0.0, 0.0, 0.0, 0.0};
    if (!zero_k) info.K = {50.0, 0.0, 32.0, 0.0, 50.0, 24.0, 0.0, 0.0, 1.0};
    sensor_msgs::Image image;
    image.header = info.header;
    image.width = w;
    image.height = h;
    image.encoding = encoding;
    image.step = w;
    image.data.assign(bytes, 0);
    info_pub.publish(info);
    image_pub.publish(image);
    pause();
  };
  camera(101.02, 64, 48, "mono8", true, 64 * 48);       // bad_camera_info
  camera(101.04, 32, 24, "mono8", false, 32 * 24);      // bad_image: not the camera info's size
  camera(101.06, 64, 48, "nonsense8", false, 64 * 48);  // bad_image: encoding
  camera(101.08, 64, 48, "mono8", false, 0);            // bad_image: no data
  geometry_msgs::PoseStamped pose;
  pose.header.stamp = ros::Time(101.1);
  pose.pose.orientation.w = 2.0;  // non_finite: not a unit quaternion
  pose_pub.publish(pose);

  const std::map<std::string, long> expected = {
      {"rejected non_finite", 4},      {"rejected zero_vector", 2},
      {"rejected missing_stamp", 1},   {"rejected duplicate_stamp", 1},
      {"rejected stamp_backwards", 1}, {"rejected magnetic_units", 2},
      {"rejected bad_camera_info", 1}, {"rejected bad_image", 3}};
  const auto values = waitForDiagnostics("hostile", 30.0, [&](const auto& v) {
    for (const auto& [key, n] : expected) {
      if (countOf(v, key) != n) return false;
    }
    return true;
  });
  for (const auto& [key, n] : expected) EXPECT_EQ(countOf(values, key), n) << key;
  EXPECT_EQ(countOf(values, "imu samples"), 20);
  const auto status = waitForStatus(
      5.0, [](const auto&) { return true; }, "/hostile");
  ASSERT_TRUE(status);
  EXPECT_FALSE(status->has_estimate);
  const bool alive = node.alive();
  node.stop();
  const std::string log = node.log();
  EXPECT_TRUE(alive) << log;
  for (const char* warning : {"/hostile/imu/data_raw: rejected (non_finite)",
                              "/hostile/imu/mag: rejected (magnetic_units)",
                              "/hostile/camera/image_raw: rejected (bad_image)",
                              "/hostile/camera/camera_info: rejected (bad_camera_info)",
                              "/hostile/camera_pose: rejected (non_finite)", "starts with '/'",
                              "'magnetometer'", "rotated from 'magnetometer' into 'imu' (tf)"}) {
    EXPECT_NE(log.find(warning), std::string::npos) << warning << "\n" << log;
  }
  EXPECT_EQ(log.find("nan"), std::string::npos) << log;
  EXPECT_FALSE(buffer_.canTransform("camera_optical", "imu", ros::Time(0)));
}

TEST_F(AlignmentRos, InputsStoppingAndComingBackAndAnUnwritableOutput) {
  SKIP_IN_THE_NODE_FILE();  // the input handling is the wrapper both share (test budget)
  // One bag played in parts: everything; the IMU alone; the camera alone; a pause with nothing;
  // everything again. The node keeps going and calibrates from the poses around the gaps. Its
  // output_file lies under a regular file: every save fails with a clear error, nothing else does.
  const std::string bag = simulate("stop_go", "--scenario nominal --seed 53 --num-poses 12");
  const Eigen::Matrix3d R_true =
      readResultYaml(bag.substr(0, bag.size() - 4) + ".truth.yaml").R_cam_imu;
  const std::string blocker = temp("not_a_directory");
  std::ofstream(blocker) << "a file where the output's directory should be\n";
  ExtraNode node("stop_go", "_load_on_start:=false _output_file:=" + blocker +
                                "/calibration.yaml _camera_frame:=sg_cam _imu_frame:=sg_imu" +
                                remapsUnder("stop_go"));
  ASSERT_TRUE(node.started());
  ASSERT_TRUE(ros::service::waitForService("/stop_go/save", ros::Duration(30.0)));
  const double duration = bagDuration(bag);
  ASSERT_GT(duration, 30.0);
  const std::string all = remapsUnder("stop_go");
  const std::string imu_only = " --topics /imu/data_raw /imu/mag" + all;
  const std::string camera_only = " --topics /camera/image_raw /camera/camera_info" + all;
  const auto part = [&](double from, double to, const std::string& args) {
    return play(bag, 4.0,
                "--start " + std::to_string(from * duration) + " --duration " +
                    std::to_string((to - from) * duration) + args)
        .get();
  };
  EXPECT_EQ(part(0.0, 0.35, all), 0);
  EXPECT_EQ(part(0.35, 0.5, imu_only), 0);
  EXPECT_EQ(part(0.5, 0.6, camera_only), 0);
  ros::WallDuration(3.0).sleep();  // nothing at all for a while
  EXPECT_EQ(part(0.6, 1.0, all), 0);

  const auto status = waitForStatus(
      30.0, [](const AlignmentStatus& s) { return s.has_estimate && s.poses_total >= 6; },
      "/stop_go");
  ASSERT_TRUE(status) << node.log();
  EXPECT_GE(status->poses_total, 6u) << node.log();
  EXPECT_LT(status->poses_total, 12u);  // the holds without camera or IMU gave no pose
  EXPECT_LT(test::angleBetweenDeg(toMatrix(status->q_cam_imu), R_true), 0.3);
  const auto R = waitForTf(buffer_, "sg_cam", "sg_imu", 10.0);
  ASSERT_TRUE(R) << node.log();
  EXPECT_LT(test::angleBetweenDeg(*R, R_true), 0.3);

  std_srvs::Trigger save;
  ASSERT_TRUE(ros::service::call("/stop_go/save", save));
  EXPECT_FALSE(save.response.success);
  EXPECT_NE(save.response.message.find(blocker), std::string::npos) << save.response.message;
  EXPECT_NE(save.response.message.find("Not a directory"), std::string::npos)
      << save.response.message;
  const auto values = waitForDiagnostics("stop_go", 10.0, [](const auto& v) {
    return v.count("last save error") && v.at("last save error") != "none";
  });
  EXPECT_NE(values.count("last save error") ? values.at("last save error").find("Not a directory")
                                            : std::string::npos,
            std::string::npos);
  EXPECT_GE(countOf(values, "imu gaps"), 1);
  EXPECT_EQ(test::readFile(blocker), "a file where the output's directory should be\n");
  EXPECT_TRUE(node.alive()) << node.log();
}

}  // namespace
}  // namespace camera_imu_alignment

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "alignment_test");
  ros::NodeHandle nh;  // keeps the node up for the whole run
  // The extra instances are of the kind under test; a missing or unknown kind fails the run.
  std::string& kind = camera_imu_alignment::g_instance_kind;
  if (!ros::param::get("~instance_kind", kind) || (kind != "node" && kind != "nodelet")) {
    std::cerr << "test_alignment_ros: ~instance_kind must be node or nodelet (set in the .test "
                 "file), got '"
              << kind << "'\n";
    return 1;
  }
  return RUN_ALL_TESTS();
}
