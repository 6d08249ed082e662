// Error budget of the joint estimate on the noisy IMU grade (MPU-6050 class on a vibrating mount):
// which of the unit's error sources limits R_cam_imu. Each row simulates the noisy grade with one
// source set to the consumer grade's value (simulation/imu_grades.cpp) and runs the pipeline's
// joint estimate with the recording's own priors (test::jointSettingsFor), camera orientations
// given with 0.03 deg noise per frame (no images). The row "intrinsics known" is the bound an
// estimate reaches when the IMU's errors (scale, axes, biases, iron) are known exactly: what
// carrying them across a remount could gain at most.
//
// Counters: rms_deg, the RMS geodesic error over the seeds; sigma_deg, the mean of the reported
// per-axis 1-sigma's norm (the error's expected RMS when the 1-sigma is honest); solved, runs with
// a joint estimate. The time is that of the whole Monte Carlo (simulation included): not a target.
// Arguments: poses per recording. Results in BENCHMARKS.md ("What limits the noisy grade").
#include <benchmark/benchmark.h>

#include <cmath>
#include <functional>

#include "../test/pipeline_simulation.h"
#include "camera_imu_alignment/simulation/imu_grades.h"

namespace cia = camera_imu_alignment;
namespace sim = camera_imu_alignment::simulation;

namespace {

constexpr int kSeeds = 10;
constexpr double kCameraNoiseDeg = 0.03;

using Variant = std::function<void(sim::SimulationConfig*, cia::PipelineSettings*)>;

const sim::ImuGradeSpec& consumer() {
  static const sim::ImuGradeSpec spec = sim::imuGradeSpec(sim::ImuGrade::kConsumer);
  return spec;
}

void runBudget(benchmark::State& state, const Variant& variant) {
  const int poses = static_cast<int>(state.range(0));
  double sum_sq_deg = 0.0, sum_sigma_deg = 0.0;
  int solved = 0;
  for (auto _ : state) {
    for (int k = 0; k < kSeeds; ++k) {
      sim::SimulationConfig c;
      c.seed = 500 + k;
      sim::applyScenario("nominal", &c);
      sim::applyImuGrade(sim::ImuGrade::kNoisy, &c);
      c.num_poses = poses;
      c.camera_rate_hz = 1.0;  // frames are given by the harness, not rendered
      cia::PipelineSettings settings;
      settings.window_poses = 200;
      settings.joint = cia::test::jointSettingsFor(c);
      variant(&c, &settings);
      const sim::SimulationRun run(c);
      const auto pipeline =
          cia::test::feedWithoutImages(run, settings, kCameraNoiseDeg, false, 100 + c.seed);
      const cia::AlignmentResult r = cia::test::solveFinalWindow(*pipeline);
      if (!r.joint || !r.joint->ok) continue;
      const double e_deg =
          cia::rad2deg(cia::geodesicDistance(r.R_cam_imu, run.trajectory.R_cam_imu_final()));
      sum_sq_deg += e_deg * e_deg;
      sum_sigma_deg += r.joint->std_dev_deg.norm();
      ++solved;
    }
  }
  if (solved > 0) {
    state.counters["rms_deg"] = std::sqrt(sum_sq_deg / solved);
    state.counters["sigma_deg"] = sum_sigma_deg / solved;
  }
  state.counters["solved"] = solved / static_cast<double>(state.iterations());
}

void BM_NoisyGrade(benchmark::State& state) {
  runBudget(state, [](sim::SimulationConfig*, cia::PipelineSettings*) {});
}
void BM_NoisyGyroNoiseAtConsumer(benchmark::State& state) {
  runBudget(state, [](sim::SimulationConfig* c, cia::PipelineSettings*) {
    c->imu_noise.gyroscope_noise_density = consumer().noise.gyroscope_noise_density;
  });
}
void BM_NoisyAccelNoiseAtConsumer(benchmark::State& state) {
  runBudget(state, [](sim::SimulationConfig* c, cia::PipelineSettings*) {
    c->imu_noise.accelerometer_noise_density = consumer().noise.accelerometer_noise_density;
  });
}
void BM_NoisyMagNoiseAtConsumer(benchmark::State& state) {
  runBudget(state, [](sim::SimulationConfig* c, cia::PipelineSettings*) {
    c->imu_noise.magnetometer_noise_sigma = consumer().noise.magnetometer_noise_sigma;
  });
}
void BM_NoisySystematicAtConsumer(benchmark::State& state) {
  runBudget(state, [](sim::SimulationConfig* c, cia::PipelineSettings* s) {
    c->imu_systematic = consumer().systematic;
    s->joint = cia::test::jointSettingsFor(*c);
  });
}
void BM_NoisyRestsOf9To12s(benchmark::State& state) {
  runBudget(state, [](sim::SimulationConfig* c, cia::PipelineSettings*) {
    c->hold_min_s = 9.0;
    c->hold_max_s = 12.0;
  });
}
void BM_NoisyIntrinsicsKnown(benchmark::State& state) {
  runBudget(state, [](sim::SimulationConfig* c, cia::PipelineSettings* s) {
    c->imu_systematic = sim::ImuSystematicSigmas();
    c->imu_noise.accelerometer_initial_bias_sigma = 0.0;
    c->imu_noise.accelerometer_random_walk = 1e-7;
    s->joint.imu_matrices = cia::ImuMatrixModel::kIdentity;
    s->joint.priors.accel_bias_m_s2 = 1e-4;
    s->joint.priors.accel_bias_walk_m_s2_sqrt_s = 1e-7;
    s->joint.priors.hard_iron_t = 1e-8;
    s->joint.priors.soft_iron_scale = s->joint.priors.soft_iron_cross = 1e-4;
  });
}

#define BUDGET_ROW(name) \
  BENCHMARK(name)->ArgName("poses")->Arg(7)->Arg(12)->Iterations(1)->Unit(benchmark::kSecond)
BUDGET_ROW(BM_NoisyGrade);
BUDGET_ROW(BM_NoisyGyroNoiseAtConsumer);
BUDGET_ROW(BM_NoisyAccelNoiseAtConsumer);
BUDGET_ROW(BM_NoisyMagNoiseAtConsumer);
BUDGET_ROW(BM_NoisySystematicAtConsumer);
BUDGET_ROW(BM_NoisyRestsOf9To12s);
BUDGET_ROW(BM_NoisyIntrinsicsKnown);

}  // namespace

BENCHMARK_MAIN();
