// The paper's simulation (Sec. III-A): 20 random relative rotations, noise |v| < 0.02 rad on both
// sides, 1000 runs. The two-step converges every time; the optimal estimator's RMS error is below
// the two-step's and at the Cramer-Rao bound of the small-angle model.
//
// The paper's own R0 value and Table I could not be consulted here (no copy of the paper's text is
// reachable from this environment), so R0 below is a stand-in mounting of the same kind (a generic
// rotation, tens of degrees about every axis) and the two-step is checked against the optimal
// estimator and the bound rather than against Table I's printed numbers.
#include <gtest/gtest.h>

#include <cmath>

#include "camera_imu_alignment/solver/alignment_solver.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

constexpr int kRuns = 1000;
constexpr int kPairs = 20;
constexpr double kNoiseRadius = 0.02;  // rad, |v| < 0.02

Eigen::Matrix3d standInR0() {
  return (Eigen::AngleAxisd(test::kPiTest / 3, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(-test::kPiTest / 4, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(test::kPiTest / 6, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

struct MonteCarlo {
  double mse_optimal = 0;   // mean |error|^2, rad^2
  double mse_two_step = 0;  // rad^2
  double crb = 0;           // mean tr(F^-1), rad^2
  int two_step_converged = 0;
  int two_step_max_iterations = 0;
  double two_step_mean_iterations = 0;
};

MonteCarlo runPaperExperiment() {
  std::mt19937_64 rng(2016);
  const Eigen::Matrix3d R0 = standInR0();
  // Per-axis variance of v uniform in a ball of radius r is r^2 / 5; the residual noise
  // A (v_a - R0 v_b) has per-axis variance 2 r^2 / 5.
  const double residual_var = 2.0 * kNoiseRadius * kNoiseRadius / 5.0;
  MonteCarlo mc;
  for (int run = 0; run < kRuns; ++run) {
    const RotationPairs pairs = test::paperPairs(rng, R0, kPairs, kNoiseRadius);
    // Fisher information of the small-angle model at the truth: r_j = (A_j - I) delta + e_j.
    Eigen::Matrix3d fisher = Eigen::Matrix3d::Zero();
    for (const auto& p : pairs) {
      const Eigen::Matrix3d A_true =
          R0 * p.B_imu * R0.transpose();  // noise on A is O(noise^2) here
      const Eigen::Matrix3d J = A_true - Eigen::Matrix3d::Identity();
      fisher += J.transpose() * J / residual_var;
    }
    mc.crb += fisher.inverse().trace() / kRuns;

    const PairSolveResult optimal = solveAlignment(pairs);
    SolverOptions two_step_options;
    two_step_options.method = SolverMethod::kTwoStep;
    const PairSolveResult two_step = solveAlignment(pairs, two_step_options);
    mc.mse_optimal += test::leftError(optimal.R_cam_imu, R0).squaredNorm() / kRuns;
    mc.mse_two_step += test::leftError(two_step.R_cam_imu, R0).squaredNorm() / kRuns;
    mc.two_step_converged += two_step.converged ? 1 : 0;
    mc.two_step_max_iterations = std::max(mc.two_step_max_iterations, two_step.iterations);
    mc.two_step_mean_iterations += static_cast<double>(two_step.iterations) / kRuns;
  }
  return mc;
}

const MonteCarlo& paperExperiment() {
  static const MonteCarlo mc = runPaperExperiment();
  return mc;
}

TEST(PaperExperiment, TwoStepConvergesInEveryRun) {
  const MonteCarlo& mc = paperExperiment();
  EXPECT_EQ(mc.two_step_converged, kRuns);
  RecordProperty("two_step_mean_iterations", std::to_string(mc.two_step_mean_iterations));
  EXPECT_LT(mc.two_step_mean_iterations, 30.0);
}

TEST(PaperExperiment, TwoStepErrorIsSmallButAboveTheOptimum) {
  const MonteCarlo& mc = paperExperiment();
  const double rms_two_step_deg = test::toDeg(std::sqrt(mc.mse_two_step));
  const double rms_optimal_deg = test::toDeg(std::sqrt(mc.mse_optimal));
  std::cout << "RMS error: two-step " << rms_two_step_deg << " deg, optimal " << rms_optimal_deg
            << " deg, ratio " << rms_two_step_deg / rms_optimal_deg << ", CRB "
            << test::toDeg(std::sqrt(mc.crb)) << " deg\n";
  // At convergence the two-step is accurate to a fraction of the noise (0.02 rad = 1.15 deg) ...
  EXPECT_LT(rms_two_step_deg, 0.5);
  // ... but it converges to a singular vector, not to the least-squares optimum.
  // Measured: 1.43x (2016 seed), the project's reference Monte Carlo says 1.44x.
  EXPECT_GT(rms_two_step_deg, 1.3 * rms_optimal_deg);
  EXPECT_LT(rms_two_step_deg, 1.6 * rms_optimal_deg);
}

TEST(PaperExperiment, OptimalEstimatorReachesTheCramerRaoBound) {
  const MonteCarlo& mc = paperExperiment();
  const double efficiency = std::sqrt(mc.mse_optimal / mc.crb);
  // 1000 runs x 3 axes: the RMS is known to about +-1.3% (1 sigma); measured 1.011.
  EXPECT_LT(efficiency, 1.05) << "RMS error / sqrt(CRB)";
  EXPECT_GT(efficiency, 0.95) << "RMS error below the bound: the bound or the test is wrong";
}

}  // namespace
}  // namespace camera_imu_alignment
