// simulate_bag's option table (simulate_bag_options.h).
#include "simulate_bag_options.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <utility>

#include "camera_imu_alignment/config/settings_error.h"
#include "camera_imu_alignment/simulation/imu_grades.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;
using Options = SimulateBagOptions;
using Key = SettingKey<Options>;

template <typename T, typename Access>
Key number(const std::string& name, Access access, SettingRange range, const std::string& unit,
           const std::string& description) {
  return numberKey<T, Options>(name, access, range, unit, description);
}

/// A number given in the option's unit and stored as `scale` x it (uT -> T, deg -> rad).
template <typename Access>
Key scaled(const std::string& name, Access access, double scale, SettingRange range,
           const std::string& unit, const std::string& description) {
  Key key = number<double>(name, access, range, unit, description);
  key.read = [access, scale](const YAML::Node& node, Options* o) {
    access(*o) = scale * node.as<double>();
  };
  key.in_range = [access, scale, range](const Options& o) {
    return range.contains(access(o) / scale);
  };
  key.text = [access, scale](const Options& o) {
    char text[32];  // 12 digits: the unit conversion's rounding (25e-6 / 1e-6) not shown
    std::snprintf(text, sizeof(text), "%.12g", access(o) / scale);
    return formatSettingNumber(std::strtod(text, nullptr));
  };
  return key;
}

/// A list of `n` numbers (n = 0: any length) given as "a,b,c"; `set` stores them (it may throw
/// YAML::Exception for values it refuses), `get` reads them back for the usage text.
template <typename Get, typename Set>
Key list(const std::string& name, std::size_t n, Get get, Set set, const std::string& allowed,
         const std::string& unit, const std::string& description) {
  return {name,
          unit,
          description,
          allowed,
          [n, set](const YAML::Node& node, Options* o) {
            // "a,b,c" on the command line.
            std::vector<double> v;
            std::stringstream items(node.as<std::string>());
            for (std::string item; std::getline(items, item, ',');) {
              v.push_back(YAML::Node(item).as<double>());
            }
            for (double x : v) {
              if (!std::isfinite(x)) throw YAML::Exception(node.Mark(), "not finite");
            }
            if (n > 0 && v.size() != n) throw YAML::Exception(node.Mark(), "wrong length");
            set(v, o);
          },
          "",
          [](const Options&) { return true; },
          [get](const Options& o) {
            std::string text;
            for (double x : get(o)) text += (text.empty() ? "" : ",") + formatSettingNumber(x);
            return text;
          },
          std::nullopt,
          false};
}

/// A flag: given, it sets `set`; never a value.
template <typename Set>
Key flag(const std::string& name, Set set, const std::string& description) {
  return {name,
          "",
          description,
          "given without a value",
          [set](const YAML::Node&, Options* o) { set(o); },
          "",
          [](const Options&) { return true; },
          [](const Options&) { return std::string(); },
          std::nullopt,
          false};
}

std::vector<std::string> firsts(const std::vector<std::pair<std::string, std::string>>& list) {
  std::vector<std::string> names;
  for (const auto& entry : list) names.push_back(entry.first);
  return names;
}

Eigen::Vector3d vec3(const std::vector<double>& v, double scale) {
  return scale * Eigen::Vector3d(v[0], v[1], v[2]);
}
std::vector<double> list3(const Eigen::Vector3d& v, double scale) {
  return {v.x() / scale, v.y() / scale, v.z() / scale};
}

const double kUt = 1e-6;  // T per uT
const double kDeg = kPi / 180.0;

