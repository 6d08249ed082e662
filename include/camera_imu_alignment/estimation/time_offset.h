// Coarse camera-IMU time offset from continuous motion, before R_cam_imu is known.
//
// The angle the camera turns between consecutive frames equals the angle the IMU turns over the
// same interval on its own clock, whatever R_cam_imu is (a rotation's angle does not depend on the
// frame it is written in). The search shifts the frames' intervals by each candidate offset and
// compares the camera's angles with |integral of the gyro| over the shifted intervals (least
// squares; the gyro's scale error of a few percent and its bias of a few deg/s barely move the
// minimum). Kalibr's sign: t_imu = t_cam + timeshift_cam_imu_s.
#pragma once

#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {

struct TimeshiftSearch {
  bool ok = false;
  double timeshift_cam_imu_s = 0;  ///< t_imu = t_cam + timeshift (s)
  /// RMS difference (rad) of the camera's and the gyro's angles per frame interval at the minimum.
  double rms_angle_difference_rad = 0;
  int intervals = 0;  ///< frame intervals compared
  /// The fit over the range: every candidate timeshift_cam_imu_s (s, ascending, 1 ms apart) and
  /// the RMS angle difference (rad) at it; filled whenever the candidates were compared (also
  /// when the best is at an end of the range).
  std::vector<double> candidates_s;
  std::vector<double> rms_difference_rad;
  std::string message;  ///< why not, when !ok (an offset beyond the range names the range)
};

/// The gyro's white noise density (rad/s/sqrt(Hz)) measured on a stream in motion: the second
/// difference of consecutive samples removes a smooth motion (its residue is ~ the angular
/// acceleration's rate of change x dt^2) and leaves 6 sigma^2 of white noise; the median of the
/// absolute values (robust to jerks) gives sigma, sigma / sqrt(rate) the density. 0 for fewer than
/// 10 samples.
double gyroNoiseDensityOf(const GyroStream& gyro);
/// The same for any sampled 3-vector signal (the accelerometer: m/s^2/sqrt(Hz)).
double whiteNoiseDensityOf(const std::vector<double>& stamps_s,
                           const std::vector<Eigen::Vector3d>& values);

/// Searches timeshift_cam_imu_s in [-range_s, range_s] (1 ms steps, then a parabola through the
/// best three). Frames further apart than max_interval_s are not compared (the target was out of
/// view). Needs frames in stamp order, a gyro stream covering them, and rotation: !ok with a
/// message when fewer than 20 intervals turn by more than 0.5 deg, or when the best offset is at an
/// end of the range (the offset is larger than the range).
TimeshiftSearch coarseTimeshift(const std::vector<MotionFrame>& frames, const GyroStream& gyro,
                                double range_s, double max_interval_s = 0.35);

/// How much the camera turned about each of its own axes during the motion (needs no IMU).
struct MotionExcitation {
  /// Sum over frame intervals of |Log(R_target_cam_k^T R_target_cam_k+1)| per component (rad,
  /// camera axes at the interval's start).
  Eigen::Vector3d about_cam_rad = Eigen::Vector3d::Zero();
  double duration_s = 0;  ///< the intervals summed (s)
};

/// The excitation of `frames` (stamp order) over intervals from each frame to the first one at
/// least min_interval_s later (up to 0.1 ms of rounding; the camera's noise per interval adds to
/// every axis; longer intervals add less of it, and a smooth motion rarely reverses within 0.1 s);
/// intervals longer than max_interval_s (the target out of view) are left out.
MotionExcitation motionExcitation(const std::vector<MotionFrame>& frames,
                                  double min_interval_s = 0.1, double max_interval_s = 0.35);

}  // namespace camera_imu_alignment
