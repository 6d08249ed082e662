// simulate_bag: writes a ROS 1 bag of a rigidly mounted camera + inertial/magnetic unit with a
// known R_cam_imu (FILE.bag), its ground truth (FILE.truth.yaml) and the Kalibr target
// (FILE.target.yaml). The science lives in camera_imu_alignment_simulation; this file only parses
// options, converts to ROS messages and writes the bag. Exit codes: 0 ok, 2 bad usage or input
// (message names the option).
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>
#include <tf2_msgs/TFMessage.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "cli_args.h"

namespace cia = camera_imu_alignment;
namespace sim = camera_imu_alignment::simulation;

namespace {

const std::set<std::string> kValueOptions = {"--out",
                                             "--seed",
                                             "--scenario",
                                             "--imu-grade",
                                             "--num-poses",
                                             "--hold-min-s",
                                             "--hold-max-s",
                                             "--move-min-s",
                                             "--move-max-s",
                                             "--motion",
                                             "--max-tilt-deg",
                                             "--max-roll-deg",
                                             "--r-cam-imu",
                                             "--imu-rate-hz",
                                             "--mag-rate-hz",
                                             "--camera-rate-hz",
                                             "--noise-scale",
                                             "--gyro-noise-density",
                                             "--gyro-random-walk",
                                             "--accel-noise-density",
                                             "--accel-random-walk",
                                             "--mag-noise-ut",
                                             "--earth-field-ut",
                                             "--mag-hard-iron-ut",
                                             "--mag-disturbance-poses",
                                             "--mag-disturbance-ut",
                                             "--camera-time-offset-s",
                                             "--remount-time-s",
                                             "--remount-deg",
                                             "--target",
                                             "--target-cols",
                                             "--target-rows",
                                             "--target-spacing-m",
                                             "--tag-spacing",
                                             "--width",
                                             "--height",
                                             "--fx",
                                             "--fy",
                                             "--cx",
                                             "--cy",
                                             "--distortion",
                                             "--blur-sigma-px",
                                             "--pixel-noise",
                                             "--supersample",
                                             "--motion-blur-s",
                                             "--imu-topic",
                                             "--mag-topic",
                                             "--image-topic",
                                             "--camera-info-topic",
                                             "--imu-frame",
                                             "--camera-frame",
                                             "--mag-frame",
                                             "--mag-frame-yaw-deg",
                                             "--start-time-s",
                                             "--compression"};
const std::set<std::string> kFlags = {"--help",      "-h",        "--no-magnetometer",
                                      "--bad-input", "--remount", "--asymmetric-grid"};

std::string usage() {
  std::ostringstream o;
  o << "usage: simulate_bag --out FILE.bag [--seed N] [--scenario NAME] [options]\n"
       "  Writes FILE.bag (sensor_msgs/Imu, MagneticField, Image mono8, CameraInfo), "
       "FILE.truth.yaml\n"
       "  (R_cam_imu, stationary intervals, true poses, noise) and FILE.target.yaml (Kalibr).\n"
       "Scenarios (presets; options below override them):\n";
  for (const auto& s : sim::scenarioList()) o << "  " << s.first << ": " << s.second << "\n";
  o << "IMU grades (--imu-grade NAME; after the scenario, before the noise options below):\n";
  for (const auto& g : sim::imuGradeList()) o << "  " << g.first << ": " << g.second << "\n";
  o << "Options (defaults of the nominal scenario):\n"
       "  --num-poses N (12)   --hold-min-s/--hold-max-s S (3/5)   --move-min-s/--move-max-s S "
       "(2/3)\n"
       "  --motion full|single_axis|small_angle   --max-tilt-deg (35)   --max-roll-deg (80)\n"
       "  --r-cam-imu qx,qy,qz,qw (random per seed)   --remount [--remount-time-s T] "
       "[--remount-deg x,y,z (0,10,0)]\n"
       "  --imu-rate-hz (200)  --mag-rate-hz (100)  --camera-rate-hz (15)  --noise-scale (1)\n"
       "  --gyro-noise-density (1.87e-4)  --gyro-random-walk (2.66e-5)  --accel-noise-density "
       "(1.86e-3)\n"
       "  --accel-random-walk (4.33e-4)  --mag-noise-ut (0.3)  --earth-field-ut x,y,z "
       "(0,22,-42)\n"
       "  --mag-hard-iron-ut x,y,z  --mag-disturbance-poses i,j  --mag-disturbance-ut (25)  "
       "--no-magnetometer\n"
       "  --camera-time-offset-s (0)  --bad-input\n"
       "  --target checkerboard|aprilgrid|circlegrid  --target-cols/--target-rows N  "
       "--target-spacing-m M\n"
       "  --tag-spacing R (0.3)  --asymmetric-grid\n"
       "  --width (640) --height (480) --fx --fy (500) --cx --cy (centre)  --distortion "
       "k1,k2,p1,p2,k3\n"
       "  --blur-sigma-px (0.6)  --pixel-noise (1.5)  --supersample (3)  --motion-blur-s (0)\n"
       "  --imu-topic (/imu/data_raw) --mag-topic (/imu/mag) --image-topic (/camera/image_raw)\n"
       "  --camera-info-topic (/camera/camera_info; a relative name is made global) --imu-frame "
       "(imu_link) --camera-frame "
       "(camera_optical_frame)\n"
       "  --mag-frame NAME --mag-frame-yaw-deg D (IMU frame, 0): magnetometer messages in frame "
       "NAME,\n"
       "    whose axes are the IMU's turned by D about its z; the rotation goes to /tf_static\n"
       "  --start-time-s (1700000000)  --compression none|lz4|bz2 (none)\n";
  return o.str();
}

std::vector<double> parseList(const cia::CliArgs& args, const std::string& name, size_t n) {
  std::vector<double> v;
  std::stringstream ss(args.get(name));
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(x)) {
      throw cia::UsageError(name + ": '" + item + "' is not a number");
    }
    v.push_back(x);
  }
  if (n > 0 && v.size() != n) {
    throw cia::UsageError(name + " needs " + std::to_string(n) + " comma-separated numbers");
  }
  return v;
}

