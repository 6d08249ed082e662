// Speed and accuracy of the rotation solvers against OpenCV's cv::calibrateHandEye.
//
// Data (same for every method): P stationary poses of a rig with a random mounting
// R_cam_imu (uniform on SO(3)) and a 5 cm lever arm, looking at a fixed target; the rig's yaw stays
// within +-60 deg and its roll and pitch within +-35 deg (uniformly random orientations make
// OpenCV's methods fail even without noise: relative rotations near 180 deg, OpenCV issue #17986).
// IMU orientations R_world_imu carry 0.3 deg (1-sigma per axis) noise, camera orientations 0.1 deg.
// Our solvers get all J = P (P - 1) / 2 pairs of the poses (our default for poses);
// cv::calibrateHandEye gets the P absolute poses (gripper = IMU, base = world) and forms the same J
// pairs internally. An IMU has no position: the rig turns about the IMU origin (t_gripper2base = 0,
// true), and the camera's PnP translations carry 2 mm (1-sigma per axis) noise. OpenCV may use
// those translations; our solvers use rotations only. P = 3, 7, 15, 46 gives J = 3, 21, 105, 1035.
// 100 data sets per J, cycled in the timing loop; err_deg is the mean geodesic error |Log(R_est^T
// R_true)| over the data sets. The "Paper" group is the paper's simulation: 20 independent random
// pairs, noise |v| < 0.02 rad on both sides (OpenCV cannot take independent pairs).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <random>

#include "camera_imu_alignment/solver/alignment_solver.h"
#include "camera_imu_alignment/solver/example_data.h"
#include "camera_imu_alignment/solver/pose_window.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace cia = camera_imu_alignment;

namespace {

constexpr int kDataSets = 100;

struct DataSet {
  Eigen::Matrix3d R_cam_imu;
  cia::RotationPairs pairs;  // consecutive pairs, for our solvers
  std::vector<cv::Mat> R_gripper2base, t_gripper2base, R_target2cam, t_target2cam;  // OpenCV
};

Eigen::Matrix3d randomRotation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  return cia::uniformRotation(u(rng), u(rng), u(rng));
}

cv::Mat toCv(const Eigen::Matrix3d& R) {
  cv::Mat m;
  cv::eigen2cv(R, m);
  return m;
}

cv::Mat toCv(const Eigen::Vector3d& t) {
  cv::Mat m;
  cv::eigen2cv(t, m);
  return m;
}

DataSet makeDataSet(unsigned seed, int P, double cam_noise_deg, double imu_noise_deg) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto translation_noise = [&]() -> Eigen::Vector3d {
    return 0.002 * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
  };
  const auto noise = [&](double sigma_deg) -> Eigen::Matrix3d {
    return cia::expSO3(cia::deg2rad(sigma_deg) *
                       Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)));
  };
  DataSet d;
  d.R_cam_imu = randomRotation(rng);
  const Eigen::Vector3d t_imu_cam(0.05, -0.02, 0.03);  // lever arm: camera origin in the IMU frame
  const Eigen::Matrix3d R_world_target = randomRotation(rng);
  const Eigen::Vector3d t_world_target(0.0, 0.0, 2.0);
  std::vector<Eigen::Matrix3d> R_target_cam, R_world_imu;
  std::uniform_real_distribution<double> yaw(-cia::deg2rad(60), cia::deg2rad(60));
  std::uniform_real_distribution<double> tilt(-cia::deg2rad(35), cia::deg2rad(35));
  for (int k = 0; k < P; ++k) {
    // Realistic calibration poses: yaw within +-60 deg, roll and pitch within +-35 deg.
    const Eigen::Matrix3d R_wi = (Eigen::AngleAxisd(yaw(rng), Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitX()))
                                     .toRotationMatrix();
    const Eigen::Vector3d t_wi = Eigen::Vector3d::Zero();  // the rig turns about the IMU origin
    const Eigen::Matrix3d R_wc = R_wi * d.R_cam_imu.transpose();
    const Eigen::Vector3d t_wc = t_wi + R_wi * t_imu_cam;
    const Eigen::Matrix3d R_cam_target = R_wc.transpose() * R_world_target;
    const Eigen::Vector3d t_cam_target = R_wc.transpose() * (t_world_target - t_wc);
    const Eigen::Matrix3d R_wi_noisy = R_wi * noise(imu_noise_deg);
    const Eigen::Matrix3d R_ct_noisy = noise(cam_noise_deg) * R_cam_target;
    R_world_imu.push_back(R_wi_noisy);
    R_target_cam.push_back(R_ct_noisy.transpose());
    d.R_gripper2base.push_back(toCv(R_wi_noisy));
    d.t_gripper2base.push_back(toCv(t_wi));
    d.R_target2cam.push_back(toCv(R_ct_noisy));
    d.t_target2cam.push_back(toCv(Eigen::Vector3d(t_cam_target + translation_noise())));
  }
  std::vector<cia::PoseOrientation> poses(P);
  for (int k = 0; k < P; ++k) {
    poses[k].R_target_cam = R_target_cam[k];
    poses[k].R_world_imu = R_world_imu[k];
  }
  d.pairs = cia::makeAllPairs(poses);
  return d;
}

