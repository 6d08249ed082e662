#include "camera_imu_alignment/io/joint_yaml.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

template <typename Derived>
std::string flow(const Eigen::MatrixBase<Derived>& m) {
  std::ostringstream out;
  out << std::setprecision(9);
  if (m.cols() == 1) {
    out << "[";
    for (int i = 0; i < m.rows(); ++i) out << (i ? ", " : "") << m(i);
    out << "]";
    return out.str();
  }
  out << "[";
  for (int i = 0; i < m.rows(); ++i) {
    out << (i ? ", " : "") << "[";
    for (int k = 0; k < m.cols(); ++k) out << (k ? ", " : "") << m(i, k);
    out << "]";
  }
  out << "]";
  return out.str();
}

const char* boolText(bool b) { return b ? "true" : "false"; }

}  // namespace

const char* dataUsed(const JointResult& j) {
  if (j.motion_nodes > 0) return j.rests_used > 0 ? "both" : "motion";
  return "rests";
}

std::string jointToYaml(const JointResult& j) {
  std::ostringstream out;
  out << std::setprecision(9);
  out << "joint:  # one maximum-likelihood estimate from camera, gravity, field and raw gyro\n";
  out << "  ok: " << boolText(j.ok) << "\n";
  out << "  message: " << quoted(j.message) << "\n";
  out << "  chi2: " << j.chi2 << "\n";
  out << "  dof: " << j.dof << "\n";
  out << "  chi2_p_value: " << j.chi2_p_value << "\n";
  out << "  misfit_ratio: " << j.misfitRatio()
      << "  # sqrt(chi2/dof): residuals over their noise\n";
  out << "  misfit_band: " << misfitBand(j.misfitRatio()) << "\n";
  out << "  consistent: " << boolText(j.consistent())
      << "  # chi-square p >= consistency_level, or misfit_ratio <= " << kConsistentMisfitRatio
      << "\n";
  out << "  measured_noise:  # the recording's noise per kind (variance components)\n";
  for (int k = 0; k < kNoiseKinds; ++k) {
    const auto kind = static_cast<NoiseKind>(k);
    if (!(j.noise.stated[static_cast<size_t>(k)] > 0.0)) continue;
    out << "    " << toString(kind) << ": {stated: " << j.noise.stated[static_cast<size_t>(k)]
        << ", measured: " << j.noise.measured(kind)
        << ", learned: " << boolText(j.noise.learned[static_cast<size_t>(k)])
        << ", redundancy: " << j.noise.redundancy[static_cast<size_t>(k)] << "}\n";
  }
  out << "  consistency_level: " << j.consistency_level << "\n";
  out << "  covariance_scale: " << j.covariance_scale << "  # chi2/dof when > 1, applied\n";
  out << "  camera_excess_sigma_deg: " << rad2deg(std::sqrt(j.camera_excess_variance_rad2))
      << "  # added to each rest's camera 1-sigma per axis (its noise as measured); 0: none\n";
  out << "  scene_link_excess_sigma_deg: " << rad2deg(std::sqrt(j.camera_link_excess_variance_rad2))
      << "  # added to each natural-scene rotation's 1-sigma per axis; 0: none\n";
  out << "  std_dev_deg: " << flow(j.std_dev_deg) << "  # 1-sigma about the camera x, y, z axes\n";
  out << "  data_used: " << dataUsed(j) << "  # rests, motion or both\n";
  out << "  rests: " << j.rests_used << "\n";
  out << "  motion_nodes: " << j.motion_nodes << "\n";
  if (j.timeshift_estimated) {
    out << "  timeshift_cam_imu_s: " << j.timeshift_cam_imu_s
        << "  # Kalibr's sign: t_imu = t_cam + timeshift_cam_imu_s\n";
    out << "  timeshift_cam_imu_sigma_s: " << j.timeshift_sigma_s << "\n";
  }
  out << "  iterations: " << j.iterations << "\n";
  out << "  solve_time_s: " << j.solve_time_s << "\n";
  out << "  pose_residual_norm: "
      << flow(Eigen::Map<const Eigen::VectorXd>(
             j.pose_residual_norm.data(), static_cast<Eigen::Index>(j.pose_residual_norm.size())))
      << "  # per pose, sigma units\n";
  out << "  suggested_rotation_axis_imu: " << flow(j.suggested_rotation_axis_imu) << "\n";
  out << "  notes:";
  for (const std::string& note : j.notes) out << "\n    - " << quoted(note);
  out << (j.notes.empty() ? " []\n" : "\n");
  const ImuIntrinsics& i = j.intrinsics;
  out << "imu_intrinsics:  # w_meas = T_g w + b_g; a_meas = T_a f + b_a; m_meas = S m + h (IMU "
         "frame = accelerometer axes)\n";
  out << "  gyro_matrix: {value: " << flow(i.gyro_matrix)
      << ", sigma: " << flow(i.gyro_matrix_sigma) << ", estimated_columns: ["
      << boolText(i.gyro_matrix_column_estimated[0]) << ", "
      << boolText(i.gyro_matrix_column_estimated[1]) << ", "
      << boolText(i.gyro_matrix_column_estimated[2]) << "]}\n";
  out << "  gyro_bias_rad_s: {value: " << flow(i.gyro_bias_rad_s)
      << ", sigma: " << flow(i.gyro_bias_sigma_rad_s) << "}  # at the first pose\n";
  out << "  accel_matrix: {value: " << flow(i.accel_matrix)
      << ", sigma: " << flow(i.accel_matrix_sigma)
      << ", estimated: " << boolText(i.accel_matrix_estimated) << "}\n";
  out << "  accel_bias_m_s2: {value: " << flow(i.accel_bias_m_s2)
      << ", sigma: " << flow(i.accel_bias_sigma_m_s2)
      << ", estimated: " << boolText(i.accel_bias_estimated) << "}  # at the first pose\n";
  out << "  accel_bias_per_pose_m_s2: [";
  for (size_t k = 0; k < i.accel_bias_per_pose_m_s2.size(); ++k) {
    out << (k ? ", " : "") << flow(i.accel_bias_per_pose_m_s2[k]);
  }
  out << "]  # the bias walks: one per pose, in pose order\n";
  out << "  magnetometer_used: " << boolText(i.magnetometer_used) << "\n";
  out << "  soft_iron: {value: " << flow(i.soft_iron) << ", sigma: " << flow(i.soft_iron_sigma)
      << ", estimated: " << boolText(i.soft_iron_estimated) << "}\n";
  out << "  hard_iron_t: {value: " << flow(i.hard_iron_t)
      << ", sigma: " << flow(i.hard_iron_sigma_t)
      << ", estimated: " << boolText(i.hard_iron_estimated) << "}\n";
  return out.str();
}

