// Variance components of the joint estimate (noise_components.h).
#include "noise_components.h"

#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <map>
#include <random>
#include <unordered_map>
#include <utility>
#include <vector>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace joint {
namespace {

/// Problems with at most this many free parameters get the exact trace (dense inverse).
constexpr int kMaxDenseParameters = 400;
/// Hutchinson probes (Rademacher vectors over every residual) otherwise.
constexpr int kProbes = 32;
/// Quantile of chi-square (a block's size) a block's squared norm is capped at in its kind's
/// chi-square.
constexpr double kCapQuantile = 0.9999;
/// Ridge on H (relative to its largest diagonal entry): the gauge directions no residual sees.
constexpr double kRidge = 1e-12;
/// The camera's noise is not taken below the stated variance by the split.
constexpr double kMinCameraFactor = 1.0;

/// Quantile q of chi-square with `dof` degrees of freedom (cached: few sizes occur).
double chiSquareQuantile(int dof, double q) {
  static thread_local std::map<std::pair<int, double>, double> cache;
  const auto key = std::make_pair(dof, q);
  auto it = cache.find(key);
  if (it == cache.end()) {
    it = cache.emplace(key, boost::math::quantile(boost::math::chi_squared(dof), q)).first;
  }
  return it->second;
}

using SparseMatrix = Eigen::SparseMatrix<double>;

SparseMatrix toSparse(const ceres::CRSMatrix& crs) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(crs.values.size());
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int i = crs.rows[static_cast<size_t>(r)]; i < crs.rows[static_cast<size_t>(r) + 1]; ++i) {
      entries.emplace_back(r, crs.cols[static_cast<size_t>(i)], crs.values[static_cast<size_t>(i)]);
    }
  }
  SparseMatrix J(crs.num_rows, crs.num_cols);
  J.setFromTriplets(entries.begin(), entries.end());
  return J;
}

/// Per row of J: its leverage (the hat matrix's diagonal entry), exact or estimated. Empty when H
/// cannot be factorised.
std::vector<double> rowLeverages(const SparseMatrix& J) {
  const int n = static_cast<int>(J.cols()), m = static_cast<int>(J.rows());
  SparseMatrix H = SparseMatrix(J.transpose()) * J;
  double largest = 0.0;
  for (int c = 0; c < n; ++c) largest = std::max(largest, H.coeff(c, c));
  if (!(largest > 0.0) || !std::isfinite(largest)) return {};
  for (int c = 0; c < n; ++c) H.coeffRef(c, c) += kRidge * largest;
  std::vector<double> leverage(static_cast<size_t>(m), 0.0);
  if (n <= kMaxDenseParameters) {
    const Eigen::MatrixXd dense(H);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(dense);
    if (ldlt.info() != Eigen::Success) return {};
    const Eigen::MatrixXd Jt = Eigen::MatrixXd(J.transpose());
    const Eigen::MatrixXd X = ldlt.solve(Jt);  // H^-1 J^T, n x m
    for (int r = 0; r < m; ++r) leverage[static_cast<size_t>(r)] = Jt.col(r).dot(X.col(r));
    return leverage;
  }
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(H);
  if (ldlt.info() != Eigen::Success) return {};
  std::mt19937 random(20240917u);
  std::bernoulli_distribution sign(0.5);
  Eigen::VectorXd z(m);
  for (int p = 0; p < kProbes; ++p) {
    for (int r = 0; r < m; ++r) z(r) = sign(random) ? 1.0 : -1.0;
    const Eigen::VectorXd y = ldlt.solve(J.transpose() * z);
    const Eigen::VectorXd hat_z = J * y;
    if (!hat_z.allFinite()) return {};
    for (int r = 0; r < m; ++r) leverage[static_cast<size_t>(r)] += z(r) * hat_z(r) / kProbes;
  }
  return leverage;
}

}  // namespace

