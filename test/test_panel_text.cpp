// The rviz panel's text (src/rviz/panel_text.cpp), without a display and without a ROS master:
// roll, pitch, yaw against rotations built from known angles, every ~status field in its row, no
// "nan" ever, the pose list's turn angles, the service answers, the namespace rules, the IMU frame
// found in a tf tree. Its background calls: test_background_calls.cpp (the same binary).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <regex>

#include "camera_imu_alignment/rviz/panel_text.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// R = Rz(yaw) Ry(pitch) Rx(roll), built from the angles (deg), independently of rollPitchYawDeg.
Eigen::Quaterniond fromRollPitchYaw(double roll_deg, double pitch_deg, double yaw_deg) {
  return Eigen::AngleAxisd(deg2rad(yaw_deg), Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(deg2rad(pitch_deg), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(deg2rad(roll_deg), Eigen::Vector3d::UnitX());
}

geometry_msgs::Quaternion message(const Eigen::Quaterniond& q) {
  geometry_msgs::Quaternion m;
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  m.w = q.w();
  return m;
}

const PanelRow& row(const StatusView& view, const std::string& label) {
  for (const PanelRow& r : view.rows) {
    if (r.label == label) return r;
  }
  ADD_FAILURE() << "no row '" << label << "'";
  static const PanelRow none;
  return none;
}

std::size_t rowIndex(const StatusView& view, const std::string& label) {
  for (std::size_t i = 0; i < view.rows.size(); ++i) {
    if (view.rows[i].label == label) return i;
  }
  return view.rows.size();
}

/// No row shows a number as printf prints a non-finite one ("nan", "-nan", "inf").
void expectNoNan(const StatusView& view) {
  const std::regex printed_non_finite("(^|[^a-z])-?(nan|inf)([^a-z]|$)", std::regex::icase);
  for (const PanelRow& r : view.rows)
    EXPECT_FALSE(std::regex_search(r.value, printed_non_finite)) << r.label << ": " << r.value;
}

/// A calibrated status as the node publishes it, with every field of the message set.
AlignmentStatus calibratedStatus() {
  AlignmentStatus s;
  s.header.frame_id = "camera_optical_frame";
  s.state = AlignmentStatus::CALIBRATED;
  s.message = "solved with optimal: 66/66 pairs";
  s.poses_in_window = 12;
  s.poses_total = 14;
  s.rests_total = 15;
  s.pairs = 66;
  s.inliers = 64;
  s.has_estimate = true;
  s.q_cam_imu = message(fromRollPitchYaw(66.58, -61.35, -105.97));
  s.residual_rms_deg = 0.14;
  s.std_dev_deg = {0.0314, 0.0374, 0.0599};
  s.observability = 0.62;
  s.rotate_about_cam.x = 0.1;
  s.rotate_about_cam.y = -0.99;
  s.rotate_about_cam.z = 0.05;
  s.broadcast = true;
  s.last_pose_start = ros::Time(1700000000.5);
  s.last_pose_end = ros::Time(1700000003.7);
  s.last_pose_frames = 30;
  s.last_pose_imu_source = "accel_mag";
  s.consistent = true;
  s.chi2 = 12.3;
  s.dof = 10;
  s.p_value = 0.27;
  s.imu_guidance = "rotate about gravity to calibrate the gyro scale";
  s.has_broadcast = true;
  s.q_broadcast = message(fromRollPitchYaw(10.0, 20.0, -30.0));
  s.broadcast_std_dev_deg = {0.05, 0.06, 0.07};
  s.broadcast_source = "estimated";
  s.broadcast_poses = 11;
  s.remounts = 0;
  return s;
}

TEST(RpyText, MatchesTheAnglesTheRotationWasBuiltFrom) {
  EXPECT_EQ(*rpyText(message(fromRollPitchYaw(10.0, -20.0, 30.0))), "[10.00, -20.00, 30.00]");
  EXPECT_EQ(*rpyText(message(fromRollPitchYaw(-170.0, 45.0, 120.0)), 1), "[-170.0, 45.0, 120.0]");
  // q and -q are one rotation.
  const Eigen::Quaterniond q = fromRollPitchYaw(5.0, 6.0, 7.0);
  EXPECT_EQ(*rpyText(message(q)), *rpyText(message(Eigen::Quaterniond(-q.coeffs()))));
  // Within 0.01 of unit norm: normalised, the same angles.
  EXPECT_EQ(*rpyText(message(Eigen::Quaterniond(1.005 * q.coeffs()))), "[5.00, 6.00, 7.00]");
}

TEST(RpyText, RefusesWhatIsNotARotation) {
  geometry_msgs::Quaternion zero;
  zero.w = 0.0;
  EXPECT_FALSE(rpyText(zero));
  geometry_msgs::Quaternion nan;
  nan.x = kNaN;
  EXPECT_FALSE(rpyText(nan));
  EXPECT_FALSE(rpyText(message(Eigen::Quaterniond(1.1 * Eigen::Quaterniond::Identity().coeffs()))));
}

TEST(RotateAboutText, NamesTheDominantCameraAxis) {
  EXPECT_EQ(rotateAboutText(0.1, -0.99, 0.05), "camera y [0.10, -0.99, 0.05]");
  EXPECT_EQ(rotateAboutText(0.0, 0.0, 1.0), "camera z [0.00, 0.00, 1.00]");
  EXPECT_EQ(rotateAboutText(0.0, 0.0, 0.0), "-");
  EXPECT_EQ(rotateAboutText(kNaN, 0.0, 1.0), "-");
}

TEST(DescribeStatus, ShowsEveryFieldOfACalibratedStatus) {
  const StatusView view = describeStatus(calibratedStatus());
  EXPECT_EQ(view.state, "calibrated");
  EXPECT_EQ(view.state_level, RowLevel::kGood);
  EXPECT_EQ(view.message, "solved with optimal: 66/66 pairs");
  EXPECT_EQ(row(view, "poses").value, "12 in the window, 14 in total (15 rests)");
  EXPECT_EQ(row(view, "pairs").value, "66 (64 kept)");
  EXPECT_EQ(row(view, "residual RMS").value, "0.140 deg");
  EXPECT_EQ(row(view, "1-sigma (x, y, z)").value, "[0.0314, 0.0374, 0.0599] deg");
  EXPECT_EQ(row(view, "observability").value, "0.62");
  EXPECT_EQ(row(view, "rotate about next").value, "camera y [0.10, -0.99, 0.05]");
  EXPECT_EQ(row(view, "IMU guidance").value, "rotate about gravity to calibrate the gyro scale");
  EXPECT_EQ(row(view, "latest estimate").value, "[66.58, -61.35, -105.97] (broadcast)");
  EXPECT_EQ(row(view, "broadcast").value, "[10.00, 20.00, -30.00]");
  EXPECT_EQ(row(view, "broadcast").level, RowLevel::kGood);
  EXPECT_EQ(row(view, "broadcast from").value,
            "estimated, 11 poses, 1-sigma [0.0500, 0.0600, 0.0700] deg");
  EXPECT_EQ(row(view, "consistency").value, "consistent: chi2 12.3 for 10 dof, p = 0.270");
  EXPECT_EQ(row(view, "consistency").level, RowLevel::kGood);
  EXPECT_EQ(row(view, "remounts").value, "0");
  EXPECT_EQ(row(view, "remounts").level, RowLevel::kNormal);
  // Stamps in full, never "1.7e+09".
  EXPECT_EQ(row(view, "last pose").value,
            "30 frames, IMU attitude from accel_mag, still 3.2 s, ended 1700000003.700 s");
  expectNoNan(view);
}

// Waving: how far the camera turned about each of its axes, and the axis still to turn about.
TEST(DescribeStatus, TheMotionsTurnPerCameraAxisAndTheAxisStillMissing) {
  AlignmentStatus s = calibratedStatus();
  EXPECT_EQ(row(describeStatus(s), "motion turned (x, y, z)").value, "-");  // rests only
  s.motion_nodes = 600;
  s.excitation_deg = {412.4, 250.0, 31.2};
  s.excitation_missing = "camera z";
  const PanelRow missing = row(describeStatus(s), "motion turned (x, y, z)");
  EXPECT_EQ(missing.value, "[412, 250, 31] deg; turn about camera z");
  EXPECT_EQ(missing.level, RowLevel::kWarning);
  s.excitation_deg[2] = 190.0;
  s.excitation_missing.clear();
  EXPECT_EQ(row(describeStatus(s), "motion turned (x, y, z)").level, RowLevel::kNormal);
  s.excitation_deg[0] = std::nan("");
  EXPECT_EQ(row(describeStatus(s), "motion turned (x, y, z)").level, RowLevel::kError);
}

TEST(DescribeStatus, StatesTheRpyConventionBeforeTheAngles) {
  const StatusView view = describeStatus(calibratedStatus());
  const std::size_t convention = rowIndex(view, "angles");
  ASSERT_LT(convention, view.rows.size());
  EXPECT_NE(view.rows[convention].value.find("R = Rz(yaw) Ry(pitch) Rx(roll)"), std::string::npos);
  EXPECT_NE(view.rows[convention].value.find("R_cam_imu"), std::string::npos);
  EXPECT_LT(convention, rowIndex(view, "latest estimate"));
  EXPECT_LT(convention, rowIndex(view, "broadcast"));
  EXPECT_NE(row(view, "latest estimate").tooltip.find("Rz(yaw)"), std::string::npos);
}

TEST(DescribeStatus, FlagsWhatNeedsAttention) {
  AlignmentStatus s = calibratedStatus();
  s.state = AlignmentStatus::NOT_OBSERVABLE;
  s.consistent = false;
  s.p_value = 0.0004;
  s.remounts = 2;
  s.broadcast = false;
  const StatusView view = describeStatus(s);
  EXPECT_EQ(view.state_level, RowLevel::kWarning);
  EXPECT_EQ(row(view, "rotate about next").level, RowLevel::kWarning);
  EXPECT_EQ(row(view, "consistency").value, "INCONSISTENT: chi2 12.3 for 10 dof, p = 0.000400");
  EXPECT_EQ(row(view, "consistency").level, RowLevel::kError);
  EXPECT_EQ(row(view, "remounts").value, "2");
  EXPECT_EQ(row(view, "remounts").level, RowLevel::kWarning);
  EXPECT_EQ(row(view, "latest estimate").value, "[66.58, -61.35, -105.97] (not broadcast)");
  s.state = AlignmentStatus::RECALIBRATING;
  EXPECT_EQ(describeStatus(s).state_level, RowLevel::kWarning);
  s.state = AlignmentStatus::COLLECTING;
  EXPECT_EQ(describeStatus(s).state_level, RowLevel::kNormal);
}

TEST(DescribeStatus, AnEmptyStatusSaysWhatIsMissing) {
  const StatusView view = describeStatus(AlignmentStatus());
  EXPECT_EQ(view.state, "(none)");
  EXPECT_EQ(row(view, "residual RMS").value, "-");
  EXPECT_EQ(row(view, "latest estimate").value, "none yet");
  EXPECT_EQ(row(view, "broadcast").value, "nothing broadcast yet");
  EXPECT_EQ(row(view, "broadcast from").value, "-");
  EXPECT_EQ(row(view, "consistency").value, "-");
  EXPECT_EQ(row(view, "rotate about next").value, "-");
  EXPECT_EQ(row(view, "IMU guidance").value, "-");
  EXPECT_EQ(row(view, "last pose").value, "none yet");
  expectNoNan(view);
}

TEST(DescribeStatus, BadNumbersReadInvalidNeverNan) {
  AlignmentStatus s = calibratedStatus();
  s.residual_rms_deg = kNaN;
  s.std_dev_deg[1] = std::numeric_limits<double>::infinity();
  s.observability = kNaN;
  s.q_broadcast = geometry_msgs::Quaternion();
  s.q_broadcast.w = 0.0;
  s.q_cam_imu.x = kNaN;
  s.chi2 = kNaN;
  const StatusView view = describeStatus(s);
  for (const char* label : {"residual RMS", "1-sigma (x, y, z)", "observability", "latest estimate",
                            "broadcast", "consistency"}) {
    EXPECT_EQ(row(view, label).level, RowLevel::kError) << label;
    EXPECT_NE(row(view, label).value.find("invalid"), std::string::npos) << label;
  }
  expectNoNan(view);
}

TEST(DescribeStatus, ALoadedCalibrationShowsItsSource) {
  AlignmentStatus s;
  s.state = AlignmentStatus::CALIBRATED;
  s.has_broadcast = true;
  s.q_broadcast = message(fromRollPitchYaw(1.0, 2.0, 3.0));
  s.broadcast_source = "loaded: /home/me/.ros/camera_imu_alignment.yaml";
  s.broadcast_poses = 12;
  s.broadcast_std_dev_deg = {std::numeric_limits<double>::infinity(), 0.0, 0.0};
  const StatusView view = describeStatus(s);
  EXPECT_EQ(row(view, "broadcast").value, "[1.00, 2.00, 3.00]");
  EXPECT_EQ(row(view, "broadcast from").value,
            "loaded: /home/me/.ros/camera_imu_alignment.yaml, 12 poses, 1-sigma unknown");
  EXPECT_EQ(row(view, "latest estimate").value, "none yet");
}

TEST(DescribeStatus, TheBroadcastLatestEstimateWhenTheBroadcastFieldsAreEmpty) {
  AlignmentStatus s = calibratedStatus();
  s.has_broadcast = false;
  s.q_broadcast = geometry_msgs::Quaternion();
  StatusView view = describeStatus(s);
  EXPECT_EQ(row(view, "broadcast").value, "[66.58, -61.35, -105.97]");
  EXPECT_EQ(row(view, "broadcast").level, RowLevel::kGood);
  EXPECT_EQ(row(view, "broadcast from").value, "the latest estimate");
  s.broadcast = false;
  view = describeStatus(s);
  EXPECT_EQ(row(view, "broadcast").value, "nothing broadcast yet");
  EXPECT_EQ(row(view, "broadcast from").value, "-");
}

TEST(DescribePoses, RowsWithRollPitchYawAndTheTurnFromThePreviousPose) {
  geometry_msgs::PoseArray poses;
  geometry_msgs::Pose pose;
  pose.orientation = message(fromRollPitchYaw(0.0, 0.0, 0.0));
  pose.position.x = 0.1;
  pose.position.y = -0.2;
  pose.position.z = 0.5;
  poses.poses.push_back(pose);
  pose.orientation = message(fromRollPitchYaw(30.0, 0.0, 0.0));
  poses.poses.push_back(pose);
  pose.orientation = message(fromRollPitchYaw(30.0, 0.0, 40.0));  // 40 deg about world z
  poses.poses.push_back(pose);
  pose.orientation = geometry_msgs::Quaternion();
  pose.orientation.w = 0.0;
  poses.poses.push_back(pose);
  const std::vector<PoseRow> rows = describePoses(poses);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].index, "1");
  EXPECT_EQ(rows[0].turn_deg, "-");
  EXPECT_EQ(rows[0].position_m, "[0.100, -0.200, 0.500]");
  EXPECT_EQ(rows[1].roll_deg, "30.0");
  EXPECT_EQ(rows[1].pitch_deg, "0.0");
  EXPECT_EQ(rows[1].yaw_deg, "0.0");
  EXPECT_EQ(rows[1].turn_deg, "30.0");
  EXPECT_EQ(rows[2].yaw_deg, "40.0");
  EXPECT_EQ(rows[2].turn_deg, "40.0");
  EXPECT_TRUE(rows[2].valid);
  EXPECT_FALSE(rows[3].valid);
  EXPECT_EQ(rows[3].roll_deg, "invalid");
  EXPECT_EQ(rows[3].index, "4");
}

