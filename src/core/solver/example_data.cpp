#include "camera_imu_alignment/solver/example_data.h"

#include <random>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

Eigen::Vector3d uniformInBall(std::mt19937_64& rng, double radius) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(u(rng), u(rng), u(rng));
  } while (v.squaredNorm() > 1.0);
  return radius * v;
}

Eigen::Matrix3d randomRotation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  return uniformRotation(u(rng), u(rng), u(rng));
}

}  // namespace

ExampleData generateExample(const ExampleOptions& o) {
  std::mt19937_64 rng(o.seed);
  ExampleData data;
  data.R_cam_imu = o.R_cam_imu ? *o.R_cam_imu : randomRotation(rng);
  const Eigen::Matrix3d R_target_world = randomRotation(rng);
  std::uniform_real_distribution<double> unit(-0.5, 0.5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto noise = [&](double sigma_deg) {
    return expSO3(deg2rad(sigma_deg) * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)));
  };
  for (int k = 0; k < o.num_poses; ++k) {
    const double yaw = deg2rad(o.yaw_range_deg) * unit(rng);
    const double pitch = deg2rad(o.tilt_range_deg) * unit(rng);
    const double roll = deg2rad(o.tilt_range_deg) * unit(rng);
    const Eigen::Matrix3d R_world_imu = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                            .toRotationMatrix();
    PoseOrientation pose;
    pose.stamp_s = 5.0 * k;
    pose.R_world_imu = R_world_imu * noise(o.imu_noise_deg);
    pose.R_target_cam =
        R_target_world * R_world_imu * data.R_cam_imu.transpose() * noise(o.camera_noise_deg);
    data.poses.push_back(pose);
  }
  return data;
}

RotationPairs generateRandomPairs(unsigned int seed, int num_pairs,
                                  const Eigen::Matrix3d& R_cam_imu, double noise_radius_rad) {
  std::mt19937_64 rng(seed);
  RotationPairs pairs(static_cast<size_t>(num_pairs));
  for (auto& p : pairs) {
    const Eigen::Matrix3d B = randomRotation(rng);
    p.A_cam = R_cam_imu * B * R_cam_imu.transpose() * expSO3(uniformInBall(rng, noise_radius_rad));
    p.B_imu = B * expSO3(uniformInBall(rng, noise_radius_rad));
  }
  return pairs;
}

}  // namespace camera_imu_alignment
