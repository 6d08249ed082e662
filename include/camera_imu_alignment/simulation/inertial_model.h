// Inertial/magnetic unit models of the simulator, in the IMU frame (REP-145):
//   gyro  = omega_imu + b_g + n_g,       n_g ~ N(0, (gyroscope_noise_density)^2 * rate)
//   accel = R_world_imu^T (a - g) + b_a + n_a   (+9.81 along the IMU's up axis at rest)
//   b_g, b_a: initial N(0, sigma0^2) per axis, then random walks with sigma = random_walk *
//   sqrt(dt) mag   = R_world_imu^T (B_earth + B_disturbance(t)) + hard_iron + n_m   (tesla)
// All noise terms are multiplied by config.noise_scale. Times are seconds since the start.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/simulation/trajectory.h"

namespace camera_imu_alignment {
namespace simulation {

struct InertialSample {
  double t = 0.0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();        ///< rad/s, IMU frame
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();       ///< m/s^2, IMU frame (specific force)
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   ///< true bias in `gyro` (rad/s)
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  ///< true bias in `accel` (m/s^2)
  Eigen::Vector3d omega_true = Eigen::Vector3d::Zero();  ///< true body rate (rad/s)
};

struct MagSample {
  double t = 0.0;
  Eigen::Vector3d field = Eigen::Vector3d::Zero();  ///< T, IMU frame
  bool disturbed = false;                           ///< inside a disturbance interval
};

/// A disturbance interval [start_s, end_s] with its extra world field (T).
struct MagDisturbance {
  double start_s = 0.0, end_s = 0.0;
  Eigen::Vector3d field_world = Eigen::Vector3d::Zero();
};

/// IMU samples at t = i / imu_rate_hz over [0, duration].
std::vector<InertialSample> simulateInertial(const SimulationConfig& config,
                                             const Trajectory& trajectory);

/// Disturbance intervals of config.mag_disturbance_poses (random field directions per seed).
std::vector<MagDisturbance> magneticDisturbances(const SimulationConfig& config,
                                                 const Trajectory& trajectory);

/// Magnetometer samples at t = i / mag_rate_hz (empty without a magnetometer).
std::vector<MagSample> simulateMagnetometer(const SimulationConfig& config,
                                            const Trajectory& trajectory);

/// The seed's independent random stream `stream` (0: mounting and poses, 1: IMU, 2: magnetometer,
/// 3: disturbances, 4: image noise, 5: bad input).
std::uint64_t streamSeed(std::uint64_t seed, int stream);

}  // namespace simulation
}  // namespace camera_imu_alignment
