#include "camera_imu_alignment/simulation/imu_model.h"

#include <cmath>
#include <random>

namespace camera_imu_alignment {
namespace simulation {

std::vector<ImuSample> simulateImu(const RigTrajectory& trajectory, const ImuSimulationOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto gaussian3 = [&]() { return Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)); };
  const double dt = 1.0 / o.rate_hz;
  const double s = o.noise.scale;
  // Discrete white noise: sigma = density / sqrt(dt); random walk step: sigma = density * sqrt(dt).
  const double gyro_sigma = s * o.noise.gyroscope_noise_density / std::sqrt(dt);
  const double accel_sigma = s * o.noise.accelerometer_noise_density / std::sqrt(dt);
  const double gyro_walk = s * o.noise.gyroscope_random_walk * std::sqrt(dt);
  const double accel_walk = s * o.noise.accelerometer_random_walk * std::sqrt(dt);
  Eigen::Vector3d gyro_bias = o.noise.gyroscope_bias_rad_s;
  Eigen::Vector3d accel_bias = o.noise.accelerometer_bias_m_s2;
  std::vector<ImuSample> samples;
  const auto count = static_cast<size_t>(std::floor(trajectory.durationS() * o.rate_hz)) + 1;
  samples.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    ImuSample sample;
    sample.t_s = static_cast<double>(i) * dt;
    const Eigen::Matrix3d R = trajectory.orientation(sample.t_s);
    sample.true_gyro_bias = gyro_bias;
    sample.true_accel_bias = accel_bias;
    sample.gyro_rad_s = trajectory.bodyRate(sample.t_s) + gyro_bias + gyro_sigma * gaussian3();
    sample.accel_m_s2 = R.transpose() * (trajectory.acceleration(sample.t_s) - o.gravity_world) +
                        accel_bias + accel_sigma * gaussian3();
    sample.mag_t = R.transpose() * o.earth_field_world_t + o.noise.magnetometer_hard_iron_t +
                   s * o.noise.magnetometer_noise_t * gaussian3();
    samples.push_back(sample);
    gyro_bias += gyro_walk * gaussian3();
    accel_bias += accel_walk * gaussian3();
  }
  return samples;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
