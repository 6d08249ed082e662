#include "camera_imu_alignment/simulation/simulation_run.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <random>
#include <set>
#include <sstream>

#include "camera_imu_alignment/simulation/room_scene.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace simulation {

namespace {

/// `count` distinct indices in [lo, hi) not in `used` (fewer if the range is too small).
std::vector<long> pick(std::mt19937_64& rng, long lo, long hi, int count, std::set<long>* used) {
  std::vector<long> out;
  if (hi <= lo) return out;
  std::uniform_int_distribution<long> u(lo, hi - 1);
  for (int tries = 0; static_cast<int>(out.size()) < count && tries < 1000; ++tries) {
    const long i = u(rng);
    if (used->count(i) || used->count(i - 1) || used->count(i + 1)) continue;
    used->insert(i);
    out.push_back(i);
  }
  std::sort(out.begin(), out.end());
  return out;
}

BadInputPlan planBadInput(std::uint64_t seed, long num_imu, long num_mag, long num_frames) {
  std::mt19937_64 rng(streamSeed(seed, 5));
  BadInputPlan plan;
  std::set<long> imu_used, mag_used, frame_used;
  plan.nan_imu = pick(rng, 10, num_imu - 10, 5, &imu_used);
  plan.duplicate_imu = pick(rng, 10, num_imu - 10, 5, &imu_used);
  plan.out_of_order_imu = pick(rng, 10, num_imu - 10, 3, &imu_used);
  plan.nan_mag = pick(rng, 10, num_mag - 10, 3, &mag_used);
  plan.empty_images = pick(rng, 2, num_frames - 2, 2, &frame_used);
  plan.wrong_encoding_images = pick(rng, 2, num_frames - 2, 2, &frame_used);
  plan.zero_k_camera_infos = pick(rng, 2, num_frames - 2, 1, &frame_used);
  return plan;
}

class Writer {
 public:
  Writer() { o_ << std::setprecision(12); }
  std::ostringstream& o() { return o_; }
  void vec(const Eigen::Vector3d& v) {
    o_ << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  }
  void quat(const Eigen::Matrix3d& R) {
    Eigen::Quaterniond q(R);
    q.normalize();
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    o_ << "[" << q.x() << ", " << q.y() << ", " << q.z() << ", " << q.w() << "]";
  }
  void matrix(const Eigen::Matrix3d& R) {
    o_ << "[";
    for (int i = 0; i < 3; ++i) {
      o_ << (i ? ", [" : "[") << R(i, 0) << ", " << R(i, 1) << ", " << R(i, 2) << "]";
    }
    o_ << "]";
  }
  void rotation(const std::string& indent, const Eigen::Matrix3d& R) {
    o_ << indent << "quaternion_xyzw: ";
    quat(R);
    o_ << "\n" << indent << "matrix: ";
    matrix(R);
    o_ << "\n";
  }
  void stamps(const std::string& key, const std::vector<long>& v, const std::vector<double>& times,
              double t0) {
    o_ << "  " << key << "_stamps_s: [";
    o_ << std::setprecision(16);
    for (size_t i = 0; i < v.size(); ++i) o_ << (i ? ", " : "") << t0 + times[v[i]];
    o_ << std::setprecision(12) << "]\n";
  }