Eigen::Vector3d vec3(const cia::CliArgs& args, const std::string& name, double scale) {
  const std::vector<double> v = parseList(args, name, 3);
  return scale * Eigen::Vector3d(v[0], v[1], v[2]);
}

sim::SimulationConfig configFromArgs(const cia::CliArgs& a) {
  sim::SimulationConfig c;
  c.seed = static_cast<std::uint64_t>(a.getInt("--seed", 1, 0, std::numeric_limits<long>::max()));
  const std::string scenario = a.get("--scenario", "nominal");
  if (!sim::applyScenario(scenario, &c)) {
    throw cia::UsageError("--scenario: unknown scenario '" + scenario + "' (see --help)");
  }
  if (a.has("--imu-grade")) {
    sim::ImuGrade grade;
    if (!sim::parseImuGrade(a.get("--imu-grade"), &grade)) {
      throw cia::UsageError("--imu-grade must be ideal, tactical, consumer or noisy, got '" +
                            a.get("--imu-grade") + "'");
    }
    sim::applyImuGrade(grade, &c);
  }
  c.num_poses = static_cast<int>(a.getInt("--num-poses", c.num_poses, 2, 1000));
  c.hold_min_s = a.getDouble("--hold-min-s", c.hold_min_s, 0.1, 600);
  c.hold_max_s = a.getDouble("--hold-max-s", std::max(c.hold_max_s, c.hold_min_s), 0.1, 600);
  c.move_min_s = a.getDouble("--move-min-s", c.move_min_s, 0.2, 600);
  c.move_max_s = a.getDouble("--move-max-s", std::max(c.move_max_s, c.move_min_s), 0.2, 600);
  if (a.has("--motion")) {
    const std::string m = a.get("--motion");
    if (m == "full") {
      c.motion = sim::MotionKind::kFull;
    } else if (m == "single_axis") {
      c.motion = sim::MotionKind::kSingleAxis;
    } else if (m == "small_angle") {
      c.motion = sim::MotionKind::kSmallAngle;
    } else {
      throw cia::UsageError("--motion must be full, single_axis or small_angle, got '" + m + "'");
    }
  }
  c.max_tilt_deg = a.getDouble("--max-tilt-deg", c.max_tilt_deg, 0, 60);
  c.max_roll_deg = a.getDouble("--max-roll-deg", c.max_roll_deg, 0, 180);
  if (a.has("--r-cam-imu")) {
    const std::vector<double> q = parseList(a, "--r-cam-imu", 4);
    const Eigen::Quaterniond quat(q[3], q[0], q[1], q[2]);
    if (std::abs(quat.norm() - 1.0) > 1e-3) {
      throw cia::UsageError("--r-cam-imu must be a unit quaternion qx,qy,qz,qw");
    }
    c.given_R_cam_imu = true;
    c.R_cam_imu = quat.normalized().toRotationMatrix();
  }
  c.imu_rate_hz = a.getDouble("--imu-rate-hz", c.imu_rate_hz, 1, 10000);
  c.mag_rate_hz = a.getDouble("--mag-rate-hz", c.mag_rate_hz, 1, 10000);
  c.camera_rate_hz = a.getDouble("--camera-rate-hz", c.camera_rate_hz, 0.1, 200);
  c.noise_scale = a.getDouble("--noise-scale", c.noise_scale, 0, 1000);
  sim::SensorNoise& n = c.imu_noise;
  n.gyroscope_noise_density = a.getDouble("--gyro-noise-density", n.gyroscope_noise_density, 0, 1);
  n.gyroscope_random_walk = a.getDouble("--gyro-random-walk", n.gyroscope_random_walk, 0, 1);
  n.accelerometer_noise_density =
      a.getDouble("--accel-noise-density", n.accelerometer_noise_density, 0, 10);
  n.accelerometer_random_walk =
      a.getDouble("--accel-random-walk", n.accelerometer_random_walk, 0, 10);
  n.magnetometer_noise_sigma =
      1e-6 * a.getDouble("--mag-noise-ut", 1e6 * n.magnetometer_noise_sigma, 0, 100);
  if (a.has("--earth-field-ut")) c.earth_field_world = vec3(a, "--earth-field-ut", 1e-6);
  if (a.has("--mag-hard-iron-ut")) c.mag_hard_iron = vec3(a, "--mag-hard-iron-ut", 1e-6);
  if (a.has("--mag-disturbance-poses")) {
    c.mag_disturbance_poses.clear();
    for (double p : parseList(a, "--mag-disturbance-poses", 0)) {
      if (p != std::floor(p) || p < 0 || p >= c.num_poses) {
        throw cia::UsageError("--mag-disturbance-poses: pose " + std::to_string(p) +
                              " is not an index in [0, num_poses)");
      }
      c.mag_disturbance_poses.push_back(static_cast<int>(p));
    }
  }
  c.mag_disturbance_t =
      1e-6 * a.getDouble("--mag-disturbance-ut", 1e6 * c.mag_disturbance_t, 0, 1000);
  if (a.has("--no-magnetometer")) c.magnetometer = false;
  c.camera_time_offset_s = a.getDouble("--camera-time-offset-s", c.camera_time_offset_s, -10, 10);
  if (a.has("--remount") || a.has("--remount-time-s") || a.has("--remount-deg")) c.remount = true;
  c.remount_time_s = a.getDouble("--remount-time-s", c.remount_time_s, 0, 1e6);
  if (a.has("--remount-deg")) c.remount_rotvec_cam = vec3(a, "--remount-deg", cia::kPi / 180.0);
  if (a.has("--bad-input")) c.bad_input = true;
  if (a.has("--target")) {
    const std::string t = a.get("--target");
    if (t != "checkerboard" && t != "aprilgrid" && t != "circlegrid") {
      throw cia::UsageError("--target must be checkerboard, aprilgrid or circlegrid, got '" + t +
                            "'");
    }
    if (t != sim::toString(c.target.type)) {
      sim::SimulationConfig preset;  // the default target of that type
      sim::applyScenario(t == "checkerboard" ? "nominal" : t, &preset);
      c.target = preset.target;
    }
  }
  c.target.cols = static_cast<int>(a.getInt("--target-cols", c.target.cols, 2, 50));
  c.target.rows = static_cast<int>(a.getInt("--target-rows", c.target.rows, 2, 50));
  c.target.spacing_m = a.getDouble("--target-spacing-m", c.target.spacing_m, 0.001, 1);
  c.target.tag_spacing = a.getDouble("--tag-spacing", c.target.tag_spacing, 0.05, 1);
  if (a.has("--asymmetric-grid")) c.target.asymmetric_grid = true;
  c.width = static_cast<int>(a.getInt("--width", c.width, 16, 4096));
  c.height = static_cast<int>(a.getInt("--height", c.height, 16, 4096));
  c.fx = a.getDouble("--fx", c.fx, 1, 1e5);
  c.fy = a.getDouble("--fy", c.fy, 1, 1e5);
  c.cx = a.getDouble("--cx", 0.5 * (c.width - 1), -1e4, 1e4);
  c.cy = a.getDouble("--cy", 0.5 * (c.height - 1), -1e4, 1e4);
  if (a.has("--distortion")) {
    const std::vector<double> d = parseList(a, "--distortion", 5);
    std::copy(d.begin(), d.end(), c.distortion.begin());
  }
  c.blur_sigma_px = a.getDouble("--blur-sigma-px", c.blur_sigma_px, 0, 10);
  c.pixel_noise_sigma = a.getDouble("--pixel-noise", c.pixel_noise_sigma, 0, 100);
  c.supersample = static_cast<int>(a.getInt("--supersample", c.supersample, 1, 8));
  c.motion_blur_exposure_s = a.getDouble("--motion-blur-s", c.motion_blur_exposure_s, 0, 1);
  // Bag topics are global names, as rosbag record writes them: `rosbag play --topics
  // /camera/image_raw` matches only "/camera/image_raw", not "camera/image_raw".
  const auto global = [](std::string topic) {
    return topic.empty() || topic[0] == '/' ? topic : "/" + topic;
  };
  c.imu_topic = global(a.get("--imu-topic", c.imu_topic));
  c.mag_topic = global(a.get("--mag-topic", c.mag_topic));
  c.image_topic = global(a.get("--image-topic", c.image_topic));
  c.camera_info_topic = global(a.get("--camera-info-topic", c.camera_info_topic));
  c.imu_frame = a.get("--imu-frame", c.imu_frame);
  c.camera_frame = a.get("--camera-frame", c.camera_frame);
  c.start_time_s = a.getDouble("--start-time-s", c.start_time_s, 1, 4e9);
  const std::string problems = sim::validateConfig(c);
  if (!problems.empty()) throw cia::UsageError(problems);
  return c;
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw cia::UsageError("cannot write " + path);
}

}  // namespace

