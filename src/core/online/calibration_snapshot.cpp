// The calibrator's snapshot: verdict, guidance and progress (calibration_snapshot.h).
#include "camera_imu_alignment/online/calibration_snapshot.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "camera_imu_alignment/pipeline/stationary_window.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

std::string remountPlace(const RemountEvent& event) {
  if (std::isfinite(event.change_stamp_s)) {
    char text[80];
    std::snprintf(text, sizeof(text), "during the motion at %.2f s", event.change_stamp_s);
    return text;
  }
  return "before pose " + std::to_string(event.first_pose_index);
}

std::optional<CalibrationVerdict> recordingVerdict(const EstimateEvent& estimate,
                                                   const std::vector<RemountEvent>& remounts,
                                                   bool accept_last_mount) {
  if (estimate.result.status != SolveStatus::kOk) return std::nullopt;
  const bool gates_passed = estimate.gate.decision != GateDecision::kReject;
  CalibrationVerdict verdict;
  verdict.passed = gates_passed && (remounts.empty() || accept_last_mount);
  if (!estimate.camera_model_problem.empty()) {
    verdict.passed = false;
    verdict.text = "FAILED: " + estimate.camera_model_problem;
    if (!remounts.empty()) {
      verdict.text += "; the mount change reported " + remountPlace(remounts.front()) +
                      " may be this model's error, not a remount";
    }
  } else if (!remounts.empty() && accept_last_mount) {
    const RemountEvent& last = remounts.back();
    char size[40];
    std::snprintf(size, sizeof(size), " (by %.2f deg)", last.change_deg);
    const std::string change = "the mount changed " + remountPlace(last) + size;
    const std::string after = std::isfinite(last.change_stamp_s) && estimate.window_poses == 0
                                  ? std::string("the motion")
                                  : "the " + std::to_string(estimate.window_poses) + " poses";
    verdict.text = gates_passed
                       ? "PASSED for the last mount (--accept-last-mount): " + change +
                             "; the estimate is from " + after + " after it"
                       : "FAILED: " + estimate.gate.why + " (the last mount, after " + change + ")";
  } else if (!remounts.empty()) {
    const bool motion = std::isfinite(remounts.back().change_stamp_s);
    verdict.text = "FAILED: the mount changed during the recording (first " +
                   remountPlace(remounts.front()) +
                   "); the estimate is of the last mount, from the " + (motion ? "data" : "poses") +
                   " after the change";
    if (!gates_passed) verdict.text += "; and " + estimate.gate.why;
  } else if (!gates_passed) {
    verdict.text = "FAILED: " + estimate.gate.why;
  } else {
    verdict.text = "PASSED (the nodelet would broadcast it)";
  }
  return verdict;
}

BroadcastEstimate storedBroadcast(const StoredCalibration& stored, const std::string& source) {
  BroadcastEstimate loaded;
  loaded.R_cam_imu = stored.R_cam_imu;
  if (stored.std_dev_deg) {
    loaded.std_dev_deg = *stored.std_dev_deg;
    const Eigen::Vector3d sigma_rad = *stored.std_dev_deg * (M_PI / 180.0);
    loaded.covariance_rad2 = Eigen::Matrix3d(sigma_rad.cwiseProduct(sigma_rad).asDiagonal());
  }
  loaded.poses = stored.num_poses;
  loaded.source = source;
  return loaded;
}

std::string imuGuidanceOf(const EstimateEvent& estimate) {
  if (!estimate.result.joint || !estimate.result.joint->ok) return "";
  const JointResult& joint = *estimate.result.joint;
  std::string held;
  for (const EstimatedValue& value : joint.parameters) {
    if (value.estimated) continue;
    held += (held.empty() ? "" : ", ") + value.name;
  }
  if (held.empty()) return "";
  const Eigen::Vector3d axis_cam = joint.R_cam_imu * joint.suggested_rotation_axis_imu;
  char text[160];
  std::snprintf(text, sizeof(text),
                "; to calibrate them, rotate about the camera axis (%.2f, %.2f, %.2f)",
                axis_cam.x(), axis_cam.y(), axis_cam.z());
  return "IMU parameters held at their priors: " + held + text;
}

