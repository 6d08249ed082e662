// When the nodelet broadcasts a new estimate (ROS-free policy, unit-tested on its own).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>

#include "camera_imu_alignment/ros/wrapper_settings.h"
#include "camera_imu_alignment/solver/alignment_solver.h"

namespace camera_imu_alignment {

/// What the static tf says now.
struct PublishedEstimate {
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();
  /// Largest 1-sigma (deg) of the estimate behind it; infinity when unknown (loaded from a file).
  double max_std_dev_deg = 0.0;
};

enum class GateDecision {
  kReject,     ///< fails a quality gate: state collecting / not_observable
  kKeep,       ///< good, but not better than or not different from what is broadcast
  kBroadcast,  ///< broadcast (and save) it
};

struct GateOutcome {
  GateDecision decision = GateDecision::kReject;
  std::string why;  ///< for kReject and kKeep
};

/// Gates of WrapperSettings in order: solved and observable, min_poses (poses in the window),
/// max_residual_deg, max_std_dev_deg; then, against what is broadcast: no silent regression (a
/// larger 1-sigma than the broadcast one is kept back unless `after_remount`: the mount changed
/// and the old estimate is wrong however precise it was), and min_change_deg.
GateOutcome judgeEstimate(const AlignmentResult& result, std::size_t window_poses,
                          const WrapperSettings& settings,
                          const std::optional<PublishedEstimate>& published, bool after_remount);

}  // namespace camera_imu_alignment
