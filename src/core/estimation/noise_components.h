// Variance components of the joint estimate (private to src/core/estimation): the noise of each
// measurement kind (NoiseKind) as the recording shows it.
//
// For kind k with residual blocks r_i (whitened by the stated noise times the factor f_k in use),
// the factor the recording calls for is f_k chi2_k / r_k: chi2_k the kind's chi-square and r_k
// its redundancy, the number of its residuals minus the trace of its share of the hat matrix,
//   r_k = n_k - tr(H^-1 J_k^T J_k),  H = J^T J over the free parameters (tangent space),
// the degrees of freedom the kind keeps after the fit (Foerstner's variance-component
// estimation), each block's squared norm capped at the 99.99 % quantile of chi-square with its
// size (a gross outlier counts as a large residual, not as its own size). The trace is exact (dense
// inverse) for small problems and a Hutchinson estimate with Rademacher probes otherwise: for a
// trace t of a matrix with eigenvalues in [0, 1] one probe has a relative standard deviation below
// sqrt(2 / t), so that 32 probes give a thousand-residual kind's redundancy to about 1 %.
#pragma once

#include <ceres/problem.h>

#include "camera_imu_alignment/estimation/joint_result.h"
#include "joint_state.h"

namespace camera_imu_alignment {
namespace joint {

/// A kind keeps its stated noise (or the problem's factor) unless its residuals keep at least
/// this redundancy: a factor from fewer would be a noisy guess (chi-square's relative spread is
/// sqrt(2 / r)).
constexpr double kMinNoiseRedundancy = 30.0;
/// A learned factor is held within [1 / kMaxNoiseFactor, kMaxNoiseFactor] of the stated noise.
constexpr double kMaxNoiseFactor = 1e4;

/// Per kind: chi2, redundancy and residual count at the problem's current estimate (the factors
/// in `noise.variance_factor` are the ones the problem was built with). False when the Jacobian
/// cannot be evaluated or factorised (then nothing is learned).
bool measureNoiseComponents(ceres::Problem* ceres_problem, const BuiltProblem& built,
                            LearnedNoise* noise);

/// The factors the components call for: f_k chi2_k / r_k for each kind with redundancy above
/// kMinNoiseRedundancy (LearnedNoise::learned), the others unchanged; clamped to kMaxNoiseFactor.
/// Kinds marked in `held` keep their factor (measured otherwise: splitCameraGyro).
NoiseFactors updatedNoiseFactors(const LearnedNoise& noise,
                                 const std::array<bool, kNoiseKinds>& held = {});

/// The camera's and the gyro's noise on the chains of motion nodes, measured apart from each
/// other on the recording: the discrepancy between the camera's rotation over m consecutive node
/// intervals and the gyro's (each interval's gyro residual at the current IMU model with the
/// camera corrections set to zero, carried into the world frame so that the camera errors of
/// the inner nodes cancel) has the variance per axis 2 sigma_c^2 + q tau over a span of tau
/// seconds: the ends' camera noise and the gyro's angle random walk (q = density^2). Its robust
/// variance (median of the squared norms over chi-square(3)'s) for m = 1 .. kMaxSpan, fitted by
/// a line in tau, gives both; a camera error that lasts over several frames shows as q (it then
/// counts as the gyro's). Variance factors against the stated noise; ok false with fewer than
/// kMinSplitIntervals intervals.
struct CameraGyroSplit {
  bool ok = false;
  double camera_factor = 1.0;  ///< NoiseKind::kCameraMotion
  double gyro_factor = 1.0;    ///< NoiseKind::kGyroWhite (at least 1: the stated density)
  int intervals = 0;
};
constexpr int kMinSplitIntervals = 50;
CameraGyroSplit splitCameraGyro(const JointProblem& problem, const Whitening& whitening,
                                const BuiltProblem& built, State* state,
                                ceres::Problem* ceres_problem);

/// Largest relative change between two sets of factors.
double noiseFactorChange(const NoiseFactors& a, const NoiseFactors& b);

/// Factors that moved by less than this (relative) have settled.
constexpr double kNoiseSettled = 0.1;

/// The noise learned over the passes of one solve (JointSettings::learn_noise). The first pass
/// gives every kind with redundancy its factor from its own components, the camera's and the
/// gyro's from splitCameraGyro instead; kinds whose components do not separate them (their
/// iteration moves noise from one to the other over many passes) then keep their ratio and
/// learn one scale per group from the pooled components (kPooled: the camera's orientation with
/// the gyro's white noise, the camera's position with the accelerometer's white noise and bias
/// walk); the others go on from their own. The IMU's white noise is not taken below its stated
/// density.
class NoiseLearner {
 public:
  explicit NoiseLearner(const NoiseFactors& start) { noise_.variance_factor = start; }
  /// Measures the components of the pass just solved (built with noise().variance_factor) and
  /// the factors for the next; true when they moved by kNoiseSettled or more (solve again with
  /// factors()), false when they settled or could not be measured.
  bool update(const JointProblem& problem, const Whitening& whitening, const BuiltProblem& built,
              State* state, ceres::Problem* ceres_problem);
  /// The factors for the next pass.
  const NoiseFactors& factors() const { return next_; }
  /// The next pass is built with factors().
  void advance();
  /// What the last pass showed, under the factors it was built with.
  const LearnedNoise& noise() const { return noise_; }

 private:
  LearnedNoise noise_;
  NoiseFactors next_ = unitNoiseFactors();
};

}  // namespace joint
}  // namespace camera_imu_alignment
