// State and records of the online calibrator (online_calibrator.h; its settings:
// config/online_settings.h), shared with the broadcast gate (broadcast_gate.h) and the ROS
// adapter. No ROS type.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>

#include "camera_imu_alignment/config/online_settings.h"
#include "camera_imu_alignment/estimation/alignment_result.h"

namespace camera_imu_alignment {

/// The calibrator's state; toString() gives AlignmentStatus's constants.
enum class CalibrationState {
  kWaitingForData,  ///< no IMU samples or no camera data yet
  kCollecting,      ///< data flowing; too few poses or the quality gates not met
  kCalibrated,      ///< an estimate passed the gates and is broadcast (or one was loaded)
  kNotObservable,   ///< the poses so far rotate about one axis only
  kRecalibrating,   ///< the mount changed: the window restarted from the poses after the change
};
/// "waiting_for_data", "collecting", "calibrated", "not_observable", "recalibrating".
const char* toString(CalibrationState state);

/// What the static tf says, and what is saved.
struct BroadcastEstimate {
  /// What the tf says. Within min_change_deg of `result`'s: a more precise estimate that moved
  /// less than that refines the saved file and the 1-sigma, not the tf.
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();
  /// 1-sigma about the camera axes (deg); infinite when unknown (a file without it).
  Eigen::Vector3d std_dev_deg = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  /// Its covariance (rad^2, left perturbation, camera axes) when known: the significance of a
  /// difference to a new estimate.
  std::optional<Eigen::Matrix3d> covariance_rad2;
  int poses = 0;       ///< poses behind it
  std::string source;  ///< "estimated" (this run) or "loaded: <file>"
  /// The best estimate that passed the gates, when estimated here: what is saved (its
  /// std_dev_deg, covariance and poses are the fields above).
  std::optional<AlignmentResult> result;
  /// "" unless broadcast on request (~calibrate with force) although a gate failed: that gate's
  /// why, saved as the file's FAILED verdict (result_yaml.h, ResultVerdict).
  std::string forced_although;
  double maxStdDevDeg() const { return std_dev_deg.maxCoeff(); }
};

}  // namespace camera_imu_alignment
