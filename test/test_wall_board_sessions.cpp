// Monte Carlo over the simulator's wall_board session (the way people hold a rig in front of a
// board on a wall: 12 rests of 3-5 s, view within 35 deg of the board's normal, roll within
// 45 deg; gravity spans a narrow cone in the IMU frame) for the IMU grades, through the pipeline
// with the default settings (a consumer unit's priors), camera orientations given (the truth with
// 0.03 deg of noise per frame at 15 Hz, as test_joint_pipeline). Errors against the simulated
// truth in the package's IMU frame (the accelerometer's axes), per-axis against the reported
// 1-sigma. Set CIA_WALL_BOARD_SEEDS to run more seeds than the tests' 20, and
// CIA_WALL_BOARD_EXACT_NOISE=1 to tell the estimator the simulator's own spread of every error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/estimation/joint_observability.h"
#include "camera_imu_alignment/estimation/mount_change.h"
#include "camera_imu_alignment/io/joint_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;

constexpr double kCameraNoiseDeg = 0.03;

struct WallBoardOutcome {
  int runs = 0, solved = 0, identity_matrices = 0;
  int accel_matrix_determined = 0;  ///< T_a reported as determined by the data
  int geometric_notes = 0;          ///< notes quoting a geometric cut-off (spread, coverage)
  int remounts = 0;  ///< mount-change verdicts (the mount never moved) over both windows tested
  double sum_sq_deg = 0.0, sum_sq_sigma_deg = 0.0, max_deg = 0.0, max_z = 0.0, max_solve_s = 0.0;
  double min_spread = 1.0, max_spread = 0.0;
  std::vector<std::string> failures;
  double rms() const { return solved > 0 ? std::sqrt(sum_sq_deg / solved) : 0.0; }
  double rmsSigma() const { return solved > 0 ? std::sqrt(sum_sq_sigma_deg / solved) : 0.0; }
};

int seedCount() {
  const char* text = std::getenv("CIA_WALL_BOARD_SEEDS");
  const int n = text ? std::atoi(text) : 0;
  return n > 0 ? n : 20;
}

/// The first `count` poses of `problem` (and the gyro segments between them).
JointProblem firstPoses(const JointProblem& problem, size_t count) {
  JointProblem out = problem;
  out.poses.resize(std::min(count, out.poses.size()));
  out.segments.clear();
  for (const GyroSegment& segment : problem.segments) {
    if (segment.to_pose < static_cast<int>(out.poses.size())) out.segments.push_back(segment);
  }
  return out;
}

/// Mount-change verdicts on an unchanged recording: the test as the online calibrator runs it
/// after the 8th pose and after the last (default settings), each on its own one-mount estimate.
int countRemounts(const JointProblem& problem, const JointResult& whole,
                  const JointSettings& settings) {
  int verdicts = 0;
  const MountChangeTest last = testMountChange(problem, whole, settings, MountChangeSettings{});
  verdicts += last.detected;
  if (last.detected) std::printf("  remount verdict: %s\n", last.message.c_str());
  const JointProblem eight = firstPoses(problem, 8);
  const JointResult one = JointEstimator(settings).solve(eight, whole.R_cam_imu);
  if (one.ok) {
    const MountChangeTest early = testMountChange(eight, one, settings, MountChangeSettings{});
    verdicts += early.detected;
    if (early.detected) std::printf("  remount verdict (8 poses): %s\n", early.message.c_str());
  }
  return verdicts;
}

/// How a wall-board run is solved: the default settings, or the unit's own priors
/// (test::jointSettingsFor), with or without the motion between the rests.
struct WallBoardSolve {
  bool unit_priors = false;
  bool motion = true;  ///< false: rests only (motion_window_s 0)
};

