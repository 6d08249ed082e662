// A recording built from real images: ViSP's eye-in-hand Franka set (8 poses of a real 9x6
// chessboard seen by a Realsense camera on the arm's flange; realdata README) with an IMU that
// follows the flange. The flange poses (franka_pose_rPe_N.yaml) give the IMU's orientation at each
// rest; between rests the rig turns along a minimum-jerk path to the next pose. The IMU has the
// consumer grade's datasheet noise and constant biases, no scale or cross-axis errors (the flange
// frame is exact); gravity is the base's -z. Each rest is 4 s of IMU at 200 Hz and frames at 5 Hz:
// the pose's real image with 1.5 grey levels of fresh sensor noise each. Real PnP has errors the
// simulator does not (lens distortion absent from ViSP's intrinsics: 0.3-0.55 px reprojection).
// Through the pipeline with the default settings: calibrated within 0.2 deg of ViSP's published
// hand-eye rotation, and the mount-change test, run as the online calibrator runs it after each new
// pose, gives no remount verdict (the mount never moved); without the camera's noise measured from
// the recording, neither holds. Skipped when the data are absent.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/estimation/mount_change.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/simulation/trajectory.h"
#include "camera_imu_alignment/solve/window_solver.h"
#include "camera_imu_alignment/solver/rotation_math.h"

#include "visp_data.h"
#include "visp_recording.h"

