// The online calibrator's two costs with a full window (the callbacks must never block):
//   BM_SampleCallbacks: every sample call (addImu, addMagnetic, addFrame) of a 40-pose recording
//     fed to a threaded OnlineCalibrator with window_poses 30, i.e. what a subscriber callback
//     spends in the core. Counters: mean_us per call, max_us the slowest call (a pose completing:
//     its statistics and the window snapshot handed to the worker).
//   BM_WindowSolve: the worker's job on a full 30-pose window: the pair estimators, the joint
//     estimate and the change-point test (4 two-mount solves): the latency from a pose to its
//     estimate.
//   BM_WindowSolveTwelveRests: the same job on the default recording (12 rests, consumer unit) with
//     the camera's orientations during the motion between the rests (motion nodes) in the window.
// Data: the simulator's long_run scenario (40 poses, consumer IMU grade), camera orientations
// given with 0.03 deg noise (no images: detection is benchmarked in bench_pipeline).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>

#include "../test/pipeline_simulation.h"
#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/solve/window_solver.h"

namespace cia = camera_imu_alignment;
namespace sim = camera_imu_alignment::simulation;

namespace {

const sim::SimulationRun& longRun() {
  static const std::unique_ptr<sim::SimulationRun> run = [] {
    sim::SimulationConfig c;
    c.seed = 5;
    sim::applyScenario("long_run", &c);
    sim::applyImuGrade(sim::ImuGrade::kConsumer, &c);
    return std::make_unique<sim::SimulationRun>(c);
  }();
  return *run;
}

cia::PipelineSettings settings() {
  cia::PipelineSettings s;
  s.window_poses = 30;
  s.joint = cia::test::jointSettingsFor(longRun().config);
  return s;
}

/// Forwards to the calibrator and times every call.
class TimingSink : public cia::SampleSink {
 public:
  explicit TimingSink(cia::OnlineCalibrator* target) : target_(target) {}
  void addImu(const cia::ImuSample& s) override {
    time([&] { target_->addImu(s); });
  }
  void addMagnetic(const cia::MagneticSample& s) override {
    time([&] { target_->addMagnetic(s); });
  }
  bool setCameraIntrinsics(const cia::CameraIntrinsics& i) override {
    return target_->setCameraIntrinsics(i);
  }
  void addFrame(const cia::CameraFrame& f) override {
    time([&] { target_->addFrame(f); });
  }
  void rejectInput(cia::RejectReason r, cia::InputStream s, const std::string& d) override {
    target_->rejectInput(r, s, d);
  }
  cia::ImuOrientationSource imuOrientationSource() const override {
    return target_->imuOrientationSource();
  }
  double total_s = 0.0, max_s = 0.0;
  long calls = 0;

 private:
  template <typename F>
  void time(F&& f) {
    const auto start = std::chrono::steady_clock::now();
    f();
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    total_s += s;
    max_s = std::max(max_s, s);
    ++calls;
  }
  cia::OnlineCalibrator* target_;
};

void BM_SampleCallbacks(benchmark::State& state) {
  const sim::SimulationRun& run = longRun();
  const cia::TargetDescription target =
      cia::parseTargetYaml(sim::targetYaml(run.config.target), "target");
  double total_s = 0.0, max_s = 0.0;
  long calls = 0;
  for (auto _ : state) {
    cia::OnlineSettings online;
    online.threaded = true;
    cia::OnlineCalibrator calibrator(target, settings(), online, {});
    TimingSink sink(&calibrator);
    cia::test::feedSinkWithoutImages(run, &sink, 0.03);
    calibrator.finish();
    state.PauseTiming();
    calibrator.waitForSolves();
    state.ResumeTiming();
    total_s += sink.total_s;
    max_s = std::max(max_s, sink.max_s);
    calls += sink.calls;
  }
  state.counters["mean_us"] = calls > 0 ? 1e6 * total_s / calls : 0.0;
  state.counters["max_us"] = 1e6 * max_s;
  state.counters["calls"] = static_cast<double>(calls) / std::max<double>(1, state.iterations());
}
BENCHMARK(BM_SampleCallbacks)->Unit(benchmark::kMillisecond)->Iterations(3);

/// The worker's job on `window`: the solve with the mount-change stage, as the calibrator asks.
void solveWindowJob(benchmark::State& state, const cia::WindowSnapshot& window,
                    const cia::PipelineSettings& settings) {
  const cia::WindowSolver solver(settings);
  cia::WindowSolveRequest request;
  request.test_mount_change = true;
  for (auto _ : state) {
    const cia::WindowSolveOutput out = solver.solve(window, request);
    if (!out.result.joint || !out.result.joint->ok || !out.mount_test) {
      state.SkipWithError("the joint estimate failed");
      break;
    }
    benchmark::DoNotOptimize(out.mount_test->p_value);
  }
  state.counters["poses"] = static_cast<double>(window.pose_indices.size());
  state.counters["motion_nodes"] = static_cast<double>(window.joint.motion_frames.size());
}

void BM_WindowSolve(benchmark::State& state) {
  static const cia::WindowSnapshot window = [] {
    const auto pipeline = cia::test::feedWithoutImages(longRun(), settings(), 0.03);
    return pipeline->snapshot();
  }();
  solveWindowJob(state, window, settings());
}
BENCHMARK(BM_WindowSolve)->Unit(benchmark::kMillisecond);

void BM_WindowSolveTwelveRests(benchmark::State& state) {
  static const std::unique_ptr<sim::SimulationRun> run = [] {
    sim::SimulationConfig c;
    c.seed = 5;
    sim::applyScenario("nominal", &c);
    sim::applyImuGrade(sim::ImuGrade::kConsumer, &c);
    return std::make_unique<sim::SimulationRun>(c);
  }();
  cia::PipelineSettings s;
  s.joint = cia::test::jointSettingsFor(run->config);
  static const cia::WindowSnapshot window = [&] {
    return cia::test::feedWithoutImages(*run, s, 0.03)->snapshot();
  }();
  solveWindowJob(state, window, s);
}
BENCHMARK(BM_WindowSolveTwelveRests)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
