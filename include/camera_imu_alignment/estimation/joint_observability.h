// Which IMU parameters the poses of a joint problem excite (joint_estimator.h). Parameters that are
// not excited are not estimated (JointSettings::pin_unexcited_parameters says how they are held);
// the decisions come from the data with the thresholds of JointSettings, and each parameter not
// estimated gets a note saying how to excite it.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {

/// Coverage of unit directions: sqrt of the smallest eigenvalue of mean(u u^T) (dimensionless, 0
/// when all lie along one line, 1/sqrt(3) ~ 0.58 for directions filling the sphere evenly);
/// `least_covered_direction` (unit) may be null. 0 for no directions.
double directionCoverage(const std::vector<Eigen::Vector3d>& unit_directions,
                         Eigen::Vector3d* least_covered_direction = nullptr);

/// Spread of unit directions about their mean: sqrt of the smallest eigenvalue of their covariance
/// (0 for fewer than 4 directions, which always lie in a plane). `least_spread_direction` may be
/// null.
double directionSpread(const std::vector<Eigen::Vector3d>& unit_directions,
                       Eigen::Vector3d* least_spread_direction = nullptr);

/// What the motions excite, summed over the gyro segments' net rotations phi = Log(DeltaR) (IMU
/// frame, from the bias-corrected gyro; net rather than sum |w| dt, which would add up the noise).
struct GyroExcitation {
  bool has_segments = false;
  Eigen::Vector3d accumulated_abs_angle_rad = Eigen::Vector3d::Zero();  ///< sum |phi_j| per axis
  Eigen::Matrix3d excitation_rad = Eigen::Matrix3d::Zero();             ///< sum phi phi^T / |phi|
};

struct JointObservability {
  std::array<bool, 3> gyro_column_estimated = {false, false, false};  ///< columns of T_g
  Eigen::Vector3d gyro_axis_rotation_deg = Eigen::Vector3d::Zero();   ///< accumulated, per axis
  double gravity_coverage = 0;  ///< directionCoverage of the accelerometer directions
  double gravity_spread = 0;    ///< directionSpread of the accelerometer directions
  bool accel_bias_estimated = false;
  bool accel_matrix_estimated = false;
  int usable_mag_poses = 0;
  double mag_coverage = 0;  ///< directionCoverage of the usable fields
  double mag_spread = 0;    ///< directionSpread of the usable fields
  bool magnetometer_used = false;
  bool hard_iron_estimated = false;
  bool soft_iron_estimated = false;
  Eigen::Vector3d suggested_rotation_axis_imu = Eigen::Vector3d::UnitX();
  std::vector<std::string> notes;
};

/// Decides from the poses' accelerometer and magnetometer means and the gyro excitation.
JointObservability decideObservability(const JointProblem& problem, const GyroExcitation& gyro,
                                       const JointSettings& settings);

}  // namespace camera_imu_alignment
