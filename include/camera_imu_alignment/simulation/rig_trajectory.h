// Ground-truth motion of a camera + IMU rig for the simulator: stationary poses joined by smooth
// motion. World frame ENU (z up). Orientation R_world_imu(t), position p_world_imu(t) (m).
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

namespace camera_imu_alignment {
namespace simulation {

struct TrajectoryOptions {
  unsigned int seed = 1;
  int num_poses = 12;
  double hold_min_s = 3.0, hold_max_s = 5.0;  ///< time held still at each pose (s)
  double move_min_s = 2.0, move_max_s = 3.0;  ///< time of each motion between poses (s)
  double yaw_range_deg = 120.0;               ///< full range of the rig's yaw over the poses
  double tilt_range_deg = 70.0;               ///< full range of roll and pitch
  double translation_range_m = 0.3;           ///< full range of the rig's position per axis
  /// Degenerate motion: every pose rotated about this single world axis (zero vector: off).
  Eigen::Vector3d single_axis_world = Eigen::Vector3d::Zero();
};

/// Piecewise motion: at rest during [start, end] of each stationary interval; between two poses a
/// minimum-jerk profile s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 along the geodesic
/// R_k Exp(s phi_k) (so the body rate is s'(tau) phi_k / T, in the IMU frame) and along the
/// straight line between positions.
class RigTrajectory {
 public:
  explicit RigTrajectory(const TrajectoryOptions& options);

  double durationS() const { return duration_s_; }
  /// Stationary intervals [start_s, end_s] (one per pose).
  const std::vector<std::pair<double, double>>& stationaryIntervals() const { return intervals_; }
  /// True orientation R_world_imu at each stationary pose.
  const std::vector<Eigen::Matrix3d>& poseOrientations() const { return orientations_; }

  Eigen::Matrix3d orientation(double t_s) const;   ///< R_world_imu(t)
  Eigen::Vector3d bodyRate(double t_s) const;      ///< angular rate in the IMU frame (rad/s)
  Eigen::Vector3d position(double t_s) const;      ///< p_world_imu(t) (m)
  Eigen::Vector3d acceleration(double t_s) const;  ///< second derivative of position, world (m/s^2)
  bool isStationary(double t_s) const;

 private:
  /// Segment index k and normalised time tau in [0, 1] of the motion from pose k to k + 1, or -1
  /// when t is inside a stationary interval (then `pose` is its pose index).
  int motionSegment(double t_s, double* tau, int* pose) const;

  std::vector<std::pair<double, double>> intervals_;
  std::vector<Eigen::Matrix3d> orientations_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<Eigen::Vector3d> phi_;  ///< Log(R_k^T R_{k+1}) per motion
  double duration_s_ = 0.0;
};

}  // namespace simulation
}  // namespace camera_imu_alignment
