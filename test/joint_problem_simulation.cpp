#include "joint_problem_simulation.h"

#include <cmath>
#include <random>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace test {
namespace {

class Random {
 public:
  explicit Random(uint64_t seed) : rng_(seed) {}
  double normal() { return normal_(rng_); }
  double uniform(double a, double b) { return a + (b - a) * uniform_(rng_); }
  Eigen::Vector3d normal3() { return Eigen::Vector3d(normal(), normal(), normal()); }
  Eigen::Vector3d unitVector() {
    Eigen::Vector3d v;
    do {
      v = normal3();
    } while (v.norm() < 1e-6);
    return v.normalized();
  }
  Eigen::Matrix3d rotation() {
    return uniformRotation(uniform(0.0, 1.0), uniform(0.0, 1.0), uniform(0.0, 1.0));
  }

 private:
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
};

/// Minimum-jerk profile: 0 -> 1 over tau in [0, 1] with zero rate and acceleration at both ends.
double minimumJerk(double tau) { return tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau); }

}  // namespace

Eigen::Matrix3d perturbedRotation(const Eigen::Matrix3d& R, double angle_rad, uint64_t seed) {
  Random random(seed);
  return expSO3(angle_rad * random.unitVector()) * R;
}

Eigen::Vector3d rotationError(const Eigen::Matrix3d& R_est, const Eigen::Matrix3d& R_true) {
  return logSO3(R_est * R_true.transpose());
}