/// The presets (applied first, in this order) and the motion.
std::vector<Key> presetAndMotionKeys() {
  return {
      // Presets, applied first in this order.
      number<std::uint64_t>("--seed", CIA_MEMBER(config.seed), within(0, 9007199254740992.0), "",
                            "random seed: same seed and options, same bag"),
      wordKey<Options>(
          "--scenario", CIA_MEMBER(config), firsts(sim::scenarioList()),
          [](const std::string& name, sim::SimulationConfig* c) {
            return sim::applyScenario(name, c);
          },
          [](const sim::SimulationConfig& c) { return c.scenario; },
          "preset (list above); the options below override it"),
      wordKey<Options>(
          "--imu-grade", CIA_MEMBER(config), firsts(sim::imuGradeList()),
          [](const std::string& name, sim::SimulationConfig* c) {
            sim::ImuGrade grade;
            if (!sim::parseImuGrade(name, &grade)) return false;
            sim::applyImuGrade(grade, c);
            return true;
          },
          [](const sim::SimulationConfig& c) { return sim::toString(c.imu_grade); },
          "IMU grade (list above), before the noise options below"),
      // Motion.
      number<int>("--num-poses", CIA_MEMBER(config.num_poses), within(2, 1000), "",
                  "stationary poses"),
      number<double>("--hold-min-s", CIA_MEMBER(config.hold_min_s), within(0.1, 600), "s",
                     "shortest hold at a pose"),
      number<double>("--hold-max-s", CIA_MEMBER(config.hold_max_s), within(0.1, 600), "s",
                     "longest hold at a pose (at least --hold-min-s)"),
      number<double>("--move-min-s", CIA_MEMBER(config.move_min_s), within(0.2, 600), "s",
                     "shortest motion between poses"),
      number<double>("--move-max-s", CIA_MEMBER(config.move_max_s), within(0.2, 600), "s",
                     "longest motion between poses (at least --move-min-s)"),
      wordKey<Options>(
          "--motion", CIA_MEMBER(config.motion), {"full", "single_axis", "small_angle"},
          [](const std::string& word, sim::MotionKind* kind) {
            for (sim::MotionKind k : {sim::MotionKind::kFull, sim::MotionKind::kSingleAxis,
                                      sim::MotionKind::kSmallAngle}) {
              if (word == sim::toString(k)) {
                *kind = k;
                return true;
              }
            }
            return false;
          },
          [](sim::MotionKind k) { return sim::toString(k); },
          "how the rig moves between poses (--scenario waving: continuously, no poses)"),
      number<double>("--duration-s", CIA_MEMBER(config.waving_duration_s), within(1, 3600), "s",
                     "length of a --scenario waving run"),
      number<double>("--max-tilt-deg", CIA_MEMBER(config.max_tilt_deg), within(0, 60), "deg",
                     "viewing direction off the target normal"),
      number<double>("--max-roll-deg", CIA_MEMBER(config.max_roll_deg), within(0, 180), "deg",
                     "rotation about the optical axis"),
      flag(
          "--moving-objects", [](Options* o) { o->config.moving_objects = true; },
          "room scenarios: the two largest boxes slide 0.2-0.5 m back and forth, during the rests "
          "too (every frame is then rendered)"),
      list(
          "--robot-tilt-deg", 2,
          [](const Options& o) {
            return std::vector<double>{o.config.robot_min_tilt_deg, o.config.robot_max_tilt_deg};
          },
          [](const std::vector<double>& v, Options* o) {
            if (!(v[0] >= 0.0 && v[0] <= v[1] && v[1] <= 40.0))
              throw YAML::Exception({}, "out of range");
            o->config.robot_min_tilt_deg = v[0];
            o->config.robot_max_tilt_deg = v[1];
          },
          "two numbers MIN,MAX with 0 <= MIN <= MAX <= 40", "deg",
          "--scenario room_robot: the base's tilt at each stop, uniform in [MIN, MAX] (default "
          "5,20)"),
      flag(
          "--texture-poor", [](Options* o) { o->config.texture_poor = true; },
          "room scenarios: near-blank surfaces, faint texture (few features)"),
      list(
          "--r-cam-imu", 4,
          [](const Options& o) {
            const Eigen::Quaterniond q(o.config.R_cam_imu);
            return std::vector<double>{q.x(), q.y(), q.z(), q.w()};
          },
          [](const std::vector<double>& q, Options* o) {
            const Eigen::Quaterniond quat(q[3], q[0], q[1], q[2]);
            if (std::abs(quat.norm() - 1.0) > 1e-3) throw YAML::Exception({}, "not unit");
            o->config.given_R_cam_imu = true;
            o->config.R_cam_imu = quat.normalized().toRotationMatrix();
          },
          "a unit quaternion qx,qy,qz,qw", "", "the mount R_cam_imu (default: random per seed)"),
      flag(
          "--remount", [](Options* o) { o->config.remount = true; },
          "R_cam_imu changes mid-run (see --remount-time-s, --remount-deg)"),
      number<double>("--remount-time-s", CIA_MEMBER(config.remount_time_s), within(0, 1e6), "s",
                     "remount time since the start (default: middle of the central motion)"),
      list(
          "--remount-deg", 3,
          [](const Options& o) { return list3(o.config.remount_rotvec_cam, kDeg); },
          [](const std::vector<double>& v, Options* o) {
            o->config.remount_rotvec_cam = vec3(v, kDeg);
          },
          "3 numbers x,y,z", "deg", "remount rotation vector (camera frame)"),
  };
}

