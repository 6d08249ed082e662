// What the rviz panel (src/rviz/alignment_panel.*) shows, as text: the node's ~status as rows of
// label and value, the ~stationary_poses as rows of a pose list, the answers of the services.
// Qt-free and display-free, so that it is unit-tested without a display (test_panel_text).
//
// Angles in degrees. Roll, pitch, yaw are the project's one convention (doc/CONVENTIONS.md,
// rollPitchYawDeg): R = Rz(yaw) Ry(pitch) Rx(roll), stated beside the numbers (kRpyConvention).
#pragma once

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/Quaternion.h>
#include <std_srvs/Trigger.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/AlignmentStatus.h"
#include "camera_imu_alignment/Calibrate.h"

namespace camera_imu_alignment {

/// How a row is shown: its colour in the panel.
enum class RowLevel {
  kNormal,   ///< plain
  kGood,     ///< green: calibrated, consistent, broadcast, a call that succeeded
  kWarning,  ///< amber: not broadcast, not observable, recalibrating, stale status
  kError,    ///< red: inconsistent estimate, a failed or unreachable service call
};
std::string toString(RowLevel level);

/// One row of the status table or one answer line.
struct PanelRow {
  std::string label;
  std::string value;
  RowLevel level = RowLevel::kNormal;
  std::string tooltip;  ///< longer explanation ("" when none)
};

/// The convention of every roll, pitch, yaw the panel shows.
extern const char* const
    kRpyConvention;  // "roll, pitch, yaw (deg), R = Rz(yaw) Ry(pitch) Rx(roll)"

/// The panel's view of one ~status message.
struct StatusView {
  std::string state;  ///< the message's state ("(none)" when empty)
  RowLevel state_level = RowLevel::kNormal;
  std::string message;  ///< the message's one-line message
  std::vector<PanelRow> rows;
};

/// Rows, in this order: poses (window / total, rests), pairs (kept), residual RMS, 1-sigma
/// (x, y, z), observability, rotate about next, IMU guidance, the rpy convention, latest
/// estimate rpy, broadcast rpy, broadcast (source, poses, 1-sigma), consistency (chi2, dof,
/// p_value), remounts, last pose. Without `has_broadcast`, a latest estimate flagged `broadcast` is
/// shown as the broadcast one (a node that does not fill the broadcast fields). Values the message
/// does not carry (no estimate, nothing broadcast, no statistics) read "-" or say so; a non-finite
/// number or a quaternion that is not a rotation reads "invalid (...)" with level kError: never
/// "nan".
StatusView describeStatus(const AlignmentStatus& status);

/// Roll, pitch, yaw (deg) of a quaternion message, e.g. "[66.58, -61.35, -105.97]"; nullopt when
/// it is not finite or its norm is far from 1 (more than 0.01 off; otherwise normalised).
std::optional<std::string> rpyText(const geometry_msgs::Quaternion& q, int decimals = 2);

/// The axis to rotate about next: "camera x [0.98, 0.10, 0.02]" naming the dominant camera axis;
/// "-" for a zero or non-finite vector.
std::string rotateAboutText(double x, double y, double z);

/// One row of the pose list: the camera at a stationary pose in the target frame (R_target_cam).
struct PoseRow {
  std::string index;     ///< 1-based, in window order (oldest first)
  std::string roll_deg;  ///< roll, pitch, yaw of R_target_cam (kRpyConvention), 1 decimal
  std::string pitch_deg;
  std::string yaw_deg;
  std::string turn_deg;    ///< rotation angle from the previous pose (deg), "-" for the first
  std::string position_m;  ///< p_target_cam "[x, y, z]" (m)
  bool valid = true;       ///< false: the orientation is not a rotation (fields say "invalid")
};
std::vector<PoseRow> describePoses(const geometry_msgs::PoseArray& poses);

/// The answer of ~calibrate: whether it solved, whether it broadcast and why not, the message,
/// the estimate (rpy, residual, 1-sigma, poses). Level kGood when broadcast, kWarning when solved
/// but not broadcast, kError when not solved.
PanelRow describeCalibrateAnswer(const Calibrate::Request& request,
                                 const Calibrate::Response& response);

/// The answer of a std_srvs/Trigger service (~capture_pose, ~reset, ~save), named `service`.
PanelRow describeTriggerAnswer(const std::string& service,
                               const std_srvs::Trigger::Response& response);

/// A call that got no answer: `service_name` (full) is not advertised or the call failed.
PanelRow describeUnreachable(const std::string& service_name, bool advertised);

/// The namespace the panel listens to, from what the user typed: spaces trimmed, a leading '/'
/// added, trailing '/' dropped. Each part must be a ROS name (a letter, then letters, digits,
/// '_'); otherwise nullopt and `error` says why, naming the text.
std::optional<std::string> normalizeNamespace(const std::string& text, std::string* error);

/// A line about the age of the latest ~status: "" while fresh (at most `stale_after_s` old),
/// otherwise "no status on <topic> for 12 s (is the node running?)"; `age_s` < 0: none yet.
std::string statusAgeText(const std::string& topic, double age_s, double stale_after_s);

/// The IMU frame next to `camera_frame` in the tf tree `parent_of` (child -> parent): the one
/// child of the camera frame other than `target_frame` (the node broadcasts camera -> IMU);
/// otherwise, when the camera frame's parent is a root (publish_inverse: IMU -> camera), that
/// parent. "" when there is none or the choice is ambiguous.
std::string findImuFrame(const std::string& camera_frame, const std::string& target_frame,
                         const std::map<std::string, std::string>& parent_of);

}  // namespace camera_imu_alignment
