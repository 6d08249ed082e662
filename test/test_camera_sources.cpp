// The pipeline's camera sources (src/core/pipeline/camera_source.h) on small synthetic inputs
// against known truth: which source a first frame chooses and the other stream refused; each
// source's assessment of a rest (given poses: their rotation; the board: rendered views, the
// simulator's true orientation; the natural scene: two rendered views from one centre, their true
// relative rotation), the reasons a rest is no pose (no camera data, no camera info, the target
// not found), and what each gives during motion.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/scene_renderer.h"
#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/simulation/trajectory.h"
#include "camera_source.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;
using test::angleBetweenDeg;
using test::axisAngle;

/// A source made as the pipeline makes it, with the pipeline's side held here.
struct SourceHarness {
  explicit SourceHarness(TargetDescription target_, PipelineSettings settings_ = {})
      : target(std::move(target_)), settings(std::move(settings_)), window(settings.window_poses) {}

  CameraSourceSetup setup() {
    return {target, settings, inputs,
            [this](RejectReason reason, InputStream stream, const std::string& detail) {
              rejections.add(reason);
              streams.push_back(stream);
              details.push_back(detail);
            }};
  }
  PoseHistoryView history() const { return {poses, window}; }

  TargetDescription target;
  PipelineSettings settings;
  CameraInputs inputs;
  RejectionCounts rejections;
  std::vector<InputStream> streams;
  std::vector<std::string> details;
  std::vector<StationaryPose> poses;
  StationaryWindow window;
};

StationarySegment segment(double start_s, double end_s) {
  StationarySegment s;
  s.start_s = start_s;
  s.end_s = end_s;
  return s;
}

CameraFrame posed(double stamp_s, const Eigen::Matrix3d& R_target_cam) {
  CameraFrame frame;
  frame.stamp_s = stamp_s;
  frame.R_target_cam = R_target_cam;
  return frame;
}

CameraFrame imaged(double stamp_s, const cv::Mat& mono8) {
  CameraFrame frame;
  frame.stamp_s = stamp_s;
  frame.mono8 = mono8;
  return frame;
}

TargetDescription boardTarget(const sim::SimulationConfig& config) {
  return parseTargetYaml(sim::targetYaml(config.target), "simulated target");
}

