// Solve time of the joint maximum-likelihood estimator (estimation/joint_estimator.h) on one core.
//
// Data: test/joint_problem_simulation.h with its defaults, a consumer unit: P stationary poses of 3
// s, minimum-jerk rotations of 20-90 deg about random axes between them (2 s, gyro at 200 Hz: 400
// samples per motion), gyro 1.7e-4 rad/s/sqrt(Hz) with 1.5 % scale and 1 % cross-axis errors and a
// walking bias up to 3 deg/s, accelerometer 0.02 m/s^2 with 1 % scale and 0.2 m/s^2 bias,
// magnetometer with 15 uT hard and 5 % soft iron, camera 0.05 deg. Initial R_cam_imu 1 deg off.
// 10 data sets per size, cycled; err_deg is the mean geodesic error, iterations the mean
// Levenberg-Marquardt iterations over all relinearisation passes. Targets: 12 poses <= 20 ms,
// 30 poses <= 50 ms. BM_JointEstimatorFlaggedFields: the same with every field flagged by the
// raw field check (the magnetometer screening: the iron estimated, fields that do not fit it left
// out one at a time).
#include <benchmark/benchmark.h>

#include <map>
#include <vector>

#include "../test/joint_problem_simulation.h"
#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace cia = camera_imu_alignment;

namespace {

constexpr int kDataSets = 10;

struct DataSet {
  cia::test::JointSimulation simulation;
  Eigen::Matrix3d R_cam_imu_initial;
};

const std::vector<DataSet>& dataSets(int poses) {
  static std::map<int, std::vector<DataSet>> cache;
  std::vector<DataSet>& sets = cache[poses];
  if (sets.empty()) {
    cia::test::JointSimulationOptions options;
    options.num_poses = poses;
    for (int s = 0; s < kDataSets; ++s) {
      DataSet d{cia::test::simulateJointProblem(options, 1000 * poses + s), {}};
      d.R_cam_imu_initial =
          cia::test::perturbedRotation(d.simulation.R_cam_imu, cia::deg2rad(1.0), s);
      sets.push_back(std::move(d));
    }
  }
  return sets;
}

/// The same data with every rest's field flagged by the pipeline's raw field check (as uncalibrated
/// iron makes it on a consumer unit): the estimator's magnetometer screening path.
std::vector<DataSet> flaggedFields(std::vector<DataSet> sets) {
  for (DataSet& d : sets) {
    for (cia::JointPose& pose : d.simulation.problem.poses) pose.mag_flagged = true;
  }
  return sets;
}

void runJointEstimator(benchmark::State& state, const std::vector<DataSet>& sets) {
  const cia::JointEstimator estimator;
  size_t i = 0;
  double error_sum = 0.0, iterations = 0.0, solves = 0.0;
  for (auto _ : state) {
    const DataSet& d = sets[i++ % sets.size()];
    const cia::JointResult result = estimator.solve(d.simulation.problem, d.R_cam_imu_initial);
    benchmark::DoNotOptimize(result.R_cam_imu.data());
    if (!result.ok) {
      state.SkipWithError(result.message.c_str());
      break;
    }
    error_sum += cia::rad2deg(cia::geodesicDistance(result.R_cam_imu, d.simulation.R_cam_imu));
    iterations += result.iterations;
    solves += 1.0;
  }
  if (solves > 0.0) {
    state.counters["err_deg"] = error_sum / solves;
    state.counters["iterations"] = iterations / solves;
  }
}
void BM_JointEstimator(benchmark::State& state) {
  runJointEstimator(state, dataSets(static_cast<int>(state.range(0))));
}
BENCHMARK(BM_JointEstimator)->ArgName("poses")->Arg(12)->Arg(30)->Unit(benchmark::kMillisecond);

void BM_JointEstimatorFlaggedFields(benchmark::State& state) {
  static std::map<int, std::vector<DataSet>> cache;
  const int poses = static_cast<int>(state.range(0));
  if (cache[poses].empty()) cache[poses] = flaggedFields(dataSets(poses));
  runJointEstimator(state, cache[poses]);
}
BENCHMARK(BM_JointEstimatorFlaggedFields)
    ->ArgName("poses")
    ->Arg(12)
    ->Arg(30)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