/// The inertial and magnetic unit, the target.
std::vector<Key> inertialAndTargetKeys() {
  return {
      number<double>("--imu-rate-hz", CIA_MEMBER(config.imu_rate_hz), within(1, 10000), "Hz",
                     "IMU sample rate"),
      number<double>("--mag-rate-hz", CIA_MEMBER(config.mag_rate_hz), within(1, 10000), "Hz",
                     "magnetometer sample rate"),
      number<double>("--camera-rate-hz", CIA_MEMBER(config.camera_rate_hz), within(0.1, 200), "Hz",
                     "camera frame rate"),
      number<double>("--noise-scale", CIA_MEMBER(config.noise_scale), within(0, 1000), "",
                     "multiplies every sensor noise and the initial IMU biases"),
      number<double>("--gyro-noise-density", CIA_MEMBER(config.imu_noise.gyroscope_noise_density),
                     within(0, 1), "rad/s/sqrt(Hz)", "gyro white noise"),
      number<double>("--gyro-random-walk", CIA_MEMBER(config.imu_noise.gyroscope_random_walk),
                     within(0, 1), "rad/s^2/sqrt(Hz)", "gyro bias random walk"),
      number<double>("--accel-noise-density",
                     CIA_MEMBER(config.imu_noise.accelerometer_noise_density), within(0, 10),
                     "m/s^2/sqrt(Hz)", "accelerometer white noise"),
      number<double>("--accel-random-walk", CIA_MEMBER(config.imu_noise.accelerometer_random_walk),
                     within(0, 10), "m/s^3/sqrt(Hz)", "accelerometer bias random walk"),
      scaled("--mag-noise-ut", CIA_MEMBER(config.imu_noise.magnetometer_noise_sigma), kUt,
             within(0, 100), "uT", "magnetometer noise per sample and axis"),
      scaled("--gravity-m-s2", CIA_MEMBER(config.gravity_world.z()), -1.0, within(9.5, 10.1),
             "m/s^2", "local gravity of the simulated world (calibrate with gravity_m_s2)"),
      list(
          "--earth-field-ut", 3,
          [](const Options& o) { return list3(o.config.earth_field_world, kUt); },
          [](const std::vector<double>& v, Options* o) {
            o->config.earth_field_world = vec3(v, kUt);
          },
          "3 numbers x,y,z", "uT", "earth field (ENU)"),
      list(
          "--mag-hard-iron-ut", 3,
          [](const Options& o) { return list3(o.config.mag_hard_iron, kUt); },
          [](const std::vector<double>& v, Options* o) { o->config.mag_hard_iron = vec3(v, kUt); },
          "3 numbers x,y,z", "uT", "hard iron added to every magnetometer sample (IMU frame)"),
      list(
          "--mag-disturbance-poses", 0,
          [](const Options& o) {
            return std::vector<double>(o.config.mag_disturbance_poses.begin(),
                                       o.config.mag_disturbance_poses.end());
          },
          [](const std::vector<double>& v, Options* o) {
            o->config.mag_disturbance_poses.clear();
            for (double p : v) {
              if (p != std::floor(p) || p < 0) throw YAML::Exception({}, "not an index");
              o->config.mag_disturbance_poses.push_back(static_cast<int>(p));
            }
          },
          "pose indices i,j (0-based, below --num-poses)", "",
          "poses whose hold has an extra field"),
      scaled("--mag-disturbance-ut", CIA_MEMBER(config.mag_disturbance_t), kUt, within(0, 1000),
             "uT", "magnitude of that extra field"),
      flag(
          "--no-magnetometer", [](Options* o) { o->config.magnetometer = false; },
          "no magnetometer topic"),
      number<double>("--camera-time-offset-s", CIA_MEMBER(config.camera_time_offset_s),
                     within(-10, 10), "s", "image stamp = capture time + this"),
      flag(
          "--bad-input", [](Options* o) { o->config.bad_input = true; },
          "inject NaNs, bad stamps, bad images and camera info"),
      // Target.
      wordKey<Options>(
          "--target", CIA_MEMBER(config.target), {"checkerboard", "aprilgrid", "circlegrid"},
          [](const std::string& word, sim::TargetSpec* target) {
            if (word != "checkerboard" && word != "aprilgrid" && word != "circlegrid") return false;
            if (word != sim::toString(target->type)) {
              sim::SimulationConfig preset;  // the default target of that type
              sim::applyScenario(word == "checkerboard" ? "nominal" : word, &preset);
              *target = preset.target;
            }
            return true;
          },
          [](const sim::TargetSpec& t) { return sim::toString(t.type); },
          "target type (its default layout; the options below change it)"),
      number<int>("--target-cols", CIA_MEMBER(config.target.cols), within(2, 50), "",
                  "inner corners / tags / circles along x"),
      number<int>("--target-rows", CIA_MEMBER(config.target.rows), within(2, 50), "",
                  "the same along y"),
      number<double>("--target-spacing-m", CIA_MEMBER(config.target.spacing_m), within(0.001, 1),
                     "m", "square, circle spacing or tag size"),
      number<double>("--tag-spacing", CIA_MEMBER(config.target.tag_spacing), within(0.05, 1), "",
                     "aprilgrid: gap between tags as a fraction of the tag size"),
      flag(
          "--asymmetric-grid", [](Options* o) { o->config.target.asymmetric_grid = true; },
          "circlegrid: asymmetric"),
  };
}

