// Covariance, consistency and the reported IMU model of the joint estimator.
#include <ceres/covariance.h>

#include <Eigen/LU>
#include <boost/math/special_functions/gamma.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <unordered_set>
#include <utility>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "joint_residuals.h"
#include "joint_state.h"

namespace camera_imu_alignment {
namespace joint {
namespace {

/// Sigmas (sqrt of the covariance diagonal, times sqrt(scale)) of `block`, or the priors' when
/// the block was not requested (held).
Eigen::VectorXd blockSigma(const ceres::Covariance& covariance,
                           const std::map<const double*, int>& requested, const double* block,
                           const Eigen::VectorXd& prior_sigma, double scale) {
  const auto it = requested.find(block);
  if (it == requested.end()) return prior_sigma;
  const int size = it->second;
  Eigen::MatrixXd C(size, size);  // row-major from Ceres; only the diagonal is read
  if (!covariance.GetCovarianceBlock(block, block, C.data())) return prior_sigma;
  Eigen::VectorXd sigma(size);
  for (int i = 0; i < size; ++i) sigma(i) = std::sqrt(std::max(0.0, C(i, i) * scale));
  return sigma;
}

Eigen::Matrix3d sixToMatrix(const Eigen::VectorXd& p, bool symmetric) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  M(0, 0) = p(0);
  M(1, 1) = p(1);
  M(2, 2) = p(2);
  M(1, 0) = p(3);
  M(2, 0) = p(4);
  M(2, 1) = p(5);
  if (symmetric) {
    M(0, 1) = p(3);
    M(0, 2) = p(4);
    M(1, 2) = p(5);
  }
  return M;
}

Eigen::VectorXd toVector(const double* values, int size) {
  return Eigen::Map<const Eigen::VectorXd>(values, size);
}

}  // namespace

double chiSquareUpperTail(double chi2, int dof) {
  if (dof <= 0 || !std::isfinite(chi2)) return 1.0;
  if (!(chi2 > 0.0)) return 1.0;
  try {
    // The chi-square upper tail is the regularised upper incomplete gamma Q(dof / 2, chi2 / 2).
    return boost::math::gamma_q(0.5 * dof, 0.5 * chi2);
  } catch (const std::exception&) {
    return 0.0;  // an evaluation error far out in the tail
  }
}

bool fillResult(const JointProblem& problem, const State& state, const BuiltProblem& built,
                const Whitening& whitening, const JointObservability& observability,
                const JointSettings& settings, ceres::Problem* ceres_problem, JointResult* result) {
  // Consistency: plain squared whitened residuals (no robust loss).
  const size_t n = problem.poses.size();
  std::vector<double> pose_sum(n, 0.0), pose_count(n, 0.0);
  double chi2 = 0.0;
  int residual_count = 0;
  Eigen::VectorXd r(16);
  result->mag_residual_chi2.assign(n, 0.0);
  result->camera_link_chi2.assign(problem.camera_links.size(), 0.0);
  result->camera_link_residual_rad.assign(problem.camera_links.size(), Eigen::Vector3d::Zero());
  result->camera_residual_rad.assign(n, Eigen::Vector3d::Zero());
  result->camera_orientation_fit.assign(n, Eigen::Matrix3d::Identity());
  for (size_t k = 0; k < n; ++k) {
    result->camera_orientation_fit[k] =
        projectToSO3(problem.poses[k].R_target_cam) *
        expSO3(Eigen::Map<const Eigen::Vector3d>(state.delta[k].data()));
    if (problem.poses[k].camera_absolute) {  // a rest's PnP or a motion node's
      result->camera_residual_rad[k] = Eigen::Map<const Eigen::Vector3d>(state.delta[k].data());
    }
  }
  for (const ResidualRecord& record : built.residuals) {
    double cost = 0.0;
    r.resize(record.size);
    ceres_problem->EvaluateResidualBlock(record.id, false, &cost, r.data(), nullptr);
    const double squared = r.squaredNorm();
    chi2 += squared;
    if (record.magnetometer && record.pose >= 0) result->mag_residual_chi2[record.pose] = squared;
    if (record.camera_link >= 0) {
      result->camera_link_chi2[record.camera_link] = squared;
      // Unwhitened: the residual is L^-1 Log(R_measured^T R_fit), L^-1 the link's whitening.
      result->camera_link_residual_rad[record.camera_link] =
          whitening.camera_link[record.camera_link].lu().solve(Eigen::Vector3d(r.head<3>()));
    }
    residual_count += record.size;
    if (record.pose < 0) continue;
    const double share = record.other_pose >= 0 ? 0.5 : 1.0;
    pose_sum[record.pose] += share * squared;
    pose_count[record.pose] += share * record.size;
    if (record.other_pose >= 0) {
      pose_sum[record.other_pose] += share * squared;
      pose_count[record.other_pose] += share * record.size;
    }
  }
  int free_parameters = 0;
  for (double* block : built.free_blocks) {
    free_parameters += ceres_problem->ParameterBlockTangentSize(block);
  }
  result->chi2 = chi2;
  result->dof = residual_count - free_parameters;
  result->chi2_p_value = chiSquareUpperTail(chi2, result->dof);
  result->pose_residual_norm.assign(n, 0.0);
  for (size_t k = 0; k < n; ++k) {
    if (pose_count[k] > 0.0) result->pose_residual_norm[k] = std::sqrt(pose_sum[k] / pose_count[k]);
  }
  const double chi2_per_dof = result->dof > 0 ? chi2 / result->dof : 1.0;
  result->covariance_scale = chi2_per_dof > 1.0 ? chi2_per_dof : 1.0;
  if (!std::isfinite(result->covariance_scale)) {
    result->message = "the residuals are not finite at the estimate";
    return false;
  }
  if (!settings.compute_covariance) return true;  // the fit alone (JointSettings)

  // Covariance of R_cam_imu and of every estimated block.
  std::map<const double*, int> requested;
  std::vector<std::pair<const double*, const double*>> pairs;
  // Not reported, and many: the mount deltas, the motion nodes' gyro biases, the acceleration
  // model's keyframe states and link biases.
  std::unordered_set<const double*> unreported = {state.e_T.data()};
  for (const auto& d : state.delta) unreported.insert(d.data());
  for (size_t k = 0; k < n; ++k) {
    if (!problem.poses[k].at_rest) unreported.insert(state.gyro_bias[k].data());
  }
  for (const auto& pv : state.keyframe_pv) unreported.insert(pv.data());
  for (const auto& b : state.link_accel_bias) unreported.insert(b.data());
  for (double* block : built.free_blocks) {
    if (unreported.count(block) > 0) continue;
    requested[block] = ceres_problem->ParameterBlockSize(block);
    pairs.emplace_back(block, block);
  }
  ceres::Covariance::Options options;
  options.num_threads = 1;
  ceres::Covariance covariance(options);
  bool computed = covariance.Compute(pairs, ceres_problem);
  std::unique_ptr<ceres::Covariance> fallback;
  const ceres::Covariance* used = &covariance;
  if (!computed) {
    // Rank-deficient for the sparse QR: the dense SVD reports it through its pseudo-inverse.
    options.algorithm_type = ceres::DENSE_SVD;
    fallback = std::make_unique<ceres::Covariance>(options);
    computed = fallback->Compute(pairs, ceres_problem);
    used = fallback.get();
  }
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> cov_x;
  if (!computed || !used->GetCovarianceBlock(state.e_X.data(), state.e_X.data(), cov_x.data()) ||
      !cov_x.allFinite()) {
    result->message = "the covariance of R_cam_imu cannot be computed (the problem is degenerate)";
    return false;
  }
  result->covariance_rad2 = cov_x * result->covariance_scale;
  result->covariance_rad2 = 0.5 * (result->covariance_rad2 + result->covariance_rad2.transpose());
  for (int i = 0; i < 3; ++i) {
    result->std_dev_deg(i) = rad2deg(std::sqrt(std::max(0.0, result->covariance_rad2(i, i))));
  }

  // The IMU model.
  const ImuModelPriors& p = settings.priors;
  const double scale = result->covariance_scale;
  ImuIntrinsics& in = result->intrinsics;
  const bool symmetric = settings.accel_matrix_form == AccelMatrixForm::kSymmetric;
  Eigen::VectorXd accel_prior(6), soft_prior(6), gyro_prior(9);
  accel_prior << p.accel_scale, p.accel_scale, p.accel_scale, p.accel_cross_axis,
      p.accel_cross_axis, p.accel_cross_axis;
  soft_prior << p.soft_iron_scale, p.soft_iron_scale, p.soft_iron_scale, p.soft_iron_cross,
      p.soft_iron_cross, p.soft_iron_cross;
  for (int i = 0; i < 9; ++i) gyro_prior(i) = i % 4 == 0 ? p.gyro_scale : p.gyro_cross_axis;

  // T_g and T_a held at I (ImuMatrixModel::kIdentity) have no uncertainty.
  const bool identity = settings.imu_matrices == ImuMatrixModel::kIdentity;
  Eigen::VectorXd accel_sigma =
      blockSigma(*used, requested, state.accel_matrix.data(), accel_prior, scale);
  if (identity) accel_sigma.setZero();
  in.accel_matrix =
      Eigen::Matrix3d::Identity() + sixToMatrix(toVector(state.accel_matrix.data(), 6), symmetric);
  in.accel_matrix_sigma = sixToMatrix(accel_sigma, symmetric);
  // Estimated = determined by the data (joint_observability.h), judged on the unscaled 1-sigma.
  const double unscale = 1.0 / std::sqrt(scale);
  in.accel_matrix_estimated = observability.accel_matrix_estimated && !identity &&
                              informedByTheData(accel_sigma * unscale, accel_prior);
  int first_rest = 0;
  while (first_rest + 1 < static_cast<int>(n) && !problem.poses[first_rest].at_rest) ++first_rest;
  const Eigen::VectorXd accel_bias_sigma =
      n == 0 ? Eigen::VectorXd(Eigen::Vector3d::Constant(p.accel_bias_m_s2))
             : blockSigma(*used, requested, state.accel_bias[first_rest].data(),
                          Eigen::Vector3d::Constant(p.accel_bias_m_s2), scale);
  in.accel_bias_m_s2 = n == 0 ? Eigen::Vector3d::Zero() : state.accelBias(first_rest);
  in.accel_bias_sigma_m_s2 = accel_bias_sigma;
  in.accel_bias_per_pose_m_s2.clear();
  for (size_t k = 0; k < n; ++k) {
    in.accel_bias_per_pose_m_s2.push_back(state.accelBias(static_cast<int>(k)));
  }
  in.accel_bias_estimated =
      observability.accel_bias_estimated &&
      informedByTheData(accel_bias_sigma * unscale, Eigen::Vector3d::Constant(p.accel_bias_m_s2));

  const bool has_gyro = !problem.segments.empty();
  Eigen::VectorXd gyro_sigma =
      blockSigma(*used, requested, state.gyro_matrix.data(), gyro_prior, scale);
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d column_sigma, column_prior;
    for (int r = 0; r < 3; ++r) {
      column_sigma(r) = gyro_sigma(3 * r + c) * unscale;
      column_prior(r) = gyro_prior(3 * r + c);
    }
    in.gyro_matrix_column_estimated[c] = has_gyro && observability.gyro_column_estimated[c] &&
                                         !identity && informedByTheData(column_sigma, column_prior);
    for (int r = 0; r < 3; ++r) {
      const bool held =
          !observability.gyro_column_estimated[c] && settings.pin_unexcited_parameters;
      if (held || !has_gyro) gyro_sigma(3 * r + c) = gyro_prior(3 * r + c);
      if (identity) gyro_sigma(3 * r + c) = 0.0;
    }
  }
  in.gyro_matrix = state.gyroMatrix();
  in.gyro_matrix_sigma =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(gyro_sigma.data());
  in.gyro_bias_per_pose_rad_s.clear();
  for (size_t k = 0; k < n; ++k)
    in.gyro_bias_per_pose_rad_s.push_back(state.gyroBias(static_cast<int>(k)));
  const std::vector<bool> with_gyro = posesWithGyro(problem);
  const auto first = std::find(with_gyro.begin(), with_gyro.end(), true);
  const int first_pose = first == with_gyro.end() ? 0 : static_cast<int>(first - with_gyro.begin());
  in.gyro_bias_rad_s = state.gyroBias(first_pose);
  in.gyro_bias_sigma_rad_s =
      blockSigma(*used, requested, state.gyro_bias[first_pose].data(),
                 problem.poses[first_pose].gyro_mean_cov.diagonal().cwiseSqrt(), scale);