bool measureNoiseComponents(ceres::Problem* ceres_problem, const BuiltProblem& built,
                            LearnedNoise* noise) {
  noise->chi2.fill(0.0);
  noise->redundancy.fill(0.0);
  noise->residuals.fill(0);
  struct Block {
    int kind = 0, size = 0;
    double squared = 0, leverage = 0;
  };
  std::unordered_map<ceres::ResidualBlockId, size_t> block_of;
  std::vector<Block> blocks;
  for (const ResidualRecord& record : built.residuals) {
    if (record.noise_kind < 0) continue;
    double cost = 0.0;
    Eigen::VectorXd r(record.size);
    ceres_problem->EvaluateResidualBlock(record.id, false, &cost, r.data(), nullptr);
    block_of[record.id] = blocks.size();
    blocks.push_back({record.noise_kind, record.size, r.squaredNorm(), 0.0});
  }
  if (blocks.empty()) return true;

  ceres::Problem::EvaluateOptions options;
  ceres_problem->GetResidualBlocks(&options.residual_blocks);
  options.parameter_blocks = built.free_blocks;
  options.apply_loss_function = true;
  options.num_threads = 1;
  ceres::CRSMatrix crs;
  if (!ceres_problem->Evaluate(options, nullptr, nullptr, nullptr, &crs)) return false;
  const std::vector<double> leverage = rowLeverages(toSparse(crs));
  if (leverage.empty()) return false;
  size_t row = 0;
  for (ceres::ResidualBlockId id : options.residual_blocks) {
    const int size = ceres_problem->GetCostFunctionForResidualBlock(id)->num_residuals();
    const auto it = block_of.find(id);
    for (int i = 0; i < size; ++i, ++row) {
      if (it != block_of.end()) blocks[it->second].leverage += leverage[row];
    }
  }
  // Each block's squared norm capped at kCapQuantile of chi-square with its size: a gross outlier
  // (a glitch, a moved object) counts as a large residual, not as its own size.
  for (const Block& block : blocks) {
    const auto k = static_cast<size_t>(block.kind);
    noise->residuals[k] += block.size;
    noise->chi2[k] += std::min(block.squared, chiSquareQuantile(block.size, kCapQuantile));
    noise->redundancy[k] += block.size - block.leverage;
  }
  for (double& r : noise->redundancy) r = std::max(0.0, r);
  return true;
}

NoiseFactors updatedNoiseFactors(const LearnedNoise& noise,
                                 const std::array<bool, kNoiseKinds>& held) {
  NoiseFactors factors = noise.variance_factor;
  for (size_t k = 0; k < factors.size(); ++k) {
    if (held[k] || !(noise.redundancy[k] >= kMinNoiseRedundancy) || !(noise.chi2[k] > 0.0)) {
      continue;
    }
    const double factor = noise.variance_factor[k] * noise.chi2[k] / noise.redundancy[k];
    if (std::isfinite(factor)) {
      factors[k] = std::clamp(factor, 1.0 / kMaxNoiseFactor, kMaxNoiseFactor);
    }
  }
  return factors;
}