const std::vector<DataSet>& dataSets(int P) {
  static std::map<int, std::vector<DataSet>> cache;
  auto& sets = cache[P];
  if (sets.empty()) {
    for (int s = 0; s < kDataSets; ++s) sets.push_back(makeDataSet(1000 * P + s, P, 0.1, 0.3));
  }
  return sets;
}

Eigen::Matrix3d solveOpenCv(const DataSet& d, cv::HandEyeCalibrationMethod method) {
  cv::Mat R_cam2gripper, t_cam2gripper;
  try {
    cv::calibrateHandEye(d.R_gripper2base, d.t_gripper2base, d.R_target2cam, d.t_target2cam,
                         R_cam2gripper, t_cam2gripper, method);
  } catch (const cv::Exception& e) {
    // ANDREFF solves rotation and translation jointly and needs gripper translations: with an IMU
    // (no position) it fails. Reported once per method; its err_deg is then nan.
    static bool reported[5] = {false, false, false, false, false};
    if (!reported[static_cast<int>(method) % 5]) {
      reported[static_cast<int>(method) % 5] = true;
      std::fprintf(stderr, "cv::calibrateHandEye method %d threw: %s\n", static_cast<int>(method),
                   e.what());
    }
    return Eigen::Matrix3d::Constant(std::nan(""));
  }
  Eigen::Matrix3d R_imu_cam;
  cv::cv2eigen(R_cam2gripper, R_imu_cam);
  return R_imu_cam.transpose();  // R_cam2gripper = R_imu_cam
}

Eigen::Matrix3d solveOurs(const DataSet& d, cia::SolverMethod method) {
  cia::SolverOptions options;
  options.method = method;
  return cia::solveAlignment(d.pairs, options).R_cam_imu;
}

/// Every OpenCV method must return the truth on noise-free data, or the comparison is meaningless.
void checkOpenCvConventions() {
  DataSet d = makeDataSet(7, 10, 0.0, 0.0);
  for (size_t k = 0; k < d.t_target2cam.size(); ++k) {  // noise-free translations for this check
    Eigen::Matrix3d R_ct, R_wi;
    cv::cv2eigen(d.R_target2cam[k], R_ct);
    cv::cv2eigen(d.R_gripper2base[k], R_wi);
    const Eigen::Matrix3d R_wc = R_wi * d.R_cam_imu.transpose();
    const Eigen::Vector3d t_wc = R_wi * Eigen::Vector3d(0.05, -0.02, 0.03);
    d.t_target2cam[k] =
        toCv(Eigen::Vector3d(R_wc.transpose() * (Eigen::Vector3d(0, 0, 2.0) - t_wc)));
  }
  for (auto method : {cv::CALIB_HAND_EYE_TSAI, cv::CALIB_HAND_EYE_PARK, cv::CALIB_HAND_EYE_HORAUD,
                      cv::CALIB_HAND_EYE_ANDREFF, cv::CALIB_HAND_EYE_DANIILIDIS}) {
    const Eigen::Matrix3d R = solveOpenCv(d, method);
    if (!R.allFinite()) continue;  // reported by solveOpenCv
    const double err = cia::rad2deg(cia::geodesicDistance(R, d.R_cam_imu));
    if (err > 1e-4) {
      std::fprintf(stderr,
                   "cv::calibrateHandEye method %d: %g deg on noise-free data (convention error)\n",
                   static_cast<int>(method), err);
      std::exit(1);
    }
  }
  if (cia::rad2deg(cia::geodesicDistance(solveOurs(d, cia::SolverMethod::kOptimal), d.R_cam_imu)) >
      1e-6) {
    std::fprintf(stderr, "optimal estimator not exact on noise-free data\n");
    std::exit(1);
  }
}

