// Recordings without rests: the cost of continuous-motion calibration on one core.
//   BM_MotionWindowSolve: solveWindow on the final window of a 60 s waving recording with 1201
//     camera frames (20 Hz, all kept: motion_frame_interval_s 0.05): the coarse time offset, the
//     motion pairs and pair solvers, and the joint estimate with its motion nodes and time offset.
//     Target: <= 2 s. Counters: frames, nodes (motion nodes used), joint_ms (the joint estimator's
//     own solve_time_s), err_deg (against the truth), dt_ms (time offset error).
//   BM_MotionPipelineIngest: the same recording (12000 IMU samples, 6000 magnetometer samples,
//     1201 camera orientations) fed to a new CalibrationPipeline, no solve: samples_per_s.
//   BM_MotionOnlineCalibrator: the same fed to an OnlineCalibrator solving on the caller's thread
//     (a motion solve every 100 motion frames) and calibrateNow at the end: the whole recording's
//     compute as calibrate_bag spends it. Counters: solves, realtime_factor (60 s of data over the
//     time taken).
// Data: the simulator's waving scenario (seed 5, consumer grade with its own priors, camera
// orientations with 0.02 deg noise, camera stamps 15 ms behind the IMU's clock).
#include <benchmark/benchmark.h>

#include <memory>

#include "../test/pipeline_simulation.h"
#include "../test/waving_sessions.h"

namespace cia = camera_imu_alignment;
namespace sim = camera_imu_alignment::simulation;

namespace {

constexpr double kTimeshiftS = 0.015;

const sim::SimulationRun& wavingRun() {
  static const std::unique_ptr<sim::SimulationRun> run = std::make_unique<sim::SimulationRun>(
      cia::test::wavingConfig(sim::ImuGrade::kConsumer, 5, kTimeshiftS, 20.0));
  return *run;
}

cia::PipelineSettings settings() {
  cia::PipelineSettings s;
  s.joint = cia::test::jointSettingsFor(wavingRun().config);
  return s;
}

void BM_MotionWindowSolve(benchmark::State& state) {
  static const cia::WindowSnapshot window = [] {
    cia::CalibrationPipeline pipeline(cia::test::simulatedTarget(wavingRun().config), settings());
    cia::test::feedOrientations(wavingRun(), &pipeline);
    pipeline.finish();
    return pipeline.snapshot();
  }();
  const cia::PipelineSettings s = settings();
  const Eigen::Matrix3d R_true = wavingRun().trajectory.R_cam_imu_final();
  double joint_s = 0.0, err_deg = 0.0, dt_s = 0.0;
  int nodes = 0;
  for (auto _ : state) {
    const cia::AlignmentResult result = cia::solveWindow(window, s);
    if (!result.joint || !result.joint->ok) {
      state.SkipWithError("the joint estimate failed");
      break;
    }
    joint_s = result.joint->solve_time_s;
    nodes = result.joint->motion_nodes;
    err_deg = cia::rad2deg(cia::geodesicDistance(result.R_cam_imu, R_true));
    dt_s = result.joint->timeshift_cam_imu_s - kTimeshiftS;
  }
  state.counters["frames"] = static_cast<double>(window.joint.motion_frames.size());
  state.counters["nodes"] = nodes;
  state.counters["joint_ms"] = 1e3 * joint_s;
  state.counters["err_deg"] = err_deg;
  state.counters["dt_ms"] = 1e3 * dt_s;
}
BENCHMARK(BM_MotionWindowSolve)->Unit(benchmark::kMillisecond);

void BM_MotionPipelineIngest(benchmark::State& state) {
  const sim::SimulationRun& run = wavingRun();
  const cia::TargetDescription target = cia::test::simulatedTarget(run.config);
  const cia::PipelineSettings s = settings();
  for (auto _ : state) {
    cia::CalibrationPipeline pipeline(target, s);
    cia::test::feedOrientations(run, &pipeline);
    pipeline.finish();
    benchmark::DoNotOptimize(pipeline.snapshot().joint.motion_frames.size());
  }
  const double samples =
      static_cast<double>(run.imu.size() + run.mag.size() + run.camera_orientations.size());
  state.counters["samples_per_s"] =
      benchmark::Counter(samples * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MotionPipelineIngest)->Unit(benchmark::kMillisecond);

void BM_MotionOnlineCalibrator(benchmark::State& state) {
  const sim::SimulationRun& run = wavingRun();
  const cia::TargetDescription target = cia::test::simulatedTarget(run.config);
  const cia::PipelineSettings s = settings();
  std::size_t solves = 0;
  bool broadcast = false;
  for (auto _ : state) {
    std::size_t estimates = 0;
    cia::OnlineCallbacks callbacks;
    callbacks.on_estimate = [&estimates](const cia::EstimateEvent&) { ++estimates; };
    cia::OnlineSettings online;
    online.threaded = false;
    cia::OnlineCalibrator calibrator(target, s, online, callbacks);
    cia::test::feedOrientations(run, &calibrator);
    calibrator.finish();
    calibrator.calibrateNow(false);
    broadcast = calibrator.snapshot(cia::SnapshotContents::kState).broadcast.has_value();
    solves = estimates;
  }
  state.counters["solves"] = static_cast<double>(solves);
  state.counters["broadcast"] = broadcast;
  state.counters["realtime_factor"] = benchmark::Counter(
      run.config.waving_duration_s * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MotionOnlineCalibrator)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
