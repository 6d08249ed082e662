// Speed of the streaming parts of the calibration pipeline: what one IMU sample and one camera
// frame cost.
//
// Data: the simulator's scenarios (seed 11; camera_rate_hz 0.5, frames are rendered here, not by
// the run). The IMU stream is the "nominal" run: 200 Hz IMU, 100 Hz magnetometer, 12 stationary
// holds joined by full-axis motions (72 s: 14375 IMU, 7188 magnetometer samples), realistic
// MEMS noise.
//
// BM_StationaryDetectorPerSample: StationaryDetector::add over the whole IMU stream (a new
//   detector per pass, built outside the timing). Time: per pass; per_sample: per IMU sample.
// BM_PipelineAddImuPerSample: CalibrationPipeline::addImu and addMagnetic over the same stream,
//   merged in stamp order, no camera frames (so every rest is rejected for lack of frames). A new
//   pipeline per pass, built outside the timing. per_sample: pass time / number of IMU samples
//   (the magnetometer samples' cost included).
// BM_DetectAndPnP/<target>: TargetDetector::detect (no orientation hint) + estimateCameraPose on
//   640x480 frames rendered at the first kViews stationary holds of the scenario ("nominal":
//   checkerboard 8x6 inner corners; "aprilgrid"; "circlegrid"), with the simulator's blur and
//   pixel noise, cycled. Every frame is checked to detect and give a pose before timing. Time:
//   ms per frame.
// BM_DetectNoTarget/<target>: TargetDetector::detect on a frame without a target (uniform grey at
//   the simulator's background level, 1.5 grey levels of pixel noise): the cost of a miss. Time:
//   ms per frame.
// per_sample and items_per_second derive from CPU time (Google Benchmark's rate counters), which
// counts the calling thread only; on a loaded machine compare CPU time, not wall time.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/inertial/stationary_detector.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/vision/camera_model.h"
#include "camera_imu_alignment/vision/camera_pose.h"
#include "camera_imu_alignment/vision/target_description.h"
#include "camera_imu_alignment/vision/target_detector.h"

namespace cia = camera_imu_alignment;
namespace sim = camera_imu_alignment::simulation;