 private:
  std::ostringstream o_;
};

/// The `imu_errors:` block, 17 significant digits (reads back exactly).
void imuErrorsYaml(const ImuErrors& e, const ImuSystematicSigmas& sigmas, Writer* w) {
  auto& o = w->o();
  const SensorNoise& n = e.noise;
  o << std::setprecision(17)
    << "imu_errors:  # drawn once per seed; gyro = T_g w + b_g(t) + n_g, accel = T_a f + b_a(t) + "
       "n_a,\n"
       "            # mag = S (R_world_imu^T B) + h + n_m (IMU frame = the accelerometer's)\n"
    << "  grade: " << toString(e.grade) << "\n  T_g: ";
  w->matrix(e.T_g);
  o << "  # gyro scale (diagonal) and cross-axis/misalignment\n  T_a: ";
  w->matrix(e.T_a);
  o << "  # accel scale (diagonal) and non-orthogonality (below it)\n  gyro_bias_initial_rad_s: ";
  w->vec(e.gyro_bias_initial);
  o << "\n  gyro_bias_walk_rad_s2_sqrt_hz: " << n.gyroscope_random_walk
    << "\n  accel_bias_initial_m_s2: ";
  w->vec(e.accel_bias_initial);
  o << "\n  accel_bias_walk_m_s3_sqrt_hz: " << n.accelerometer_random_walk
    << "\n  mag_hard_iron_t: ";
  w->vec(e.mag_hard_iron);
  o << "  # h\n  mag_soft_iron: ";
  w->matrix(e.mag_soft_iron);
  o << "  # S, symmetric\n  gyro_noise_density_rad_s_sqrt_hz: " << n.gyroscope_noise_density
    << "\n  accel_noise_density_m_s2_sqrt_hz: " << n.accelerometer_noise_density
    << "\n  mag_noise_sigma_t: " << n.magnetometer_noise_sigma << std::setprecision(12)
    << "\n  sigmas:  # the grade's 1-sigma spread of the drawn errors"
    << "\n    gyro_scale: " << sigmas.gyro_scale_sigma
    << "\n    gyro_cross_axis: " << sigmas.gyro_cross_axis_sigma
    << "\n    accel_scale: " << sigmas.accel_scale_sigma
    << "\n    accel_cross_axis: " << sigmas.accel_cross_axis_sigma
    << "\n    gyro_bias_initial_rad_s: " << n.gyroscope_initial_bias_sigma
    << "\n    accel_bias_initial_m_s2: " << n.accelerometer_initial_bias_sigma
    << "\n    mag_hard_iron_t: " << sigmas.mag_hard_iron_sigma
    << "\n    mag_soft_iron: " << sigmas.mag_soft_iron_sigma << "\n";
}

}  // namespace

std::vector<CameraOrientation> simulateCameraOrientations(const SimulationConfig& config,
                                                          const Trajectory& trajectory,
                                                          const std::vector<double>& frame_times) {
  std::mt19937_64 rng(streamSeed(config.seed, 7));
  std::normal_distribution<double> unit(0.0, 1.0);
  const double sigma = deg2rad(config.noise_scale * config.camera_pose_noise_deg);
  std::mt19937_64 position_rng(streamSeed(config.seed, 9));
  const double sigma_p = config.noise_scale * config.camera_pose_position_noise_m;
  std::vector<CameraOrientation> out;
  out.reserve(frame_times.size());
  const Eigen::Matrix3d R_target_world = trajectory.R_world_target().transpose();
  for (double t : frame_times) {
    const RigState st = trajectory.at(t);
    CameraOrientation o;
    o.capture_s = t;
    o.stamp_s = t + config.camera_time_offset_s;
    o.R_target_cam_true = R_target_world * st.R_world_cam;
    o.p_target_cam_true = R_target_world * (st.p_world_cam - trajectory.p_world_target());
    const Eigen::Vector3d n(unit(rng), unit(rng), unit(rng));
    o.R_target_cam = o.R_target_cam_true * expSO3(sigma * n);
    const Eigen::Vector3d m(unit(position_rng), unit(position_rng), unit(position_rng));
    o.p_target_cam = o.p_target_cam_true + o.R_target_cam_true * (sigma_p * m);
    out.push_back(o);
  }
  return out;
}

SimulationRun::SimulationRun(const SimulationConfig& c)
    : config(c),
      trajectory(c),
      imu(simulateInertial(c, trajectory)),
      mag(simulateMagnetometer(c, trajectory)),
      disturbances(magneticDisturbances(c, trajectory)),
      imu_errors(drawImuErrors(c)) {
  const long frames = static_cast<long>(std::floor(trajectory.duration() * c.camera_rate_hz)) + 1;
  for (long j = 0; j < frames; ++j) frame_times.push_back(j / c.camera_rate_hz);
  camera_orientations = simulateCameraOrientations(c, trajectory, frame_times);
  if (c.bad_input) {
    bad_input =
        planBadInput(c.seed, static_cast<long>(imu.size()), static_cast<long>(mag.size()), frames);
  }
}

std::uint64_t SimulationRun::frameNoiseSeed(long j) const {
  return streamSeed(config.seed, 4) ^ (0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(j + 1));
}

