// simulate_bag: writes a ROS 1 bag of a rigidly mounted camera + inertial/magnetic unit with a
// known R_cam_imu (FILE.bag), its ground truth (FILE.truth.yaml) and the Kalibr target
// (FILE.target.yaml). The science lives in camera_imu_alignment_simulation; this file only parses
// options, converts to ROS messages and writes the bag. Exit codes: 0 ok, 2 bad usage or input
// (message names the option).
#include <geometry_msgs/PoseStamped.h>
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
#include <optional>
#include <sstream>

#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/room_scene.h"
#include "camera_imu_alignment/simulation/scene_renderer.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "cli_args.h"
#include "simulate_bag_options.h"

namespace cia = camera_imu_alignment;
namespace sim = camera_imu_alignment::simulation;

namespace {

std::string usage() {
  std::ostringstream o;
  o << "usage: simulate_bag --out FILE.bag [--seed N] [--scenario NAME] [options]\n"
       "  Writes FILE.bag (sensor_msgs/Imu, MagneticField, Image mono8, CameraInfo; with\n"
       "  --camera-pose geometry_msgs/PoseStamped), FILE.truth.yaml\n"
       "  (R_cam_imu, stationary intervals, true poses, noise) and FILE.target.yaml (Kalibr;\n"
       "  the room scenarios have no board: no target file, no camera pose).\n"
       "Scenarios (presets; options below override them):\n";
  for (const auto& s : sim::scenarioList()) o << "  " << s.first << ": " << s.second << "\n";
  o << "IMU grades (--imu-grade NAME; after the scenario, before the noise options below):\n";
  for (const auto& g : sim::imuGradeList()) o << "  " << g.first << ": " << g.second << "\n";
  o << "Options ((allowed, unit): what it sets [default of the nominal scenario]):\n"
    << cia::simulateBagOptionsUsage();
  return o.str();
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

/// The CameraInfo of the rendering camera, its focal lengths times `focal_scale`.
sensor_msgs::CameraInfo cameraInfo(const sim::SimulationConfig& c, double focal_scale) {
  const double fx = focal_scale * c.fx, fy = focal_scale * c.fy;
  sensor_msgs::CameraInfo info;
  info.width = c.width;
  info.height = c.height;
  info.distortion_model = "plumb_bob";
  info.D.assign(c.distortion.begin(), c.distortion.end());
  info.K = {fx, 0.0, c.cx, 0.0, fy, c.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {fx, 0.0, c.cx, 0.0, 0.0, fy, c.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

/// The camera in the target frame (doc/CONVENTIONS.md): orientation q_target_cam (with the
/// simulated noise), position p_target_cam; frame_id the target frame; stamped as the images.
geometry_msgs::PoseStamped cameraPoseMessage(const sim::CameraOrientation& o, double t0,
                                             const std::string& target_frame, std::uint32_t* seq) {
  geometry_msgs::PoseStamped m;
  setHeader(&m.header, seq, t0 + o.stamp_s, target_frame);
  const Eigen::Quaterniond q(o.R_target_cam);
  m.pose.orientation.x = q.x();
  m.pose.orientation.y = q.y();
  m.pose.orientation.z = q.z();
  m.pose.orientation.w = q.w();
  m.pose.position.x = o.p_target_cam.x();
  m.pose.position.y = o.p_target_cam.y();
  m.pose.position.z = o.p_target_cam.z();
  return m;
}

}  // namespace

using cia::BagOptions;

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

/// A mono8 image as its message (header not set); `empty`: no pixels, `rgb`: the same pixels as
/// rgb8 (both injected bad inputs).
sensor_msgs::Image imageMessage(const cv::Mat& mono, bool empty, bool rgb) {
  sensor_msgs::Image image;
  image.encoding = "mono8";
  if (empty) {
    image.height = image.width = image.step = 0;
  } else if (rgb) {
    image.encoding = "rgb8";
    image.height = mono.rows;
    image.width = mono.cols;
    image.step = 3 * mono.cols;
    image.data.reserve(3 * mono.total());
    for (size_t p = 0; p < mono.total(); ++p) image.data.insert(image.data.end(), 3, mono.data[p]);
  } else {
    image.height = mono.rows;
    image.width = mono.cols;
    image.step = mono.cols;
    image.data.assign(mono.data, mono.data + mono.total());
  }
  return image;
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
  // --no-images: no texture, nothing rendered. The room scenarios see the room, the others the
  // board.
  const bool room = sim::isRoomMotion(c.motion);
  std::optional<sim::ImageRenderer> renderer;
  std::optional<sim::SceneRenderer> scene_renderer;
  if (c.images && room) {
    scene_renderer.emplace(sim::CameraModel::fromConfig(c), sim::RoomScene::fromConfig(c),
                           c.supersample, c.blur_sigma_px);
  } else if (c.images) {
    renderer.emplace(sim::CameraModel::fromConfig(c),
                     sim::makeTargetTexture(c.target, sim::textureTexelFor(c)), c.supersample,
                     c.blur_sigma_px);
  }
  const auto renderAt = [&](double t, double exposure_s) {
    return room ? scene_renderer->renderAt(run.trajectory, t, exposure_s)
                : renderer->renderAt(run.trajectory, t, exposure_s);
  };

  // IMU and magnetometer messages up to a bag time, in sample order (bag time = true sample time;
  // injected out-of-order stamps only change the header stamps).
  const double k = c.noise_scale;
  const double gyro_var = std::pow(k * c.imu_noise.gyroscope_noise_density, 2) * c.imu_rate_hz;
  const double accel_var = std::pow(k * c.imu_noise.accelerometer_noise_density, 2) * c.imu_rate_hz;
  const double mag_var = std::pow(k * c.imu_noise.magnetometer_noise_sigma, 2);
  std::uint32_t imu_seq = 0, mag_seq = 0, image_seq = 0, info_seq = 0, pose_seq = 0;
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

  // Camera frames; a stationary pose is rendered once and only the pixel noise changes (unless
  // objects move in the scene: then every frame is rendered).
  const sensor_msgs::CameraInfo info_template = cameraInfo(c, options.camera_info_focal_scale);
  const double exposure = c.motion_blur_exposure_s;
  int rendered = 0, cached_pose = -1;
  cv::Mat cached;
  for (long j = 0; j < static_cast<long>(run.frame_times.size()); ++j) {
    const double t = run.frame_times[j], stamp = t0 + t + c.camera_time_offset_s;
    writeInertialUpTo(stamp);
    if (c.camera_pose) {
      bag.write(c.camera_pose_topic, ros::Time(stamp),
                cameraPoseMessage(run.camera_orientations[j], t0, c.target_frame, &pose_seq));
    }
    if (!c.images) continue;
    const int pose_a = run.trajectory.at(t - 0.5 * exposure).pose;
    const int pose_b = run.trajectory.at(t + 0.5 * exposure).pose;
    cv::Mat grey;
    if (pose_a >= 0 && pose_a == pose_b && !c.moving_objects) {
      if (cached_pose != pose_a) {
        cached = renderAt(t, exposure);
        cached_pose = pose_a;
        ++rendered;
      }
      grey = cached;
    } else {
      grey = renderAt(t, exposure);
      ++rendered;
    }
    const cv::Mat mono = sim::ImageRenderer::toMono8(grey, c.noise_scale * c.pixel_noise_sigma,
                                                     run.frameNoiseSeed(j));
    sensor_msgs::Image image =
        imageMessage(mono, contains(bad.empty_images, j), contains(bad.wrong_encoding_images, j));
    setHeader(&image.header, &image_seq, stamp, c.camera_frame);
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
    const cia::CliArgs args(argc, argv, cia::simulateBagValueOptions(), cia::simulateBagFlags());
    if (args.has("--help") || args.has("-h")) {
      std::cout << usage();
      return 0;
    }
    cia::SimulateBagOptions options = cia::parseSimulateBagOptions(args);
    // Bag topics are global names, as rosbag record writes them: `rosbag play --topics
    // /camera/image_raw` matches only "/camera/image_raw", not "camera/image_raw".
    for (std::string* topic :
         {&options.config.imu_topic, &options.config.mag_topic, &options.config.image_topic,
          &options.config.camera_info_topic, &options.config.camera_pose_topic}) {
      if (!topic->empty() && (*topic)[0] != '/') *topic = "/" + *topic;
    }
    const std::string& out = options.out;
    const BagOptions& bag_options = options.bag;
    const sim::SimulationConfig& config = options.config;
    const auto start = std::chrono::steady_clock::now();
    const sim::SimulationRun run(config);
    const std::string base = out.substr(0, out.size() - 4);
    const bool room = sim::isRoomMotion(config.motion);  // no board: no target file
    if (!room) writeText(base + ".target.yaml", sim::targetYaml(config.target));
    writeText(base + ".truth.yaml", sim::truthYaml(run));
    const int rendered = writeBag(run, out, bag_options);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "simulate_bag: wrote " << out << " (" << run.trajectory.duration() << " s, "
              << run.trajectory.poses().size() << " poses, " << run.imu.size() << " IMU, "
              << run.mag.size() << " magnetometer, " << (config.images ? run.frame_times.size() : 0)
              << " images, " << rendered << " rendered, "
              << (config.camera_pose ? run.camera_orientations.size() : 0) << " camera poses) in "
              << secs << " s\n"
              << "simulate_bag: wrote " << base << ".truth.yaml"
              << (room ? " (a room scene: no board, no target file)\n"
                       : " and " + base + ".target.yaml\n");
    return 0;
  } catch (const cia::UsageError& e) {
    std::cerr << "simulate_bag: " << e.what() << "\n" << usage();
    return cia::kExitBadInput;
  } catch (const cia::SettingsError& e) {
    std::cerr << "simulate_bag: " << e.what() << "\n" << usage();
    return cia::kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "simulate_bag: " << e.what() << "\n";
    return cia::kExitBadInput;
  }
}
