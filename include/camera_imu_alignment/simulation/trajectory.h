// Ground-truth motion of the simulated rig: N stationary poses in front of a planar target fixed in
// the world, joined by minimum-jerk rotation + translation segments (or, for MotionKind::kWaving,
// continuous hand-held motion without rests: waving_motion.h; for the room motions, rests in a
// textured room without a board, room_motion.h, the target frame then being the room's = world),
// and the (possibly remounted) mounting R_cam_imu(t). Everything is analytic: orientation, body
// rate and acceleration are exact.
//
// Frames: world ENU (z up). Target frame as Kalibr's (x along the columns, y along the rows, z out
// of the printed face towards the camera); the target hangs on a wall facing south (-y world).
// Camera: optical frame (z forward, x right, y down). Times t are seconds since the start.
#pragma once

#include <Eigen/Core>
#include <random>
#include <vector>

#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/simulation/waving_motion.h"

namespace camera_imu_alignment {
namespace simulation {

/// One stationary pose of the camera.
struct StationaryPose {
  double start_s = 0.0, end_s = 0.0;                          ///< hold interval
  Eigen::Matrix3d R_world_cam = Eigen::Matrix3d::Identity();  ///< camera orientation
  Eigen::Vector3d p_world_cam = Eigen::Vector3d::Zero();      ///< camera centre (m)
};

/// Rig state at one instant.
struct RigState {
  Eigen::Matrix3d R_world_cam = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_world_cam = Eigen::Vector3d::Zero();  ///< m
  Eigen::Vector3d omega_cam = Eigen::Vector3d::Zero();    ///< body rate in the camera frame, rad/s
  Eigen::Vector3d a_world = Eigen::Vector3d::Zero();      ///< acceleration, m/s^2, world
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();  ///< mounting at t
  Eigen::Vector3d omega_imu = Eigen::Vector3d::Zero();      ///< IMU body rate, IMU frame, rad/s
  int pose = -1;  ///< index of the stationary pose held at t, -1 while moving
  Eigen::Matrix3d R_world_imu() const { return R_world_cam * R_cam_imu; }
};

class Trajectory {
 public:
  /// Draws the poses, hold/motion durations and (unless given) R_cam_imu from the seed.
  explicit Trajectory(const SimulationConfig& config);

  RigState at(double t) const;
  double duration() const { return duration_; }
  /// The stationary poses in time order; empty for MotionKind::kWaving (no rests).
  const std::vector<StationaryPose>& poses() const { return poses_; }
  bool waving() const { return waving_; }

  /// Mounting before any remount, and at the end of the run (equal without remount).
  const Eigen::Matrix3d& R_cam_imu_initial() const { return R_cam_imu_initial_; }
  Eigen::Matrix3d R_cam_imu_final() const;
  bool remount() const { return remount_; }
  double remountTime() const { return remount_time_; }  ///< centre of the 1 s remount motion

  /// Target pose in the world (target frame: see the file comment).
  const Eigen::Matrix3d& R_world_target() const { return R_world_target_; }
  const Eigen::Vector3d& p_world_target() const { return p_world_target_; }

 private:
  RigState poseMotionAt(double t) const;  ///< camera motion of the pose scenarios (no mounting)
  void finishPoses(const SimulationConfig& config);  ///< duration and remount time from poses_

  std::vector<StationaryPose> poses_;
  bool waving_ = false;
  WavingMotion waving_motion_;
  double duration_ = 0.0;
  Eigen::Matrix3d R_cam_imu_initial_;
  bool remount_ = false;
  double remount_time_ = 0.0;
  Eigen::Vector3d remount_rotvec_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_world_target_;
  Eigen::Vector3d p_world_target_;
};

/// Minimum-jerk profile s -> 10s^3 - 15s^4 + 6s^5 on [0, 1] and its first two derivatives.
void minimumJerk(double s, double* f, double* df, double* ddf);

}  // namespace simulation
}  // namespace camera_imu_alignment
