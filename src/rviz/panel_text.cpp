// The rviz panel's text: ~status rows, pose list rows, service answers (see panel_text.h).
#include "camera_imu_alignment/rviz/panel_text.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

const char* const kRpyConvention = "roll, pitch, yaw (deg), R = Rz(yaw) Ry(pitch) Rx(roll)";

std::string toString(RowLevel level) {
  switch (level) {
    case RowLevel::kNormal:
      return "normal";
    case RowLevel::kGood:
      return "good";
    case RowLevel::kWarning:
      return "warning";
    case RowLevel::kError:
      return "error";
  }
  return "unknown";
}

namespace {

std::string fixed(double value, int decimals) {
  if (std::abs(value) < 0.5 * std::pow(10.0, -decimals)) value = 0.0;  // never "-0.0"
  std::ostringstream out;
  out << std::fixed << std::setprecision(decimals) << value;
  return out.str();
}

/// About three significant digits in fixed notation: 0.0314, 1.28, 123.
std::string significant(double value, int digits = 3) {
  if (std::isnan(value)) return "not a number";
  if (std::isinf(value)) return value > 0 ? "infinite" : "-infinite";
  if (value == 0.0) return "0";
  const int magnitude = static_cast<int>(std::floor(std::log10(std::abs(value))));
  return fixed(value, std::clamp(digits - 1 - magnitude, 0, 6));
}

bool allFinite(std::initializer_list<double> values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

std::string vectorText(double x, double y, double z, int decimals) {
  return "[" + fixed(x, decimals) + ", " + fixed(y, decimals) + ", " + fixed(z, decimals) + "]";
}

std::string sigmaText(const boost::array<double, 3>& sigma_deg) {
  if (!allFinite({sigma_deg[0], sigma_deg[1], sigma_deg[2]})) return "unknown";
  return "[" + significant(sigma_deg[0]) + ", " + significant(sigma_deg[1]) + ", " +
         significant(sigma_deg[2]) + "] deg";
}

/// The rotation of a quaternion message: nullopt when not finite or its norm is more than 0.01
/// away from 1 (doc/CONVENTIONS.md, the readers' rule), otherwise normalised.
std::optional<Eigen::Matrix3d> rotationOf(const geometry_msgs::Quaternion& q) {
  if (!allFinite({q.w, q.x, q.y, q.z})) return std::nullopt;
  const Eigen::Quaterniond quaternion(q.w, q.x, q.y, q.z);
  if (std::abs(quaternion.norm() - 1.0) > 0.01) return std::nullopt;
  return quaternion.normalized().toRotationMatrix();
}

std::string invalidQuaternionText(const geometry_msgs::Quaternion& q) {
  return "invalid quaternion (x, y, z, w) = [" + significant(q.x) + ", " + significant(q.y) + ", " +
         significant(q.z) + ", " + significant(q.w) + "]";
}

RowLevel stateLevel(const std::string& state) {
  if (state == AlignmentStatus::CALIBRATED) return RowLevel::kGood;
  if (state == AlignmentStatus::NOT_OBSERVABLE || state == AlignmentStatus::RECALIBRATING)
    return RowLevel::kWarning;
  return RowLevel::kNormal;
}

/// A row with a rotation as rpy, or "invalid" (kError) when the quaternion is not a rotation.
PanelRow rpyRow(const std::string& label, const geometry_msgs::Quaternion& q,
                const std::string& suffix) {
  const std::optional<std::string> rpy = rpyText(q);
  if (!rpy) return {label, invalidQuaternionText(q), RowLevel::kError, ""};
  return {label, *rpy + suffix, RowLevel::kNormal, kRpyConvention};
}

PanelRow consistencyRow(const AlignmentStatus& s) {
  const std::string tooltip =
      "chi-square test of the latest estimate's normalised residuals: consistent when one mount "
      "with the modelled noise explains them (p_value: the probability of a chi2 this large)";
  if (!s.has_estimate || (s.dof == 0 && s.chi2 == 0.0 && s.p_value == 0.0))
    return {"consistency", "-", RowLevel::kNormal, tooltip};
  if (!allFinite({s.chi2, s.p_value}))
    return {"consistency",
            "invalid (chi2 " + significant(s.chi2) + ", p " + significant(s.p_value) + ")",
            RowLevel::kError, tooltip};
  const std::string figures = "chi2 " + significant(s.chi2) + " for " + std::to_string(s.dof) +
                              " dof, p = " + significant(s.p_value);
  if (s.consistent) return {"consistency", "consistent: " + figures, RowLevel::kGood, tooltip};
  return {"consistency", "INCONSISTENT: " + figures, RowLevel::kError, tooltip};
}

PanelRow broadcastSourceRow(const AlignmentStatus& s) {
  if (!s.has_broadcast) return {"broadcast from", "-", RowLevel::kNormal, ""};
  std::string value = s.broadcast_source.empty() ? "(source not given)" : s.broadcast_source;
  value += ", " + std::to_string(s.broadcast_poses) + " poses, 1-sigma " +
           sigmaText(s.broadcast_std_dev_deg);
  return {"broadcast from", value, RowLevel::kNormal,
          "\"estimated\": this run; \"loaded: <file>\": the saved calibration"};
}

PanelRow lastPoseRow(const AlignmentStatus& s) {
  if (s.last_pose_end.isZero()) return {"last pose", "none yet", RowLevel::kNormal, ""};
  const double still_s = (s.last_pose_end - s.last_pose_start).toSec();
  std::string value = std::to_string(s.last_pose_frames) + " frames, IMU attitude from " +
                      (s.last_pose_imu_source.empty() ? "-" : s.last_pose_imu_source) + ", still " +
                      fixed(still_s, 1) + " s, ended " + fixed(s.last_pose_end.toSec(), 3) + " s";
  return {"last pose", value, RowLevel::kNormal, "stamps in header time (s)"};
}

bool isRosNamePart(const std::string& part) {
  if (part.empty() || !std::isalpha(static_cast<unsigned char>(part[0]))) return false;
  return std::all_of(part.begin(), part.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

}  // namespace

std::optional<std::string> rpyText(const geometry_msgs::Quaternion& q, int decimals) {
  const std::optional<Eigen::Matrix3d> R = rotationOf(q);
  if (!R) return std::nullopt;
  const Eigen::Vector3d rpy = rollPitchYawDeg(*R);
  return vectorText(rpy.x(), rpy.y(), rpy.z(), decimals);
}

std::string rotateAboutText(double x, double y, double z) {
  if (!allFinite({x, y, z})) return "-";
  const Eigen::Vector3d axis(x, y, z);
  if (axis.norm() < 1e-9) return "-";
  Eigen::Index dominant = 0;
  axis.cwiseAbs().maxCoeff(&dominant);
  const char* const names[] = {"x", "y", "z"};
  return std::string("camera ") + names[dominant] + " " + vectorText(x, y, z, 2);
}

namespace {

/// The rotation the motion made about each camera axis (waving) and the axes still to turn about.
PanelRow motionTurnedRow(const AlignmentStatus& s) {
  PanelRow row{"motion turned (x, y, z)", "-", RowLevel::kNormal,
               "rotation the camera made about its x, y, z axes during the motion of the latest "
               "estimate; every axis needs min_motion_rotation_deg"};
  if (s.motion_nodes == 0) return row;
  if (!allFinite({s.excitation_deg[0], s.excitation_deg[1], s.excitation_deg[2]})) {
    row.value = "invalid (not finite)";
    row.level = RowLevel::kError;
    return row;
  }
  row.value = vectorText(s.excitation_deg[0], s.excitation_deg[1], s.excitation_deg[2], 0) + " deg";
  if (!s.excitation_missing.empty()) {
    row.value += "; turn about " + s.excitation_missing;
    row.level = RowLevel::kWarning;
  }
  return row;
}

}  // namespace

StatusView describeStatus(const AlignmentStatus& s) {
  StatusView view;
  view.state = s.state.empty() ? "(none)" : s.state;
  view.state_level = stateLevel(s.state);
  view.message = s.message;
  std::vector<PanelRow>& rows = view.rows;

  rows.push_back({"poses",
                  std::to_string(s.poses_in_window) + " in the window, " +
                      std::to_string(s.poses_total) + " in total (" +
                      std::to_string(s.rests_total) + " rests)",
                  RowLevel::kNormal, "stationary poses; rests: IMU rests, poses or not"});
  rows.push_back({"pairs",
                  s.has_estimate
                      ? std::to_string(s.pairs) + " (" + std::to_string(s.inliers) + " kept)"
                      : std::to_string(s.pairs),
                  RowLevel::kNormal, "relative-rotation pairs of the window"});
  if (!s.has_estimate) {
    rows.push_back({"residual RMS", "-", RowLevel::kNormal, ""});
    rows.push_back({"1-sigma (x, y, z)", "-", RowLevel::kNormal, ""});
    rows.push_back({"observability", "-", RowLevel::kNormal, ""});
  } else {
    rows.push_back({"residual RMS",
                    std::isfinite(s.residual_rms_deg)
                        ? significant(s.residual_rms_deg) + " deg"
                        : "invalid (" + significant(s.residual_rms_deg) + ")",
                    std::isfinite(s.residual_rms_deg) ? RowLevel::kNormal : RowLevel::kError,
                    "RMS of the pair residuals at the latest estimate"});
    const bool sigma_finite = allFinite({s.std_dev_deg[0], s.std_dev_deg[1], s.std_dev_deg[2]});
    rows.push_back({"1-sigma (x, y, z)",
                    sigma_finite ? sigmaText(s.std_dev_deg) : "invalid (not finite)",
                    sigma_finite ? RowLevel::kNormal : RowLevel::kError,
                    "1-sigma of the latest estimate about the camera x, y, z axes"});
    rows.push_back({"observability",
                    std::isfinite(s.observability) ? fixed(s.observability, 2) : "invalid",
                    std::isfinite(s.observability) ? RowLevel::kNormal : RowLevel::kError,
                    "0: all rotations about one axis .. 1: all axes evenly"});
  }
  rows.push_back(
      {"rotate about next",
       rotateAboutText(s.rotate_about_cam.x, s.rotate_about_cam.y, s.rotate_about_cam.z),
       s.state == AlignmentStatus::NOT_OBSERVABLE ? RowLevel::kWarning : RowLevel::kNormal,
       "unit axis in the camera frame to rotate the rig about next"});
  rows.push_back(motionTurnedRow(s));
  rows.push_back({"IMU guidance", s.imu_guidance.empty() ? "-" : s.imu_guidance, RowLevel::kNormal,
                  "which rotation would calibrate the IMU parameters still "
                  "held at their priors"});
  rows.push_back({"angles", std::string(kRpyConvention) + ", of R_cam_imu", RowLevel::kNormal,
                  "R_cam_imu maps IMU vectors into the camera frame: p_cam = R_cam_imu p_imu"});
  if (s.has_estimate) {
    rows.push_back(
        rpyRow("latest estimate", s.q_cam_imu, s.broadcast ? " (broadcast)" : " (not broadcast)"));
  } else {
    rows.push_back({"latest estimate", "none yet", RowLevel::kNormal, ""});
  }
  if (s.has_broadcast) {
    rows.push_back(rpyRow("broadcast", s.q_broadcast, ""));
    rows.back().level = rows.back().level == RowLevel::kError ? RowLevel::kError : RowLevel::kGood;
    rows.push_back(broadcastSourceRow(s));
  } else if (s.has_estimate && s.broadcast) {
    // A node that says the latest estimate is broadcast without filling the broadcast fields.
    rows.push_back(rpyRow("broadcast", s.q_cam_imu, ""));
    rows.back().level = rows.back().level == RowLevel::kError ? RowLevel::kError : RowLevel::kGood;
    rows.push_back({"broadcast from", "the latest estimate", RowLevel::kNormal, ""});
  } else {
    rows.push_back({"broadcast", "nothing broadcast yet", RowLevel::kNormal, ""});
    rows.push_back(broadcastSourceRow(s));
  }
  rows.push_back(consistencyRow(s));
  rows.push_back({"remounts", std::to_string(s.remounts),
                  s.remounts > 0 ? RowLevel::kWarning : RowLevel::kNormal,
                  "mount changes detected since the start or the last reset"});
  rows.push_back(lastPoseRow(s));
  return view;
}

std::vector<PoseRow> describePoses(const geometry_msgs::PoseArray& poses) {
  std::vector<PoseRow> rows;
  std::optional<Eigen::Matrix3d> previous;
  for (std::size_t i = 0; i < poses.poses.size(); ++i) {
    const geometry_msgs::Pose& pose = poses.poses[i];
    PoseRow row;
    row.index = std::to_string(i + 1);
    const geometry_msgs::Point& p = pose.position;
    row.position_m = allFinite({p.x, p.y, p.z}) ? vectorText(p.x, p.y, p.z, 3) : "invalid";
    const std::optional<Eigen::Matrix3d> R_target_cam = rotationOf(pose.orientation);
    if (!R_target_cam) {
      row.valid = false;
      row.roll_deg = row.pitch_deg = row.yaw_deg = row.turn_deg = "invalid";
    } else {
      const Eigen::Vector3d rpy = rollPitchYawDeg(*R_target_cam);
      row.roll_deg = fixed(rpy.x(), 1);
      row.pitch_deg = fixed(rpy.y(), 1);
      row.yaw_deg = fixed(rpy.z(), 1);
      row.turn_deg = previous ? fixed(rad2deg(geodesicDistance(*previous, *R_target_cam)), 1) : "-";
    }
    previous = R_target_cam;
    rows.push_back(row);
  }
  return rows;
}

PanelRow describeCalibrateAnswer(const Calibrate::Request& request,
                                 const Calibrate::Response& response) {
  PanelRow row{"calibrate", "", RowLevel::kError, ""};
  if (!response.success) {
    row.value = "not solved: " + (response.message.empty() ? "(no message)" : response.message);
    return row;
  }
  if (response.broadcast) {
    row.level = RowLevel::kGood;
    row.value = request.force ? "broadcast (forced)" : "broadcast";
  } else {
    row.level = RowLevel::kWarning;
    row.value = "solved, not broadcast: " + (response.not_broadcast_reason.empty()
                                                 ? std::string("(the node gave no reason)")
                                                 : response.not_broadcast_reason);
  }
  const std::optional<std::string> rpy = rpyText(response.q_cam_imu);
  row.value += ". R_cam_imu " + (rpy ? *rpy + " (" + kRpyConvention + ")"
                                     : invalidQuaternionText(response.q_cam_imu));
  row.value += ", residual RMS " + significant(response.residual_rms_deg) + " deg, 1-sigma " +
               sigmaText(response.std_dev_deg) + ", " + std::to_string(response.poses) + " poses";
  if (!response.observable) row.value += ", not observable";
  if (!response.message.empty()) row.value += ". " + response.message;
  return row;
}

PanelRow describeTriggerAnswer(const std::string& service,
                               const std_srvs::Trigger::Response& response) {
  const std::string message = response.message.empty() ? "(no message)" : response.message;
  if (response.success) return {service, "done: " + message, RowLevel::kGood, ""};
  return {service, "failed: " + message, RowLevel::kError, ""};
}

PanelRow describeUnreachable(const std::string& service_name, bool advertised) {
  const std::string service = service_name.substr(service_name.find_last_of('/') + 1);
  if (!advertised)
    return {service,
            service_name +
                " is not advertised (is the node running under this "
                "namespace?)",
            RowLevel::kError, ""};
  return {service, "the call to " + service_name + " failed (did the node stop during the call?)",
          RowLevel::kError, ""};
}

std::optional<std::string> normalizeNamespace(const std::string& text, std::string* error) {
  const std::size_t first = text.find_first_not_of(" \t");
  const std::size_t last = text.find_last_not_of(" \t");
  std::string name = first == std::string::npos ? "" : text.substr(first, last - first + 1);
  while (!name.empty() && name.back() == '/') name.pop_back();
  if (!name.empty() && name.front() == '/') name.erase(0, 1);
  if (name.empty()) {
    if (error)
      *error = "namespace '" + text + "' is empty: give the node's name, e.g. " +
               "/camera_imu_alignment";
    return std::nullopt;
  }
  std::size_t start = 0;
  while (start <= name.size()) {
    const std::size_t end = std::min(name.find('/', start), name.size());
    const std::string part = name.substr(start, end - start);
    if (!isRosNamePart(part)) {
      if (error)
        *error = "namespace '" + text + "': '" + part +
                 "' is not a ROS name (a letter, then letters, digits or '_')";
      return std::nullopt;
    }
    start = end + 1;
  }
  return "/" + name;
}

std::string statusAgeText(const std::string& topic, double age_s, double stale_after_s) {
  if (age_s < 0.0) return "no status on " + topic + " yet (is the node running?)";
  if (age_s <= stale_after_s) return "";
  return "no status on " + topic + " for " + fixed(std::floor(age_s), 0) +
         " s (is the node running?)";
}

std::string findImuFrame(const std::string& camera_frame, const std::string& target_frame,
                         const std::map<std::string, std::string>& parent_of) {
  if (camera_frame.empty()) return "";
  std::vector<std::string> children;
  for (const auto& [child, parent] : parent_of) {
    if (parent == camera_frame && child != target_frame && child != camera_frame)
      children.push_back(child);
  }
  if (children.size() == 1) return children.front();
  if (!children.empty()) return "";  // ambiguous: several children of the camera frame
  const auto camera_parent = parent_of.find(camera_frame);
  if (camera_parent == parent_of.end() || camera_parent->second == target_frame) return "";
  const bool parent_is_root = parent_of.find(camera_parent->second) == parent_of.end();
  return parent_is_root ? camera_parent->second : "";
}

}  // namespace camera_imu_alignment