CameraGyroSplit splitCameraGyro(const JointProblem& problem, const Whitening& whitening,
                                const BuiltProblem& built, State* state,
                                ceres::Problem* ceres_problem) {
  CameraGyroSplit split;
  const size_t n = problem.poses.size();
  // The gyro residual of each interval between two motion nodes, with the camera corrections
  // zeroed, unwhitened and carried into the world frame (frame of its `to` node).
  std::vector<std::array<double, 3>> saved(state->delta);
  for (size_t k = 0; k < n; ++k) {
    if (!problem.poses[k].at_rest) state->delta[k] = {0.0, 0.0, 0.0};
  }
  const Eigen::Matrix3d X =
      expSO3(Eigen::Map<const Eigen::Vector3d>(state->e_X.data())) * state->R_cam_imu_0;
  struct Interval {
    int from = 0, to = 0;
    double duration_s = 0;
    Eigen::Vector3d world = Eigen::Vector3d::Zero();
  };
  std::vector<Interval> intervals;
  for (const ResidualRecord& record : built.residuals) {
    if (record.noise_kind != static_cast<int>(NoiseKind::kGyroWhite) || record.segment < 0) {
      continue;
    }
    const GyroSegment& segment = problem.segments[static_cast<size_t>(record.segment)];
    const auto from = static_cast<size_t>(segment.from_pose),
               to = static_cast<size_t>(segment.to_pose);
    if (!segment.interval || problem.poses[from].at_rest || problem.poses[to].at_rest) continue;
    double cost = 0.0;
    Eigen::Vector3d r;
    ceres_problem->EvaluateResidualBlock(record.id, false, &cost, r.data(), nullptr);
    const Eigen::Vector3d error =
        whitening.gyro_relative[static_cast<size_t>(record.segment)].lu().solve(r);
    Interval interval;
    interval.from = segment.from_pose;
    interval.to = segment.to_pose;
    interval.duration_s = problem.poses[to].start_s - problem.poses[from].start_s;
    interval.world = projectToSO3(problem.poses[to].R_target_cam) * X * error;
    if (interval.world.allFinite() && interval.duration_s > 0.0) intervals.push_back(interval);
  }
  state->delta = saved;
  std::sort(intervals.begin(), intervals.end(),
            [](const Interval& a, const Interval& b) { return a.from < b.from; });
  split.intervals = static_cast<int>(intervals.size());
  if (split.intervals < kMinSplitIntervals) return split;
  // Per span length m: the robust per-axis variance of the summed discrepancy and the mean span.
  constexpr int kMaxSpan = 8;
  constexpr double kChi2ThreeMedianPerAxis = 2.366 / 3.0;
  Eigen::Matrix<double, kMaxSpan, 2> A;
  Eigen::Matrix<double, kMaxSpan, 1> b;
  int rows = 0;
  for (int m = 1; m <= kMaxSpan; ++m) {
    std::vector<double> squared;
    double tau_sum = 0.0;
    for (size_t i = 0; i + static_cast<size_t>(m) <= intervals.size(); ++i) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      double tau = 0.0;
      bool chained = true;
      for (size_t j = i; j < i + static_cast<size_t>(m); ++j) {
        if (j > i && intervals[j].from != intervals[j - 1].to) chained = false;
        sum += intervals[j].world;
        tau += intervals[j].duration_s;
      }
      if (!chained) continue;
      squared.push_back(sum.squaredNorm() / 3.0);
      tau_sum += tau;
    }
    if (squared.size() < static_cast<size_t>(kMinSplitIntervals) / 2) break;
    std::nth_element(squared.begin(), squared.begin() + squared.size() / 2, squared.end());
    A(rows, 0) = 1.0;
    A(rows, 1) = tau_sum / static_cast<double>(squared.size());
    b(rows) = squared[squared.size() / 2] / kChi2ThreeMedianPerAxis;
    ++rows;
  }
  if (rows < 3) return split;
  const Eigen::Vector2d line =
      A.topRows(rows).colPivHouseholderQr().solve(b.topRows(rows));  // [2 sigma_c^2, q]
  std::vector<double> camera_variance;
  for (const JointPose& pose : problem.poses) {
    if (!pose.at_rest) camera_variance.push_back(pose.cov_cam_rad2.trace() / 3.0);
  }
  std::nth_element(camera_variance.begin(), camera_variance.begin() + camera_variance.size() / 2,
                   camera_variance.end());
  const double stated_camera = camera_variance[camera_variance.size() / 2];
  double density = problem.motion_gyro.noise_density_rad_s_sqrt_hz;
  if (!(density > 0.0) && !problem.segments.empty()) {
    density = problem.segments.front().noise_density_rad_s_sqrt_hz;
  }
  if (!(stated_camera > 0.0) || !(density > 0.0) || !line.allFinite()) return split;
  split.camera_factor =
      std::clamp(0.5 * line(0) / stated_camera, kMinCameraFactor, kMaxNoiseFactor);
  split.gyro_factor = std::clamp(line(1) / (density * density), 1.0, kMaxNoiseFactor);
  split.ok = true;
  return split;
}

double noiseFactorChange(const NoiseFactors& a, const NoiseFactors& b) {
  double change = 0.0;
  for (size_t k = 0; k < a.size(); ++k) {
    change = std::max(change, std::abs(a[k] - b[k]) / std::max(1e-12, std::min(a[k], b[k])));
  }
  return change;
}