/// The camera, ROS names, time base and the bag.
std::vector<Key> cameraAndBagKeys() {
  return {
      number<int>("--width", CIA_MEMBER(config.width), within(16, 4096), "px", "image width"),
      number<int>("--height", CIA_MEMBER(config.height), within(16, 4096), "px", "image height"),
      number<double>("--fx", CIA_MEMBER(config.fx), within(1, 1e5), "px", "focal length x"),
      number<double>("--fy", CIA_MEMBER(config.fy), within(1, 1e5), "px", "focal length y"),
      number<double>("--cx", CIA_MEMBER(config.cx), within(-1e4, 1e4), "px",
                     "principal point x (default: the centre)"),
      number<double>("--cy", CIA_MEMBER(config.cy), within(-1e4, 1e4), "px",
                     "principal point y (default: the centre)"),
      list(
          "--distortion", 5,
          [](const Options& o) {
            return std::vector<double>(o.config.distortion.begin(), o.config.distortion.end());
          },
          [](const std::vector<double>& v, Options* o) {
            std::copy(v.begin(), v.end(), o->config.distortion.begin());
          },
          "5 numbers k1,k2,p1,p2,k3", "", "plumb_bob distortion"),
      number<double>("--camera-info-focal-scale", CIA_MEMBER(bag.camera_info_focal_scale),
                     within(0.1, 10), "",
                     "CameraInfo's fx, fy = the true ones times this (1: true; else a wrong "
                     "camera_info; the truth file keeps the true K)"),
      number<double>("--blur-sigma-px", CIA_MEMBER(config.blur_sigma_px), within(0, 10), "px",
                     "Gaussian optical blur"),
      number<double>("--pixel-noise", CIA_MEMBER(config.pixel_noise_sigma), within(0, 100),
                     "grey levels", "pixel noise (before --noise-scale)"),
      number<int>("--supersample", CIA_MEMBER(config.supersample), within(1, 8), "",
                  "samples per pixel along each axis"),
      number<double>("--motion-blur-s", CIA_MEMBER(config.motion_blur_exposure_s), within(0, 1),
                     "s", "> 0: frames in motion average renders over this exposure"),
      flag(
          "--no-images", [](Options* o) { o->config.images = false; },
          "no Image / CameraInfo messages, nothing rendered (fast bags; with --camera-pose)"),
      flag(
          "--camera-pose", [](Options* o) { o->config.camera_pose = true; },
          "write the camera in the target frame as geometry_msgs/PoseStamped at every frame "
          "(stamped as the images, --camera-time-offset-s included)"),
      number<double>("--camera-pose-noise-deg", CIA_MEMBER(config.camera_pose_noise_deg),
                     within(0, 10), "deg",
                     "1-sigma orientation noise per axis of --camera-pose (x --noise-scale)"),
      number<double>("--camera-pose-position-noise-m",
                     CIA_MEMBER(config.camera_pose_position_noise_m), within(0, 0.1), "m",
                     "1-sigma position noise per camera axis of --camera-pose (x --noise-scale)"),
      // ROS names, time base, bag.
      textKey<Options>("--imu-topic", CIA_MEMBER(config.imu_topic), "a topic name",
                       "IMU topic (a relative name is made global)"),
      textKey<Options>("--mag-topic", CIA_MEMBER(config.mag_topic), "a topic name",
                       "magnetometer topic"),
      textKey<Options>("--image-topic", CIA_MEMBER(config.image_topic), "a topic name",
                       "image topic"),
      textKey<Options>("--camera-info-topic", CIA_MEMBER(config.camera_info_topic), "a topic name",
                       "camera info topic"),
      textKey<Options>("--camera-pose-topic", CIA_MEMBER(config.camera_pose_topic), "a topic name",
                       "camera pose topic (--camera-pose)"),
      textKey<Options>("--target-frame", CIA_MEMBER(config.target_frame), "a frame name",
                       "frame_id of the camera pose messages (the target's)"),
      textKey<Options>("--imu-frame", CIA_MEMBER(config.imu_frame), "a frame name",
                       "frame_id of the IMU"),
      textKey<Options>("--camera-frame", CIA_MEMBER(config.camera_frame), "a frame name",
                       "frame_id of the camera"),
      textKey<Options>("--mag-frame", CIA_MEMBER(bag.mag_frame), "a frame name",
                       "frame_id of the magnetometer (default: the IMU's)"),
      scaled("--mag-frame-yaw-deg", CIA_MEMBER(bag.mag_frame_yaw_rad), kDeg, within(-360, 360),
             "deg", "--mag-frame's axes are the IMU's turned by this about z (to /tf_static)"),
      number<double>("--start-time-s", CIA_MEMBER(config.start_time_s), within(1, 4e9), "s",
                     "bag time of the simulation's start"),
      wordKey<Options>("--compression", CIA_MEMBER(bag.compression), {"none", "lz4", "bz2"},
                       "bag compression"),
  };
}

}  // namespace

