// IMU grades of the simulator: noise terms plus the systematic errors of real units, drawn once per
// seed. Model (IMU frame = the accelerometer's, as in Kalibr; REP-145 specific force):
//   gyro  = T_g w + b_g(t) + n_g
//   accel = T_a f + b_a(t) + n_a,          f = R_world_imu^T (a_world - g_world)
//   mag   = S (R_world_imu^T B_world) + h + n_m
// T_g = I + scale errors on the diagonal + cross-axis/misalignment off the diagonal (all nine
// entries random: the gyro's axes are slightly off the IMU frame). T_a = I + scale errors on the
// diagonal + non-orthogonality below it (lower triangular, no rotation: the accelerometer defines
// the frame). S = I + a random symmetric matrix (soft iron), h = hard iron (T). b_g, b_a start at a
// random value and walk. The numbers of each grade, with their datasheets, are in imu_grades.cpp.
// Units: SI (rad/s, m/s^2, tesla); sigmas are 1-sigma per entry or per axis.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace camera_imu_alignment {
namespace simulation {

struct SimulationConfig;

enum class ImuGrade {
  kIdeal,     ///< white noise, bias and bias walk only (the simulator's original model)
  kTactical,  ///< Analog Devices ADIS16495-1 class, with a separate calibrated magnetometer
  kConsumer,  ///< TDK InvenSense ICM-20948 (+ AK09916) / Bosch BMI088 class
  kNoisy,     ///< InvenSense MPU-6050 / MPU-9250 class on a vibrating mount
};

/// Kalibr imu.yaml noise terms (continuous time) and the initial bias spread, before
/// SimulationConfig::noise_scale. The defaults are the ideal grade.
struct SensorNoise {
  double accelerometer_noise_density = 1.86e-3;    ///< m/s^2/sqrt(Hz)
  double accelerometer_random_walk = 4.33e-4;      ///< m/s^3/sqrt(Hz)
  double gyroscope_noise_density = 1.87e-4;        ///< rad/s/sqrt(Hz)
  double gyroscope_random_walk = 2.66e-5;          ///< rad/s^2/sqrt(Hz)
  double gyroscope_initial_bias_sigma = 5e-3;      ///< rad/s, per axis, drawn once per seed
  double accelerometer_initial_bias_sigma = 0.05;  ///< m/s^2, per axis, drawn once per seed
  double magnetometer_noise_sigma = 0.3e-6;        ///< T per sample, per axis
};

/// Spread of the systematic errors, drawn once per seed (not multiplied by noise_scale). All zero:
/// T_g = T_a = S = I and no drawn hard iron.
struct ImuSystematicSigmas {
  double gyro_scale_sigma = 0.0;        ///< diagonal of T_g - I (fraction)
  double gyro_cross_axis_sigma = 0.0;   ///< each off-diagonal entry of T_g (fraction ~ rad)
  double accel_scale_sigma = 0.0;       ///< diagonal of T_a - I (fraction)
  double accel_cross_axis_sigma = 0.0;  ///< each entry of T_a below the diagonal (fraction ~ rad)
  double mag_hard_iron_sigma = 0.0;     ///< T per axis, added to SimulationConfig::mag_hard_iron
  double mag_soft_iron_sigma = 0.0;     ///< each of the 6 distinct entries of S - I (fraction)
};

struct ImuGradeSpec {
  SensorNoise noise;
  ImuSystematicSigmas systematic;
};

/// Grade names ("ideal", "tactical", "consumer", "noisy") with a one-line description, in order.
const std::vector<std::pair<std::string, std::string>>& imuGradeList();

const char* toString(ImuGrade grade);

/// False (and `grade` untouched) for an unknown name.
bool parseImuGrade(const std::string& name, ImuGrade* grade);

/// The grade's numbers (see the datasheet table in imu_grades.cpp).
ImuGradeSpec imuGradeSpec(ImuGrade grade);

/// Sets config->imu_grade, config->imu_noise and config->imu_systematic from the grade's table.
void applyImuGrade(ImuGrade grade, SimulationConfig* config);

}  // namespace simulation
}  // namespace camera_imu_alignment
