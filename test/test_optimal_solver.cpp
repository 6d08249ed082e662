// The default optimal estimator: exactness without noise (all J, near identity and near 180 deg),
// degenerate numerics, outlier rejection, monotonicity in the amount of data.
#include <gtest/gtest.h>

#include <cmath>

#include "camera_imu_alignment/solver/alignment_solver.h"
#include "camera_imu_alignment/solver/closed_form_solver.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

using test::angleBetweenDeg;
using test::axisAngle;
using test::exactPair;
using test::randomRotation;
using test::randomUnitVector;

RotationPairs exactPairs(std::mt19937_64& rng, const Eigen::Matrix3d& X, int J) {
  RotationPairs pairs;
  for (int j = 0; j < J; ++j) pairs.push_back(exactPair(X, randomRotation(rng)));
  return pairs;
}

void expectExact(const RotationPairs& pairs, const Eigen::Matrix3d& X, const std::string& what) {
  const PairSolveResult r = solveAlignment(pairs);
  ASSERT_EQ(r.status, SolveStatus::kOk) << what << ": " << r.message;
  EXPECT_TRUE(r.R_cam_imu.allFinite()) << what;
  EXPECT_LT(angleBetweenDeg(r.R_cam_imu, X), 1e-9) << what;
  EXPECT_EQ(r.quality.num_inliers, static_cast<int>(pairs.size())) << what;
}

TEST(OptimalSolver, NoiseFreeExactForRandomMountings) {
  std::mt19937_64 rng(21);
  for (int J : {3, 4, 10, 20, 100, 1000}) {
    for (int trial = 0; trial < 5; ++trial) {
      const Eigen::Matrix3d X = randomRotation(rng);
      expectExact(exactPairs(rng, X, J), X, "J=" + std::to_string(J));
    }
  }
}

TEST(OptimalSolver, NoiseFreeExactWithTwoNonParallelPairs) {
  std::mt19937_64 rng(22);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d X = randomRotation(rng);
    const Eigen::Vector3d b1 = randomUnitVector(rng);
    const Eigen::Vector3d b2 = (b1.cross(randomUnitVector(rng))).normalized();  // perpendicular
    const RotationPairs pairs = {exactPair(X, axisAngle(b1, 0.7)),
                                 exactPair(X, axisAngle(b2, 1.1))};
    expectExact(pairs, X, "two pairs, trial " + std::to_string(trial));
  }
}

TEST(OptimalSolver, NoiseFreeExactNearIdentityAndNear180) {
  std::mt19937_64 rng(23);
  for (double angle :
       {0.0, 1e-9, 1e-6, test::kPiTest - 1e-6, test::kPiTest - 1e-12, test::kPiTest}) {
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::Matrix3d X = axisAngle(randomUnitVector(rng), angle);
      expectExact(exactPairs(rng, X, 20), X, "mounting angle " + std::to_string(angle));
    }
  }
}

TEST(OptimalSolver, PairsNear0And180DegreesGiveNoNaN) {
  // Relative rotations of (almost) 0 deg carry no axis; of (almost) 180 deg have an axis whose sign
  // the trace/acos formula cannot see (OpenCV #17986, #24871). Neither may break the solve.
  std::mt19937_64 rng(24);
  const Eigen::Matrix3d X = randomRotation(rng);
  RotationPairs pairs = exactPairs(rng, X, 6);
  for (double angle : {0.0, 1e-12, 1e-8, test::kPiTest - 1e-10, test::kPiTest}) {
    for (int k = 0; k < 3; ++k)
      pairs.push_back(exactPair(X, axisAngle(randomUnitVector(rng), angle)));
  }
  const PairSolveResult r = solveAlignment(pairs);
  ASSERT_EQ(r.status, SolveStatus::kOk) << r.message;
  EXPECT_LT(angleBetweenDeg(r.R_cam_imu, X), 1e-9);
  for (const auto& d : r.quality.pairs) {
    EXPECT_TRUE(std::isfinite(d.residual_deg));
    EXPECT_LT(d.residual_deg, 1e-6);
  }
  EXPECT_TRUE(r.quality.std_dev_deg.allFinite());
  // Only 180-degree pairs (plus 0-degree ones): still solvable, exactly.
  RotationPairs half_turns;
  for (const Eigen::Vector3d& b :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 1, 1)}) {
    half_turns.push_back(exactPair(X, axisAngle(b, test::kPiTest)));
  }
  half_turns.push_back(exactPair(X, Eigen::Matrix3d::Identity()));
  const PairSolveResult h = solveAlignment(half_turns);
  ASSERT_EQ(h.status, SolveStatus::kOk) << h.message;
  EXPECT_LT(angleBetweenDeg(h.R_cam_imu, X), 1e-9);
}

TEST(OptimalSolver, ClosedFormIsExactWithoutNoise) {
  std::mt19937_64 rng(25);
  for (int J : {2, 3, 50}) {
    const Eigen::Matrix3d X = randomRotation(rng);
    const auto R = solveClosedForm(exactPairs(rng, X, J));
    ASSERT_TRUE(R.has_value());
    EXPECT_LT(angleBetweenDeg(*R, X), 1e-9);
  }
}