template <typename Solve>
void runBenchmark(benchmark::State& state, const std::vector<DataSet>& sets, Solve solve,
                  int error_sets) {
  size_t i = 0;
  for (auto _ : state) {
    Eigen::Matrix3d R = solve(sets[i++ % sets.size()]);
    benchmark::DoNotOptimize(R);
  }
  double sum = 0.0;
  const int n = std::min<int>(error_sets, static_cast<int>(sets.size()));
  for (int s = 0; s < n; ++s)
    sum += cia::rad2deg(cia::geodesicDistance(solve(sets[s]), sets[s].R_cam_imu));
  state.counters["err_deg"] = sum / n;
  state.counters["pairs"] = static_cast<double>(sets.front().pairs.size());
}

void BM_Optimal(benchmark::State& state) {
  runBenchmark(
      state, dataSets(state.range(0)),
      [](const DataSet& d) { return solveOurs(d, cia::SolverMethod::kOptimal); }, kDataSets);
}

void BM_TwoStep(benchmark::State& state) {
  runBenchmark(
      state, dataSets(state.range(0)),
      [](const DataSet& d) { return solveOurs(d, cia::SolverMethod::kTwoStep); }, kDataSets);
}

template <cv::HandEyeCalibrationMethod Method>
void BM_OpenCv(benchmark::State& state) {
  const int P = static_cast<int>(state.range(0));
  runBenchmark(
      state, dataSets(P), [](const DataSet& d) { return solveOpenCv(d, Method); }, kDataSets);
}

/// The paper's simulation: independent pairs, noise |v| < 0.02 rad, random mounting per data set.
const std::vector<DataSet>& paperSets() {
  static std::vector<DataSet> sets;
  if (sets.empty()) {
    for (unsigned s = 0; s < kDataSets; ++s) {
      DataSet d;
      std::mt19937_64 rng(s);
      d.R_cam_imu = randomRotation(rng);
      d.pairs = cia::generateRandomPairs(s, 20, d.R_cam_imu, 0.02);
      sets.push_back(d);
    }
  }
  return sets;
}

void BM_Paper_Optimal(benchmark::State& state) {
  runBenchmark(
      state, paperSets(),
      [](const DataSet& d) { return solveOurs(d, cia::SolverMethod::kOptimal); }, kDataSets);
}

void BM_Paper_TwoStep(benchmark::State& state) {
  runBenchmark(
      state, paperSets(),
      [](const DataSet& d) { return solveOurs(d, cia::SolverMethod::kTwoStep); }, kDataSets);
}

// Argument: number of poses P (pairs J = P (P - 1) / 2 = 3, 21, 105, 1035).
#define CIA_PAIR_COUNTS Arg(3)->Arg(7)->Arg(15)->Arg(46)->Unit(benchmark::kMicrosecond)
BENCHMARK(BM_Optimal)->CIA_PAIR_COUNTS;
BENCHMARK(BM_TwoStep)->CIA_PAIR_COUNTS;
BENCHMARK(BM_OpenCv<cv::CALIB_HAND_EYE_TSAI>)->Name("BM_OpenCV_TSAI")->CIA_PAIR_COUNTS;
BENCHMARK(BM_OpenCv<cv::CALIB_HAND_EYE_PARK>)->Name("BM_OpenCV_PARK")->CIA_PAIR_COUNTS;
BENCHMARK(BM_OpenCv<cv::CALIB_HAND_EYE_HORAUD>)->Name("BM_OpenCV_HORAUD")->CIA_PAIR_COUNTS;
BENCHMARK(BM_OpenCv<cv::CALIB_HAND_EYE_ANDREFF>)->Name("BM_OpenCV_ANDREFF")->CIA_PAIR_COUNTS;
BENCHMARK(BM_OpenCv<cv::CALIB_HAND_EYE_DANIILIDIS>)->Name("BM_OpenCV_DANIILIDIS")->CIA_PAIR_COUNTS;
BENCHMARK(BM_Paper_Optimal)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Paper_TwoStep)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  checkOpenCvConventions();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