JointSimulation simulateJointProblem(const JointSimulationOptions& o, uint64_t seed) {
  Random random(seed);
  JointSimulation sim;
  sim.R_cam_imu = random.rotation();
  sim.R_world_target = random.rotation();

  // Systematic errors of this unit.
  sim.T_g = Eigen::Matrix3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      sim.T_g(r, c) += (r == c ? o.gyro_scale : o.gyro_cross_axis) * random.normal();
    }
  }
  sim.T_a = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) sim.T_a(i, i) += o.accel_scale * random.normal();
  const double kyx = o.accel_cross_axis * random.normal(),
               kzx = o.accel_cross_axis * random.normal(),
               kzy = o.accel_cross_axis * random.normal();
  sim.T_a(1, 0) = kyx;
  sim.T_a(2, 0) = kzx;
  sim.T_a(2, 1) = kzy;
  if (o.accel_matrix_form == AccelMatrixForm::kSymmetric) {
    sim.T_a(0, 1) = kyx;
    sim.T_a(0, 2) = kzx;
    sim.T_a(1, 2) = kzy;
  }
  sim.accel_bias_m_s2 = o.accel_bias_m_s2 * random.normal3();
  if (o.soft_iron_isotropic) {
    sim.soft_iron = (1.0 + o.soft_iron * random.normal()) * Eigen::Matrix3d::Identity();
  } else {
    Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = r; c < 3; ++c) {
        const double e = o.soft_iron * random.normal();
        S(r, c) += e;
        if (c != r) S(c, r) = e;
      }
    }
    sim.soft_iron = S;
  }
  sim.hard_iron_t = o.hard_iron_t * random.normal3();
  const Eigen::Vector3d field_world(0.0, o.field_t * std::cos(o.dip_rad),
                                    -o.field_t * std::sin(o.dip_rad));

  // Orientations: each motion a rotation about one IMU axis.
  const int n = o.num_poses;
  std::vector<Eigen::Vector3d> motion_rotvec(n, Eigen::Vector3d::Zero());  // into pose k + 1
  sim.R_world_imu.resize(n);
  sim.R_world_imu[0] = random.rotation();
  if (o.initial_R_world_imu) sim.R_world_imu[0] = *o.initial_R_world_imu;
  for (int k = 1; k < n; ++k) {
    if (static_cast<int>(o.motions_imu_rad.size()) == n - 1) {
      motion_rotvec[k - 1] = o.motions_imu_rad[k - 1];
      sim.R_world_imu[k] = sim.R_world_imu[k - 1] * expSO3(motion_rotvec[k - 1]);
      continue;
    }
    Eigen::Vector3d axis = random.unitVector();
    if (o.rotation_axis_imu) axis = o.rotation_axis_imu->normalized();
    if (o.vertical_rotations_only) axis = sim.R_world_imu[k - 1].transpose().col(2);
    const double sign = random.uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0;
    const double angle = sign * deg2rad(random.uniform(o.min_rotation_deg, o.max_rotation_deg));
    motion_rotvec[k - 1] = angle * axis;
    sim.R_world_imu[k] = sim.R_world_imu[k - 1] * expSO3(motion_rotvec[k - 1]);
  }

  // Timeline and gyro bias: per rest a level (ramped linearly during the motions) plus a walk.
  const bool noise = o.noise;
  const double walk_step = noise ? o.gyro_bias_walk / std::sqrt(o.rate_hz) : 0.0;
  const int rest_samples = static_cast<int>(std::lround(o.rest_s * o.rate_hz));
  const int motion_samples = static_cast<int>(std::lround(o.motion_s * o.rate_hz));
  const double period = 1.0 / o.rate_hz;
  const double gyro_sample_sigma = o.gyro_noise_density * std::sqrt(o.rate_hz);
  auto group_of = [&](int k) { return k * o.groups / n; };
  std::vector<Eigen::Vector3d> level(n);
  for (int k = 0; k < n; ++k) {
    const bool new_group = k == 0 || group_of(k) != group_of(k - 1);
    level[k] = new_group
                   ? Eigen::Vector3d(random.uniform(-1.0, 1.0), random.uniform(-1.0, 1.0),
                                     random.uniform(-1.0, 1.0)) *
                         o.gyro_bias_max_rad_s
                   : Eigen::Vector3d(level[k - 1] + o.gyro_bias_step_rad_s * random.normal3());
  }
  Eigen::Vector3d walk = Eigen::Vector3d::Zero();
  // The accelerometer bias walks through rests and motions alike, from the first rest's bias.
  Random accel_random(seed ^ 0x5eedacce1ULL);
  const double accel_walk_step = noise ? o.accel_bias_walk / std::sqrt(o.rate_hz) : 0.0;
  Eigen::Vector3d accel_bias = sim.accel_bias_m_s2;
  auto walkAccelBias = [&](int samples) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int i = 0; i < samples; ++i) {
      if (accel_walk_step > 0.0) accel_bias += accel_walk_step * accel_random.normal3();
      sum += accel_bias;
    }
    return Eigen::Vector3d(sum / std::max(samples, 1));
  };
  double t = 100.0;
  const Eigen::Matrix3d& X = sim.R_cam_imu;
  for (int k = 0; k < n; ++k) {
    if (k > 0 && group_of(k) != group_of(k - 1)) {
      t += 10.0;  // a new recording
      walk.setZero();
    }
    JointPose pose;
    pose.group = group_of(k);
    pose.start_s = t;
    pose.end_s = t + rest_samples * period;
    const Eigen::Matrix3d& R = sim.R_world_imu[k];

    // Rest: gyro bias mean over the rest samples, accelerometer, magnetometer, camera.
    Eigen::Vector3d bias_sum = Eigen::Vector3d::Zero();
    for (int i = 0; i < rest_samples; ++i) {
      walk += walk_step * random.normal3();
      bias_sum += level[k] + walk;
    }
    sim.gyro_bias_rest_mean.push_back(bias_sum / rest_samples);
    const double mean_scale = 1.0 / std::sqrt(static_cast<double>(rest_samples));
    const double gyro_mean_sigma = gyro_sample_sigma * mean_scale;
    pose.gyro_mean_rad_s = sim.gyro_bias_rest_mean.back();
    if (noise) pose.gyro_mean_rad_s += gyro_mean_sigma * random.normal3();
    pose.gyro_mean_cov = gyro_mean_sigma * gyro_mean_sigma * Eigen::Matrix3d::Identity();

    const double accel_mean_sigma = o.accel_noise_m_s2 * mean_scale;
    sim.accel_bias_rest_mean.push_back(walkAccelBias(rest_samples));
    if (k == 0) sim.accel_bias_m_s2 = sim.accel_bias_rest_mean[0];
    pose.accel_mean_m_s2 = sim.T_a * R.transpose() * Eigen::Vector3d(0.0, 0.0, o.gravity_m_s2) +
                           sim.accel_bias_rest_mean.back();
    if (noise) pose.accel_mean_m_s2 += accel_mean_sigma * random.normal3();
    pose.accel_mean_cov = accel_mean_sigma * accel_mean_sigma * Eigen::Matrix3d::Identity();

    const bool mag_usable =
        o.with_magnetometer && !(o.unusable_mag_every > 0 && k % o.unusable_mag_every == 0);
    if (mag_usable) {
      const double mag_mean_sigma = o.mag_noise_t * mean_scale;
      Eigen::Vector3d m = sim.soft_iron * (R.transpose() * field_world) + sim.hard_iron_t;
      if (noise) m += mag_mean_sigma * random.normal3();
      pose.mag_mean_t = m;
      pose.mag_mean_cov = mag_mean_sigma * mag_mean_sigma * Eigen::Matrix3d::Identity();
    }

    const Eigen::Matrix3d R_target_cam = sim.R_world_target.transpose() * R * X.transpose();
    pose.R_target_cam =
        noise ? Eigen::Matrix3d(R_target_cam * expSO3(o.camera_sigma_rad * random.normal3()))
              : R_target_cam;
    pose.cov_cam_rad2 = o.camera_sigma_rad * o.camera_sigma_rad * Eigen::Matrix3d::Identity();
    sim.problem.poses.push_back(pose);
    t = pose.end_s;

    // Motion to the next pose (same group): minimum-jerk rotation about one IMU axis.
    if (k + 1 < n) {
      const bool joined = group_of(k + 1) == group_of(k);
      GyroSegment segment;
      segment.from_pose = k;
      segment.to_pose = k + 1;
      segment.noise_density_rad_s_sqrt_hz = o.gyro_noise_density;
      const double motion_end = t + motion_samples * period;
      for (int i = 0; i < motion_samples; ++i) {
        const double t_i = t + i * period;
        walk += walk_step * random.normal3();
        const double s = (t_i - t) / (motion_end - t);
        const Eigen::Vector3d bias = level[k] + s * (level[k + 1] - level[k]) + walk;
        const double fraction = minimumJerk(static_cast<double>(i + 1) / motion_samples) -
                                minimumJerk(static_cast<double>(i) / motion_samples);
        const Eigen::Vector3d rate = motion_rotvec[k] * (fraction * o.rate_hz);
        Eigen::Vector3d w = sim.T_g * rate + bias;
        if (noise) w += gyro_sample_sigma * random.normal3();
        segment.stamps_s.push_back(t_i);
        segment.gyro_rad_s.push_back(w);
      }
      if (joined && o.with_gyro) sim.problem.segments.push_back(std::move(segment));
      walkAccelBias(motion_samples + (joined ? 0 : static_cast<int>(10.0 * o.rate_hz)));
      t = motion_end;
    }
  }
  return sim;
}

}  // namespace test
}  // namespace camera_imu_alignment