/// The wall_board session of `grade` for seeds 1..count; `systematic` false: the grade's noise
/// only (T_g = T_a = I, no iron).
WallBoardOutcome runWallBoard(sim::ImuGrade grade, bool systematic, int count,
                              WallBoardSolve solve = {}) {
  WallBoardOutcome out;
  for (int k = 0; k < count; ++k) {
    sim::SimulationConfig c;
    c.seed = 1 + k;
    EXPECT_TRUE(sim::applyScenario("wall_board", &c));
    sim::applyImuGrade(grade, &c);
    if (!systematic) c.imu_systematic = sim::ImuSystematicSigmas();
    c.camera_rate_hz = 1.0;  // frames are given by the harness, not rendered
    const sim::SimulationRun run(c);
    PipelineSettings settings;
    if (solve.unit_priors) settings.joint = test::jointSettingsFor(c);
    if (std::getenv("CIA_WALL_BOARD_EXACT_NOISE") != nullptr) {
      // The estimator told the simulator's own spread of every error (an information bound):
      // the unit's priors, the accelerometer's initial bias at its sigma (not 2x), both walks.
      settings.joint = test::jointSettingsFor(c);
      settings.joint.priors.accel_bias_m_s2 = c.imu_noise.accelerometer_initial_bias_sigma;
      settings.joint.priors.gyro_bias_walk_rad_s_sqrt_s = c.imu_noise.gyroscope_random_walk;
    }
    if (!solve.motion) settings.motion_window_s = 0.0;
    const bool rendered = std::getenv("CIA_WALL_BOARD_RENDERED") != nullptr;
    test::PipelineRun rendered_run;
    std::unique_ptr<CalibrationPipeline> fed;
    if (rendered) {
      c.camera_rate_hz = 5.0;  // as test_calibration_pipeline_grades
      rendered_run = test::runPipeline(c, settings);
    } else {
      fed = test::feedWithoutImages(run, settings, kCameraNoiseDeg, false,
                                    100 + static_cast<unsigned>(c.seed));
    }
    CalibrationPipeline* pipeline = rendered ? rendered_run.pipeline.get() : fed.get();
    ++out.runs;
    std::vector<Eigen::Vector3d> gravity;
    for (const JointPose& pose : pipeline->snapshot().joint.poses) {
      gravity.push_back(pose.accel_mean_m_s2.normalized());
    }
    const double spread = directionSpread(gravity);
    out.min_spread = std::min(out.min_spread, spread);
    out.max_spread = std::max(out.max_spread, spread);
    const AlignmentResult r = test::solveFinalWindow(*pipeline);
    if (!r.joint || !r.joint->ok) {
      out.failures.push_back("seed " + std::to_string(c.seed) + ": " +
                             (r.joint ? r.joint->message : r.message));
      continue;
    }
    ++out.solved;
    out.identity_matrices += r.joint->intrinsics.gyro_matrix_sigma.isZero();
    out.accel_matrix_determined += r.joint->intrinsics.accel_matrix_estimated;
    for (const std::string& note : r.joint->notes) {
      out.geometric_notes +=
          note.find("spread") != std::string::npos || note.find("coverage") != std::string::npos;
    }
    out.max_solve_s = std::max(out.max_solve_s, r.joint->solve_time_s);
    out.remounts += countRemounts(pipeline->snapshot().joint, *r.joint, settings.joint);
    const Eigen::Matrix3d R_true =
        rendered ? rendered_run.R_cam_imu_true() : run.trajectory.R_cam_imu_final();
    const Eigen::Vector3d e = test::leftError(r.R_cam_imu, R_true);
    out.sum_sq_sigma_deg += r.joint->std_dev_deg.squaredNorm();
    const double e_deg = rad2deg(e.norm());
    out.sum_sq_deg += e_deg * e_deg;
    out.max_deg = std::max(out.max_deg, e_deg);
    double z_max = 0.0;
    for (int a = 0; a < 3; ++a) {
      z_max = std::max(z_max, std::abs(e(a)) / std::sqrt(r.joint->covariance_rad2(a, a)));
    }
    out.max_z = std::max(out.max_z, z_max);
    if (z_max > 3.0) {
      out.failures.push_back("seed " + std::to_string(c.seed) + ": error " + std::to_string(e_deg) +
                             " deg at " + std::to_string(z_max) + " of its 1-sigma");
    }
  }
  std::printf(
      "wall_board %-9s %-13s %2d/%2d solved  RMS %.4f deg (1-sigma norm RMS %.4f)  max %.4f deg  "
      "max |z| %.2f  T = I in "
      "%d  T_a determined in %d  geometric notes %d  remounts %d  gravity spread %.3f-%.3f  "
      "slowest solve %.1f "
      "ms\n",
      sim::toString(grade), systematic ? "systematic" : "noise only", out.solved, out.runs,
      out.rms(), out.rmsSigma(), out.max_deg, out.max_z, out.identity_matrices,
      out.accel_matrix_determined, out.geometric_notes, out.remounts, out.min_spread,
      out.max_spread, 1e3 * out.max_solve_s);
  for (const std::string& f : out.failures) std::printf("  %s\n", f.c_str());
  return out;
}

