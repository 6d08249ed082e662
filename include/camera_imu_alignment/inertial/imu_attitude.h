// IMU orientation at rest (accelerometer + magnetometer) and gyro integration between rests.
//
// World frame: ENU (REP-103): x east, y north, z up. At rest the accelerometer measures the
// specific force, which points up: accel_imu = R_world_imu^T * (0, 0, +g). The magnetometer's
// horizontal component points to magnetic north (declination is ignored: the calibration only
// uses relative rotations, in which a constant heading offset cancels).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "camera_imu_alignment/inertial/inertial_samples.h"

namespace camera_imu_alignment {

/// Orientation from gravity and the magnetic field.
struct AttitudeFromVectors {
  Eigen::Matrix3d R_world_imu = Eigen::Matrix3d::Identity();  ///< ENU
  double dip_deg = 0.0;       ///< magnetic inclination (below horizontal: positive in the north)
  double field_norm_t = 0.0;  ///< |field| (T)
  bool valid = false;         ///< false when a vector is zero/non-finite or they are parallel
};

/// Davenport q-method (weighted, optimal in the Wahba sense) on two observations: up (the
/// normalised accelerometer, weight accel_weight) and magnetic north (the field's component
/// perpendicular to the measured up, normalised, weight 1 - accel_weight). With this choice the
/// magnetometer cannot tilt the estimate: roll and pitch come from gravity alone and the field
/// only sets the heading, so a disturbed field spoils the yaw only.
AttitudeFromVectors attitudeFromAccelMag(const Eigen::Vector3d& accel_m_s2,
                                         const Eigen::Vector3d& field_t, double accel_weight = 0.9);

/// Roll and pitch from the accelerometer alone, heading (yaw) zero: for poses without a usable
/// magnetometer (the heading must then come from the gyro).
Eigen::Matrix3d attitudeFromAccel(const Eigen::Vector3d& accel_m_s2);

/// Integrates bias-corrected gyro samples on SO(3) from t_begin_s to t_end_s (s) and returns
/// R_imu_begin_imu_end (maps vectors of the IMU frame at t_end into the IMU frame at t_begin; as
/// B = R_world_imu_k^T R_world_imu_t with k = begin, t = end). Samples must be in stamp order;
/// each interval between samples uses the midpoint of the two rates; the ends are clipped to
/// [t_begin_s, t_end_s]. `max_gap_s`: a larger gap between samples inside the span makes the
/// integration fail (returns false) because the rotation over the gap is unknown.
bool integrateGyro(const std::vector<ImuSample>& samples, const Eigen::Vector3d& gyro_bias_rad_s,
                   double t_begin_s, double t_end_s, Eigen::Matrix3d* R_imu_begin_imu_end,
                   double max_gap_s = 0.1);

}  // namespace camera_imu_alignment
