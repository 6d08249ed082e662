// Continuous-motion joint problems (estimation/joint_types.h: motion_frames and motion_gyro)
// generated from a known truth, for the tests of the joint estimator's motion nodes and time
// offset: the IMU turns as R_world_imu(t) = R0 Exp(phi(t)), phi a sum of sinusoids per axis
// (smooth, every axis excited, never still); the gyro samples T_g omega(t_i) + b(t_i) + noise at
// their stamps (IMU clock = true time); the camera's orientation at frame stamps t_cam with
// t_true = t_cam + timeshift (Kalibr's sign), with PnP-like noise.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {
namespace test {

struct MotionSimulationOptions {
  double duration_s = 60.0;
  double camera_rate_hz = 20.0, imu_rate_hz = 200.0;
  double timeshift_cam_imu_s = 0.015;
  double amplitude_deg = 20.0;         ///< per sinusoid and axis (two sinusoids per axis)
  double camera_sigma_rad = 3.5e-4;    ///< per axis (0.02 deg)
  double gyro_noise_density = 1.7e-4;  ///< rad/s/sqrt(Hz)
  double gyro_bias_walk = 4e-5;        ///< rad/s/sqrt(s)
  double gyro_bias_max_rad_s = 0.02;   ///< uniform +- per axis (about 1 deg/s)
  double gyro_scale = 0.015, gyro_cross_axis = 0.01;  ///< T_g - I entries, 1-sigma
  bool noise = true;
};

struct MotionSimulation {
  JointProblem problem;  ///< motion frames and gyro only (no rests)
  Eigen::Matrix3d R_cam_imu, T_g;
  double timeshift_cam_imu_s = 0;
};

MotionSimulation simulateMotionProblem(const MotionSimulationOptions& options, uint64_t seed);

}  // namespace test
}  // namespace camera_imu_alignment
