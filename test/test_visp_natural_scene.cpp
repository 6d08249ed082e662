// Real images without a target: the ViSP recording (visp_recording.h: 8 real views from a camera on
// a robot arm, an IMU following the flange) through the pipeline with no target description, so
// that the camera's rotation between rests would come from the images' features (the chessboard
// is merely part of the scene; nothing knows it is one). A scene that cannot work: it is said,
// per rest with the counts, and nothing is answered. Skipped when the data are absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/solve/window_solver.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "visp_data.h"
#include "visp_recording.h"

namespace camera_imu_alignment {
namespace {

TEST(VispNaturalScene, RepetitiveBoardOnAPlainTableIsSaidNotGuessed) {
  const std::string dir = test::vispDir();
  if (!std::ifstream(dir + "/franka_image-1.png")) GTEST_SKIP() << "no realdata at " << dir;
  test::VispRecording rec;
  ASSERT_TRUE(test::loadVispRecording(dir, &rec));
  CameraIntrinsics intrinsics;
  std::string error;
  ASSERT_TRUE(test::vispIntrinsics(&intrinsics, &error)) << error;
  CalibrationPipeline pipeline(TargetDescription{}, PipelineSettings{});
  ASSERT_TRUE(pipeline.setCameraIntrinsics(intrinsics));
  test::feedVispRecording(rec, &pipeline);
  for (const RejectedPose& r : pipeline.rejectedPoses())
    std::printf("rejected: %s\n", r.reason.c_str());

  // Each measured rotation against the flange's, seen from the camera through ViSP's hand-eye.
  const Eigen::Matrix3d R_cam_imu = test::vispCameraImu();
  int links = 0;
  for (const StationaryPose& pose : pipeline.poses()) {
    EXPECT_EQ(pose.camera_source, PoseCameraSource::kScene);
    std::printf("pose %d: scene %d, %d features %s\n", pose.index, pose.scene, pose.scene_features,
                pose.scene_note.c_str());
    for (const SceneLinkSummary& link : pose.scene_links) {
      const Eigen::Matrix3d R_true = R_cam_imu * rec.R_world_imu[link.from_pose].transpose() *
                                     rec.R_world_imu[pose.index] * R_cam_imu.transpose();
      const StationaryPose& from = pipeline.poses()[link.from_pose];
      // The measured rotation is the chained orientations' only where this link placed the pose.
      const Eigen::Matrix3d R_measured = from.R_target_cam.transpose() * pose.R_target_cam;
      std::printf(
          "  from pose %d: %d matches, %d inliers, %.3f px, 1-sigma %.3f deg; chained "
          "vs flange %.3f deg\n",
          link.from_pose, link.matches, link.inliers, link.residual_rms_px, link.sigma_deg,
          rad2deg(geodesicDistance(R_measured, R_true)));
      ++links;
    }
  }
  // The scene is a chessboard on a plain table: SIFT finds 200-330 keypoints, the ratio test
  // rejects the repeated corners, and no pair keeps min_inliers (test_scene_rotation: 12-59
  // matches, at most 34 inliers; lowered to 15, three pairs come back 17-29 deg wrong). Each rest
  // says why it starts a scene of its own, with the counts, and no pair of poses is formed: the
  // solve says so instead of answering.
  EXPECT_EQ(pipeline.poses().size(), static_cast<size_t>(test::kVispPoses));
  for (const StationaryPose& pose : pipeline.poses()) {
    if (pose.index == 0) continue;
    EXPECT_NE(pose.scene_note.find("overlaps none"), std::string::npos) << pose.scene_note;
    EXPECT_NE(pose.scene_note.find("inliers"), std::string::npos) << pose.scene_note;
  }
  const AlignmentResult result = solveWindow(pipeline.snapshot(), pipeline.settings());
  if (links == 0) {
    EXPECT_EQ(result.status, SolveStatus::kBadInput) << result.message;
    return;
  }
  // Should a future matcher link these views, the answer must hold against ViSP's.
  ASSERT_TRUE(result.joint && result.joint->ok) << result.message;
  const double error_deg = rad2deg(geodesicDistance(result.R_cam_imu, R_cam_imu));
  std::printf("natural scene: R_cam_imu %.3f deg from ViSP's eMc (1-sigma norm %.3f deg)\n",
              error_deg, result.quality.std_dev_deg.norm());
  EXPECT_LT(error_deg, 3.0 * result.quality.std_dev_deg.norm());
}

}  // namespace
}  // namespace camera_imu_alignment