TEST(ServiceAnswers, CalibrateSaysWhetherItBroadcastAndWhyNot) {
  Calibrate::Request request;
  Calibrate::Response response;
  response.success = true;
  response.broadcast = true;
  response.message = "solved with optimal";
  response.q_cam_imu = message(fromRollPitchYaw(1.0, 2.0, 3.0));
  response.residual_rms_deg = 0.2;
  response.std_dev_deg = {0.1, 0.1, 0.2};
  response.poses = 9;
  response.observable = true;
  PanelRow answer = describeCalibrateAnswer(request, response);
  EXPECT_EQ(answer.level, RowLevel::kGood);
  EXPECT_EQ(answer.value.rfind("broadcast. R_cam_imu [1.00, 2.00, 3.00] (roll, pitch, yaw", 0), 0u)
      << answer.value;
  EXPECT_NE(answer.value.find("9 poses"), std::string::npos);
  request.force = true;
  EXPECT_EQ(describeCalibrateAnswer(request, response).value.rfind("broadcast (forced)", 0), 0u);

  response.broadcast = false;
  response.not_broadcast_reason = "1-sigma 2.1 deg above max_std_dev_deg 1.0";
  answer = describeCalibrateAnswer(request, response);
  EXPECT_EQ(answer.level, RowLevel::kWarning);
  EXPECT_EQ(answer.value.rfind("solved, not broadcast: 1-sigma 2.1 deg above", 0), 0u);

  response.success = false;
  response.message = "not observable: rotate the rig about the camera x axis";
  answer = describeCalibrateAnswer(request, response);
  EXPECT_EQ(answer.level, RowLevel::kError);
  EXPECT_EQ(answer.value, "not solved: not observable: rotate the rig about the camera x axis");
}

