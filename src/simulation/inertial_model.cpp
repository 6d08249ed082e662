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

/// b_g(0) and b_a(0): the first draws of the IMU stream (stream 1).
void drawInitialBiases(std::mt19937_64& rng, const SimulationConfig& c, Eigen::Vector3d* bg,
                       Eigen::Vector3d* ba) {
  const double k = c.noise_scale;
  *bg = gaussian3(rng, k * c.imu_noise.gyroscope_initial_bias_sigma);
  *ba = gaussian3(rng, k * c.imu_noise.accelerometer_initial_bias_sigma);
}

}  // namespace

ImuErrors drawImuErrors(const SimulationConfig& c) {
  ImuErrors e;
  e.grade = c.imu_grade;
  std::mt19937_64 rng(streamSeed(c.seed, 6));
  std::normal_distribution<double> unit(0.0, 1.0);
  // Every entry is drawn whatever its sigma, so one sigma never shifts the others' draws.
  const auto draw = [&](double sigma) {
    const double x = unit(rng);
    return sigma > 0.0 ? sigma * x : 0.0;
  };
  const ImuSystematicSigmas& s = c.imu_systematic;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      e.T_g(i, j) += draw(i == j ? s.gyro_scale_sigma : s.gyro_cross_axis_sigma);
    }
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j <= i; ++j) {
      e.T_a(i, j) += draw(i == j ? s.accel_scale_sigma : s.accel_cross_axis_sigma);
    }
  }
  Eigen::Vector3d drawn_hard_iron;
  for (int i = 0; i < 3; ++i) drawn_hard_iron(i) = draw(s.mag_hard_iron_sigma);
  e.mag_hard_iron = c.mag_hard_iron + drawn_hard_iron;
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) {
      e.mag_soft_iron(i, j) += draw(s.mag_soft_iron_sigma);
      e.mag_soft_iron(j, i) = e.mag_soft_iron(i, j);
    }
  }
  std::mt19937_64 imu_rng(streamSeed(c.seed, 1));
  drawInitialBiases(imu_rng, c, &e.gyro_bias_initial, &e.accel_bias_initial);
  const double k = c.noise_scale;
  e.noise = c.imu_noise;
  for (double* v : {&e.noise.accelerometer_noise_density, &e.noise.accelerometer_random_walk,
                    &e.noise.gyroscope_noise_density, &e.noise.gyroscope_random_walk,
                    &e.noise.gyroscope_initial_bias_sigma,
                    &e.noise.accelerometer_initial_bias_sigma, &e.noise.magnetometer_noise_sigma}) {
    *v *= k;
  }
  return e;
}

std::uint64_t streamSeed(std::uint64_t seed, int stream) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(stream) + 100u};
  std::uint32_t out[2];
  seq.generate(out, out + 2);
  return (static_cast<std::uint64_t>(out[0]) << 32) | out[1];
}

std::vector<InertialSample> simulateInertial(const SimulationConfig& c,
                                             const Trajectory& trajectory) {
  const ImuErrors errors = drawImuErrors(c);
  std::mt19937_64 rng(streamSeed(c.seed, 1));
  const double dt = 1.0 / c.imu_rate_hz, k = c.noise_scale;
  const SensorNoise& n = c.imu_noise;
  Eigen::Vector3d bg, ba;
  drawInitialBiases(rng, c, &bg, &ba);
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
    const Eigen::Vector3d specific_force = R_world_imu.transpose() * (st.a_world - c.gravity_world);
    s.gyro = errors.T_g * st.omega_imu + bg + gaussian3(rng, sg);
    s.accel = errors.T_a * specific_force + ba + gaussian3(rng, sa);
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
  const ImuErrors errors = drawImuErrors(c);
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
    const Eigen::Vector3d external_imu = st.R_world_imu().transpose() * field_world;
    s.field = errors.mag_soft_iron * external_imu + errors.mag_hard_iron + gaussian3(rng, sigma);
    samples.push_back(s);
  }
  return samples;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