std::string kalibrImuYaml(const JointResult& j, double gyro_noise_density_rad_s_sqrt_hz,
                          double accel_noise_density_m_s2_sqrt_hz, double update_rate_hz,
                          const std::string& rostopic) {
  // Each density: as the recording's residuals measured it (variance components), else the
  // scatter at the rests, else the noise the estimate was given (never 0).
  const auto pick = [&](NoiseKind kind, double at_rests, double fallback, std::string* source) {
    const auto k = static_cast<size_t>(kind);
    if (j.noise.learned[k] && j.noise.stated[k] > 0.0) {
      *source = "measured on the recording (variance components)";
      return j.noise.measured(kind);
    }
    if (at_rests > 0.0) {
      *source = "the scatter at the rests";
      return at_rests;
    }
    *source = j.noise.stated[k] > 0.0 ? "as stated (not measured by this recording)"
                                      : "a MEMS default (not measured by this recording)";
    return j.noise.stated[k] > 0.0 ? j.noise.stated[k] : fallback;
  };
  std::string source[4];
  const double accel_white =
      pick(NoiseKind::kAccelWhite, accel_noise_density_m_s2_sqrt_hz, 2.0e-3, &source[0]);
  const double accel_walk = pick(NoiseKind::kAccelWalk, 0.0, 2.0e-4, &source[1]);
  const double gyro_white =
      pick(NoiseKind::kGyroWhite, gyro_noise_density_rad_s_sqrt_hz, 1.7e-4, &source[2]);
  const double gyro_walk = pick(NoiseKind::kGyroWalk, 0.0, 4.0e-6, &source[3]);
  std::ostringstream out;
  out << std::setprecision(6);
  out << "# Kalibr imu.yaml. Extra keys: the intrinsics of camera_imu_alignment's joint "
         "estimate.\n";
  out << "accelerometer_noise_density: " << accel_white << "  # m/s^2/sqrt(Hz), " << source[0]
      << "\n";
  out << "accelerometer_random_walk: " << accel_walk << "  # m/s^3/sqrt(Hz), " << source[1] << "\n";
  out << "gyroscope_noise_density: " << gyro_white << "  # rad/s/sqrt(Hz), " << source[2] << "\n";
  out << "gyroscope_random_walk: " << gyro_walk << "  # rad/s^2/sqrt(Hz), " << source[3] << "\n";
  out << "rostopic: " << rostopic << "\n";
  out << "update_rate: " << update_rate_hz << "  # Hz\n";
  out << std::setprecision(9);
  out << jointToYaml(j);
  return out.str();
}

}  // namespace camera_imu_alignment