CameraIntrinsics intrinsicsOf(const sim::CameraModel& camera) {
  const double K[9] = {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
  CameraIntrinsics intrinsics;
  std::string error;
  const std::vector<double> D(camera.distortion.begin(), camera.distortion.end());
  EXPECT_TRUE(CameraIntrinsics::fromCameraInfo(camera.width, camera.height, K, "plumb_bob", D,
                                               &intrinsics, &error))
      << error;
  return intrinsics;
}

sim::SimulationConfig scenario(const std::string& name, std::uint64_t seed) {
  sim::SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(sim::applyScenario(name, &c));
  return c;
}

TEST(CameraSources, TheFirstFramesStreamChoosesTheSource) {
  SourceHarness board(boardTarget(scenario("nominal", 1))), scene{TargetDescription()};
  ASSERT_GT(board.target.numPoints(), 0);
  ASSERT_EQ(scene.target.numPoints(), 0);
  EXPECT_EQ(chooseCameraSource(InputStream::kImage, board.setup())->describe(),
            "images of the target (detection and PnP)");
  EXPECT_EQ(chooseCameraSource(InputStream::kImage, scene.setup())->describe(),
            "images of the natural scene (no target)");
  // Camera poses need no target: given whatever the target file says.
  EXPECT_EQ(chooseCameraSource(InputStream::kCameraPose, board.setup())->describe(),
            "camera poses (camera_pose)");
  EXPECT_EQ(chooseCameraSource(InputStream::kCameraPose, scene.setup())->describe(),
            "camera poses (camera_pose)");
}

TEST(CameraSources, APipelineRefusesFramesOfTheOtherStreamAndSaysWhichSourceItHas) {
  const TargetDescription target = boardTarget(scenario("nominal", 1));
  struct Refusal {
    RejectReason reason;
    InputStream stream;
    std::string detail;
  };
  for (const bool poses_first : {true, false}) {
    std::vector<Refusal> refused;
    PipelineCallbacks callbacks;
    callbacks.on_reject = [&](RejectReason r, InputStream s, const std::string& d) {
      refused.push_back({r, s, d});
    };
    CalibrationPipeline pipeline(target, PipelineSettings(), callbacks);
    const CameraFrame pose = posed(1.0, Eigen::Matrix3d::Identity());
    const CameraFrame image = imaged(1.1, cv::Mat(48, 64, CV_8UC1, cv::Scalar(128)));
    pipeline.addFrame(poses_first ? pose : image);
    pipeline.addFrame(poses_first ? image : pose);
    EXPECT_EQ(pipeline.frames(), 1u);
    EXPECT_EQ(pipeline.rejections().count(RejectReason::kMixedCameraSource), 1u);
    ASSERT_EQ(refused.size(), 1u);
    EXPECT_EQ(refused[0].reason, RejectReason::kMixedCameraSource);
    EXPECT_EQ(refused[0].stream, poses_first ? InputStream::kImage : InputStream::kCameraPose);
    EXPECT_NE(refused[0].detail.find(poses_first ? "the camera source is camera poses"
                                                 : "the camera source is images of the target"),
              std::string::npos)
        << refused[0].detail;
    // A reset (a clock jump, a remount) keeps the source's stream, as it keeps the intrinsics.
    pipeline.reset();
    CameraFrame later = poses_first ? image : pose;
    later.stamp_s = 2.0;
    pipeline.addFrame(later);
    EXPECT_EQ(pipeline.rejections().count(RejectReason::kMixedCameraSource), 2u);
  }
  EXPECT_STREQ(toString(RejectReason::kMixedCameraSource), "mixed_camera_source");
}

TEST(CameraSources, ARestWithoutCameraFramesIsSaidSilent) {
  SourceHarness h(boardTarget(scenario("nominal", 1)));
  StationaryPose pose;
  StationaryWindow::Entry entry;
  EXPECT_EQ(makeNoCameraSource()->assessRest(segment(1, 3), h.history(), &pose, &entry),
            kNoCameraDataReason);
  // No frame counted by the pipeline (the counts cleared by a reset): no camera data either.
  for (const InputStream stream : {InputStream::kCameraPose, InputStream::kImage}) {
    EXPECT_EQ(chooseCameraSource(stream, h.setup())
                  ->assessRest(segment(1, 3), h.history(), &pose, &entry),
              kNoCameraDataReason);
  }
  SourceHarness scene{TargetDescription()};
  EXPECT_EQ(chooseCameraSource(InputStream::kImage, scene.setup())
                ->assessRest(segment(1, 3), scene.history(), &pose, &entry),
            kNoCameraDataReason);
  // Frames came, none in this rest.
  h.inputs.frames = 5;
  EXPECT_EQ(chooseCameraSource(InputStream::kCameraPose, h.setup())
                ->assessRest(segment(1, 3), h.history(), &pose, &entry),
            "target seen in 0 frame(s), 2 needed");
  scene.inputs.frames = 5;
  scene.inputs.intrinsics = intrinsicsOf(sim::CameraModel());
  EXPECT_EQ(chooseCameraSource(InputStream::kImage, scene.setup())
                ->assessRest(segment(1, 3), scene.history(), &pose, &entry),
            "natural scene: no image inside the rest");
}

TEST(CameraSources, GivenPosesAtRestGiveTheirRotation) {
  SourceHarness h(boardTarget(scenario("nominal", 1)));
  std::unique_ptr<CameraSource> source = chooseCameraSource(InputStream::kCameraPose, h.setup());
  const Eigen::Matrix3d R_true = axisAngle(Eigen::Vector3d(0.3, -1.0, 0.5), 0.8);
  // 16 Hz camera poses over a rest of 10-12 s; the next rest's first frame at 12.5 s.
  h.inputs.frames = 34;
  for (int k = 0; k <= 32; ++k) {
    source->takeRestFrame(posed(10.0 + k / 16.0, R_true), 10.0, h.history());
  }
  source->takeRestFrame(posed(12.5, R_true), 12.4, h.history());
  // Spaced min_frame_interval_s (0.15 s: every third), at most max_frames_per_pose (10) per rest.
  EXPECT_EQ(source->heldRestFrames(), 11u);
  StationaryPose pose;
  StationaryWindow::Entry entry;
  EXPECT_EQ(source->assessRest(segment(10.0, 12.0), h.history(), &pose, &entry), "");
  EXPECT_LT(angleBetweenDeg(pose.R_target_cam, R_true), 1e-9);
  EXPECT_EQ(pose.num_frames, 9);  // 10.1875 .. 11.6875 s: inside the margins (frame_margin_s 0.15)
  EXPECT_NEAR(pose.camera_spread_deg, 0.0, 1e-9);
  EXPECT_EQ(pose.camera_source, PoseCameraSource::kTarget);
  EXPECT_TRUE(entry.camera_links.empty());
  EXPECT_EQ(source->heldRestFrames(), 1u);  // the frame after the rest, for the next one
  EXPECT_TRUE(h.rejections.total() == 0);
  EXPECT_EQ(source->targetNotFoundDiagnosis(h.rejections), "");
  EXPECT_EQ(source->sceneLinkRefitter(JointProblem(), {}), nullptr);

  // During motion every frame is a motion frame, with the assumed 0.05 deg 1-sigma per axis.
  CameraFrame moving = posed(13.0, R_true);
  moving.p_target_cam_m = Eigen::Vector3d(0.1, -0.2, 1.5);
  const std::optional<MotionFrame> motion = source->takeMotionFrame(moving, nullptr);
  ASSERT_TRUE(motion);
  EXPECT_EQ(motion->stamp_s, 13.0);
  EXPECT_LT(angleBetweenDeg(motion->R_target_cam, R_true), 1e-12);
  ASSERT_TRUE(motion->p_target_cam_m);
  EXPECT_LT((*motion->p_target_cam_m - *moving.p_target_cam_m).norm(), 1e-12);
  const double sigma_rad = 0.05 * M_PI / 180.0;
  EXPECT_LT((motion->cov_cam_rad2 - sigma_rad * sigma_rad * Eigen::Matrix3d::Identity()).norm(),
            1e-15);
  EXPECT_EQ(motion->reprojection_dof, 0);

  // Frames that scatter beyond max_camera_spread_deg (0.5 deg) make no pose.
  for (int k = 0; k < 6; ++k) {
    const Eigen::Matrix3d turned = R_true * axisAngle(Eigen::Vector3d::UnitX(), (k % 2) * 0.03);
    source->takeRestFrame(posed(20.0 + 0.2 * k, turned), 20.0, h.history());
  }
  const std::string scattered = source->assessRest(segment(20.0, 21.4), h.history(), &pose, &entry);
  EXPECT_EQ(scattered.rfind("camera orientation scatter", 0), 0u) << scattered;
}

TEST(CameraSources, TheBoardAtRestGivesTheRenderedOrientation) {
  const sim::SimulationConfig config = scenario("nominal", 3);
  SourceHarness h(boardTarget(config));
  const sim::Trajectory trajectory(config);
  const sim::StationaryPose& held = trajectory.poses()[0];
  const Eigen::Matrix3d R_true = trajectory.R_world_target().transpose() * held.R_world_cam;
  const Eigen::Vector3d p_true =
      trajectory.R_world_target().transpose() * (held.p_world_cam - trajectory.p_world_target());
  const sim::CameraModel camera = sim::CameraModel::fromConfig(config);
  const sim::ImageRenderer renderer(
      camera, sim::makeTargetTexture(config.target, sim::textureTexelFor(config)),
      config.supersample, config.blur_sigma_px);
  const cv::Mat rendered = renderer.render(R_true, p_true);
  std::unique_ptr<CameraSource> source = chooseCameraSource(InputStream::kImage, h.setup());
  // The board looks the same turned by 180 deg: a previous pose (the IMU not turned since) tells
  // the detector which way up it is.
  StationaryPose previous;
  previous.R_target_cam = R_true;
  h.poses.push_back(previous);

  // Images before any camera info are counted and named at the rest's end.
  h.inputs.frames = 3;
  for (int k = 0; k < 3; ++k) {
    source->takeRestFrame(imaged(1.0 + 0.2 * k, sim::ImageRenderer::toMono8(rendered, 0.5, k)), 1.0,
                          h.history());
  }
  StationaryPose pose;
  StationaryWindow::Entry entry;
  EXPECT_EQ(source->assessRest(segment(1.0, 2.0), h.history(), &pose, &entry),
            "no camera info received yet (3 image(s) waiting for it)");

  h.inputs.intrinsics = intrinsicsOf(camera);
  h.inputs.frames = 8;
  for (int k = 0; k < 5; ++k) {
    source->takeRestFrame(
        imaged(20.0 + 0.2 * k, sim::ImageRenderer::toMono8(rendered, config.pixel_noise_sigma, k)),
        20.0, h.history());
  }
  EXPECT_EQ(h.inputs.detected, 5u);
  EXPECT_EQ(h.rejections.total(), 0u) << (h.details.empty() ? "" : h.details[0]);
  EXPECT_EQ(source->assessRest(segment(20.0, 21.0), h.history(), &pose, &entry), "");
  EXPECT_EQ(pose.num_frames, 4);  // 20.2 .. 20.8 s, inside the margins
  EXPECT_LT(angleBetweenDeg(pose.R_target_cam, R_true), 0.1);
  EXPECT_LT((pose.p_target_cam - p_true).norm(), 0.01 * p_true.norm());
  EXPECT_GT(pose.reprojection_rms_px, 0.0);
  EXPECT_LT(pose.reprojection_rms_px, 1.0);
  EXPECT_EQ(
      source->cameraModelCheck(CalibrationPipeline::kCameraModelLevel, &*h.inputs.intrinsics).views,
      1);

  // During motion: the same view is a motion frame with its PnP fit.
  MotionFrame latest;
  latest.R_target_cam = R_true;
  const std::optional<MotionFrame> motion = source->takeMotionFrame(
      imaged(30.0, sim::ImageRenderer::toMono8(rendered, config.pixel_noise_sigma, 9)), &latest);
  ASSERT_TRUE(motion);
  EXPECT_LT(angleBetweenDeg(motion->R_target_cam, R_true), 0.2);
  EXPECT_GT(motion->reprojection_dof, 0);
  EXPECT_GT(motion->cov_cam_rad2.trace(), 0.0);
}

TEST(CameraSources, ABoardNeverFoundIsSaidAndDetectionBacksOff) {
  SourceHarness h(boardTarget(scenario("nominal", 1)));
  h.inputs.intrinsics = intrinsicsOf(sim::CameraModel());
  std::unique_ptr<CameraSource> source = chooseCameraSource(InputStream::kImage, h.setup());
  const cv::Mat blank(480, 640, CV_8UC1, cv::Scalar(128));
  // 5 Hz for 3 s: tried at 30.0, 30.2, 30.4, then (3 misses in a row) 1 s apart: 31.4, 32.4.
  for (int k = 0; k <= 15; ++k)
    source->takeRestFrame(imaged(30.0 + 0.2 * k, blank), 30.0, h.history());
  h.inputs.frames = 16;
  EXPECT_EQ(h.inputs.detected, 5u);
  EXPECT_EQ(h.rejections.count(RejectReason::kTargetNotFound), 5u);
  ASSERT_FALSE(h.streams.empty());
  EXPECT_EQ(h.streams[0], InputStream::kImage);
  StationaryPose pose;
  StationaryWindow::Entry entry;
  EXPECT_EQ(source->assessRest(segment(30.0, 33.0), h.history(), &pose, &entry),
            "target seen in 0 frame(s), 2 needed");
  const std::string diagnosis = source->targetNotFoundDiagnosis(h.rejections);
  EXPECT_NE(diagnosis.find("was not found in any of 5 frames at rest"), std::string::npos)
      << diagnosis;
  // An image of another size than the camera info's is refused.
  source->takeRestFrame(imaged(40.0, cv::Mat(48, 64, CV_8UC1, cv::Scalar(0))), 40.0, h.history());
  EXPECT_EQ(h.rejections.count(RejectReason::kBadImage), 1u);
}

TEST(CameraSources, TheNaturalSceneLinksTwoRestsByTheirTrueRotation) {
  const sim::SimulationConfig config = scenario("room_handheld", 5);
  const sim::CameraModel camera = sim::CameraModel::fromConfig(config);
  const sim::SceneRenderer renderer(camera, sim::RoomScene::fromConfig(config), 2, 0.6);
  const Eigen::Vector3d centre(3.0, 2.5, 1.4);  // the room's free middle
  Eigen::Matrix3d along_x;                      // the camera looking along the room's +x, level
  along_x << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Matrix3d R1 = along_x * axisAngle(Eigen::Vector3d::UnitX(), -0.2);
  const Eigen::Matrix3d R2 = R1 * axisAngle(Eigen::Vector3d(0.3, 1.0, 0.4), 0.25);
  const Eigen::Matrix3d R_1_2 = R1.transpose() * R2;  // the second view in the first's frame
  const cv::Mat view1 = renderer.render(R1, centre), view2 = renderer.render(R2, centre);

  SourceHarness h{TargetDescription()};
  h.inputs.intrinsics = intrinsicsOf(camera);
  std::unique_ptr<CameraSource> source = chooseCameraSource(InputStream::kImage, h.setup());
  h.inputs.frames = 10;
  const auto rest = [&](int index, const cv::Mat& view, const Eigen::Matrix3d& R_world_cam,
                        double start_s, StationaryWindow::Entry* entry) {
    for (int k = 0; k < 5; ++k) {
      source->takeRestFrame(
          imaged(start_s + 0.2 * k, sim::ImageRenderer::toMono8(view, 1.0, 10 * index + k)),
          start_s, h.history());
    }
    StationaryPose pose;
    pose.index = index;
    pose.R_world_imu = R_world_cam;  // R_cam_imu = I: the IMU turns as the camera
    EXPECT_EQ(source->assessRest(segment(start_s, start_s + 1.0), h.history(), &pose, entry), "");
    h.poses.push_back(pose);
    return pose;
  };
  StationaryWindow::Entry first_entry, second_entry;
  const StationaryPose first = rest(0, view1, R1, 10.0, &first_entry);
  EXPECT_EQ(first.camera_source, PoseCameraSource::kScene);
  EXPECT_EQ(first.scene, 0);  // the first view starts scene 0, whose frame is its camera's
  EXPECT_LT(angleBetweenDeg(first.R_target_cam, Eigen::Matrix3d::Identity()), 1e-12);
  EXPECT_GT(first.scene_features, 100);
  EXPECT_TRUE(first_entry.camera_links.empty());
  EXPECT_FALSE(first_entry.joint.camera_absolute);

  const StationaryPose second = rest(1, view2, R2, 20.0, &second_entry);
  EXPECT_EQ(second.scene, 0);
  EXPECT_LT(angleBetweenDeg(second.R_target_cam, R_1_2), 0.2);
  ASSERT_EQ(second_entry.camera_links.size(), 1u);
  const CameraLink& link = second_entry.camera_links[0];
  EXPECT_EQ(link.from_pose, 0);
  EXPECT_EQ(link.to_pose, 1);
  EXPECT_LT(angleBetweenDeg(link.R_from_to, R_1_2), 0.2);
  ASSERT_EQ(second.scene_links.size(), 1u);
  EXPECT_EQ(second.scene_links[0].from_pose, 0);
  EXPECT_FALSE(source->takeMotionFrame(imaged(30.0, view1), nullptr));

  // The snapshot's refitter holds both views: the link fitted again near the truth.
  JointProblem problem;
  problem.camera_links.push_back(link);  // the window's poses 0 and 1 are poses 0 and 1
  const std::shared_ptr<const SceneLinkRefitter> refitter =
      source->sceneLinkRefitter(problem, {0, 1});
  ASSERT_NE(refitter, nullptr);
  EXPECT_EQ(refitter->key(0), SceneLinkKey(0, 1));
  const std::optional<SceneRotation> again = refitter->refit(0, R_1_2);
  ASSERT_TRUE(again);
  EXPECT_TRUE(again->ok) << again->message;
  EXPECT_LT(angleBetweenDeg(again->R_from_to, R_1_2), 0.2);
  // A remembered fit serves the next snapshot's refitter.
  SceneRefit fit;
  fit.key = {0, 1};
  fit.R_from_to_near = R_1_2;
  fit.rotation = *again;
  source->rememberRefits({fit});
  EXPECT_TRUE(source->sceneLinkRefitter(problem, {0, 1})->remembered(0, R_1_2));
}

}  // namespace
}  // namespace camera_imu_alignment