  if (requested.count(state.timeshift.data()) > 0) {
    result->timeshift_estimated = true;
    result->timeshift_cam_imu_s = state.timeshift[0];
    result->timeshift_sigma_s =
        blockSigma(*used, requested, state.timeshift.data(), Eigen::VectorXd::Zero(1), scale)(0);
  }

  // The lever arm (acceleration model only): measured when the data determine every axis.
  if (requested.count(state.lever_arm_m.data()) > 0) {
    const Eigen::VectorXd prior = Eigen::Vector3d::Constant(settings.lever_arm_prior_m);
    const Eigen::VectorXd sigma =
        blockSigma(*used, requested, state.lever_arm_m.data(), prior, scale);
    result->lever_arm_in_model = true;
    result->p_cam_imu_m =
        Eigen::Vector3d(state.lever_arm_m[0], state.lever_arm_m[1], state.lever_arm_m[2]);
    result->p_cam_imu_sigma_m = sigma;
    result->lever_arm_measured = informedByTheData(sigma * unscale, prior);
  }

  in.magnetometer_used = observability.magnetometer_used;
  const Eigen::VectorXd soft_sigma =
      blockSigma(*used, requested, state.soft_iron.data(), soft_prior, scale);
  in.soft_iron_estimated = observability.magnetometer_used && observability.soft_iron_estimated &&
                           informedByTheData(soft_sigma * unscale, soft_prior);
  in.soft_iron =
      Eigen::Matrix3d::Identity() + sixToMatrix(toVector(state.soft_iron.data(), 6), true);
  in.soft_iron_sigma = sixToMatrix(soft_sigma, true);
  in.hard_iron_t = toVector(state.hard_iron_ut.data(), 3) / kMicroteslaPerTesla;
  in.hard_iron_sigma_t =
      blockSigma(*used, requested, state.hard_iron_ut.data(),
                 Eigen::Vector3d::Constant(p.hard_iron_t * kMicroteslaPerTesla), scale) /
      kMicroteslaPerTesla;
  in.hard_iron_estimated =
      observability.magnetometer_used && observability.hard_iron_estimated &&
      informedByTheData(in.hard_iron_sigma_t * unscale, Eigen::Vector3d::Constant(p.hard_iron_t));
  if (observability.magnetometer_used) {
    in.magnetic_field_t = std::hypot(state.field_ut[0], state.field_ut[1]) / kMicroteslaPerTesla;
    in.magnetic_dip_rad = std::atan2(-state.field_ut[1], state.field_ut[0]);
  }