TEST(ServiceAnswers, TriggerAndUnreachable) {
  std_srvs::Trigger::Response response;
  response.success = true;
  response.message = "saved to /tmp/r.yaml";
  EXPECT_EQ(describeTriggerAnswer("save", response).value, "done: saved to /tmp/r.yaml");
  EXPECT_EQ(describeTriggerAnswer("save", response).level, RowLevel::kGood);
  response.success = false;
  response.message = "nothing broadcast";
  EXPECT_EQ(describeTriggerAnswer("save", response).value, "failed: nothing broadcast");
  EXPECT_EQ(describeTriggerAnswer("save", response).level, RowLevel::kError);
  const PanelRow missing = describeUnreachable("/cia/calibrate", false);
  EXPECT_EQ(missing.label, "calibrate");
  EXPECT_NE(missing.value.find("/cia/calibrate is not advertised"), std::string::npos);
  EXPECT_EQ(missing.level, RowLevel::kError);
  EXPECT_NE(describeUnreachable("/cia/save", true).value.find("call to /cia/save failed"),
            std::string::npos);
}

TEST(NormalizeNamespace, AcceptsRosNamesAndSaysWhyNot) {
  std::string error;
  EXPECT_EQ(*normalizeNamespace("camera_imu_alignment", &error), "/camera_imu_alignment");
  EXPECT_EQ(*normalizeNamespace("  /robot/cia2/ ", &error), "/robot/cia2");
  EXPECT_FALSE(normalizeNamespace("  ", &error));
  EXPECT_NE(error.find("is empty"), std::string::npos);
  EXPECT_FALSE(normalizeNamespace("/a b", &error));
  EXPECT_NE(error.find("'a b' is not a ROS name"), std::string::npos) << error;
  EXPECT_FALSE(normalizeNamespace("/robot/1cia", &error));
  EXPECT_NE(error.find("'1cia'"), std::string::npos) << error;
  EXPECT_FALSE(normalizeNamespace("//cia", &error));
  EXPECT_FALSE(normalizeNamespace("/robot//cia", &error));
}