namespace {

void setHeader(std_msgs::Header* h, std::uint32_t* seq, double stamp, const std::string& frame) {
  h->seq = (*seq)++;
  h->stamp = ros::Time(stamp);
  h->frame_id = frame;
}

bool contains(const std::vector<long>& v, long i) {
  return std::binary_search(v.begin(), v.end(), i);
}

sensor_msgs::CameraInfo cameraInfo(const sim::SimulationConfig& c) {
  sensor_msgs::CameraInfo info;
  info.width = c.width;
  info.height = c.height;
  info.distortion_model = "plumb_bob";
  info.D.assign(c.distortion.begin(), c.distortion.end());
  info.K = {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {c.fx, 0.0, c.cx, 0.0, 0.0, c.fy, c.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

}  // namespace

/// How the bag is written (beyond the simulation itself).
struct BagOptions {
  std::string compression = "none";  ///< none, lz4 or bz2
  std::string mag_frame;             ///< frame_id of the magnetometer; empty: the IMU's
  double mag_frame_yaw_rad = 0.0;    ///< R_imu_mag = rotation about the IMU's z by this angle
};

/// The static transform imu_frame -> mag_frame (rotation R_imu_mag: magnetometer axes to IMU axes).
tf2_msgs::TFMessage magnetometerTf(const sim::SimulationConfig& c, const BagOptions& o) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time(c.start_time_s);
  t.header.frame_id = c.imu_frame;
  t.child_frame_id = o.mag_frame;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(o.mag_frame_yaw_rad, Eigen::Vector3d::UnitZ()));
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  tf2_msgs::TFMessage msg;
  msg.transforms.push_back(t);
  return msg;
}

/// Writes the bag, messages merged in stamp order; returns the number of rendered images.
int writeBag(const sim::SimulationRun& run, const std::string& path, const BagOptions& options) {
  const sim::SimulationConfig& c = run.config;
  const sim::BadInputPlan& bad = run.bad_input;
  const double t0 = c.start_time_s, nan = std::numeric_limits<double>::quiet_NaN();
  rosbag::Bag bag;
  try {
    bag.open(path, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw cia::UsageError("--out: cannot write " + path + ": " + e.what());
  }
  if (options.compression == "lz4") bag.setCompression(rosbag::compression::LZ4);
  if (options.compression == "bz2") bag.setCompression(rosbag::compression::BZ2);
  const std::string mag_frame = options.mag_frame.empty() ? c.imu_frame : options.mag_frame;
  // Field in magnetometer axes: f_mag = R_imu_mag^T f_imu.
  const Eigen::Matrix3d R_mag_imu =
      Eigen::AngleAxisd(options.mag_frame_yaw_rad, Eigen::Vector3d::UnitZ())
          .toRotationMatrix()
          .transpose();
  if (mag_frame != c.imu_frame && c.magnetometer) {
    bag.write("/tf_static", ros::Time(c.start_time_s), magnetometerTf(c, options));
  }
  const sim::ImageRenderer renderer(sim::CameraModel::fromConfig(c),
                                    sim::makeTargetTexture(c.target, sim::textureTexelFor(c)),
                                    c.supersample, c.blur_sigma_px);

  // IMU and magnetometer messages up to a bag time, in sample order (bag time = true sample time;
  // injected out-of-order stamps only change the header stamps).
  const double k = c.noise_scale;
  const double gyro_var = std::pow(k * c.imu_noise.gyroscope_noise_density, 2) * c.imu_rate_hz;
  const double accel_var = std::pow(k * c.imu_noise.accelerometer_noise_density, 2) * c.imu_rate_hz;
  const double mag_var = std::pow(k * c.imu_noise.magnetometer_noise_sigma, 2);
  std::uint32_t imu_seq = 0, mag_seq = 0, image_seq = 0, info_seq = 0;
  long next_imu = 0, next_mag = 0;
  const auto writeInertialUpTo = [&](double bag_time) {
    for (; next_imu < static_cast<long>(run.imu.size()) && t0 + run.imu[next_imu].t <= bag_time;
         ++next_imu) {
      const long i = next_imu;
      const sim::InertialSample& s = run.imu[i];
      double stamp = t0 + s.t;
      if (contains(bad.out_of_order_imu, i)) stamp = t0 + run.imu[i + 1].t;
      if (contains(bad.out_of_order_imu, i - 1)) stamp = t0 + run.imu[i - 1].t;
      sensor_msgs::Imu m;
      setHeader(&m.header, &imu_seq, stamp, c.imu_frame);
      m.orientation_covariance[0] = -1.0;  // no orientation estimate
      const bool is_nan = contains(bad.nan_imu, i);
      m.angular_velocity.x = is_nan ? nan : s.gyro.x();
      m.angular_velocity.y = is_nan ? nan : s.gyro.y();
      m.angular_velocity.z = is_nan ? nan : s.gyro.z();
      m.linear_acceleration.x = is_nan ? nan : s.accel.x();
      m.linear_acceleration.y = is_nan ? nan : s.accel.y();
      m.linear_acceleration.z = is_nan ? nan : s.accel.z();
      for (int d = 0; d < 3; ++d) {
        m.angular_velocity_covariance[4 * d] = gyro_var;
        m.linear_acceleration_covariance[4 * d] = accel_var;
      }
      bag.write(c.imu_topic, ros::Time(t0 + s.t), m);
      if (contains(bad.duplicate_imu, i)) {
        m.header.seq = imu_seq++;
        bag.write(c.imu_topic, ros::Time(t0 + s.t), m);
      }
    }
    for (; next_mag < static_cast<long>(run.mag.size()) && t0 + run.mag[next_mag].t <= bag_time;
         ++next_mag) {
      const sim::MagSample& s = run.mag[next_mag];
      sensor_msgs::MagneticField m;
      setHeader(&m.header, &mag_seq, t0 + s.t, mag_frame);
      const bool is_nan = contains(bad.nan_mag, next_mag);
      const Eigen::Vector3d field = R_mag_imu * s.field;
      m.magnetic_field.x = is_nan ? nan : field.x();
      m.magnetic_field.y = is_nan ? nan : field.y();
      m.magnetic_field.z = is_nan ? nan : field.z();
      for (int d = 0; d < 3; ++d) m.magnetic_field_covariance[4 * d] = mag_var;
      bag.write(c.mag_topic, ros::Time(t0 + s.t), m);
    }
  };

  // Camera frames; a stationary pose is rendered once and only the pixel noise changes.
  const sensor_msgs::CameraInfo info_template = cameraInfo(c);
  const double exposure = c.motion_blur_exposure_s;
  int rendered = 0, cached_pose = -1;
  cv::Mat cached;
  for (long j = 0; j < static_cast<long>(run.frame_times.size()); ++j) {
    const double t = run.frame_times[j], stamp = t0 + t + c.camera_time_offset_s;
    writeInertialUpTo(stamp);
    const int pose_a = run.trajectory.at(t - 0.5 * exposure).pose;
    const int pose_b = run.trajectory.at(t + 0.5 * exposure).pose;
    cv::Mat grey;
    if (pose_a >= 0 && pose_a == pose_b) {
      if (cached_pose != pose_a) {
        cached = renderer.renderAt(run.trajectory, t, exposure);
        cached_pose = pose_a;
        ++rendered;
      }
      grey = cached;
    } else {
      grey = renderer.renderAt(run.trajectory, t, exposure);
      ++rendered;
    }
    const cv::Mat mono = sim::ImageRenderer::toMono8(grey, c.noise_scale * c.pixel_noise_sigma,
                                                     run.frameNoiseSeed(j));
    sensor_msgs::Image image;
    setHeader(&image.header, &image_seq, stamp, c.camera_frame);
    image.encoding = "mono8";
    if (contains(bad.empty_images, j)) {
      image.height = image.width = image.step = 0;
    } else if (contains(bad.wrong_encoding_images, j)) {
      image.encoding = "rgb8";
      image.height = mono.rows;
      image.width = mono.cols;
      image.step = 3 * mono.cols;
      image.data.reserve(3 * mono.total());
      for (size_t p = 0; p < mono.total(); ++p)
        image.data.insert(image.data.end(), 3, mono.data[p]);
    } else {
      image.height = mono.rows;
      image.width = mono.cols;
      image.step = mono.cols;
      image.data.assign(mono.data, mono.data + mono.total());
    }
    sensor_msgs::CameraInfo info = info_template;
    setHeader(&info.header, &info_seq, stamp, c.camera_frame);
    if (contains(bad.zero_k_camera_infos, j)) {
      info.K.fill(0.0);
      info.P.fill(0.0);
    }
    bag.write(c.image_topic, ros::Time(stamp), image);
    bag.write(c.camera_info_topic, ros::Time(stamp), info);
  }
  writeInertialUpTo(std::numeric_limits<double>::infinity());
  bag.close();
  return rendered;
}

int main(int argc, char** argv) {
  try {
    const cia::CliArgs args(argc, argv, kValueOptions, kFlags);
    if (args.has("--help") || args.has("-h")) {
      std::cout << usage();
      return 0;
    }
    if (!args.has("--out")) throw cia::UsageError("--out FILE.bag is required");
    const std::string out = args.get("--out");
    if (out.size() < 5 || out.compare(out.size() - 4, 4, ".bag") != 0) {
      throw cia::UsageError("--out must name a file ending in .bag, got '" + out + "'");
    }
    BagOptions bag_options;
    bag_options.compression = args.get("--compression", "none");
    if (bag_options.compression != "none" && bag_options.compression != "lz4" &&
        bag_options.compression != "bz2") {
      throw cia::UsageError("--compression must be none, lz4 or bz2");
    }
    bag_options.mag_frame = args.get("--mag-frame", "");
    bag_options.mag_frame_yaw_rad =
        cia::deg2rad(args.getDouble("--mag-frame-yaw-deg", 0.0, -360.0, 360.0));
    const sim::SimulationConfig config = configFromArgs(args);
    if (bag_options.mag_frame_yaw_rad != 0.0 &&
        (bag_options.mag_frame.empty() || bag_options.mag_frame == config.imu_frame)) {
      throw cia::UsageError("--mag-frame-yaw-deg needs a --mag-frame other than the IMU's frame");
    }
    const auto start = std::chrono::steady_clock::now();
    const sim::SimulationRun run(config);
    const std::string base = out.substr(0, out.size() - 4);
    writeText(base + ".target.yaml", sim::targetYaml(config.target));
    writeText(base + ".truth.yaml", sim::truthYaml(run));
    const int rendered = writeBag(run, out, bag_options);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "simulate_bag: wrote " << out << " (" << run.trajectory.duration() << " s, "
              << run.trajectory.poses().size() << " poses, " << run.imu.size() << " IMU, "
              << run.mag.size() << " magnetometer, " << run.frame_times.size() << " images, "
              << rendered << " rendered) in " << secs << " s\n"
              << "simulate_bag: wrote " << base << ".truth.yaml and " << base << ".target.yaml\n";
    return 0;
  } catch (const cia::UsageError& e) {
    std::cerr << "simulate_bag: " << e.what() << "\n" << usage();
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "simulate_bag: " << e.what() << "\n";
    return 2;
  }
}
