#include "camera_imu_alignment/simulation/rig_trajectory.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "camera_imu_alignment/rotation_math.h"

namespace camera_imu_alignment {
namespace simulation {
namespace {

double minJerk(double tau) { return tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau); }
double minJerkRate(double tau) { return 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau); }
double minJerkAccel(double tau) { return 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau); }

}  // namespace

RigTrajectory::RigTrajectory(const TrajectoryOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> unit(-0.5, 0.5), u01(0.0, 1.0);
  const bool single_axis = o.single_axis_world.norm() > 0.0;
  double t = 0.0;
  for (int k = 0; k < std::max(1, o.num_poses); ++k) {
    Eigen::Matrix3d R;
    if (single_axis) {
      R = Eigen::AngleAxisd(deg2rad(o.yaw_range_deg) * unit(rng), o.single_axis_world.normalized())
              .toRotationMatrix();
    } else {
      R = (Eigen::AngleAxisd(deg2rad(o.yaw_range_deg) * unit(rng), Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(deg2rad(o.tilt_range_deg) * unit(rng), Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(deg2rad(o.tilt_range_deg) * unit(rng), Eigen::Vector3d::UnitX()))
              .toRotationMatrix();
    }
    orientations_.push_back(R);
    positions_.push_back(o.translation_range_m * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
    if (k > 0) {
      phi_.push_back(logSO3(orientations_[k - 1].transpose() * R));
      t += o.move_min_s + (o.move_max_s - o.move_min_s) * u01(rng);
    }
    const double hold = o.hold_min_s + (o.hold_max_s - o.hold_min_s) * u01(rng);
    intervals_.emplace_back(t, t + hold);
    t += hold;
  }
  duration_s_ = t;
}

int RigTrajectory::motionSegment(double t_s, double* tau, int* pose) const {
  const double t = std::clamp(t_s, 0.0, duration_s_);
  for (size_t k = 0; k < intervals_.size(); ++k) {
    if (t <= intervals_[k].second) {
      if (t >= intervals_[k].first || k == 0) {
        *pose = static_cast<int>(k);
        return -1;
      }
      const double start = intervals_[k - 1].second, length = intervals_[k].first - start;
      *tau = (t - start) / length;
      return static_cast<int>(k) - 1;
    }
  }
  *pose = static_cast<int>(intervals_.size()) - 1;
  return -1;
}

Eigen::Matrix3d RigTrajectory::orientation(double t_s) const {
  double tau = 0.0;
  int pose = 0;
  const int k = motionSegment(t_s, &tau, &pose);
  if (k < 0) return orientations_[pose];
  return orientations_[k] * expSO3(minJerk(tau) * phi_[k]);
}

Eigen::Vector3d RigTrajectory::bodyRate(double t_s) const {
  double tau = 0.0;
  int pose = 0;
  const int k = motionSegment(t_s, &tau, &pose);
  if (k < 0) return Eigen::Vector3d::Zero();
  const double length = intervals_[k + 1].first - intervals_[k].second;
  // R(t) = R_k Exp(s phi): R^T dR/dt = s' skew(phi), so the body rate is s'(tau) / T * phi.
  return minJerkRate(tau) / length * phi_[k];
}

Eigen::Vector3d RigTrajectory::position(double t_s) const {
  double tau = 0.0;
  int pose = 0;
  const int k = motionSegment(t_s, &tau, &pose);
  if (k < 0) return positions_[pose];
  return positions_[k] + minJerk(tau) * (positions_[k + 1] - positions_[k]);
}

Eigen::Vector3d RigTrajectory::acceleration(double t_s) const {
  double tau = 0.0;
  int pose = 0;
  const int k = motionSegment(t_s, &tau, &pose);
  if (k < 0) return Eigen::Vector3d::Zero();
  const double length = intervals_[k + 1].first - intervals_[k].second;
  return minJerkAccel(tau) / (length * length) * (positions_[k + 1] - positions_[k]);
}

bool RigTrajectory::isStationary(double t_s) const {
  double tau = 0.0;
  int pose = 0;
  return motionSegment(t_s, &tau, &pose) < 0;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