namespace camera_imu_alignment {
namespace {

const std::string kDir = test::vispDir();
using test::feedVispRecording;
using test::kVispPoses;
using test::loadVispRecording;
using test::VispRecording;

/// The first `count` poses of `problem` and the gyro segments between them.
JointProblem firstPoses(const JointProblem& problem, size_t count) {
  JointProblem out = problem;
  out.poses.resize(std::min(count, out.poses.size()));
  out.segments.clear();
  for (const GyroSegment& segment : problem.segments) {
    if (segment.to_pose < static_cast<int>(out.poses.size())) out.segments.push_back(segment);
  }
  return out;
}

struct VispOutcome {
  AlignmentResult result;
  JointProblem problem;
  double error_deg = 0.0;
  std::vector<MountChangeTest> tests;  ///< the change test after 4, 5, ..., 8 poses
};

/// The recording through the pipeline (default settings), its error against ViSP's eMc, and the
/// change test after each new pose, as the online calibrator runs it.
bool runVisp(VispOutcome* out, double camera_excess_level = JointSettings{}.camera_excess_level) {
  VispRecording rec;
  if (!loadVispRecording(kDir, &rec)) return false;
  const TargetDescription board = test::vispBoard();
  CameraIntrinsics intrinsics;
  std::string error;
  EXPECT_TRUE(test::vispIntrinsics(&intrinsics, &error)) << error;
  PipelineSettings settings;
  settings.joint.camera_excess_level = camera_excess_level;
  CalibrationPipeline pipeline(board, settings);
  EXPECT_TRUE(pipeline.setCameraIntrinsics(intrinsics));
  feedVispRecording(rec, &pipeline);
  EXPECT_EQ(pipeline.poses().size(), static_cast<size_t>(kVispPoses));
  for (const StationaryPose& pose : pipeline.poses()) {
    std::printf("pose %d: %d frames, reprojection %.2f px, camera spread %.4f deg\n", pose.index,
                pose.num_frames, pose.reprojection_rms_px, pose.camera_spread_deg);
  }
  // ViSP's intrinsics are right for these images: the camera-model check must not name them.
  const CameraModelCheck camera = pipeline.cameraModelCheck();
  std::printf("camera model: %d views, focal factor %.4f +- %.4f (p %.3g), median view p %.3g\n",
              camera.views, camera.focal_scale, camera.focal_scale_sigma, camera.p_value,
              camera.view_p_value);
  EXPECT_TRUE(camera.tested);
  EXPECT_FALSE(camera.wrong) << camera.message;
  out->result = solveWindow(pipeline.snapshot(), pipeline.settings());
  if (out->result.status != SolveStatus::kOk || !out->result.joint || !out->result.joint->ok) {
    ADD_FAILURE() << out->result.message;
    return false;
  }
  const JointResult& joint = *out->result.joint;
  out->error_deg = rad2deg(geodesicDistance(out->result.R_cam_imu, test::vispCameraImu()));
  std::printf("ViSP recording: %s\nR_cam_imu %.3f deg from ViSP's eMc\n", joint.message.c_str(),
              out->error_deg);
  for (const std::string& note : joint.notes) std::printf("  note: %s\n", note.c_str());
  out->problem = pipeline.snapshot().joint;
  for (size_t count = 4; count <= out->problem.poses.size(); ++count) {
    const JointProblem window = firstPoses(out->problem, count);
    const JointResult one = JointEstimator(settings.joint).solve(window, out->result.R_cam_imu);
    EXPECT_TRUE(one.ok) << one.message;
    out->tests.push_back(testMountChange(window, one, settings.joint, MountChangeSettings{}));
    std::printf("%zu poses: %s\n", count, out->tests.back().message.c_str());
  }
  return true;
}

// History on this recording: with the camera's covariance from the frames' scatter and a 0.01 deg
// floor only, chi2/dof 111, 2.03 deg from ViSP's eMc and remount verdicts after 4, 5 and 6 poses;
// with each frame's PnP covariance (pose_assembly.cpp), chi2/dof 5.8, 0.42 deg (T_g and T_a
// estimated by the likelihood ratio: they absorbed the camera's misfit, though this IMU has none)
// and a verdict after 8 poses (1.3 deg, chi2 drop 296). The flange poses and ViSP's eMc leave
// each rest's camera 0.3-0.65 deg off, about the optical axis too: errors of the whole pose (lens,
// board, the arm's kinematics), not of the pixels. Measured now (JointSettings::
// camera_excess_level: the rests' camera noise as the recording shows it, 0.31 deg per axis
// added): T_g and T_a held at identity, 0.041 deg from ViSP's eMc with a 1-sigma of [0.13 0.14
// 0.26] deg, no verdict after any pose (7 poses: suspected, p 6e-5 with one pose after the split,
// pending; the 8th pose clears it, p 0.048).
TEST(VispRecording, WithinTwoTenthsOfVispAndNoRemountAtAll) {
  if (!std::ifstream(kDir + "/franka_image-1.png")) GTEST_SKIP() << "no realdata at " << kDir;
  VispOutcome o;
  ASSERT_TRUE(runVisp(&o)) << "unreadable or unsolved ViSP data in " << kDir;
  EXPECT_LT(o.error_deg, 0.2);
  EXPECT_LT(o.error_deg, 3.0 * o.result.quality.std_dev_deg.norm());
  EXPECT_GT(o.result.joint->camera_excess_variance_rad2, 0.0) << "real PnP's errors measured";
  EXPECT_EQ(o.result.joint->imu_matrices, ImuMatrixModel::kIdentity)
      << "this IMU has no scale or cross-axis errors";
  ASSERT_EQ(o.tests.size(), 5u);
  for (const MountChangeTest& test : o.tests) EXPECT_FALSE(test.detected) << test.message;
}

// Without the measured camera noise (camera_excess_level 0) the same recording fails both
// targets: the test above fails without it.
TEST(VispRecording, WithoutTheMeasuredCameraNoiseAMisfitReadsAsARemount) {
  if (!std::ifstream(kDir + "/franka_image-1.png")) GTEST_SKIP() << "no realdata at " << kDir;
  VispOutcome o;
  ASSERT_TRUE(runVisp(&o, /*camera_excess_level=*/0.0));
  EXPECT_GT(o.error_deg, 0.3);
  bool detected = false;
  for (const MountChangeTest& test : o.tests) detected = detected || test.detected;
  EXPECT_TRUE(detected);
}

}  // namespace
}  // namespace camera_imu_alignment