namespace {

/// Kinds whose variance components do not separate them (one's noise passes for the other's
/// over many passes): after their first estimate their ratio is held and one scale learned for
/// the group from its pooled components. The camera's orientation and the gyro's white noise
/// (one chain of nodes); the camera's position, the accelerometer's white noise and its bias
/// walk (one chain of keyframes).
constexpr std::array<std::array<int, 3>, 2> kPooled = {
    {{static_cast<int>(NoiseKind::kCameraMotion), static_cast<int>(NoiseKind::kGyroWhite), -1},
     {static_cast<int>(NoiseKind::kCameraPosition), static_cast<int>(NoiseKind::kAccelWhite),
      static_cast<int>(NoiseKind::kAccelWalk)}}};

/// The IMU's white noise and the camera's orientation noise are not taken below their stated
/// values (a datasheet density, a PnP covariance: what a sensor does at best).
double floorOf(size_t kind) {
  return kind == static_cast<size_t>(NoiseKind::kGyroWhite) ||
                 kind == static_cast<size_t>(NoiseKind::kAccelWhite) ||
                 kind == static_cast<size_t>(NoiseKind::kCameraMotion)
             ? 1.0
             : 1.0 / kMaxNoiseFactor;
}

}  // namespace

bool NoiseLearner::update(const JointProblem& problem, const Whitening& whitening,
                          const BuiltProblem& built, State* state, ceres::Problem* ceres_problem) {
  next_ = noise_.variance_factor;
  if (!measureNoiseComponents(ceres_problem, built, &noise_)) {
    noise_.settled = true;
    return false;
  }
  const auto camera = static_cast<size_t>(NoiseKind::kCameraMotion),
             gyro = static_cast<size_t>(NoiseKind::kGyroWhite);
  NoiseFactors factors = noise_.variance_factor;
  std::array<bool, kNoiseKinds> held{};
  const bool first = noise_.passes == 0;
  if (first) {
    factors = updatedNoiseFactors(noise_);
    const CameraGyroSplit measured =
        splitCameraGyro(problem, whitening, built, state, ceres_problem);
    if (measured.ok) {
      factors[camera] = measured.camera_factor;
      factors[gyro] = measured.gyro_factor;
    }
    for (size_t k = 0; k < factors.size(); ++k) {
      noise_.learned[k] = noise_.redundancy[k] >= kMinNoiseRedundancy ||
                          (measured.ok && (k == camera || k == gyro));
    }
  }
  for (const std::array<int, 3>& group : kPooled) {
    double chi2 = 0.0, redundancy = 0.0;
    bool learned = false;
    for (int kind : group) {
      if (kind < 0) continue;
      const auto k = static_cast<size_t>(kind);
      held[k] = true;
      chi2 += noise_.chi2[k];
      redundancy += noise_.redundancy[k];
      learned = learned || noise_.learned[k];
    }
    if (first || !learned || !(redundancy >= kMinNoiseRedundancy) || !(chi2 > 0.0)) continue;
    const double pooled = chi2 / redundancy;
    for (int kind : group) {
      if (kind < 0 || noise_.residuals[static_cast<size_t>(kind)] == 0) continue;
      const auto k = static_cast<size_t>(kind);
      factors[k] = std::clamp(factors[k] * pooled, floorOf(k), kMaxNoiseFactor);
      noise_.learned[k] = true;
    }
  }
  if (!first) {
    const NoiseFactors components = updatedNoiseFactors(noise_, held);
    for (size_t k = 0; k < factors.size(); ++k) {
      if (held[k]) continue;
      factors[k] = components[k];
      noise_.learned[k] = noise_.learned[k] || noise_.redundancy[k] >= kMinNoiseRedundancy;
    }
  }
  for (size_t k = 0; k < factors.size(); ++k) factors[k] = std::max(factors[k], floorOf(k));
  next_ = factors;
  noise_.settled = noiseFactorChange(factors, noise_.variance_factor) < kNoiseSettled;
  return !noise_.settled;
}

/// The factors of the next pass become the ones it is built with.
void NoiseLearner::advance() {
  noise_.variance_factor = next_;
  ++noise_.passes;
}

}  // namespace joint
}  // namespace camera_imu_alignment
