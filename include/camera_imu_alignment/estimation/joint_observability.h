// What the poses of a joint problem tell about the IMU parameters (joint_estimator.h). Nothing is
// decided by geometry: every parameter is estimated with its prior, and afterwards a parameter
// counts as estimated (determined by the data) when the data carry at least as much information
// about each of its entries as its prior does (posterior 1-sigma <= kInformedFraction x prior
// 1-sigma). A parameter that is not gets a note saying that it rests on its prior (its prior
// uncertainty is in R_cam_imu's 1-sigma) and which rotation would add the most.
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

/// Posterior 1-sigma over prior 1-sigma at or below which an entry counts as determined by the
/// data: 1/sqrt(2), the data's information at least the prior's.
constexpr double kInformedFraction = 0.70710678118654752;

/// True when every entry of `posterior_sigma` is at most kInformedFraction of `prior_sigma`'s
/// (entries with a zero prior are skipped); false for empty or mismatched vectors.
bool informedByTheData(const Eigen::VectorXd& posterior_sigma, const Eigen::VectorXd& prior_sigma);

/// What is estimated (JointSettings): before the solve every parameter the model has, all true
/// (the magnetometer used per JointSettings::use_magnetometer); with pin_unexcited_parameters the
/// second solve's copy marks the parameters a first solve found undetermined, which are held.
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
  /// The rotation that would add the most: the least-excited gyro axis (IMU frame, unit), and
  /// an axis perpendicular to the mean gravity direction (the least excited among those).
  Eigen::Vector3d least_excited_axis_imu = Eigen::Vector3d::UnitX();
  Eigen::Vector3d perpendicular_to_gravity_imu = Eigen::Vector3d::UnitX();
  Eigen::Vector3d suggested_rotation_axis_imu = Eigen::Vector3d::UnitX();
  std::vector<std::string> notes;
};

/// What the problem's model has (every parameter estimated; the magnetometer per the settings and
/// the usable fields), with the geometry of the poses for the notes and the suggestion.
JointObservability decideObservability(const JointProblem& problem, const GyroExcitation& gyro,
                                       const JointSettings& settings);

struct JointResult;

/// After the solve: a note for each IMU parameter the data did not determine (its
/// ImuIntrinsics::*_estimated false), saying that it rests on its prior (held, with
/// pin_unexcited_parameters), and the suggested rotation; sets
/// result->suggested_rotation_axis_imu.
void describeInformation(const JointObservability& observability, const JointSettings& settings,
                         JointResult* result);

}  // namespace camera_imu_alignment
