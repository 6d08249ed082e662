#include "camera_imu_alignment/simulation/imu_grades.h"

#include "camera_imu_alignment/simulation/sim_config.h"

namespace camera_imu_alignment {
namespace simulation {

// clang-format off
// Datasheet table. Each number is 1 sigma per entry or per axis: a datasheet's "typical +-x" is
// taken as 1 sigma (Bosch Sensortec states that its typical values are; InvenSense gives no
// statistic). [J] marks a judgement, not a datasheet number; letters point to the sources below.
//
// | term                     | tactical          | consumer            | noisy              |
// |--------------------------|-------------------|---------------------|--------------------|
// | gyro noise, rad/s/rtHz   | 2.6e-5 (a)        | 2.6e-4 (c)          | 4e-3 [J] (j1, m)   |
// | gyro bias walk, /s       | 5e-7 [J] (b)      | 4e-5 [J]            | 2e-4 [J]           |
// | gyro initial bias        | 0.1 deg/s [J]     | 1 deg/s (i, d)      | 3 deg/s (m)        |
// | gyro scale, T_g diagonal | 0.1 % [J]         | 1.5 % (i, c)        | 3 % (m)            |
// | gyro cross-axis, T_g off | 0.05 deg (a)      | 1 % (i, c2)         | 2 % (m)            |
// | accel noise, m/s^2/rtHz  | 2e-4 [J]          | 2.26e-3 (c)         | 0.02 [J] (j2, n)   |
// | accel bias walk, /s      | 4e-6 [J] (b)      | 6e-4 [J]            | 2e-3 [J]           |
// | accel initial bias       | 2 mg [J]          | 0.2 m/s^2 (i, c3)   | 0.6 m/s^2 (n)      |
// | accel scale, T_a diag.   | 0.1 % [J]         | 1 % (i, c4)         | 3 % (n)            |
// | accel non-orthogonality  | 0.05 deg [J] (a)  | 1 % (i, c2)         | 2 % (n)            |
// | mag hard iron, per axis  | 2 uT [J]          | 15 uT (i, k)        | 40 uT [J]          |
// | mag soft iron, S - I     | 1 % [J]           | 5 % (i)             | 10 % [J]           |
// | mag noise, per sample    | 0.3 uT [J]        | 0.6 uT [J] (k)      | 1.5 uT [J]         |
//
// (a) Analog Devices ADIS16495 data sheet Rev. C, features: angular random walk 0.09 deg/sqrt(h)
//     (ADIS16495-1) = 0.0015 deg/s/sqrt(Hz); axis-to-axis misalignment +-0.05 deg (gyro; used for
//     the accelerometer too as a judgement). The ADIS16495 has no magnetometer: a separate,
//     calibrated one is assumed [J].
// (b) ADIS16495: in-run bias stability 0.8 deg/h (gyro), 3.2 ug (accel); the walks are chosen so
//     that the drift over 100 s is of that order [J].
// (c) TDK InvenSense ICM-20948, DS-000189 rev 1.3: gyro rate noise 0.015 deg/s/sqrt(Hz) and
//     sensitivity tolerance +-1.5 % (Table 1); accel noise 230 ug/sqrt(Hz) (Table 2).
// (c2) ICM-20948 cross-axis sensitivity +-2 % (Tables 1, 2); the 1 % per entry is used.
// (c3) ICM-20948 Table 2: zero-g output +-25 mg component level, +-50 mg board level.
// (c4) ICM-20948 Table 2: accel sensitivity tolerance +-0.5 % component level; 1 % on a board is
//     the number.
// (d) Bosch Sensortec BMI088 (BST-BMI088-DS001): typical gyro zero-rate offset +-1 deg/s, as
//     Bosch's support confirms; the ICM-20948's board-level ZRO is +-5 deg/s.
// (i) The consumer reference numbers of the issue that asked for the grades.
// (k) ICM-20948 Table 3 (AK09916): zero-field output +-2000 LSB x 0.15 uT = +-300 uT before any
//     calibration; 15 uT is the residual for a mounted unit; 0.6 uT noise = 4 LSB [J].
// (m) InvenSense MPU-6050 (PS-MPU-6000A-00 rev 3.4, gyro table): scale +-3 %, cross-axis +-2 %,
//     initial ZRO +-20 deg/s, 0.005 deg/s/sqrt(Hz); MPU-9250 (PS-MPU-9250A-01 rev 1.0, Table 1):
//     scale +-3 %, cross-axis +-2 %, initial ZRO +-5 deg/s, 0.01 deg/s/sqrt(Hz).
// (n) MPU-9250 Table 2: accel sensitivity +-3 %, cross-axis +-2 %, zero-g +-60 mg (x, y) and
//     +-80 mg (z), noise 300 ug/sqrt(Hz).
// (j1) The datasheets' 0.005-0.01 deg/s/sqrt(Hz) raised 25-45x by a vibrating mount [J].
// (j2) 300 ug/sqrt(Hz) raised ~7x by the same vibration [J].
// clang-format on

namespace {

constexpr double kDegPerS = 3.14159265358979323846 / 180.0;  // rad/s per deg/s
constexpr double kG = 9.80665;                               // m/s^2 per g
constexpr double kMicroTesla = 1e-6;

ImuGradeSpec tactical() {
  ImuGradeSpec s;
  SensorNoise& n = s.noise;
  n.gyroscope_noise_density = 0.09 / 60.0 * kDegPerS;  // 0.09 deg/sqrt(h) = 2.6e-5 rad/s/sqrt(Hz)
  n.gyroscope_random_walk = 5e-7;
  n.gyroscope_initial_bias_sigma = 0.1 * kDegPerS;
  n.accelerometer_noise_density = 2e-4;
  n.accelerometer_random_walk = 4e-6;
  n.accelerometer_initial_bias_sigma = 2e-3 * kG;
  n.magnetometer_noise_sigma = 0.3 * kMicroTesla;
  ImuSystematicSigmas& e = s.systematic;
  e.gyro_scale_sigma = 0.001;
  e.gyro_cross_axis_sigma = 0.05 * kDegPerS;  // 0.05 deg = 8.7e-4 rad
  e.accel_scale_sigma = 0.001;
  e.accel_cross_axis_sigma = 0.05 * kDegPerS;
  e.mag_hard_iron_sigma = 2.0 * kMicroTesla;
  e.mag_soft_iron_sigma = 0.01;
  return s;
}

ImuGradeSpec consumer() {
  ImuGradeSpec s;
  SensorNoise& n = s.noise;
  n.gyroscope_noise_density = 0.015 * kDegPerS;  // 2.6e-4 rad/s/sqrt(Hz)
  n.gyroscope_random_walk = 4e-5;
  n.gyroscope_initial_bias_sigma = 1.0 * kDegPerS;
  n.accelerometer_noise_density = 230e-6 * kG;  // 2.3e-3 m/s^2/sqrt(Hz)
  n.accelerometer_random_walk = 6e-4;
  n.accelerometer_initial_bias_sigma = 0.2;
  n.magnetometer_noise_sigma = 0.6 * kMicroTesla;
  ImuSystematicSigmas& e = s.systematic;
  e.gyro_scale_sigma = 0.015;
  e.gyro_cross_axis_sigma = 0.01;
  e.accel_scale_sigma = 0.01;
  e.accel_cross_axis_sigma = 0.01;
  e.mag_hard_iron_sigma = 15.0 * kMicroTesla;
  e.mag_soft_iron_sigma = 0.05;
  return s;
}

ImuGradeSpec noisy() {
  ImuGradeSpec s;
  SensorNoise& n = s.noise;
  n.gyroscope_noise_density = 0.004;
  n.gyroscope_random_walk = 2e-4;
  n.gyroscope_initial_bias_sigma = 3.0 * kDegPerS;
  n.accelerometer_noise_density = 0.02;
  n.accelerometer_random_walk = 2e-3;
  n.accelerometer_initial_bias_sigma = 0.6;
  n.magnetometer_noise_sigma = 1.5 * kMicroTesla;
  ImuSystematicSigmas& e = s.systematic;
  e.gyro_scale_sigma = 0.03;
  e.gyro_cross_axis_sigma = 0.02;
  e.accel_scale_sigma = 0.03;
  e.accel_cross_axis_sigma = 0.02;
  e.mag_hard_iron_sigma = 40.0 * kMicroTesla;
  e.mag_soft_iron_sigma = 0.10;
  return s;
}

}  // namespace

const std::vector<std::pair<std::string, std::string>>& imuGradeList() {
  static const std::vector<std::pair<std::string, std::string>> list = {
      {"ideal", "white noise, bias and bias walk only; no scale, misalignment or iron errors"},
      {"tactical", "ADIS16495-1 class: 0.09 deg/sqrt(h), 0.05 deg axis misalignment, 0.1 % scale"},
      {"consumer",
       "ICM-20948/BMI088 class: gyro bias 1 deg/s, scale 1.5 %, cross-axis 1 %, "
       "accel bias 0.2 m/s^2, hard iron 15 uT, soft iron 5 %"},
      {"noisy",
       "MPU-6050/MPU-9250 on a vibrating mount: gyro 0.004 rad/s/sqrt(Hz), bias 3 deg/s, "
       "scale 3 %, cross-axis 2 %, accel bias 0.6 m/s^2, hard iron 40 uT"},
  };
  return list;
}

const char* toString(ImuGrade grade) {
  switch (grade) {
    case ImuGrade::kTactical:
      return "tactical";
    case ImuGrade::kConsumer:
      return "consumer";
    case ImuGrade::kNoisy:
      return "noisy";
    default:
      return "ideal";
  }
}

bool parseImuGrade(const std::string& name, ImuGrade* grade) {
  for (ImuGrade g :
       {ImuGrade::kIdeal, ImuGrade::kTactical, ImuGrade::kConsumer, ImuGrade::kNoisy}) {
    if (name == toString(g)) {
      *grade = g;
      return true;
    }
  }
  return false;
}

ImuGradeSpec imuGradeSpec(ImuGrade grade) {
  switch (grade) {
    case ImuGrade::kTactical:
      return tactical();
    case ImuGrade::kConsumer:
      return consumer();
    case ImuGrade::kNoisy:
      return noisy();
    default:
      return ImuGradeSpec();  // the SensorNoise defaults, no systematic errors
  }
}

void applyImuGrade(ImuGrade grade, SimulationConfig* config) {
  const ImuGradeSpec spec = imuGradeSpec(grade);
  config->imu_grade = grade;
  config->imu_noise = spec.noise;
  config->imu_systematic = spec.systematic;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
