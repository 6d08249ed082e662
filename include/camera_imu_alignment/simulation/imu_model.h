// Inertial/magnetic sensor model for the simulator. Noise parameters in Kalibr's IMU yaml terms:
// white-noise densities (unit / sqrt(Hz)) and bias random walks (unit / s / sqrt(Hz)).
// Frames: world ENU, gravity (0, 0, -9.81) m/s^2; IMU frame as in REP-145 (the accelerometer reads
// +9.81 along the IMU axis that points up when at rest).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "camera_imu_alignment/simulation/rig_trajectory.h"

namespace camera_imu_alignment {
namespace simulation {

struct ImuNoise {
  double gyroscope_noise_density = 1.7e-4;      ///< rad/s/sqrt(Hz) (consumer MEMS)
  double gyroscope_random_walk = 2.0e-5;        ///< rad/s^2/sqrt(Hz)
  double accelerometer_noise_density = 2.0e-3;  ///< m/s^2/sqrt(Hz)
  double accelerometer_random_walk = 3.0e-3;    ///< m/s^3/sqrt(Hz)
  double magnetometer_noise_t = 1.0e-7;         ///< tesla, 1-sigma per axis and sample
  Eigen::Vector3d gyroscope_bias_rad_s = Eigen::Vector3d(0.002, -0.003, 0.001);  ///< initial bias
  Eigen::Vector3d accelerometer_bias_m_s2 = Eigen::Vector3d(0.02, -0.01, 0.03);  ///< initial bias
  Eigen::Vector3d magnetometer_hard_iron_t = Eigen::Vector3d::Zero();  ///< constant offset
  /// Multiplies every noise term and random walk (0: noise-free, biases kept).
  double scale = 1.0;
};

struct ImuSample {
  double t_s = 0.0;
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();      ///< IMU frame
  Eigen::Vector3d accel_m_s2 = Eigen::Vector3d::Zero();      ///< specific force, IMU frame
  Eigen::Vector3d mag_t = Eigen::Vector3d::Zero();           ///< magnetic field, IMU frame (tesla)
  Eigen::Vector3d true_gyro_bias = Eigen::Vector3d::Zero();  ///< truth, for tests
  Eigen::Vector3d true_accel_bias = Eigen::Vector3d::Zero();
};

struct ImuSimulationOptions {
  double rate_hz = 200.0;
  unsigned int seed = 1;
  ImuNoise noise;
  Eigen::Vector3d gravity_world = Eigen::Vector3d(0.0, 0.0, -9.81);           ///< m/s^2
  Eigen::Vector3d earth_field_world_t = Eigen::Vector3d(0.0, 22e-6, -42e-6);  ///< tesla, ENU
};

/// Samples the sensors along the trajectory: gyro = body rate + bias + white noise (bias random
/// walk); accel = R^T (a - g) + bias + noise; mag = R^T field + hard iron + noise.
std::vector<ImuSample> simulateImu(const RigTrajectory& trajectory,
                                   const ImuSimulationOptions& options);

}  // namespace simulation
}  // namespace camera_imu_alignment