std::string truthYaml(const SimulationRun& run) {
  const SimulationConfig& c = run.config;
  const Trajectory& tr = run.trajectory;
  const double t0 = c.start_time_s;
  Writer w;
  auto& o = w.o();
  o << "# Ground truth of camera_imu_alignment simulate_bag. Times are bag times (s).\n";
  o << "scenario: " << c.scenario << "\nseed: " << c.seed << "\n";
  o << "camera_frame: " << c.camera_frame << "\nimu_frame: " << c.imu_frame << "\n";
  const Eigen::Matrix3d R = tr.R_cam_imu_final();
  o << "R_cam_imu:  # p_cam = R_cam_imu * p_imu" << (tr.remount() ? " (after the remount)" : "")
    << "\n";
  w.rotation("  ", R);
  o << "T_cam_imu:  # Kalibr camchain-imucam convention, translation zero\n";
  for (int i = 0; i < 3; ++i) {
    o << "  - [" << R(i, 0) << ", " << R(i, 1) << ", " << R(i, 2) << ", 0.0]\n";
  }
  o << "  - [0.0, 0.0, 0.0, 1.0]\n";
  o << "timeshift_cam_imu_s: " << 0.0 - c.camera_time_offset_s  // never "-0"
    << "  # Kalibr's name and sign: t_imu = t_cam + timeshift_cam_imu_s (camera stamps are "
       "true capture time - timeshift)\n";
  o << "remount:\n  enabled: " << (tr.remount() ? "true" : "false") << "\n";
  if (tr.remount()) {
    o << std::setprecision(16) << "  time_s: " << t0 + tr.remountTime() << std::setprecision(12)
      << "  # centre of a 1 s smooth change\n  R_cam_imu_before:\n";
    w.rotation("    ", tr.R_cam_imu_initial());
    o << "  rotation_vector_cam_rad: ";
    w.vec(c.remount_rotvec_cam);
    o << "  # R_cam_imu = Exp(v) * R_cam_imu_before\n";
  }
  o << std::setprecision(16) << "start_time_s: " << t0 << "\n" << std::setprecision(12);
  o << "duration_s: " << tr.duration() << "\n";
  o << "gravity_world: ";
  w.vec(c.gravity_world);
  o << "  # m/s^2, ENU\nmotion: " << toString(c.motion) << "\n";
  const char* none = tr.poses().empty() ? " []" : "";  // waving: no rests
  o << "stationary_intervals:" << none << "  # [start_s, end_s], bag time\n"
    << std::setprecision(16);
  for (const StationaryPose& p : tr.poses())
    o << "  - [" << t0 + p.start_s << ", " << t0 + p.end_s << "]\n";
  const bool room = isRoomMotion(c.motion);  // no board: no target frame, the room's = world
  o << std::setprecision(12) << "poses:" << none << "  # true orientations during each hold"
    << (room ? "; world = the room frame (scene:)" : "") << "\n";
  for (size_t k = 0; k < tr.poses().size(); ++k) {
    const StationaryPose& p = tr.poses()[k];
    const RigState st = tr.at(0.5 * (p.start_s + p.end_s));
    o << "  - index: " << k << "\n    q_world_imu_xyzw: ";
    w.quat(st.R_world_imu());
    if (!room) {
      o << "\n    q_target_cam_xyzw: ";
      w.quat(tr.R_world_target().transpose() * p.R_world_cam);
    }
    o << "\n    q_world_cam_xyzw: ";
    w.quat(p.R_world_cam);
    o << "\n    p_world_cam_m: ";
    w.vec(p.p_world_cam);
    if (!room) {
      o << "\n    p_target_cam_m: ";
      w.vec(tr.R_world_target().transpose() * (p.p_world_cam - tr.p_world_target()));
    }
    o << "\n";
  }
  if (room) {
    o << RoomScene::fromConfig(c).yaml();
  } else {
    o << "target:  # pose of the target frame in the world (see the target YAML)\n  type: "
      << toString(c.target.type) << "\n  R_world_target:\n";
    w.rotation("    ", tr.R_world_target());
    o << "  p_world_target_m: ";
    w.vec(tr.p_world_target());
    o << "\n";
  }
  o << "camera:\n  width: " << c.width << "\n  height: " << c.height
    << "\n  rate_hz: " << c.camera_rate_hz << "\n  K: [" << c.fx << ", 0, " << c.cx << ", 0, "
    << c.fy << ", " << c.cy << ", 0, 0, 1]\n  distortion_model: plumb_bob\n  D: ["
    << c.distortion[0] << ", " << c.distortion[1] << ", " << c.distortion[2] << ", "
    << c.distortion[3] << ", " << c.distortion[4]
    << "]\n  time_offset_s: " << c.camera_time_offset_s
    << "  # image stamp = true capture time + offset\n  timeshift_cam_imu: "
    << -c.camera_time_offset_s << "  # Kalibr: t_imu = t_cam + timeshift_cam_imu\n"
    << "  blur_sigma_px: " << c.blur_sigma_px
    << "\n  pixel_noise_sigma: " << c.noise_scale * c.pixel_noise_sigma
    << "\n  motion_blur_exposure_s: " << c.motion_blur_exposure_s << "\n";
  if (c.camera_pose) {
    o << "  pose_position_noise_m: " << c.noise_scale * c.camera_pose_position_noise_m << "\n";
    o << "  pose_noise_deg: " << c.noise_scale * c.camera_pose_noise_deg
      << "  # 1-sigma per axis of the camera_pose orientations\n";
  }
  const SensorNoise& n = c.imu_noise;
  const double k = c.noise_scale;
  o << "imu:  # Kalibr imu.yaml terms, noise_scale applied\n  rate_hz: " << c.imu_rate_hz
    << "\n  noise_scale: " << k
    << "\n  accelerometer_noise_density: " << k * n.accelerometer_noise_density
    << "  # m/s^2/sqrt(Hz)\n  accelerometer_random_walk: " << k * n.accelerometer_random_walk
    << "  # m/s^3/sqrt(Hz)\n  gyroscope_noise_density: " << k * n.gyroscope_noise_density
    << "  # rad/s/sqrt(Hz)\n  gyroscope_random_walk: " << k * n.gyroscope_random_walk
    << "  # rad/s^2/sqrt(Hz)\n";
  if (!run.imu.empty()) {
    o << "  gyroscope_bias_initial: ";
    w.vec(run.imu.front().gyro_bias);
    o << "  # rad/s\n  gyroscope_bias_final: ";
    w.vec(run.imu.back().gyro_bias);
    o << "\n  accelerometer_bias_initial: ";
    w.vec(run.imu.front().accel_bias);
    o << "  # m/s^2\n  accelerometer_bias_final: ";
    w.vec(run.imu.back().accel_bias);
    o << "\n";
  }
  o << "magnetometer:\n  enabled: " << (c.magnetometer ? "true" : "false")
    << "\n  rate_hz: " << c.mag_rate_hz << "\n  noise_sigma_t: " << k * n.magnetometer_noise_sigma
    << "\n  earth_field_world_t: ";
  w.vec(c.earth_field_world);
  o << "\n  hard_iron_t: ";
  w.vec(run.imu_errors.mag_hard_iron);
  o << "  # IMU frame, option and drawn parts (imu_errors)\n  disturbances:  # extra world field "
       "during [start_s, end_s]\n";
  for (const MagDisturbance& d : run.disturbances) {
    o << std::setprecision(16) << "    - interval: [" << t0 + d.start_s << ", " << t0 + d.end_s
      << "]\n"
      << std::setprecision(12) << "      field_world_t: ";
    w.vec(d.field_world);
    o << "\n";
  }
  imuErrorsYaml(run.imu_errors, c.imu_systematic, &w);
  o << "topics:\n  imu: " << c.imu_topic << "\n  magnetometer: " << c.mag_topic
    << "\n  image: " << c.image_topic << "\n  camera_info: " << c.camera_info_topic << "\n";
  if (c.camera_pose) {
    o << "  camera_pose: " << c.camera_pose_topic << "  # geometry_msgs/PoseStamped, frame_id "
      << c.target_frame << "\n";
  }
  o << "counts:\n  imu: " << run.imu.size() << "\n  magnetometer: " << run.mag.size()
    << "\n  images: " << (c.images ? run.frame_times.size() : 0) << "\n";
  if (c.camera_pose) o << "  camera_poses: " << run.camera_orientations.size() << "\n";
  const BadInputPlan& b = run.bad_input;
  o << "bad_input:\n  enabled: " << (c.bad_input ? "true" : "false") << "\n";
  std::vector<double> imu_t, mag_t;
  for (const InertialSample& s : run.imu) imu_t.push_back(s.t);
  for (const MagSample& s : run.mag) mag_t.push_back(s.t);
  w.stamps("nan_imu", b.nan_imu, imu_t, t0);
  w.stamps("duplicate_imu", b.duplicate_imu, imu_t, t0);
  w.stamps("out_of_order_imu", b.out_of_order_imu, imu_t, t0);
  w.stamps("nan_magnetometer", b.nan_mag, mag_t, t0);
  std::vector<double> cam_t;
  for (double t : run.frame_times) cam_t.push_back(t + c.camera_time_offset_s);
  w.stamps("empty_image", b.empty_images, cam_t, t0);
  w.stamps("wrong_encoding_image", b.wrong_encoding_images, cam_t, t0);
  w.stamps("zero_k_camera_info", b.zero_k_camera_infos, cam_t, t0);
  return o.str();
}

}  // namespace simulation
}  // namespace camera_imu_alignment