namespace {

constexpr int kViews = 4;  // rendered holds per target, cycled in the timing loop

sim::SimulationConfig scenarioConfig(const std::string& name) {
  sim::SimulationConfig c;
  c.seed = 11;
  if (!sim::applyScenario(name, &c)) std::abort();
  c.camera_rate_hz = 0.5;  // frame times only; keeps the run small
  return c;
}

cia::TargetDescription targetOf(const sim::SimulationConfig& c) {
  return cia::parseTargetYaml(sim::targetYaml(c.target), "simulated target");
}

cia::CameraIntrinsics intrinsicsOf(const sim::SimulationConfig& c) {
  cia::CameraIntrinsics intrinsics;
  intrinsics.width = c.width;
  intrinsics.height = c.height;
  intrinsics.K << c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0;
  intrinsics.distortion = cia::CameraIntrinsics::Distortion::kPlumbBob;
  intrinsics.D.assign(c.distortion.begin(), c.distortion.end());
  return intrinsics;
}

/// The nominal run's IMU and magnetometer samples in the pipeline's types (built once).
struct InertialStream {
  std::vector<cia::ImuSample> imu;
  std::vector<cia::MagneticSample> mag;
};

const InertialStream& nominalStream() {
  static const InertialStream stream = [] {
    const sim::SimulationRun run(scenarioConfig("nominal"));
    InertialStream s;
    for (const auto& x : run.imu) s.imu.push_back({x.t, x.gyro, x.accel});
    for (const auto& x : run.mag) s.mag.push_back({x.t, x.field});
    return s;
  }();
  return stream;
}

/// Per-pass time divided by `samples`, shown in seconds per sample.
benchmark::Counter perSample(double samples) {
  return benchmark::Counter(
      samples, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_StationaryDetectorPerSample(benchmark::State& state) {
  const std::vector<cia::ImuSample>& imu = nominalStream().imu;
  int segments = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto detector = std::make_unique<cia::StationaryDetector>();
    state.ResumeTiming();
    for (const cia::ImuSample& s : imu) {
      if (detector->add(s)) ++segments;
    }
    benchmark::DoNotOptimize(segments);
    state.PauseTiming();
    detector.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(imu.size()));
  state.counters["per_sample"] = perSample(static_cast<double>(imu.size()));
  state.counters["segments"] = static_cast<double>(segments) / state.iterations();
}

void BM_PipelineAddImuPerSample(benchmark::State& state) {
  const InertialStream& stream = nominalStream();
  const cia::TargetDescription target = targetOf(scenarioConfig("nominal"));
  for (auto _ : state) {
    state.PauseTiming();
    auto pipeline = std::make_unique<cia::CalibrationPipeline>(target, cia::PipelineSettings());
    state.ResumeTiming();
    std::size_t m = 0;
    for (const cia::ImuSample& s : stream.imu) {
      while (m < stream.mag.size() && stream.mag[m].stamp_s <= s.stamp_s) {
        pipeline->addMagnetic(stream.mag[m++]);
      }
      pipeline->addImu(s);
    }
    benchmark::DoNotOptimize(pipeline->segments().size());
    state.PauseTiming();
    pipeline.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(stream.imu.size()));
  state.counters["per_sample"] = perSample(static_cast<double>(stream.imu.size()));
}

/// A scenario's target, intrinsics and frames rendered at its first kViews holds (built once).
struct RenderedScenario {
  cia::TargetDescription target;
  cia::CameraIntrinsics intrinsics;
  std::vector<cv::Mat> frames;
  cv::Mat empty_frame;  // no target
};

const RenderedScenario& rendered(const std::string& scenario) {
  static std::map<std::string, RenderedScenario> cache;
  auto it = cache.find(scenario);
  if (it != cache.end()) return it->second;
  const sim::SimulationConfig c = scenarioConfig(scenario);
  const sim::SimulationRun run(c);
  const sim::ImageRenderer renderer(sim::CameraModel::fromConfig(c),
                                    sim::makeTargetTexture(c.target, sim::textureTexelFor(c)),
                                    c.supersample, c.blur_sigma_px);
  RenderedScenario out{targetOf(c), intrinsicsOf(c), {}, {}};
  const sim::Trajectory& tr = run.trajectory;
  const int views = std::min<int>(kViews, static_cast<int>(tr.poses().size()));
  for (int k = 0; k < views; ++k) {
    const double t = 0.5 * (tr.poses()[k].start_s + tr.poses()[k].end_s);
    out.frames.push_back(
        sim::ImageRenderer::toMono8(renderer.renderAt(tr, t), c.pixel_noise_sigma, 100 + k));
  }
  const sim::Photometry photometry;
  const double grey =
      photometry.black + photometry.background * (photometry.white - photometry.black);
  out.empty_frame = sim::ImageRenderer::toMono8(
      cv::Mat(c.height, c.width, CV_32F, cv::Scalar(grey)), c.pixel_noise_sigma, 7);
  return cache.emplace(scenario, std::move(out)).first->second;
}

void BM_DetectAndPnP(benchmark::State& state, const std::string& scenario) {
  const RenderedScenario& r = rendered(scenario);
  const cia::TargetDetector detector(r.target);
  const cia::PoseSettings pose_settings;
  auto detectAndPose = [&](const cv::Mat& frame, std::string* why) {
    cia::TargetObservation observation;
    if (!detector.detect(frame, &observation)) {
      *why = "not detected";
      return std::optional<cia::CameraPose>();
    }
    return cia::estimateCameraPose(observation, r.target, r.intrinsics, pose_settings, why);
  };
  for (std::size_t k = 0; k < r.frames.size(); ++k) {  // every frame must give a pose
    std::string why;
    if (!detectAndPose(r.frames[k], &why)) {
      state.SkipWithError(("frame " + std::to_string(k) + ": " + why).c_str());
      return;
    }
  }
  std::size_t k = 0, found = 0;
  for (auto _ : state) {
    std::string why;
    if (detectAndPose(r.frames[k], &why)) ++found;
    k = (k + 1) % r.frames.size();
  }
  state.counters["found"] = static_cast<double>(found) / state.iterations();
}

void BM_DetectNoTarget(benchmark::State& state, const std::string& scenario) {
  const RenderedScenario& r = rendered(scenario);
  const cia::TargetDetector detector(r.target);
  std::size_t found = 0;
  for (auto _ : state) {
    cia::TargetObservation observation;
    if (detector.detect(r.empty_frame, &observation)) ++found;
  }
  state.counters["found"] = static_cast<double>(found) / state.iterations();
}

}  // namespace

BENCHMARK(BM_StationaryDetectorPerSample)->Unit(benchmark::kMillisecond)->MinTime(0.5);
BENCHMARK(BM_PipelineAddImuPerSample)->Unit(benchmark::kMillisecond)->MinTime(0.5);
BENCHMARK_CAPTURE(BM_DetectAndPnP, checkerboard, std::string("nominal"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK_CAPTURE(BM_DetectAndPnP, aprilgrid, std::string("aprilgrid"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK_CAPTURE(BM_DetectAndPnP, circlegrid, std::string("circlegrid"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK_CAPTURE(BM_DetectNoTarget, checkerboard, std::string("nominal"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK_CAPTURE(BM_DetectNoTarget, aprilgrid, std::string("aprilgrid"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK_CAPTURE(BM_DetectNoTarget, circlegrid, std::string("circlegrid"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

BENCHMARK_MAIN();
