#include "camera_imu_alignment/simulation/trajectory.h"

#include <algorithm>
#include <cmath>

#include "camera_imu_alignment/simulation/room_motion.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace simulation {

namespace {

constexpr double kRemountWindowS = 1.0;

double frac(double x) { return x - std::floor(x); }

/// Camera orientation in the target frame looking from `position` at `look_at`, image x along the
/// target x (then rolled by `roll` rad about the optical axis).
Eigen::Matrix3d lookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& look_at,
                       double roll) {
  const Eigen::Vector3d z = (look_at - position).normalized();
  const Eigen::Vector3d tx = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = (tx - tx.dot(z) * z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R << x, y, z;
  return R * expSO3(Eigen::Vector3d(0.0, 0.0, roll));
}

}  // namespace

void minimumJerk(double s, double* f, double* df, double* ddf) {
  s = std::min(1.0, std::max(0.0, s));
  const double s2 = s * s, s3 = s2 * s;
  *f = s3 * (10.0 - 15.0 * s + 6.0 * s2);
  *df = 30.0 * s2 * (1.0 - 2.0 * s + s2);
  *ddf = 60.0 * s * (1.0 - 3.0 * s + 2.0 * s2);
}

Trajectory::Trajectory(const SimulationConfig& config) {
  std::seed_seq seq{static_cast<std::uint32_t>(config.seed),
                    static_cast<std::uint32_t>(config.seed >> 32), 1u};
  std::mt19937_64 rng(seq);
  std::uniform_real_distribution<double> uni(0.0, 1.0);

  // Mounting: an arbitrary rotation at least 30 deg from the identity.
  R_cam_imu_initial_ = config.R_cam_imu;
  do {
    const double u1 = uni(rng), u2 = uni(rng), u3 = uni(rng);
    if (!config.given_R_cam_imu) R_cam_imu_initial_ = uniformRotation(u1, u2, u3);
  } while (!config.given_R_cam_imu && rotationAngle(R_cam_imu_initial_) < deg2rad(30.0));

  // Target on a wall facing south: x east, y up, z south.
  R_world_target_ << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  p_world_target_ = Eigen::Vector3d(-0.2, 2.0, 1.0);

  const Eigen::Vector3d centre = targetCentre(config.target);
  remount_ = config.remount;
  remount_rotvec_ = config.remount_rotvec_cam;
  if (config.motion == MotionKind::kWaving) {
    waving_ = true;
    waving_motion_ = WavingMotion(config, centre, &rng);
    duration_ = config.waving_duration_s;
    remount_time_ = config.remount_time_s >= 0.0 ? config.remount_time_s : 0.5 * duration_;
    return;
  }
  if (isRoomMotion(config.motion)) {
    // No board: the target frame is the room's (= world), the rests look into the room.
    R_world_target_.setIdentity();
    p_world_target_.setZero();
    poses_ = roomRests(config, RoomScene::fromConfig(config), &rng);
    double t = 0.0;
    for (size_t k = 0; k < poses_.size(); ++k) {
      poses_[k].start_s = t;
      poses_[k].end_s = t + config.hold_min_s + (config.hold_max_s - config.hold_min_s) * uni(rng);
      t = poses_[k].end_s + config.move_min_s + (config.move_max_s - config.move_min_s) * uni(rng);
    }
    finishPoses(config);
    return;
  }
  double max_tilt = deg2rad(config.max_tilt_deg), max_roll = deg2rad(config.max_roll_deg);
  if (config.motion == MotionKind::kSmallAngle) {
    max_tilt = std::min(max_tilt, deg2rad(4.0));
    max_roll = std::min(max_roll, deg2rad(4.0));
  }
  const double phase_az = uni(rng), phase_roll = uni(rng);
  const int n = config.num_poses;
  double t = 0.0;
  for (int k = 0; k < n; ++k) {
    const double azimuth = 2.0 * kPi * frac(0.618034 * k + phase_az);
    const double tilt = max_tilt * std::sqrt(0.15 + 0.85 * uni(rng));
    const double roll_unit = 2.0 * frac(0.381966 * k + phase_roll + 0.1 * uni(rng)) - 1.0;
    const double distance =
        config.min_distance_m + (config.max_distance_m - config.min_distance_m) * uni(rng);
    const Eigen::Vector3d jitter(0.04 * (uni(rng) - 0.5), 0.04 * (uni(rng) - 0.5), 0.0);
    Eigen::Vector3d pos, look = centre;
    double roll = max_roll * roll_unit;
    if (config.motion == MotionKind::kSingleAxis) {
      pos =
          centre + 0.5 * (config.min_distance_m + config.max_distance_m) * Eigen::Vector3d::UnitZ();
    } else {
      look += jitter;
      pos = centre + distance * Eigen::Vector3d(std::sin(tilt) * std::cos(azimuth),
                                                std::sin(tilt) * std::sin(azimuth), std::cos(tilt));
    }
    StationaryPose pose;
    pose.R_world_cam = R_world_target_ * lookAt(pos, look, roll);
    pose.p_world_cam = p_world_target_ + R_world_target_ * pos;
    pose.start_s = t;
    pose.end_s = t + config.hold_min_s + (config.hold_max_s - config.hold_min_s) * uni(rng);
    t = pose.end_s;
    if (k + 1 < n) t += config.move_min_s + (config.move_max_s - config.move_min_s) * uni(rng);
    poses_.push_back(pose);
  }
  finishPoses(config);
}