  // The same as a list, one entry per block.
  auto add = [&](const std::string& name, const Eigen::VectorXd& value,
                 const Eigen::VectorXd& sigma, bool estimated) {
    result->parameters.push_back({name, value, sigma, estimated});
  };
  const char* axes[3] = {"x", "y", "z"};
  for (int c = 0; c < 3; ++c) {
    add(std::string("gyro_matrix_column_") + axes[c], in.gyro_matrix.col(c),
        in.gyro_matrix_sigma.col(c), in.gyro_matrix_column_estimated[c]);
  }
  add("gyro_bias_rad_s", in.gyro_bias_rad_s, in.gyro_bias_sigma_rad_s, has_gyro);
  add("accel_matrix_minus_identity", toVector(state.accel_matrix.data(), 6), accel_sigma,
      in.accel_matrix_estimated);
  add("accel_bias_m_s2", in.accel_bias_m_s2, in.accel_bias_sigma_m_s2, in.accel_bias_estimated);
  add("soft_iron_minus_identity", toVector(state.soft_iron.data(), 6), soft_sigma,
      in.soft_iron_estimated);
  add("hard_iron_t", in.hard_iron_t, in.hard_iron_sigma_t, in.hard_iron_estimated);
  return true;
}

}  // namespace joint
}  // namespace camera_imu_alignment
