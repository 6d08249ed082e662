// Inertial/magnetic unit models of the simulator, in the IMU frame (REP-145); see imu_grades.h:
//   gyro  = T_g omega_imu + b_g + n_g,   n_g ~ N(0, (gyroscope_noise_density)^2 * rate)
//   accel = T_a R_world_imu^T (a - g) + b_a + n_a   (+9.81 along the IMU's up axis at rest)
//   mag   = S R_world_imu^T (B_earth + B_disturbance(t)) + h + n_m   (tesla)
//   b_g, b_a: initial N(0, sigma0^2) per axis, then random walks with sigma = random_walk *
//   sqrt(dt). T_g, T_a, S, h: drawn once per seed from the grade's sigmas (identity and
//   config.mag_hard_iron for the ideal grade).
// The noise terms and initial biases are multiplied by config.noise_scale, the systematic errors
// are not. Times are seconds since the start.
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

/// Every error of one simulated unit (drawn once per seed), for the truth file and the tests.
struct ImuErrors {
  ImuGrade grade = ImuGrade::kIdeal;
  Eigen::Matrix3d T_g = Eigen::Matrix3d::Identity();  ///< gyro scale and axis misalignment
  Eigen::Matrix3d T_a = Eigen::Matrix3d::Identity();  ///< accel scale, lower-triangular skew
  Eigen::Vector3d gyro_bias_initial = Eigen::Vector3d::Zero();   ///< rad/s, b_g(0)
  Eigen::Vector3d accel_bias_initial = Eigen::Vector3d::Zero();  ///< m/s^2, b_a(0)
  Eigen::Matrix3d mag_soft_iron = Eigen::Matrix3d::Identity();   ///< S, symmetric
  Eigen::Vector3d mag_hard_iron = Eigen::Vector3d::Zero();       ///< h in T: config + drawn part
  SensorNoise noise;  ///< the noise terms in use, noise_scale applied
};

/// The errors of config's unit: T_g, T_a, S and the drawn hard iron from random stream 6, the
/// initial biases as simulateInertial draws them (stream 1).
ImuErrors drawImuErrors(const SimulationConfig& config);

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
/// 3: disturbances, 4: image noise, 5: bad input, 6: systematic IMU errors, 7: camera orientation
/// noise).
std::uint64_t streamSeed(std::uint64_t seed, int stream);

}  // namespace simulation
}  // namespace camera_imu_alignment