void Trajectory::finishPoses(const SimulationConfig& config) {
  const int n = static_cast<int>(poses_.size());
  duration_ = poses_.back().end_s;
  if (remount_) {
    const int k = std::max(0, n / 2 - 1);
    remount_time_ = config.remount_time_s >= 0.0
                        ? config.remount_time_s
                        : 0.5 * (poses_[k].end_s + poses_[std::min(k + 1, n - 1)].start_s);
  }
}

Eigen::Matrix3d Trajectory::R_cam_imu_final() const {
  return remount_ ? Eigen::Matrix3d(expSO3(remount_rotvec_) * R_cam_imu_initial_)
                  : R_cam_imu_initial_;
}

RigState Trajectory::poseMotionAt(double t) const {
  RigState st;
  // Last pose starting at or before t.
  auto it = std::upper_bound(poses_.begin(), poses_.end(), t,
                             [](double v, const StationaryPose& p) { return v < p.start_s; });
  const int k = it == poses_.begin() ? 0 : static_cast<int>(it - poses_.begin()) - 1;
  const StationaryPose& a = poses_[k];
  if (t <= a.end_s || k + 1 >= static_cast<int>(poses_.size())) {
    st.R_world_cam = a.R_world_cam;
    st.p_world_cam = a.p_world_cam;
    st.pose = k;
  } else {
    const StationaryPose& b = poses_[k + 1];
    const double T = b.start_s - a.end_s;
    double f, df, ddf;
    minimumJerk((t - a.end_s) / T, &f, &df, &ddf);
    const Eigen::Vector3d phi = logSO3(a.R_world_cam.transpose() * b.R_world_cam);
    st.R_world_cam = a.R_world_cam * expSO3(f * phi);
    st.omega_cam = (df / T) * phi;
    st.p_world_cam = a.p_world_cam + f * (b.p_world_cam - a.p_world_cam);
    st.a_world = (ddf / (T * T)) * (b.p_world_cam - a.p_world_cam);
  }
  return st;
}

RigState Trajectory::at(double t) const {
  RigState st;
  if (waving_) {
    const WavingState w = waving_motion_.at(t);
    st.R_world_cam = R_world_target_ * w.R_target_cam;
    st.p_world_cam = p_world_target_ + R_world_target_ * w.p_target_cam;
    st.omega_cam = w.omega_cam;
    st.a_world = R_world_target_ * w.a_target;
  } else {
    st = poseMotionAt(t);
  }
  st.R_cam_imu = R_cam_imu_initial_;
  Eigen::Vector3d omega_mount = Eigen::Vector3d::Zero();  // IMU rate relative to the camera
  if (remount_) {
    double g, dg, ddg;
    minimumJerk((t - (remount_time_ - 0.5 * kRemountWindowS)) / kRemountWindowS, &g, &dg, &ddg);
    st.R_cam_imu = expSO3(g * remount_rotvec_) * R_cam_imu_initial_;
    omega_mount = (dg / kRemountWindowS) * st.R_cam_imu.transpose() * remount_rotvec_;
  }
  st.omega_imu = st.R_cam_imu.transpose() * st.omega_cam + omega_mount;
  return st;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