/// RMS error (deg) over `runs` data sets of J pairs with a fraction of gross outliers, for the
/// default estimator on all pairs and for the estimator on the inliers alone.
void outlierExperiment(double outlier_fraction, double* rms_all, double* rms_inliers, int* missed) {
  std::mt19937_64 rng(26);
  const int runs = 200, J = 30;
  double sum_all = 0, sum_in = 0;
  *missed = 0;
  for (int run = 0; run < runs; ++run) {
    const Eigen::Matrix3d X = randomRotation(rng);
    RotationPairs inliers = test::paperPairs(rng, X, J, 0.02);
    RotationPairs all = inliers;
    const int n_out = static_cast<int>(std::round(outlier_fraction * J));
    for (int k = 0; k < n_out; ++k) {
      RotationPair bad;  // a gross error: an unrelated camera rotation
      bad.A_cam = randomRotation(rng);
      bad.B_imu = randomRotation(rng);
      all[k] = bad;
      inliers.erase(inliers.begin());
    }
    const PairSolveResult r_all = solveAlignment(all);
    const PairSolveResult r_in = solveAlignment(inliers);
    ASSERT_EQ(r_all.status, SolveStatus::kOk) << r_all.message;
    for (int k = 0; k < n_out; ++k) {
      if (r_all.quality.pairs[k].inlier && r_all.quality.pairs[k].residual_deg > 5.0) ++*missed;
    }
    sum_all += std::pow(angleBetweenDeg(r_all.R_cam_imu, X), 2);
    sum_in += std::pow(angleBetweenDeg(r_in.R_cam_imu, X), 2);
  }
  *rms_all = std::sqrt(sum_all / runs);
  *rms_inliers = std::sqrt(sum_in / runs);
}

void expectOutliersCostLessThanTwiceTheInlierOnlyError(double outlier_fraction) {
  double rms_all, rms_in;
  int missed;
  outlierExperiment(outlier_fraction, &rms_all, &rms_in, &missed);
  EXPECT_LT(rms_all, 2.0 * rms_in) << "all " << rms_all << " inliers-only " << rms_in;
  EXPECT_EQ(missed, 0);
}

TEST(OptimalSolver, TenPercentOutliersCostLessThanTwiceTheInlierOnlyError) {
  expectOutliersCostLessThanTwiceTheInlierOnlyError(0.1);
}

TEST(OptimalSolver, ThirtyPercentOutliersCostLessThanTwiceTheInlierOnlyError) {
  expectOutliersCostLessThanTwiceTheInlierOnlyError(0.3);
}

TEST(OptimalSolver, MorePairsNeverMakeTheAnswerWorse) {
  // Nested data sets: the first J pairs of one long sequence. The RMS error over many runs must
  // fall as J grows (roughly as 1/sqrt(J)).
  std::mt19937_64 rng(27);
  const std::vector<int> sizes = {5, 10, 20, 40, 80};
  std::vector<double> sum_sq(sizes.size(), 0.0);
  const int runs = 200;
  for (int run = 0; run < runs; ++run) {
    const Eigen::Matrix3d X = randomRotation(rng);
    const RotationPairs all = test::paperPairs(rng, X, sizes.back(), 0.02);
    for (size_t s = 0; s < sizes.size(); ++s) {
      const RotationPairs subset(all.begin(), all.begin() + sizes[s]);
      sum_sq[s] += std::pow(angleBetweenDeg(solveAlignment(subset).R_cam_imu, X), 2);
    }
  }
  for (size_t s = 1; s < sizes.size(); ++s) {
    EXPECT_LT(sum_sq[s], sum_sq[s - 1]) << "J=" << sizes[s] << " worse than J=" << sizes[s - 1];
  }
  EXPECT_LT(sum_sq.back(), 0.25 * sum_sq.front());
}

TEST(OptimalSolver, TwoStepMethodReturnsThePapersLeftIterate) {
  std::mt19937_64 rng(28);
  const Eigen::Matrix3d X = randomRotation(rng);
  const RotationPairs pairs = test::paperPairs(rng, X, 20, 0.02);
  SolverOptions options;
  options.method = SolverMethod::kTwoStep;
  const PairSolveResult r = solveAlignment(pairs, options);
  ASSERT_EQ(r.status, SolveStatus::kOk);
  EXPECT_EQ(r.R_cam_imu, r.two_step.R_cam_imu_left);
  EXPECT_EQ(r.iterations, r.two_step.iterations);
  // The default method also runs the two-step and reports it.
  const PairSolveResult opt = solveAlignment(pairs);
  EXPECT_GT(opt.two_step.iterations, 0);
  EXPECT_LT(angleBetweenDeg(opt.two_step.R_cam_imu_left, r.R_cam_imu), 1e-6);
}

TEST(OptimalSolver, BadInputIsReportedNotSolved) {
  EXPECT_EQ(solveAlignment({}).status, SolveStatus::kBadInput);
  RotationPair nan_pair;
  nan_pair.A_cam(1, 2) = std::nan("");
  EXPECT_EQ(solveAlignment({nan_pair, nan_pair}).status, SolveStatus::kBadInput);
  RotationPair scaled;
  scaled.A_cam *= 2.0;
  EXPECT_EQ(solveAlignment({scaled}).status, SolveStatus::kBadInput);
  RotationPair reflection;
  reflection.B_imu(2, 2) = -1.0;
  const PairSolveResult r = solveAlignment({reflection});
  EXPECT_EQ(r.status, SolveStatus::kBadInput);
  EXPECT_NE(r.message.find("pair 0"), std::string::npos);
}

TEST(OptimalSolver, ParsesMethodNames) {
  SolverMethod m;
  EXPECT_TRUE(parseSolverMethod("two_step", &m));
  EXPECT_EQ(m, SolverMethod::kTwoStep);
  EXPECT_TRUE(parseSolverMethod("optimal", &m));
  EXPECT_EQ(m, SolverMethod::kOptimal);
  EXPECT_FALSE(parseSolverMethod("Optimal", &m));
  EXPECT_STREQ(toString(SolverMethod::kTwoStep), "two_step");
}

}  // namespace
}  // namespace camera_imu_alignment
