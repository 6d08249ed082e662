#include "camera_imu_alignment/simulation/inertial_model.h"

#include <cmath>
#include <random>

namespace camera_imu_alignment {
namespace simulation {

namespace {

Eigen::Vector3d gaussian3(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> g(0.0, 1.0);
  const double x = g(rng), y = g(rng), z = g(rng);
  return sigma * Eigen::Vector3d(x, y, z);
}

}  // namespace

std::uint64_t streamSeed(std::uint64_t seed, int stream) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(stream) + 100u};
  std::uint32_t out[2];
  seq.generate(out, out + 2);
  return (static_cast<std::uint64_t>(out[0]) << 32) | out[1];
}

std::vector<InertialSample> simulateInertial(const SimulationConfig& c,
                                             const Trajectory& trajectory) {
  std::mt19937_64 rng(streamSeed(c.seed, 1));
  const double dt = 1.0 / c.imu_rate_hz, k = c.noise_scale;
  const SensorNoise& n = c.imu_noise;
  Eigen::Vector3d bg = gaussian3(rng, k * n.gyroscope_initial_bias_sigma);
  Eigen::Vector3d ba = gaussian3(rng, k * n.accelerometer_initial_bias_sigma);
  const double sg = k * n.gyroscope_noise_density / std::sqrt(dt);
  const double sa = k * n.accelerometer_noise_density / std::sqrt(dt);
  const double sbg = k * n.gyroscope_random_walk * std::sqrt(dt);
  const double sba = k * n.accelerometer_random_walk * std::sqrt(dt);
  const long count = static_cast<long>(std::floor(trajectory.duration() / dt)) + 1;
  std::vector<InertialSample> samples;
  samples.reserve(count);
  for (long i = 0; i < count; ++i) {
    InertialSample s;
    s.t = i * dt;
    const RigState st = trajectory.at(s.t);
    const Eigen::Matrix3d R_world_imu = st.R_world_imu();
    s.omega_true = st.omega_imu;
    s.gyro_bias = bg;
    s.accel_bias = ba;
    s.gyro = st.omega_imu + bg + gaussian3(rng, sg);
    s.accel = R_world_imu.transpose() * (st.a_world - c.gravity_world) + ba + gaussian3(rng, sa);
    samples.push_back(s);
    bg += gaussian3(rng, sbg);
    ba += gaussian3(rng, sba);
  }
  return samples;
}

std::vector<MagDisturbance> magneticDisturbances(const SimulationConfig& c,
                                                 const Trajectory& trajectory) {
  std::mt19937_64 rng(streamSeed(c.seed, 3));
  std::vector<MagDisturbance> out;
  for (int p : c.mag_disturbance_poses) {
    if (p < 0 || p >= static_cast<int>(trajectory.poses().size())) continue;
    MagDisturbance d;
    d.start_s = trajectory.poses()[p].start_s;
    d.end_s = trajectory.poses()[p].end_s;
    d.field_world = c.mag_disturbance_t * gaussian3(rng, 1.0).normalized();
    out.push_back(d);
  }
  return out;
}

std::vector<MagSample> simulateMagnetometer(const SimulationConfig& c,
                                            const Trajectory& trajectory) {
  std::vector<MagSample> samples;
  if (!c.magnetometer) return samples;
  std::mt19937_64 rng(streamSeed(c.seed, 2));
  const std::vector<MagDisturbance> disturbances = magneticDisturbances(c, trajectory);
  const double dt = 1.0 / c.mag_rate_hz;
  const double sigma = c.noise_scale * c.imu_noise.magnetometer_noise_sigma;
  const long count = static_cast<long>(std::floor(trajectory.duration() / dt)) + 1;
  samples.reserve(count);
  for (long i = 0; i < count; ++i) {
    MagSample s;
    s.t = i * dt;
    Eigen::Vector3d field_world = c.earth_field_world;
    for (const MagDisturbance& d : disturbances) {
      if (s.t >= d.start_s && s.t <= d.end_s) {
        field_world += d.field_world;
        s.disturbed = true;
      }
    }
    const RigState st = trajectory.at(s.t);
    s.field = st.R_world_imu().transpose() * field_world + c.mag_hard_iron + gaussian3(rng, sigma);
    samples.push_back(s);
  }
  return samples;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
