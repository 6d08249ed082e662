// Cost of the natural-scene camera rotation (vision/scene_rotation.h) on one core
// (cv::setNumThreads(1)): SIFT extraction per 640x480 view (features and bearings), and per pair
// the matching and the rotation (both models, GRIC). The views are test/scene_texture.h's
// corner-rich texture under a 6.3 deg pure rotation (as test_scene_rotation renders them), f = 500
// px. Extraction is measured at the default settings and with fewer features, fewer octave layers
// and a higher contrast threshold; the pair at 1500 and 1000 features per view. Counters: the
// keypoints per view, the matches and inliers per pair.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "../test/scene_texture.h"
#include "camera_imu_alignment/vision/scene_rotation.h"

namespace cia = camera_imu_alignment;

namespace {

constexpr double kF = 500;

cia::CameraIntrinsics intrinsics() {
  const double K[9] = {kF, 0, 320, 0, kF, 240, 0, 0, 1};
  cia::CameraIntrinsics c;
  std::string error;
  cia::CameraIntrinsics::fromCameraInfo(640, 480, K, "", {}, &c, &error);
  return c;
}

/// The two views: the same orientations as test_scene_rotation's rendered pair.
struct Views {
  cv::Mat first, second;
  Eigen::Matrix3d R_from_to;  ///< truth
};

const Views& views() {
  static const Views pair = [] {
    const cv::Mat texture = cia::test::cornerTexture(1600, 1200, 7);
    const Eigen::Matrix3d K = intrinsics().K;
    const Eigen::Matrix3d R_G_from =
        Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.3, -1, 0.2).normalized()).toRotationMatrix();
    const Eigen::Matrix3d R_G_to =
        Eigen::AngleAxisd(0.09, Eigen::Vector3d(1, 0.4, -0.5).normalized()).toRotationMatrix();
    return Views{cia::test::renderRotatedView(texture, kF, K, R_G_from, cv::Size(640, 480)),
                 cia::test::renderRotatedView(texture, kF, K, R_G_to, cv::Size(640, 480)),
                 R_G_from.transpose() * R_G_to};
  }();
  return pair;
}

// Args: max_features, octave_layers, contrast_threshold x 1000, image_scale x 100.
void BM_ExtractFeatures(benchmark::State& state) {
  cia::SceneFeatureSettings settings;
  settings.max_features = static_cast<int>(state.range(0));
  settings.octave_layers = static_cast<int>(state.range(1));
  settings.contrast_threshold = state.range(2) / 1000.0;
  settings.image_scale = state.range(3) / 100.0;
  const cia::CameraIntrinsics camera = intrinsics();
  size_t keypoints = 0;
  for (auto _ : state) {
    const cia::SceneFeatures f = cia::extractSceneFeatures(views().first, camera, settings, 0);
    keypoints = f.keypoints.size();
    benchmark::DoNotOptimize(f.bearings.data());
  }
  state.counters["keypoints"] = static_cast<double>(keypoints);
}
BENCHMARK(BM_ExtractFeatures)
    ->Args({1500, 3, 40, 100})
    ->Args({1000, 3, 40, 100})
    ->Args({1000, 2, 40, 100})
    ->Args({1500, 3, 40, 50})
    ->Args({1000, 3, 40, 50})
    ->Unit(benchmark::kMillisecond);

void BM_ImageSharpness(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(cia::imageSharpness(views().first));
}
BENCHMARK(BM_ImageSharpness)->Unit(benchmark::kMillisecond);

// Args: max_features per view, image_scale x 100, refine_matches (0/1). Matching (ratio test,
// mutual check), the matches' refinement at full resolution and the rotation. Counter error_mdeg:
// the rotation's error (millidegrees).
void BM_PairRotation(benchmark::State& state) {
  cia::SceneFeatureSettings settings;
  settings.max_features = static_cast<int>(state.range(0));
  settings.image_scale = state.range(1) / 100.0;
  const cia::CameraIntrinsics camera = intrinsics();
  const cia::SceneFeatures from = cia::extractSceneFeatures(views().first, camera, settings, 0);
  const cia::SceneFeatures to = cia::extractSceneFeatures(views().second, camera, settings, 1);
  cia::SceneRotationSettings rotation_settings;
  rotation_settings.refine_matches = state.range(2) != 0;
  cia::SceneRotation r;
  for (auto _ : state) {
    r = cia::estimateSceneRotation(from, to, camera, std::nullopt, rotation_settings);
    benchmark::DoNotOptimize(r.R_from_to.data());
  }
  if (!r.ok) state.SkipWithError(r.message.c_str());
  state.counters["matches"] = r.matches;
  state.counters["inliers"] = r.inliers;
  state.counters["refined"] = r.refined_matches;
  state.counters["error_mdeg"] =
      1e3 * 180 / M_PI * Eigen::AngleAxisd(r.R_from_to.transpose() * views().R_from_to).angle();
}
BENCHMARK(BM_PairRotation)
    ->Args({1500, 100, 0})
    ->Args({1000, 100, 0})
    ->Args({1500, 50, 0})
    ->Args({1000, 50, 0})
    ->Args({1500, 100, 1})
    ->Args({1000, 50, 1})
    ->Unit(benchmark::kMillisecond);

// A link fitted again in the solve (estimateSceneRotationNear: the rotation held at the truth,
// 1.5 px gate) from the matches of its first fit, as the pipeline does; arg 0: matched again.
void BM_PairRotationHeld(benchmark::State& state) {
  const cia::SceneFeatureSettings settings;
  const cia::CameraIntrinsics camera = intrinsics();
  const cia::SceneFeatures from = cia::extractSceneFeatures(views().first, camera, settings, 0);
  const cia::SceneFeatures to = cia::extractSceneFeatures(views().second, camera, settings, 1);
  const cia::SceneRotation first =
      cia::estimateSceneRotation(from, to, camera, std::nullopt, cia::SceneRotationSettings());
  const bool reuse = state.range(0) != 0;
  cia::SceneRotation r;
  for (auto _ : state) {
    r = cia::estimateSceneRotationNear(from, to, camera, views().R_from_to, 1.5,
                                       cia::SceneRotationSettings(),
                                       reuse ? &first.matched : nullptr);
    benchmark::DoNotOptimize(r.R_from_to.data());
  }
  if (!r.ok) state.SkipWithError(r.message.c_str());
  state.counters["inliers"] = r.inliers;
  state.counters["error_mdeg"] =
      1e3 * 180 / M_PI * Eigen::AngleAxisd(r.R_from_to.transpose() * views().R_from_to).angle();
}
BENCHMARK(BM_PairRotationHeld)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  cv::setNumThreads(1);  // the budget is per core
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