/// What every grade must show: solved, no error beyond 3 of its per-axis 1-sigma, no note quoting
/// a geometric cut-off, no remount verdict on the unchanged mount.
void expectHonest(const WallBoardOutcome& o) {
  EXPECT_EQ(o.solved, o.runs);
  EXPECT_LT(o.max_z, 3.0);
  EXPECT_EQ(o.geometric_notes, 0);
  EXPECT_EQ(o.remounts, 0);
}

// Measured 2026-11-26 (seeds 1-20), rests only: RMS 0.0795 deg, max 0.133, |z| <= 1.56, reported
// 1-sigma norm 0.108 RMS; with the motion between the rests (motion nodes, the default since issue
// 25): RMS 0.0755, max 0.141, |z| <= 1.56, 1-sigma norm 0.108; T_a determined by the data in 20/20
// (before: "held at its prior: gravity direction spread 0.050-0.123 < 0.100" in most). The issue's
// target of 0.06 deg RMS is not met: the error is the information the session carries (with T_g
// known exactly 0.020, with T_a known 0.028, with the soft iron known 0.045), and the reported
// 1-sigma says so. Told the simulator's exact spread of every error (CIA_WALL_BOARD_EXACT_NOISE=1,
// 2026-11-27) the estimator's posterior 1-sigma is 0.0925 deg RMS and its error 0.0803 (max 0.166):
// the Bayesian bound on these sessions is above 0.06. Asserted: the max target (0.15) and 3 sigma,
// RMS within 0.10.
TEST(WallBoardSessions, ConsumerGradeWithSystematicErrors) {
  const WallBoardOutcome o = runWallBoard(sim::ImuGrade::kConsumer, true, seedCount());
  expectHonest(o);
  EXPECT_LT(o.rms(), 0.10);
  EXPECT_LT(o.max_deg, 0.15);
  EXPECT_GE(o.accel_matrix_determined, o.runs * 9 / 10);
}

// Measured, rests only: RMS 0.0192 deg, max 0.033, |z| <= 2.18 (T_g = T_a = I kept by the model
// selection in 20/20); with the motion: RMS 0.0149, max 0.021, |z| <= 1.66. Target: <= 0.04 deg
// RMS within 3 sigma.
TEST(WallBoardSessions, ConsumerNoiseWithoutSystematicErrors) {
  const WallBoardOutcome o = runWallBoard(sim::ImuGrade::kConsumer, false, seedCount());
  expectHonest(o);
  EXPECT_LT(o.rms(), 0.04);
}

// Measured: tactical RMS 0.0254 deg (max 0.051, |z| <= 0.72), with the motion 0.0258 (max 0.056,
// |z| <= 0.68).
TEST(WallBoardSessions, TacticalGrade) {
  const WallBoardOutcome o = runWallBoard(sim::ImuGrade::kTactical, true, seedCount());
  expectHonest(o);
  EXPECT_LT(o.rms(), 0.04);
}

// The noisy unit (MPU-6050 class: gyro and accelerometer scale 3 %, cross-axis 2 %, accelerometer
// bias 0.6 m/s^2, hard iron 40 uT) is 2-3x outside the default (consumer) priors; it is solved with
// its own (test::jointSettingsFor), as its users are told to. Measured: RMS 0.315 deg (max 0.596,
// |z| <= 2.74). Under the default priors, rests only: RMS 0.337 (max 0.564, |z| <= 2.62); with the
// motion the errors are the same (RMS 0.342) but the 1-sigma 25 % smaller and seed 18 at 3.36
// sigma: the motion nodes tie R_cam_imu to a gyro model whose priors are too narrow.
TEST(WallBoardSessions, NoisyGrade) {
  WallBoardSolve solve;
  solve.unit_priors = true;
  const WallBoardOutcome o = runWallBoard(sim::ImuGrade::kNoisy, true, seedCount(), solve);
  expectHonest(o);
  EXPECT_LT(o.rms(), 0.45);
}

// Issue 25: the motion between the rests never makes the answer worse than the rests alone
// (Monte Carlo RMS over the same seeds; measured 0.0755 against 0.0795 deg).
TEST(WallBoardSessions, TheMotionBetweenTheRestsNeverMakesTheAnswerWorse) {
  WallBoardSolve rests_only;
  rests_only.motion = false;
  const WallBoardOutcome with_motion = runWallBoard(sim::ImuGrade::kConsumer, true, seedCount());
  const WallBoardOutcome without =
      runWallBoard(sim::ImuGrade::kConsumer, true, seedCount(), rests_only);
  EXPECT_LE(with_motion.rms(), without.rms() * 1.02);
  EXPECT_LE(with_motion.max_deg, without.max_deg * 1.25);
}

}  // namespace
}  // namespace camera_imu_alignment
