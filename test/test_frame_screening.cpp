// Frames during motion judged by their reprojection error against the recording's own
// (pipeline/frame_screening.h, issue 25): on constructed fits drawn from the chi-square model
// (frames with twice the pixel error dropped when the others agree; gross misfits dropped and
// sound frames kept when the frames' errors differ by 10x; the same decisions for a camera with 7x
// the pixel error, where a 1 px threshold would drop every frame; orientations without a fit
// kept); on rendered frames of the waving scenario: every sharp frame kept, frames with a
// mis-detected corner dropped, and frames blurred by a 60 ms exposure at 50-100 deg/s kept because
// their fit is as good (the simulator's blur is symmetric about the capture time: the corners stay
// at the streaks' centres). The pipeline's motion frames (screenMotionFrames): judged the same way,
// the setting max_reprojection_rms_px only when fewer than 10 frames have a fit; through the
// pipeline, rendered waving frames are kept under a pixel threshold chosen for another camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "camera_imu_alignment/pipeline/frame_screening.h"
#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/solve/window_solver.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/camera_pose.h"
#include "camera_imu_alignment/vision/target_description.h"
#include "camera_imu_alignment/vision/target_detector.h"
#include "pipeline_simulation.h"
#include "test_helpers.h"
#include "waving_sessions.h"