const std::vector<Key>& simulateBagOptionTable() {
  static const std::vector<Key> table = [] {
    std::vector<Key> keys = presetAndMotionKeys();
    for (auto part : {inertialAndTargetKeys(), cameraAndBagKeys()}) {
      keys.insert(keys.end(), part.begin(), part.end());
    }
    return keys;
  }();
  return table;
}

std::set<std::string> simulateBagValueOptions() {
  std::set<std::string> names = {"--out"};
  for (const Key& key : simulateBagOptionTable()) {
    if (key.allowed != "given without a value") names.insert(key.name);
  }
  return names;
}

std::set<std::string> simulateBagFlags() {
  std::set<std::string> names = {"--help", "-h"};
  for (const Key& key : simulateBagOptionTable()) {
    if (key.allowed == "given without a value") names.insert(key.name);
  }
  return names;
}

std::string simulateBagOptionsUsage() {
  Options defaults;
  defaults.config.cx = 0.5 * (defaults.config.width - 1);
  defaults.config.cy = 0.5 * (defaults.config.height - 1);
  std::ostringstream out;
  for (const Key& key : simulateBagOptionTable()) {
    out << "  " << key.name;
    if (key.allowed == "given without a value") {
      out << ": " << key.description << "\n";
      continue;
    }
    out << " (" << key.allowed << (key.unit.empty() ? "" : ", " + key.unit) << ")";
    const std::string value = key.text(defaults);
    const bool has_default = key.name != "--seed" && key.name != "--r-cam-imu" &&
                             key.name != "--remount-time-s" && !value.empty();
    out << ": " << key.description;
    if (has_default) out << " [" << value << "]";
    out << "\n";
  }
  return out.str();
}

