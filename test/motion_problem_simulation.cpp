#include "motion_problem_simulation.h"

#include <cmath>
#include <random>

#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace test {

MotionSimulation simulateMotionProblem(const MotionSimulationOptions& o, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const auto normal3 = [&] { return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)); };
  constexpr double kPi = 3.14159265358979323846;

  MotionSimulation sim;
  sim.R_cam_imu = uniformRotation(uniform(rng), uniform(rng), uniform(rng));
  const Eigen::Matrix3d R_world_imu0 = uniformRotation(uniform(rng), uniform(rng), uniform(rng));
  const Eigen::Matrix3d R_target_world = uniformRotation(uniform(rng), uniform(rng), uniform(rng));
  sim.T_g = Eigen::Matrix3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      sim.T_g(r, c) += (r == c ? o.gyro_scale : o.gyro_cross_axis) * normal(rng);
    }
  }
  Eigen::Vector3d bias;
  for (int i = 0; i < 3; ++i) bias(i) = o.gyro_bias_max_rad_s * (2.0 * uniform(rng) - 1.0);
  // phi_a(t) = sum_s A sin(2 pi f_as t + p_as): frequencies 0.25-0.7 Hz, incommensurate.
  double frequency[3][2], phase[3][2];
  for (int a = 0; a < 3; ++a) {
    for (int s = 0; s < 2; ++s) {
      frequency[a][s] = 0.25 + 0.45 * uniform(rng);
      phase[a][s] = 2.0 * kPi * uniform(rng);
    }
  }
  const double amplitude = o.amplitude_deg * kPi / 180.0;
  const auto phiAt = [&](double t, Eigen::Vector3d* rate) {
    Eigen::Vector3d phi = Eigen::Vector3d::Zero(), dphi = Eigen::Vector3d::Zero();
    for (int a = 0; a < 3; ++a) {
      for (int s = 0; s < 2; ++s) {
        const double w = 2.0 * kPi * frequency[a][s];
        phi(a) += amplitude * std::sin(w * t + phase[a][s]);
        dphi(a) += amplitude * w * std::cos(w * t + phase[a][s]);
      }
    }
    if (rate) *rate = rightJacobianSO3(phi) * dphi;  // body rate of R0 Exp(phi)
    return phi;
  };
  const double scale = o.noise ? 1.0 : 0.0;
  sim.timeshift_cam_imu_s = o.timeshift_cam_imu_s;
  sim.problem.motion_gyro.noise_density_rad_s_sqrt_hz = o.gyro_noise_density;
  const double imu_dt = 1.0 / o.imu_rate_hz;
  const double sample_sigma = o.gyro_noise_density * std::sqrt(o.imu_rate_hz);
  for (double t = 0.0; t <= o.duration_s + 0.5; t += imu_dt) {
    Eigen::Vector3d rate;
    phiAt(t, &rate);
    sim.problem.motion_gyro.stamps_s.push_back(t);
    sim.problem.motion_gyro.gyro_rad_s.push_back(sim.T_g * rate + bias +
                                                 scale * sample_sigma * normal3());
    bias += scale * o.gyro_bias_walk * std::sqrt(imu_dt) * normal3();
  }
  // Camera frames: t_true = t_cam + timeshift, within the gyro's span.
  for (double t_cam = 0.25; t_cam + o.timeshift_cam_imu_s <= o.duration_s;
       t_cam += 1.0 / o.camera_rate_hz) {
    const double t_true = t_cam + o.timeshift_cam_imu_s;
    const Eigen::Matrix3d R_world_imu = R_world_imu0 * expSO3(phiAt(t_true, nullptr));
    MotionFrame frame;
    frame.stamp_s = t_cam;
    frame.R_target_cam = R_target_world * R_world_imu * sim.R_cam_imu.transpose() *
                         expSO3(scale * o.camera_sigma_rad * normal3());
    frame.cov_cam_rad2 = o.camera_sigma_rad * o.camera_sigma_rad * Eigen::Matrix3d::Identity();
    sim.problem.motion_frames.push_back(frame);
  }
  return sim;
}

}  // namespace test
}  // namespace camera_imu_alignment
