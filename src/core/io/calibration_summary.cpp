// The stdout summary of a calibration run with blocks for Kalibr, OpenVINS, VINS-Mono/Fusion and
// tf2.
#include "camera_imu_alignment/io/calibration_summary.h"
#include "camera_imu_alignment/io/default_frames.h"

#include <Eigen/Geometry>
#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>

#include "camera_imu_alignment/io/joint_yaml.h"
#include "camera_imu_alignment/io/report_figures.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "report_text.h"

namespace camera_imu_alignment {
namespace {

using report_text::canonicalQuaternion;
using report_text::exact;
using report_text::fixed;
using report_text::fixedList;
using report_text::hasAxisAdvice;

/// The four rows of the 4x4 transform [R t; 0 1] as YAML flow sequences, one per line. A template
/// so that R may be a transpose expression (no temporary).
template <typename Derived>
std::string transformRows(const Eigen::MatrixBase<Derived>& R, const Eigen::Vector3d& t,
                          const std::string& indent) {
  std::string rows;
  for (int i = 0; i < 3; ++i) {
    rows += indent + "- [" + exact(R(i, 0)) + ", " + exact(R(i, 1)) + ", " + exact(R(i, 2)) + ", " +
            (t(i) == 0.0 ? std::string("0.0") : exact(t(i))) + "]\n";
  }
  return rows + indent + "- [0.0, 0.0, 0.0, 1.0]\n";
}

/// The comment line about the translation: measured (with its 1-sigma) or why not.
std::string translationComment(const ExportTranslation& t) {
  if (!t.measured) return "# translation: " + t.not_measured_reason + " (0 here).\n";
  return "# translation measured during motion, 1-sigma per camera axis " +
         fixedList(t.sigma_m, 4) + " m.\n";
}

std::string kalibrBlock(const Eigen::Matrix3d& R_cam_imu, const ExportTranslation& t,
                        std::optional<double> timeshift_s) {
  std::string block =
      "# Kalibr camchain-imucam.yaml: T_cam_imu maps IMU-frame points into the camera frame\n"
      "# (p_cam = T_cam_imu * p_imu);\n" +
      translationComment(t) + "cam0:\n  T_cam_imu:\n" +
      transformRows(R_cam_imu, t.p_cam_imu_m, "  ");
  if (timeshift_s)
    block += "  timeshift_cam_imu: " + exact(*timeshift_s) + "  # t_imu = t_cam + this\n";
  return block;
}

std::string openVinsBlock(const Eigen::Matrix3d& R_cam_imu, const ExportTranslation& t) {
  const Eigen::Vector3d t_imu_cam = -(R_cam_imu.transpose() * t.p_cam_imu_m);
  return "# OpenVINS kalibr_imucam_chain.yaml: T_imu_cam = T_cam_imu^-1, R_imu_cam = R_cam_imu^T\n"
         "# (p_imu = T_imu_cam * p_cam);\n" +
         translationComment(t) + "cam0:\n  T_imu_cam:\n" +
         transformRows(R_cam_imu.transpose(), t_imu_cam, "    ");
}

std::string vinsBlock(const Eigen::Matrix3d& R_cam_imu, const ExportTranslation& t) {
  std::string data;  // R_imu_cam row by row: R_imu_cam(i, k) = R_cam_imu(k, i)
  for (int i = 0; i < 3; ++i) {
    data += (i == 0 ? "   data: [" : ",\n          ");
    data += exact(R_cam_imu(0, i)) + ", " + exact(R_cam_imu(1, i)) + ", " + exact(R_cam_imu(2, i));
  }
  std::string block =
      "# VINS-Mono / VINS-Fusion config: extrinsicRotation = R_imu_cam (camera to body/IMU,\n"
      "# p_imu = R * p_cam, row-major); VINS-Fusion's body_T_cam0 has the same rotation;\n" +
      translationComment(t) +
      "extrinsicRotation: !!opencv-matrix\n"
      "   rows: 3\n"
      "   cols: 3\n"
      "   dt: d\n" +
      data + "]\n";
  if (t.measured) {
    const Eigen::Vector3d t_imu_cam = -(R_cam_imu.transpose() * t.p_cam_imu_m);
    block +=
        "extrinsicTranslation: !!opencv-matrix  # the camera in the IMU frame (m)\n"
        "   rows: 3\n"
        "   cols: 1\n"
        "   dt: d\n"
        "   data: [" +
        exact(t_imu_cam(0)) + ", " + exact(t_imu_cam(1)) + ", " + exact(t_imu_cam(2)) + "]\n";
  }
  return block;
}

std::string tfBlock(const Eigen::Matrix3d& R_cam_imu, const ExportTranslation& t,
                    const std::string& camera_frame, const std::string& imu_frame) {
  const Eigen::Quaterniond q = canonicalQuaternion(R_cam_imu);
  const Eigen::Vector3d& p = t.p_cam_imu_m;
  const std::string xyz =
      t.measured ? exact(p(0)) + " " + exact(p(1)) + " " + exact(p(2)) : std::string("0 0 0");
  return "# tf2: parent = camera frame, child = IMU frame (maps IMU-frame points into the camera "
         "frame);\n" +
         translationComment(t) + "rosrun tf2_ros static_transform_publisher " + xyz + " " +
         exact(q.x()) + " " + exact(q.y()) + " " + exact(q.z()) + " " + exact(q.w()) + " " +
         frameOr(camera_frame, kDefaultCameraFrame) + " " + frameOr(imu_frame, kDefaultImuFrame) +
         "\n";
}

// --- Summary sections

void writeEstimate(std::ostream& out, const ReportInput& in) {
  const Eigen::Matrix3d& R = in.result.R_cam_imu;
  const Eigen::Quaterniond q = canonicalQuaternion(R);
  out << "R_cam_imu (p_cam = R_cam_imu * p_imu; camera '" << in.camera_frame << "', IMU '"
      << in.imu_frame << "'):\n";
  out << "  quaternion xyzw: [" << fixed(q.x(), 9) << ", " << fixed(q.y(), 9) << ", "
      << fixed(q.z(), 9) << ", " << fixed(q.w(), 9) << "]\n";
  out << "  matrix:\n";
  for (int i = 0; i < 3; ++i) out << "    " << fixedList(R.row(i).transpose(), 9) << "\n";
  out << "  " << rollPitchYawText(R, 4) << "\n";
  const ExportTranslation t = exportTranslationOf(in.result);
  if (t.measured) {
    out << "translation p_cam_imu (the IMU's position in the camera frame, m): "
        << fixedList(t.p_cam_imu_m, 4) << " +- " << fixedList(t.sigma_m, 4)
        << " (1-sigma; measured during motion)\n";
  } else {
    out << "translation: " << t.not_measured_reason << "\n";
  }
}

/// The joint estimate: consistency, which IMU errors the data determined, what to rotate.
void writeJoint(std::ostream& out, const JointResult& j) {
  if (!j.ok) {
    out << "joint estimate: FAILED (" << j.message << "); the pair solve is reported\n";
    return;
  }
  out << "joint estimate: " << jointConsistencyText(j) << ", " << j.iterations << " iteration(s)\n";
  out << "  data used: " << dataUsed(j) << " (" << j.rests_used << " rest(s), " << j.motion_nodes
      << " motion node(s))\n";
  if (j.timeshift_estimated) {
    const std::ios::fmtflags flags = out.flags();
    const std::streamsize precision = out.precision();
    out << "  camera-IMU time offset timeshift_cam_imu_s: " << std::fixed << std::setprecision(5)
        << j.timeshift_cam_imu_s << " s +- " << j.timeshift_sigma_s
        << " (1-sigma; t_imu = t_cam + timeshift)\n";
    out.flags(flags);
    out.precision(precision);
  }
  if (j.motion_nodes > 0 && j.motion.excitation_duration_s > 0.0) {
    out << "  motion: rotation about camera x, y, z (deg): "
        << fixedList(rad2deg(1.0) * j.motion.excitation_rad, 1) << " over "
        << fixed(j.motion.excitation_duration_s, 1) << " s\n";
  }
  const ImuIntrinsics& i = j.intrinsics;
  // Every parameter is estimated with its prior; "estimated": the data determined it.
  const auto state = [](bool estimated) {
    return estimated ? "estimated" : "rests on its prior, in the 1-sigma";
  };
  const bool gyro_any = i.gyro_matrix_column_estimated[0] || i.gyro_matrix_column_estimated[1] ||
                        i.gyro_matrix_column_estimated[2];
  out << "  gyro scale (%): "
      << fixedList(100.0 * (i.gyro_matrix.diagonal() - Eigen::Vector3d::Ones()), 3) << " ("
      << state(gyro_any) << ")\n";
  out << "  accelerometer bias (m/s^2): " << fixedList(i.accel_bias_m_s2, 4) << " ("
      << state(i.accel_bias_estimated) << "), scale (%): "
      << fixedList(100.0 * (i.accel_matrix.diagonal() - Eigen::Vector3d::Ones()), 3) << " ("
      << state(i.accel_matrix_estimated) << ")\n";
  if (i.magnetometer_used) {
    out << "  hard iron (uT): " << fixedList(1e6 * i.hard_iron_t, 3) << " ("
        << state(i.hard_iron_estimated) << "), soft iron " << state(i.soft_iron_estimated) << "\n";
  }
  for (const std::string& note : j.notes) out << "  note: " << note << "\n";
}

void writeQuality(std::ostream& out, const ReportInput& in) {
  const SolutionQuality& q = in.result.quality;
  out << "1-sigma about camera x, y, z (deg): " << fixedList(q.std_dev_deg, 4) << "\n";
  out << "residual RMS (deg): " << fixed(q.residual_rms_deg, 4) << " over " << q.num_inliers
      << " inlier(s) of " << q.num_pairs << " pair(s)\n";
  out << "observable: " << (q.observable ? "yes" : "NO") << " (observability "
      << fixed(q.observability, 3) << ", 0 = one rotation axis .. 1 = all axes evenly)\n";
  if (hasAxisAdvice(in.result)) {
    out << "  rotate the rig about the camera " << axisName(q.excite_axis_cam)
        << " axis to constrain the rotation about camera " << axisName(q.weak_axis_cam) << "\n";
  }
  if (!q.observable && !q.observability_message.empty()) {
    out << "  (" << q.observability_message << ")\n";
  }
  out << "pair solver: " << toString(in.result.method) << ", " << in.result.iterations
      << " iteration(s), " << (in.result.converged ? "converged" : "not converged") << "\n";
  if (in.result.joint) writeJoint(out, *in.result.joint);
}

/// The natural scene's poses (no target): features, and the links that measured each camera.
void writeScenePoses(std::ostream& out, const ReportInput& in) {
  bool any = false;
  for (const StationaryPose& p : in.poses) any = any || p.camera_source == PoseCameraSource::kScene;
  if (!any) return;
  out << "camera from the natural scene (no target): per pose its features and the rotations "
         "measured from earlier rests (matches, inliers, model, 1-sigma per axis; the other "
         "solutions the gyro chooses between):\n";
  for (const StationaryPose& p : in.poses) {
    if (p.camera_source != PoseCameraSource::kScene) continue;
    out << "  pose " << std::setw(3) << p.index << "  scene " << p.scene << "  " << p.scene_features
        << " features";
    if (p.scene_links.empty()) out << "  no link";
    for (const SceneLinkSummary& link : p.scene_links) {
      out << "  | from pose " << link.from_pose << ": " << link.matches << " matches, "
          << link.inliers << " inliers, "
          << (link.model == SceneMotionModel::kGeneral ? "general" : "rotation-only") << ", "
          << fixed(link.sigma_deg, 3) << " deg";
      if (!link.alternatives.empty()) {
        out << ", " << link.alternatives.size() << " other solution"
            << (link.alternatives.size() > 1 ? "s" : "") << " (a near-planar view)";
      }
    }
    out << "\n";
    if (!p.scene_note.empty()) out << "    " << p.scene_note << "\n";
  }
}

void writePoses(std::ostream& out, const ReportInput& in) {
  out << "poses used: " << in.poses.size() << ", rests rejected: " << in.rejected.size()
      << ", IMU rests: " << in.segments.size() << "\n";
  for (const RejectedPose& r : in.rejected) {
    out << "  rejected rest " << fixed(r.start_s - in.start_s, 2) << "-"
        << fixed(r.end_s - in.start_s, 2)
        << " s (from start): " << (r.reason.empty() ? "(no reason given)" : r.reason) << "\n";
  }
  out << "inputs rejected: " << in.rejections.summary() << "\n";
  writeScenePoses(out, in);
}

/// One line per pose: what the report's per-pose panel draws.
void writePoseFigures(std::ostream& out, const ReportFigures& figures) {
  if (figures.poses.empty()) return;
  out << "per pose (t: s from start, middle of the rest; reprojection: px; pairs: RMS residual of "
         "its pairs at the estimate, deg;\n"
         "  mount: the rotation from the estimate this pose implies about camera x, y, z, deg; "
         "joint: whitened residual, sigma):\n";
  for (const PoseFigure& f : figures.poses) {
    std::ostringstream line;
    line << "  pose " << std::setw(3) << f.index << "  t " << std::setw(8) << fixed(f.time_s, 1)
         << "  frames " << std::setw(3) << f.num_frames << "  reprojection "
         << fixed(f.reprojection_rms_px, 3) << "  pairs " << fixed(f.pair_residual_rms_deg, 3)
         << "  mount " << fixedList(f.mount_offset_deg, 3) << "  joint "
         << fixed(f.joint_residual_sigma, 2);
    if (f.group != 0) line << "  group " << f.group;
    if (!f.in_window) line << "  (not in the window)";
    out << line.str() << "\n";
  }
}

}  // namespace

ExportTranslation exportTranslationOf(const AlignmentResult& result) {
  ExportTranslation t;
  t.not_measured_reason = translationNotMeasuredReason(result);
  t.measured = t.not_measured_reason.empty();
  if (t.measured) {
    t.p_cam_imu_m = result.joint->p_cam_imu_m;
    t.sigma_m = result.joint->p_cam_imu_sigma_m;
  }
  return t;
}

std::string exportBlocks(const Eigen::Matrix3d& R_cam_imu, const std::string& camera_frame,
                         const std::string& imu_frame, std::optional<double> timeshift_cam_imu_s,
                         const ExportTranslation& t) {
  return kalibrBlock(R_cam_imu, t, timeshift_cam_imu_s) + "\n" + openVinsBlock(R_cam_imu, t) +
         "\n" + vinsBlock(R_cam_imu, t) + "\n" + tfBlock(R_cam_imu, t, camera_frame, imu_frame);
}

std::string formatSummary(const ReportInput& input) {
  std::ostringstream out;
  out << "=== camera-IMU rotation"
      << (input.source.empty() ? std::string() : " (" + input.source + ")") << " ===\n";
  out << "status: " << toString(input.result.status) << "\n";
  if (input.verdict) out << "verdict: " << input.verdict->text << "\n";
  if (!input.result.message.empty()) out << "message: " << input.result.message << "\n";
  const ReportFigures figures = reportFigures(input);
  const bool estimate = hasEstimate(input.result);
  if (estimate) {
    writeEstimate(out, input);
    writeQuality(out, input);
  } else {  // nothing solved: no rotation, no quality of one, nothing to paste
    out << "R_cam_imu: no estimate\n";
    if (input.result.joint) writeJoint(out, *input.result.joint);
  }
  if (figures.truth_error) out << truthErrorText(*figures.truth_error) << "\n";
  writePoses(out, input);
  writePoseFigures(out, figures);
  if (!estimate) {
    out << "\n# no estimate: no blocks for other tools (Kalibr, OpenVINS, VINS, tf2)\n";
    return out.str();
  }
  out << "\n";
  if (input.result.status != SolveStatus::kOk) {
    out << "# WARNING: status '" << toString(input.result.status)
        << "': the blocks below hold the best guess only, do not use them as a calibration.\n";
  }
  const std::optional<JointResult>& joint = input.result.joint;
  out << exportBlocks(input.result.R_cam_imu, input.camera_frame, input.imu_frame,
                      joint && joint->ok && joint->timeshift_estimated
                          ? std::optional<double>(joint->timeshift_cam_imu_s)
                          : std::nullopt,
                      exportTranslationOf(input.result));
  return out.str();
}

}  // namespace camera_imu_alignment