namespace camera_imu_alignment {
namespace {

/// A PnP fit of `corners` points whose coordinates have pixel noise `sigma_px`: RMS over the
/// points of the residual distance, its 2 N - 6 coordinates chi-square distributed.
FrameFit drawnFit(std::mt19937_64& rng, int corners, double sigma_px) {
  std::normal_distribution<double> normal(0.0, sigma_px);
  const int dof = 2 * corners - 6;
  double sum = 0.0;
  for (int i = 0; i < dof; ++i) sum += std::pow(normal(rng), 2);
  return {std::sqrt(sum / corners), dof};
}

/// Indices of the dropped frames.
std::vector<int> droppedOf(const FrameScreening& s) {
  std::vector<int> out;
  for (std::size_t k = 0; k < s.keep.size(); ++k) {
    if (!s.keep[k]) out.push_back(static_cast<int>(k));
  }
  return out;
}

TEST(FrameScreening, FramesWithTwiceThePixelErrorOfAgreeingOthersAreDropped) {
  std::mt19937_64 rng(5);
  std::vector<FrameFit> fits;
  std::vector<int> poor;
  for (int k = 0; k < 400; ++k) {
    const bool bad = k % 37 == 0;
    fits.push_back(drawnFit(rng, 48, bad ? 0.4 : 0.2));
    if (bad) poor.push_back(k);
  }
  fits.push_back({std::numeric_limits<double>::quiet_NaN(), 90});  // a failed fit
  fits.push_back({5.0, 0});  // a given orientation (camera_pose): nothing to judge
  poor.push_back(400);
  const FrameScreening screening = screenFramesByReprojection(fits);
  ASSERT_EQ(screening.keep.size(), fits.size());
  EXPECT_EQ(droppedOf(screening), poor);
  EXPECT_NEAR(screening.typical_rms_px, 0.2 * std::sqrt(90.0 / 48.0), 0.01);
  EXPECT_NE(screening.note.find("12 of 401 frames dropped"), std::string::npos) << screening.note;

  // Another camera, 7x the pixel error everywhere: a 1 px threshold would drop every frame; the
  // screening decides the same.
  std::vector<FrameFit> scaled = fits;
  for (FrameFit& f : scaled) f.reprojection_rms_px *= 7.0;
  const FrameScreening same = screenFramesByReprojection(scaled);
  EXPECT_EQ(same.keep, screening.keep);
  EXPECT_GT(same.typical_rms_px, 1.0);

  // Too few frames to judge: the finite fits kept.
  const std::vector<FrameFit> few(fits.begin() + 1, fits.begin() + 10);
  EXPECT_EQ(screenFramesByReprojection(few).dropped, 0);
}

TEST(FrameScreening, GrossMisfitsAreDroppedAndSoundFramesKeptWhenTheFramesDifferTenfold) {
  // Pixel noise per frame log-uniform in 0.03-0.3 px (distance, view angle, aliasing differ), 20
  // to 48 corners; every 50th frame a misfit 100x its noise (a corner matched to its neighbour,
  // tens of px away). The limit: a misfit within the recording's own spread of errors (30x at the
  // low end here) is not told from a sound noisier frame; its PnP covariance weights it instead.
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> log_sigma(std::log(0.03), std::log(0.3));
  std::uniform_int_distribution<int> corners(20, 48);
  std::vector<FrameFit> fits;
  std::vector<int> gross;
  for (int k = 0; k < 600; ++k) {
    const double sigma = std::exp(log_sigma(rng));
    const bool bad = k % 50 == 7;
    fits.push_back(drawnFit(rng, corners(rng), bad ? 100.0 * sigma : sigma));
    if (bad) gross.push_back(k);
  }
  const FrameScreening screening = screenFramesByReprojection(fits);
  EXPECT_EQ(droppedOf(screening), gross) << screening.note;
}

TEST(FrameScreening, RenderedSharpAndBlurredFramesAreKeptAndAMisdetectedCornerDropped) {
  namespace sim = simulation;
  const sim::SimulationConfig c = test::wavingConfig(sim::ImuGrade::kConsumer, 2);
  const sim::SimulationRun run(c);
  const sim::ImageRenderer renderer(sim::CameraModel::fromConfig(c),
                                    sim::makeTargetTexture(c.target, sim::textureTexelFor(c)),
                                    c.supersample, c.blur_sigma_px);
  const TargetDescription target = test::simulatedTarget(c);
  const TargetDetector detector(target);
  const CameraIntrinsics intrinsics = test::simulatedIntrinsics(c);
  PoseSettings settings;
  settings.max_reprojection_rms_px = std::numeric_limits<double>::infinity();  // judged here
  constexpr double kExposureS = 0.06;  // 3-6 deg of rotation during the exposure
  enum Kind { kSharp, kBlurred, kMisdetected };
  std::vector<FrameFit> fits;
  std::vector<Kind> kinds;
  int counts[3] = {0, 0, 0};
  for (std::size_t j = 0; j < run.camera_orientations.size() && counts[kSharp] < 30; j += 7) {
    const sim::CameraOrientation& o = run.camera_orientations[j];
    const double speed_deg_s = rad2deg(run.trajectory.at(o.capture_s).omega_cam.norm());
    if (speed_deg_s < 50.0) continue;  // fast motion only
    const Kind kind = j % 4 == 0 && counts[kBlurred] < 8       ? kBlurred
                      : j % 4 == 1 && counts[kMisdetected] < 4 ? kMisdetected
                                                               : kSharp;
    const cv::Mat mono = sim::ImageRenderer::toMono8(
        renderer.renderAt(run.trajectory, o.capture_s, kind == kBlurred ? kExposureS : 0.0),
        c.pixel_noise_sigma, run.frameNoiseSeed(j));
    TargetObservation observation;
    ASSERT_TRUE(detector.detect(mono, &observation, &o.R_target_cam_true)) << "frame " << j;
    if (kind == kMisdetected) {  // two corners found 3 px off
      observation.image_points[5] += cv::Point2f(3.0f, 0.0f);
      observation.image_points[20] += cv::Point2f(0.0f, -3.0f);
    }
    std::string why;
    const auto pose = estimateCameraPose(observation, target, intrinsics, settings, &why);
    ASSERT_TRUE(pose) << "frame " << j << ": " << why;
    fits.push_back({pose->reprojection_rms_px, 2 * pose->num_points - 6});
    kinds.push_back(kind);
    ++counts[kind];
    const double error_deg = test::angleBetweenDeg(pose->R_target_cam, o.R_target_cam_true);
    if (kind == kBlurred) {
      EXPECT_LT(error_deg, 0.1) << "frame " << j << ": the fit is sound";
    }
    std::printf("frame %3zu at %3.0f deg/s %-12s reprojection RMS %.3f px, PnP %.3f deg off\n", j,
                speed_deg_s,
                kind == kSharp     ? "sharp"
                : kind == kBlurred ? "blurred"
                                   : "misdetected",
                pose->reprojection_rms_px, error_deg);
  }
  ASSERT_EQ(counts[kSharp], 30);
  ASSERT_EQ(counts[kBlurred], 8);
  ASSERT_EQ(counts[kMisdetected], 4);
  const FrameScreening screening = screenFramesByReprojection(fits);
  for (std::size_t k = 0; k < fits.size(); ++k) {
    EXPECT_EQ(screening.keep[k], kinds[k] != kMisdetected) << "frame " << k << ": " << kinds[k];
  }
  std::printf("typical %.3f px, spread of log r %.2f: %s\n", screening.typical_rms_px,
              screening.spread, screening.note.c_str());
}

MotionFrame frameWithFit(double stamp_s, double rms_px, int dof) {
  MotionFrame frame;
  frame.stamp_s = stamp_s;
  frame.reprojection_rms_px = rms_px;
  frame.reprojection_dof = dof;
  return frame;
}

TEST(MotionFrameScreening, TheWindowsFramesAreJudgedByEachOtherAndTheDroppedErased) {
  std::mt19937_64 rng(11);
  std::vector<MotionFrame> frames;
  std::vector<double> poor_stamps;
  for (int k = 0; k < 60; ++k) {
    const bool bad = k % 20 == 3;
    const FrameFit fit = drawnFit(rng, 48, bad ? 10.0 : 1.5);  // a camera at 1.5 px
    frames.push_back(frameWithFit(0.05 * k, fit.reprojection_rms_px, fit.dof));
    if (bad) poor_stamps.push_back(frames.back().stamp_s);
  }
  frames.push_back(frameWithFit(3.5, 0.0, 0));  // a given orientation: kept
  const FrameScreening screening = screenMotionFrames(&frames, 1.0);
  EXPECT_EQ(screening.dropped, 3) << screening.note;
  ASSERT_EQ(frames.size(), 58u);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_EQ(std::count(poor_stamps.begin(), poor_stamps.end(), frames[k].stamp_s), 0);
    if (k > 0) {
      EXPECT_GT(frames[k].stamp_s, frames[k - 1].stamp_s) << "stamp order kept";
    }
  }
  EXPECT_GT(screening.typical_rms_px, 1.0) << "above the 1 px setting, and kept";
}

TEST(MotionFrameScreening, TooFewFramesToJudgeFallBackToTheSetting) {
  std::vector<MotionFrame> frames = {frameWithFit(0.0, 0.2, 90), frameWithFit(0.1, 0.3, 90),
                                     frameWithFit(0.2, 1.6, 90), frameWithFit(0.3, 0.25, 90),
                                     frameWithFit(0.4, 2.0, 0)};  // a given orientation
  const FrameScreening screening = screenMotionFrames(&frames, 1.0);
  EXPECT_EQ(screening.dropped, 1);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[2].stamp_s, 0.3);
  EXPECT_NE(screening.note.find("max_reprojection_rms_px"), std::string::npos) << screening.note;
}