TEST(StatusAgeText, QuietWhileFreshNamesTheTopicWhenStale) {
  EXPECT_EQ(statusAgeText("/cia/status", 1.0, 3.0), "");
  EXPECT_EQ(statusAgeText("/cia/status", -1.0, 3.0),
            "no status on /cia/status yet (is the node running?)");
  EXPECT_EQ(statusAgeText("/cia/status", 12.7, 3.0),
            "no status on /cia/status for 12 s (is the node running?)");
}

TEST(FindImuFrame, TheCameraFramesOtherNeighbour) {
  const std::string camera = "camera_optical_frame", target = "calibration_target";
  // The node's tree: camera -> IMU (static) and camera -> target.
  EXPECT_EQ(findImuFrame(camera, target, {{"imu_link", camera}, {target, camera}}), "imu_link");
  // publish_inverse: IMU -> camera, the IMU frame the root.
  EXPECT_EQ(findImuFrame(camera, target, {{camera, "imu_link"}, {target, camera}}), "imu_link");
  // A robot's tree where the camera's parent is not a root: no guess.
  EXPECT_EQ(findImuFrame(camera, target, {{camera, "camera_link"}, {"camera_link", "base_link"}}),
            "");
  // Two children of the camera: ambiguous.
  EXPECT_EQ(findImuFrame(camera, target, {{"imu_link", camera}, {"lidar", camera}}), "");
  EXPECT_EQ(findImuFrame("", target, {{"imu_link", camera}}), "");
  EXPECT_EQ(findImuFrame(camera, target, {}), "");
}

}  // namespace
}  // namespace camera_imu_alignment
