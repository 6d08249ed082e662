// The camera-model check (vision/camera_model_check.h) against independent truth: rendered views
// of the simulator's boards whose true focal length is known, read through a camera_info with the
// true K and with K scaled, and ViSP's real images with ViSP's own intrinsics (which must pass).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/vision/camera_model_check.h"
#include "camera_imu_alignment/vision/target_detector.h"
#include "visp_data.h"

namespace camera_imu_alignment {
namespace {

using simulation::SimulationConfig;

/// The significance level the pipeline judges at (CalibrationPipeline).
constexpr double kLevel = 1e-4;

CameraIntrinsics intrinsicsOf(const SimulationConfig& c, double focal_scale) {
  const double K[9] = {focal_scale * c.fx, 0, c.cx, 0, focal_scale * c.fy, c.cy, 0, 0, 1};
  CameraIntrinsics intrinsics;
  std::string error;
  const std::vector<double> D(c.distortion.begin(), c.distortion.end());
  EXPECT_TRUE(
      CameraIntrinsics::fromCameraInfo(c.width, c.height, K, "plumb_bob", D, &intrinsics, &error))
      << error;
  return intrinsics;
}

/// The detections of the held poses of a simulated run, rendered as the simulator renders them.
struct RenderedRun {
  SimulationConfig config;
  TargetDescription target;
  std::vector<TargetObservation> observations;
};

SimulationConfig configOf(const std::string& scenario, unsigned seed) {
  SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(simulation::applyScenario(scenario, &c));
  return c;
}

RenderedRun renderRun(const SimulationConfig& config, int max_views) {
  RenderedRun out;
  out.config = config;
  const SimulationConfig& c = out.config;
  out.target = parseTargetYaml(simulation::targetYaml(c.target), "simulated target");
  const simulation::SimulationRun run(c);
  const simulation::ImageRenderer renderer(
      simulation::CameraModel::fromConfig(c),
      simulation::makeTargetTexture(c.target, simulation::textureTexelFor(c)), c.supersample,
      c.blur_sigma_px);
  const TargetDetector detector(out.target);
  const auto& tr = run.trajectory;
  for (int k = 0; k < std::min<int>(max_views, tr.poses().size()); ++k) {
    const auto& p = tr.poses()[k];
    const Eigen::Matrix3d R_target_cam = tr.R_world_target().transpose() * p.R_world_cam;
    const Eigen::Vector3d p_target_cam =
        tr.R_world_target().transpose() * (p.p_world_cam - tr.p_world_target());
    const cv::Mat image = simulation::ImageRenderer::toMono8(
        renderer.render(R_target_cam, p_target_cam), c.pixel_noise_sigma, 99 + k);
    TargetObservation observation;
    if (detector.detect(image, &observation, &R_target_cam)) {
      out.observations.push_back(observation);
    }
  }
  EXPECT_GE(static_cast<int>(out.observations.size()), std::min(max_views, 4))
      << " seed " << c.seed;
  return out;
}

CameraModelCheck checkRun(const RenderedRun& run, double focal_scale) {
  const CameraIntrinsics intrinsics = intrinsicsOf(run.config, focal_scale);
  std::vector<CameraModelFit> views;
  for (const TargetObservation& o : run.observations) {
    const auto fit = fitCameraModel(o, run.target, intrinsics);
    EXPECT_TRUE(fit);
    if (fit) views.push_back(*fit);
  }
  return checkCameraModel(views, kLevel, &intrinsics);
}

std::string describe(const CameraModelCheck& c) {
  std::ostringstream out;
  out << "views " << c.views << ", focal factor " << c.focal_scale << " +- " << c.focal_scale_sigma
      << " (p " << c.p_value << "), median view p " << c.view_p_value << ", reprojection "
      << c.reprojection_rms_px << " px, noise " << c.noise_rms_px << " px";
  return out.str();
}

TEST(CameraModelCheck, TheTrueIntrinsicsPass) {
  for (const std::string scenario : {"nominal", "wall_board"}) {
    for (unsigned seed = 1; seed <= 6; ++seed) {
      const RenderedRun run = renderRun(configOf(scenario, seed), 8);
      const CameraModelCheck check = checkRun(run, 1.0);
      std::cout << scenario << " seed " << seed << ", true K: " << describe(check) << "\n";
      EXPECT_TRUE(check.tested);
      EXPECT_FALSE(check.wrong) << check.message;
      EXPECT_TRUE(check.message.empty());
      EXPECT_NEAR(check.focal_scale, 1.0, 4.0 * check.focal_scale_sigma + 1e-9);
    }
  }
}

TEST(CameraModelCheck, OtherTargetsAndADistortedLensWithTheTrueIntrinsicsPass) {
  // Circle centres are biased by perspective (test_target_detection): a model error of the target,
  // not of K; the aprilgrid; plumb_bob distortion in the true camera_info.
  for (const std::string scenario : {"aprilgrid", "circlegrid", "distorted"}) {
    SimulationConfig c = configOf(scenario == "distorted" ? "nominal" : scenario, 7);
    if (scenario == "distorted") c.distortion = {-0.25, 0.08, 0.001, -0.0005, 0.0};
    const RenderedRun run = renderRun(c, 8);
    const CameraModelCheck check = checkRun(run, 1.0);
    std::cout << scenario << ", true K: " << describe(check) << "\n";
    EXPECT_TRUE(check.tested) << scenario;
    EXPECT_FALSE(check.wrong) << scenario << ": " << check.message;
  }
}

TEST(CameraModelCheck, AFocalLengthThirtyPercentOffIsNamedWithItsFactor) {
  const RenderedRun run = renderRun(configOf("wall_board", 4), 8);
  for (const double scale : {1.3, 0.7}) {
    const CameraModelCheck check = checkRun(run, scale);
    std::cout << "camera_info K x " << scale << ": " << describe(check) << "\n  " << check.message
              << "\n";
    EXPECT_TRUE(check.wrong);
    // The images' focal length is camera_info's / scale (truth), within 2 %.
    EXPECT_NEAR(check.focal_scale * scale, 1.0, 0.02);
    EXPECT_NE(check.message.find("camera_info"), std::string::npos);
    EXPECT_GT(check.reprojection_rms_px, 3.0 * check.noise_rms_px);
  }
}

TEST(CameraModelCheck, ASmallFocalErrorIsMeasuredAndJudgedByItsSignificance) {
  // 2 %: the simulator's corners (about 0.03 px of noise) can tell it; the factor must be found
  // within its stated uncertainty whatever the verdict.
  const RenderedRun run = renderRun(configOf("wall_board", 5), 8);
  const CameraModelCheck check = checkRun(run, 1.02);
  std::cout << "camera_info K x 1.02: " << describe(check) << "; wrong: " << check.wrong << "\n";
  EXPECT_NEAR(check.focal_scale * 1.02, 1.0, 4.0 * check.focal_scale_sigma * 1.02 + 0.002);
  EXPECT_EQ(check.wrong, check.p_value < kLevel && check.view_p_value < kLevel);
}

TEST(CameraModelCheck, FewerThanTwoViewsAreNotTested) {
  const RenderedRun run = renderRun(configOf("nominal", 6), 1);
  const CameraModelCheck check = checkRun(run, 1.3);
  EXPECT_FALSE(check.tested);
  EXPECT_FALSE(check.wrong);
}

#ifndef CIA_REALDATA_DIR
#define CIA_REALDATA_DIR "/work/shared/realdata"
#endif

TEST(CameraModelCheck, VispRealImagesWithVispsIntrinsicsPass) {
  const std::string dir = test::vispDir();
  if (!std::ifstream(dir + "/franka_image-1.png")) GTEST_SKIP() << "no realdata at " << dir;
  test::VispViews visp;
  std::string error;
  ASSERT_TRUE(test::loadVispViews(&visp, &error)) << error;
  const TargetDescription& board = visp.board;
  const CameraIntrinsics& intrinsics = visp.intrinsics;
  std::vector<CameraModelFit> views;
  for (int i = 1; i <= 8; ++i) {
    const TargetObservation& observation = visp.observations[i - 1];
    const auto start = std::chrono::steady_clock::now();
    const auto fit = fitCameraModel(observation, board, intrinsics);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(fit) << i;
    std::cout << "ViSP image " << i << " (fitted in " << ms << " ms): reprojection "
              << fit->reprojectionRmsPx() << " px, homography " << fit->noiseRmsPx()
              << " px, focal factor " << fit->focal_scale << " +- " << fit->focal_scale_sigma
              << ", F " << fit->f_statistic << " p " << fit->p_value << "\n";
    views.push_back(*fit);
  }
  const CameraModelCheck check = checkCameraModel(views, kLevel, &intrinsics);
  std::cout << "ViSP: " << describe(check) << "\n";
  EXPECT_TRUE(check.tested);
  EXPECT_FALSE(check.wrong) << check.message;
  // ViSP's K scaled by 1.3 is named.
  CameraIntrinsics scaled = intrinsics;
  scaled.K(0, 0) *= 1.3;
  scaled.K(1, 1) *= 1.3;
  std::vector<CameraModelFit> scaled_views;
  for (const TargetObservation& observation : visp.observations) {
    const auto fit = fitCameraModel(observation, board, scaled);
    ASSERT_TRUE(fit);
    scaled_views.push_back(*fit);
  }
  const CameraModelCheck wrong = checkCameraModel(scaled_views, kLevel, &scaled);
  std::cout << "ViSP, K x 1.3: " << describe(wrong) << "\n";
  EXPECT_TRUE(wrong.wrong);
  EXPECT_NEAR(wrong.focal_scale * 1.3, 1.0, 0.03);
}

}  // namespace
}  // namespace camera_imu_alignment