std::string howToMove(const Eigen::Vector3d& axis_cam, const Eigen::Vector3d& up_cam) {
  const double cosine = std::abs(axis_cam.normalized().dot(up_cam.normalized()));
  if (!std::isfinite(cosine)) return "";
  const double from_vertical_deg = rad2deg(std::acos(std::min(1.0, cosine)));
  char text[200];
  if (from_vertical_deg <= 30.0) {
    std::snprintf(text, sizeof(text),
                  "turn in place (about the vertical; the axis is %.0f deg from it)",
                  from_vertical_deg);
  } else if (from_vertical_deg >= 60.0) {
    std::snprintf(text, sizeof(text),
                  "tilt about a horizontal axis (pitch or roll; a robot: a ramp, a kerb or uneven "
                  "ground; the axis is %.0f deg from the vertical)",
                  from_vertical_deg);
  } else {
    std::snprintf(text, sizeof(text),
                  "turn and tilt together (the axis is %.0f deg from the vertical)",
                  from_vertical_deg);
  }
  return text;
}

CalibrationProgress progressOf(const std::optional<EstimateEvent>& estimate, double max_std_dev_deg,
                               const std::optional<Eigen::Vector3d>& up_cam) {
  CalibrationProgress progress;
  progress.max_std_dev_deg = max_std_dev_deg;
  progress.std_dev_deg = std::numeric_limits<double>::infinity();
  if (!estimate) return progress;
  const AlignmentResult& r = estimate->result;
  progress.imu_guidance = imuGuidanceOf(*estimate);
  // While R_cam_imu is not determined, the axis the pairs excite least; once it is, the axis that
  // would calibrate the IMU parameters still held.
  progress.rotate_about_cam = r.quality.excite_axis_cam;
  if (estimate->gate.determined && r.joint && r.joint->ok && !progress.imu_guidance.empty()) {
    progress.rotate_about_cam =
        (r.joint->R_cam_imu * r.joint->suggested_rotation_axis_imu).normalized();
  }
  if (up_cam && up_cam->allFinite() && up_cam->norm() > 0.5) {
    progress.how_to_move = howToMove(progress.rotate_about_cam, *up_cam);
  }
  if (r.status != SolveStatus::kOk || !r.quality.std_dev_deg.allFinite()) return progress;
  progress.std_dev_deg = r.quality.std_dev_deg.maxCoeff();
  if (progress.std_dev_deg <= max_std_dev_deg) {
    progress.poses_needed = 0;
  } else if (estimate->window_poses > 0) {
    // 1-sigma ~ 1/sqrt(poses): n (sigma / max)^2 poses reach max_std_dev_deg.
    const double ratio = progress.std_dev_deg / max_std_dev_deg;
    const double needed = static_cast<double>(estimate->window_poses) * ratio * ratio;
    progress.poses_needed = static_cast<int>(
        std::ceil(std::min(needed, 1e6) - static_cast<double>(estimate->window_poses)));
  }
  return progress;
}

std::string progressText(const CalibrationProgress& progress) {
  if (!std::isfinite(progress.std_dev_deg)) return "no estimate yet";
  char text[240];
  if (progress.poses_needed == 0) {
    std::snprintf(text, sizeof(text), "1-sigma %.3f deg, max_std_dev_deg %.3f reached",
                  progress.std_dev_deg, progress.max_std_dev_deg);
  } else {
    const Eigen::Vector3d& axis = progress.rotate_about_cam;
    std::snprintf(text, sizeof(text),
                  "1-sigma %.3f deg > max_std_dev_deg %.3f: about %d more poses, rotating about "
                  "the camera axis (%.2f, %.2f, %.2f)",
                  progress.std_dev_deg, progress.max_std_dev_deg, progress.poses_needed, axis.x(),
                  axis.y(), axis.z());
    if (!progress.how_to_move.empty()) return text + (": " + progress.how_to_move);
  }
  return text;
}

std::vector<PoseOrientation> CalibrationSnapshot::windowOrientations() const {
  std::vector<PoseOrientation> out;
  for (const StationaryPose& pose : window) out.push_back(orientationOf(pose));
  return out;
}

}  // namespace camera_imu_alignment