// Through the pipeline: 20 s of the waving scenario rendered at 10 Hz, PnP on every frame, with a
// pixel threshold chosen for another camera (0.01 px; these frames fit at 0.02-0.1 px). Every
// motion frame was refused by it before the frames were judged against each other; now they are
// kept, none dropped, and the motion calibrates R_cam_imu within its 3-sigma.
TEST(MotionFrameScreening, RenderedWavingFramesAreNotJudgedByAnotherCamerasThreshold) {
  simulation::SimulationConfig c =
      test::wavingConfig(simulation::ImuGrade::kConsumer, 4, 0.015, 10.0);
  c.waving_duration_s = 20.0;
  c.images = true;
  const simulation::SimulationRun run(c);
  PipelineSettings settings;
  settings.pose.max_reprojection_rms_px = 0.01;
  settings.joint = test::jointSettingsFor(c);
  CalibrationPipeline pipeline(test::simulatedTarget(c), settings);
  test::feedRenderedRun(run, &pipeline);
  pipeline.finish();
  EXPECT_GT(pipeline.motionFrames(), 150u) << "frames with the target in view, 200 rendered";
  const AlignmentResult result = solveWindow(pipeline.snapshot(), pipeline.settings());
  ASSERT_TRUE(result.joint && result.joint->ok) << result.message;
  EXPECT_EQ(result.joint->motion.frames_dropped, 0);
  EXPECT_GT(result.joint->motion_nodes, 50);
  const double error_deg =
      test::angleBetweenDeg(result.R_cam_imu, run.trajectory.R_cam_imu_final());
  std::printf("%llu motion frames, %d nodes: %.3f deg from the truth, 1-sigma norm %.3f deg\n",
              static_cast<unsigned long long>(pipeline.motionFrames()), result.joint->motion_nodes,
              error_deg, result.quality.std_dev_deg.norm());
  EXPECT_LT(error_deg, 3.0 * result.quality.std_dev_deg.norm());
}

}  // namespace
}  // namespace camera_imu_alignment