SimulateBagOptions parseSimulateBagOptions(const CliArgs& args) {
  const std::string source = "command line";
  if (!args.has("--out")) throw UsageError("--out FILE.bag is required");
  Options o;
  o.out = args.get("--out");
  if (o.out.size() < 5 || o.out.compare(o.out.size() - 4, 4, ".bag") != 0) {
    throw SettingsError(source, "--out", "--out = " + o.out + ": must be a file ending in .bag");
  }
  for (const Key& key : simulateBagOptionTable()) {
    if (!args.has(key.name)) continue;
    const std::string text = args.get(key.name);
    readKey(key, source, YAML::Node(text), &o);
    if (!key.in_range(o)) {
      throw SettingsError(source, key.name,
                          key.name + " = " + text + ": must be " + key.range_allowed);
    }
  }
  // Defaults that follow other options.
  sim::SimulationConfig& c = o.config;
  if (!args.has("--hold-max-s")) c.hold_max_s = std::max(c.hold_max_s, c.hold_min_s);
  if (!args.has("--move-max-s")) c.move_max_s = std::max(c.move_max_s, c.move_min_s);
  if (!args.has("--cx")) c.cx = 0.5 * (c.width - 1);
  if (!args.has("--cy")) c.cy = 0.5 * (c.height - 1);
  if (args.has("--remount-time-s") || args.has("--remount-deg")) c.remount = true;
  // Checks across options.
  for (int p : c.mag_disturbance_poses) {
    if (p >= c.num_poses) {
      throw SettingsError(
          source, "--mag-disturbance-poses",
          "--mag-disturbance-poses: pose " + std::to_string(p) +
              " is not an index in [0, --num-poses = " + std::to_string(c.num_poses) + ")");
    }
  }
  if (o.bag.mag_frame_yaw_rad != 0.0 &&
      (o.bag.mag_frame.empty() || o.bag.mag_frame == c.imu_frame)) {
    throw SettingsError(source, "--mag-frame-yaw-deg",
                        "--mag-frame-yaw-deg needs a --mag-frame other than the IMU's frame");
  }
  const bool room = sim::isRoomMotion(c.motion);
  for (const auto& [given, name] : {std::make_pair(c.moving_objects, "--moving-objects"),
                                    std::make_pair(c.texture_poor, "--texture-poor")}) {
    if (given && !room) {
      throw SettingsError(source, name,
                          std::string(name) +
                              " changes the room scene: use it with --scenario room_robot or "
                              "room_handheld");
    }
  }
  if ((c.robot_min_tilt_deg != sim::SimulationConfig().robot_min_tilt_deg ||
       c.robot_max_tilt_deg != sim::SimulationConfig().robot_max_tilt_deg) &&
      c.motion != sim::MotionKind::kRoomRobot) {
    throw SettingsError(source, "--robot-tilt-deg",
                        "--robot-tilt-deg tilts the robot's base at its stops: use it with "
                        "--scenario room_robot");
  }
  if (room && c.camera_pose) {
    throw SettingsError(source, "--camera-pose",
                        "--camera-pose gives the camera in the board's frame: --scenario " +
                            c.scenario + " has no board");
  }
  if (!c.images && !c.camera_pose) {
    throw SettingsError(source, "--no-images",
                        "--no-images leaves no camera data: add --camera-pose");
  }
  const std::string problems = sim::validateConfig(c);
  if (!problems.empty()) throw SettingsError(source, "", problems);
  return o;
}

}  // namespace camera_imu_alignment
