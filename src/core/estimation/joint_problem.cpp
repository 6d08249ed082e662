// The Ceres problem of the joint estimator: residuals, priors and what is held (joint_estimator.h).
#include <ceres/autodiff_cost_function.h>
#include <ceres/dynamic_autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/normal_prior.h>

#include <algorithm>
#include <cmath>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "joint_residuals.h"
#include "joint_state.h"

namespace camera_imu_alignment {
namespace joint {
namespace {

/// Shortest time between two rests' centres a walk residual assumes (s): keeps its sigma > 0.
constexpr double kMinWalkDt = 1e-3;
/// 1-sigma (rad) of the weak prior on each step of the second mount's rotation (30 deg): it
/// holds what the poses after a change do not determine (one pose without the magnetometer
/// leaves the rotation about its gravity free) and is far too weak to move what they do.
constexpr double kAfterChangeStepSigmaRad = 0.52;
/// 1-sigma (rad) of the weak prior on the camera correction of a relative-only pose that no
/// camera link measures (its links left the window): 30 deg, as kAfterChangeStepSigmaRad; the
/// pose's IMU measurements still count, its camera tells nothing.
constexpr double kUnlinkedCameraSigmaRad = 0.52;

ceres::LossFunction* makeLoss(const JointSettings& settings) {
  switch (settings.robust_loss) {
    case RobustLossKind::kHuber:
      return new ceres::HuberLoss(settings.robust_loss_scale);
    case RobustLossKind::kCauchy:
      return new ceres::CauchyLoss(settings.robust_loss_scale);
    case RobustLossKind::kNone:
      break;
  }
  return nullptr;
}

/// Prior (x[i] - 0) / sigma[i] on the entries of a block listed in `entries`.
ceres::CostFunction* maskedPrior(int block_size, const std::vector<int>& entries,
                                 const std::vector<double>& sigmas) {
  ceres::Matrix A = ceres::Matrix::Zero(static_cast<int>(entries.size()), block_size);
  for (size_t i = 0; i < entries.size(); ++i) A(i, entries[i]) = 1.0 / sigmas[i];
  return new ceres::NormalPrior(A, ceres::Vector::Zero(block_size));
}

class Builder {
 public:
  Builder(const JointProblem& problem, const Whitening& whitening,
          const JointObservability& observability, const JointSettings& settings, State* state,
          ceres::Problem* ceres_problem)
      : problem_(problem),
        whitening_(whitening),
        observability_(observability),
        settings_(settings),
        state_(*state),
        ceres_(*ceres_problem),
        loss_(makeLoss(settings)),
        pin_(settings.pin_unexcited_parameters),
        identity_matrices_(settings.imu_matrices == ImuMatrixModel::kIdentity) {}

  BuiltProblem build(const std::vector<GyroPreintegration>& gyro,
                     const std::vector<Eigen::Vector3d>& rates_from,
                     const std::vector<Eigen::Vector3d>& rates_to,
                     const std::vector<AccelLinkIntegral>& accel_links) {
    const size_t n = problem_.poses.size();
    for (size_t k = 0; k < n; ++k) {
      if (problem_.poses[k].at_rest) rests_.push_back(k);
    }
    addBlock(state_.e_X.data(), 3);
    if (problem_.mount_change_pose >= 0) {
      addBlock(state_.e_X_after.data(), 3);
      // Not recorded: it is no measurement and stays out of the chi-square and its dof.
      ceres_.AddResidualBlock(
          new ceres::NormalPrior(Eigen::Matrix3d::Identity() / kAfterChangeStepSigmaRad,
                                 ceres::Vector::Zero(3)),
          nullptr, state_.e_X_after.data());
    }
    addBlock(state_.e_T.data(), 3);
    // Without the magnetometer, W's yaw is a gauge: hold the increment about world z.
    if (!observability_.magnetometer_used) {
      ceres_.SetManifold(state_.e_T.data(), new ceres::SubsetManifold(3, {2}));
    }
    // Without rests or accelerometer links nothing sees the world frame: R_world_target is a
    // gauge.
    if (rests_.empty() && problem_.accel_links.empty() && !observability_.magnetometer_used) {
      holdBlock(state_.e_T.data());
    }
    for (size_t k = 0; k < n; ++k) addBlock(state_.delta[k].data(), 3);
    addCameraLinks();
    addAccelerometer();
    if (observability_.magnetometer_used) addMagnetometer();
    if (!problem_.segments.empty()) addGyro(gyro, rates_from, rates_to);
    if (!problem_.accel_links.empty()) addAccelLinks(accel_links);
    return std::move(built_);
  }

 private:
  void addBlock(double* block, int size) {
    ceres_.AddParameterBlock(block, size);
    built_.free_blocks.push_back(block);
  }

  void holdBlock(double* block) {
    ceres_.SetParameterBlockConstant(block);
    built_.free_blocks.erase(
        std::remove(built_.free_blocks.begin(), built_.free_blocks.end(), block),
        built_.free_blocks.end());
  }

  void record(ceres::ResidualBlockId id, int pose, int other_pose, int size,
              bool magnetometer = false) {
    built_.residuals.push_back({id, pose, other_pose, size, magnetometer});
  }
  /// The last recorded residual measures `kind` (its noise is learned, JointProblem::noise).
  void learned(NoiseKind kind) { built_.residuals.back().noise_kind = static_cast<int>(kind); }
  /// 1-sigma factor of a learned kind in this problem.
  double sigmaFactor(NoiseKind kind) const {
    return std::sqrt(problem_.noise[static_cast<size_t>(kind)]);
  }

  bool afterChange(size_t k) const {
    return problem_.mount_change_pose >= 0 && static_cast<int>(k) >= problem_.mount_change_pose;
  }
  /// R_cam_imu of pose k: its linearisation point and increment block.
  const Eigen::Matrix3d& cameraImu0(size_t k) const {
    return afterChange(k) ? state_.R_cam_imu_after_0 : state_.R_cam_imu_0;
  }
  double* cameraImuIncrement(size_t k) {
    return afterChange(k) ? state_.e_X_after.data() : state_.e_X.data();
  }

  Eigen::Matrix3d targetCam(size_t k) const {
    return state_.R_world_target_0 * projectToSO3(problem_.poses[k].R_target_cam);
  }

  void addAccelerometer() {
    const size_t n = problem_.poses.size();
    addBlock(state_.accel_matrix.data(), 6);
    for (size_t k : rests_) addBlock(state_.accel_bias[k].data(), 3);
    for (size_t k = 0; k < n; ++k) {
      if (!problem_.poses[k].at_rest) {  // a motion node: its camera prior only
        auto* camera = new ceres::NormalPrior(whitening_.camera[k], ceres::Vector::Zero(3));
        record(ceres_.AddResidualBlock(camera, loss_, state_.delta[k].data()), static_cast<int>(k),
               -1, 3);
        learned(NoiseKind::kCameraMotion);
        continue;
      }
      const JointPose& pose = problem_.poses[k];
      auto* accel = new ceres::AutoDiffCostFunction<AccelResidual, 3, 3, 3, 3, 6, 3>(
          new AccelResidual{targetCam(k), cameraImu0(k), pose.accel_mean_m_s2, whitening_.accel[k],
                            settings_.gravity_m_s2, settings_.accel_matrix_form});
      record(ceres_.AddResidualBlock(accel, loss_, state_.e_T.data(), cameraImuIncrement(k),
                                     state_.delta[k].data(), state_.accel_matrix.data(),
                                     state_.accel_bias[k].data()),
             static_cast<int>(k), -1, 3);
      if (!pose.camera_absolute) continue;  // measured by its camera links
      auto* camera = new ceres::NormalPrior(whitening_.camera[k], ceres::Vector::Zero(3));
      record(ceres_.AddResidualBlock(camera, loss_, state_.delta[k].data()), static_cast<int>(k),
             -1, 3);
    }
    const ImuModelPriors& p = settings_.priors;
    if (rests_.empty() && problem_.accel_links.empty()) {
      holdBlock(state_.accel_matrix.data());  // no accelerometer data: nothing to estimate
      return;
    }
    if (identity_matrices_) {
      holdBlock(state_.accel_matrix.data());
    } else if (observability_.accel_matrix_estimated || !pin_) {
      record(ceres_.AddResidualBlock(
                 maskedPrior(6, {0, 1, 2, 3, 4, 5},
                             {p.accel_scale, p.accel_scale, p.accel_scale, p.accel_cross_axis,
                              p.accel_cross_axis, p.accel_cross_axis}),
                 nullptr, state_.accel_matrix.data()),
             -1, -1, 6);
    } else {
      holdBlock(state_.accel_matrix.data());
    }
    if (rests_.empty()) return;  // the accelerometer links have a bias of their own
    if (observability_.accel_bias_estimated || !pin_) {
      // The prior holds the first pose's bias, the walk each next one's.
      record(ceres_.AddResidualBlock(
                 maskedPrior(3, {0, 1, 2}, std::vector<double>(3, p.accel_bias_m_s2)), nullptr,
                 state_.accel_bias[rests_[0]].data()),
             -1, -1, 3);
      for (size_t i = 0; i + 1 < rests_.size(); ++i) {
        const size_t k = rests_[i], l = rests_[i + 1];
        const double dt = std::max(std::abs(restCentre(l) - restCentre(k)), kMinWalkDt);
        auto* walk = new ceres::AutoDiffCostFunction<BiasWalkResidual, 3, 3, 3>(
            new BiasWalkResidual{1.0 / (p.accel_bias_walk_m_s2_sqrt_s *
                                        sigmaFactor(NoiseKind::kAccelWalk) * std::sqrt(dt))});
        record(ceres_.AddResidualBlock(walk, nullptr, state_.accel_bias[k].data(),
                                       state_.accel_bias[l].data()),
               static_cast<int>(k), static_cast<int>(l), 3);
        learned(NoiseKind::kAccelWalk);
      }
    } else {
      for (size_t k : rests_) holdBlock(state_.accel_bias[k].data());
    }
  }

  /// The relative camera rotations (natural scene), and the gauge they leave: with no absolute
  /// camera orientation at all, the first pose's correction is held (the scene frame is that
  /// pose's camera frame up to its starting value; R_world_target takes the rest). Other groups
  /// of linked poses turn with their own correction, which the IMU determines.
  void addCameraLinks() {
    std::vector<bool> linked(problem_.poses.size(), false);
    for (const CameraLink& link : problem_.camera_links) {
      linked[static_cast<size_t>(link.from_pose)] = linked[static_cast<size_t>(link.to_pose)] =
          true;
    }
    for (size_t k = 0; k < problem_.poses.size(); ++k) {
      if (problem_.poses[k].camera_absolute || linked[k]) continue;
      // Not recorded: no measurement, out of the chi-square and its dof.
      ceres_.AddResidualBlock(
          new ceres::NormalPrior(Eigen::Matrix3d::Identity() / kUnlinkedCameraSigmaRad,
                                 ceres::Vector::Zero(3)),
          nullptr, state_.delta[k].data());
    }
    const bool any_absolute =
        std::any_of(problem_.poses.begin(), problem_.poses.end(),
                    [](const JointPose& pose) { return pose.camera_absolute; });
    if (!any_absolute) holdBlock(state_.delta[0].data());
    for (size_t j = 0; j < problem_.camera_links.size(); ++j) {
      const CameraLink& link = problem_.camera_links[j];
      const size_t from = static_cast<size_t>(link.from_pose),
                   to = static_cast<size_t>(link.to_pose);
      auto* cost = new ceres::AutoDiffCostFunction<CameraLinkResidual, 3, 3, 3>(
          new CameraLinkResidual{projectToSO3(link.R_from_to).transpose(),
                                 projectToSO3(problem_.poses[from].R_target_cam).transpose() *
                                     projectToSO3(problem_.poses[to].R_target_cam),
                                 whitening_.camera_link[j]});
      record(
          ceres_.AddResidualBlock(cost, loss_, state_.delta[from].data(), state_.delta[to].data()),
          static_cast<int>(from), static_cast<int>(to), 3);
      built_.residuals.back().camera_link = static_cast<int>(j);
    }
  }

  double restCentre(size_t k) const {
    return 0.5 * (problem_.poses[k].start_s + problem_.poses[k].end_s);
  }

  void addMagnetometer() {
    addBlock(state_.soft_iron.data(), 6);
    addBlock(state_.hard_iron_ut.data(), 3);
    addBlock(state_.field_ut.data(), 2);
    for (size_t k = 0; k < problem_.poses.size(); ++k) {
      const JointPose& pose = problem_.poses[k];
      if (!pose.mag_mean_t) continue;
      auto* mag = new ceres::AutoDiffCostFunction<MagResidual, 3, 3, 3, 3, 6, 3, 2>(
          new MagResidual{targetCam(k), cameraImu0(k), *pose.mag_mean_t * kMicroteslaPerTesla,
                          whitening_.mag_ut[k]});
      record(ceres_.AddResidualBlock(mag, loss_, state_.e_T.data(), cameraImuIncrement(k),
                                     state_.delta[k].data(), state_.soft_iron.data(),
                                     state_.hard_iron_ut.data(), state_.field_ut.data()),
             static_cast<int>(k), -1, 3, true);
    }
    const ImuModelPriors& p = settings_.priors;
    if (observability_.soft_iron_estimated || !pin_) {
      record(ceres_.AddResidualBlock(
                 maskedPrior(6, {0, 1, 2, 3, 4, 5},
                             {p.soft_iron_scale, p.soft_iron_scale, p.soft_iron_scale,
                              p.soft_iron_cross, p.soft_iron_cross, p.soft_iron_cross}),
                 nullptr, state_.soft_iron.data()),
             -1, -1, 6);
    } else {
      holdBlock(state_.soft_iron.data());
    }
    if (observability_.hard_iron_estimated || !pin_) {
      const double sigma_ut = p.hard_iron_t * kMicroteslaPerTesla;
      record(ceres_.AddResidualBlock(maskedPrior(3, {0, 1, 2}, std::vector<double>(3, sigma_ut)),
                                     nullptr, state_.hard_iron_ut.data()),
             -1, -1, 3);
    } else {
      holdBlock(state_.hard_iron_ut.data());
    }
  }

  void addGyro(const std::vector<GyroPreintegration>& gyro,
               const std::vector<Eigen::Vector3d>& rates_from,
               const std::vector<Eigen::Vector3d>& rates_to) {
    const std::vector<bool> with_gyro = posesWithGyro(problem_);
    const size_t n = problem_.poses.size();
    addBlock(state_.gyro_matrix.data(), 9);
    for (size_t k = 0; k < n; ++k) {
      if (!with_gyro[k]) continue;
      addBlock(state_.gyro_bias[k].data(), 3);
      if (!problem_.poses[k].at_rest) continue;  // a motion node: no rest mean
      auto* mean =
          new ceres::NormalPrior(whitening_.gyro_mean[k], problem_.poses[k].gyro_mean_rad_s);
      record(ceres_.AddResidualBlock(mean, nullptr, state_.gyro_bias[k].data()),
             static_cast<int>(k), -1, 3);
    }
    // Bias random walk between consecutive rests of one group.
    const double walk =
        settings_.priors.gyro_bias_walk_rad_s_sqrt_s * sigmaFactor(NoiseKind::kGyroWalk);
    for (size_t k = 0; k + 1 < n; ++k) {
      const JointPose& a = problem_.poses[k];
      const JointPose& b = problem_.poses[k + 1];
      if (!with_gyro[k] || !with_gyro[k + 1] || a.group != b.group) continue;
      const double dt = std::max(restCentre(k + 1) - restCentre(k), kMinWalkDt);
      auto* cost = new ceres::AutoDiffCostFunction<BiasWalkResidual, 3, 3, 3>(
          new BiasWalkResidual{1.0 / (walk * std::sqrt(dt))});
      record(ceres_.AddResidualBlock(cost, nullptr, state_.gyro_bias[k].data(),
                                     state_.gyro_bias[k + 1].data()),
             static_cast<int>(k), static_cast<int>(k + 1), 3);
      learned(NoiseKind::kGyroWalk);
    }
    for (size_t j = 0; j < problem_.segments.size(); ++j) {
      const GyroSegment& segment = problem_.segments[j];
      const int from = segment.from_pose, to = segment.to_pose;
      // The mount moved during this motion: the gyro measured the IMU's turn from the first
      // mount's orientation to the second's (below); a motion node's segment is left out (the
      // mount-change test solves the rests alone).
      const bool across_change =
          afterChange(static_cast<size_t>(to)) && !afterChange(static_cast<size_t>(from));
      if (across_change && segment.interval) continue;
      GyroModelVector theta0_minus_identity = gyro[j].theta0;
      theta0_minus_identity(0) -= 1.0;
      theta0_minus_identity(4) -= 1.0;
      theta0_minus_identity(8) -= 1.0;
      const Eigen::Matrix3d camera_relative =
          projectToSO3(problem_.poses[from].R_target_cam).transpose() *
          projectToSO3(problem_.poses[to].R_target_cam);
      GyroResidual residual{quaternionOf(camera_relative), quaternionOf(cameraImu0(from)),
                            quaternionOf(gyro[j].delta_R), gyro[j].jacobian,
                            theta0_minus_identity,         whitening_.gyro_relative[j]};
      if (across_change) {
        residual.q_X0_to = quaternionOf(cameraImu0(static_cast<size_t>(to)));
        auto* cost = new ceres::AutoDiffCostFunction<ChangeGyroResidual, 3, 3, 3, 3, 3, 9, 3, 3>(
            new ChangeGyroResidual{residual});
        record(ceres_.AddResidualBlock(cost, loss_, cameraImuIncrement(from),
                                       cameraImuIncrement(to), state_.delta[from].data(),
                                       state_.delta[to].data(), state_.gyro_matrix.data(),
                                       state_.gyro_bias[from].data(), state_.gyro_bias[to].data()),
               from, to, 3);
        learned(NoiseKind::kGyroWhite);
        built_.residuals.back().segment = static_cast<int>(j);
        continue;
      }
      if (segment.interval) {
        residual.rate_from = rates_from[j];
        residual.rate_to = rates_to[j];
        residual.timeshift0 = state_.timeshift_0;
        addTimeshift();
        auto* cost = new ceres::AutoDiffCostFunction<MotionGyroResidual, 3, 3, 3, 3, 9, 3, 3, 1>(
            new MotionGyroResidual{residual});
        record(ceres_.AddResidualBlock(cost, loss_, cameraImuIncrement(from),
                                       state_.delta[from].data(), state_.delta[to].data(),
                                       state_.gyro_matrix.data(), state_.gyro_bias[from].data(),
                                       state_.gyro_bias[to].data(), state_.timeshift.data()),
               from, to, 3);
        learned(NoiseKind::kGyroWhite);
        built_.residuals.back().segment = static_cast<int>(j);
        continue;
      }
      auto* cost = new ceres::AutoDiffCostFunction<GyroResidual, 3, 3, 3, 3, 9, 3, 3>(
          new GyroResidual(residual));
      record(
          ceres_.AddResidualBlock(cost, loss_, cameraImuIncrement(from), state_.delta[from].data(),
                                  state_.delta[to].data(), state_.gyro_matrix.data(),
                                  state_.gyro_bias[from].data(), state_.gyro_bias[to].data()),
          from, to, 3);
      learned(NoiseKind::kGyroWhite);
      built_.residuals.back().segment = static_cast<int>(j);
    }
    if (identity_matrices_) {
      holdBlock(state_.gyro_matrix.data());
      return;
    }
    // Priors on the columns of T_g - I; with pin_, the columns not excited are held instead.
    std::vector<int> free_entries, held_entries;
    std::vector<double> sigmas;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        if (observability_.gyro_column_estimated[c] || !pin_) {
          free_entries.push_back(3 * r + c);
          sigmas.push_back(r == c ? settings_.priors.gyro_scale : settings_.priors.gyro_cross_axis);
        } else {
          held_entries.push_back(3 * r + c);
        }
      }
    }
    if (free_entries.empty()) {
      holdBlock(state_.gyro_matrix.data());
      return;
    }
    if (!held_entries.empty()) {
      ceres_.SetManifold(state_.gyro_matrix.data(), new ceres::SubsetManifold(9, held_entries));
    }
    record(ceres_.AddResidualBlock(maskedPrior(9, free_entries, sigmas), nullptr,
                                   state_.gyro_matrix.data()),
           -1, -1, static_cast<int>(free_entries.size()));
  }

  /// The accelerometer between keyframes (AccelLink): the keyframes' position and velocity states
  /// with the camera's positions, the bias during the links and the lever arm.
  void addAccelLinks(const std::vector<AccelLinkIntegral>& integrals) {
    const ImuModelPriors& p = settings_.priors;
    const size_t links = problem_.accel_links.size();
    // Start values (kept between the passes): the measured positions and the central
    // differences of the keyframes' positions.
    if (state_.link_accel_bias.size() != links) state_.link_accel_bias.assign(links, {0, 0, 0});
    if (state_.keyframe_pv.size() != problem_.poses.size()) {
      state_.keyframe_pv.assign(problem_.poses.size(), {0, 0, 0, 0, 0, 0});
      for (const AccelLink& link : problem_.accel_links) {
        setKeyframe(link.from_pose, link.p_from_target_m, link.v_from_target_m_s);
        setKeyframe(link.to_pose, link.p_to_target_m, link.v_to_target_m_s);
      }
    }
    // Each keyframe's camera centre, measured once.
    std::vector<bool> measured(problem_.poses.size(), false);
    const auto measure = [&](int pose, const Eigen::Vector3d& p_target_m) {
      if (measured[static_cast<size_t>(pose)]) return;
      measured[static_cast<size_t>(pose)] = true;
      double* block = state_.keyframe_pv[static_cast<size_t>(pose)].data();
      addBlock(block, 6);
      ceres::Matrix A = ceres::Matrix::Zero(3, 6);
      A.leftCols(3) = ceres::Matrix::Identity(3, 3) /
                      (settings_.camera_position_sigma_m * sigmaFactor(NoiseKind::kCameraPosition));
      ceres::Vector b = ceres::Vector::Zero(6);
      b.head(3) = p_target_m;
      record(ceres_.AddResidualBlock(new ceres::NormalPrior(A, b), nullptr, block), pose, -1, 3);
      learned(NoiseKind::kCameraPosition);
    };
    // The bias during the links: the first with the bias prior, each next one a random walk from
    // the one before (link starts dt apart), as the rests' biases.
    for (size_t j = 0; j < links; ++j) {
      addBlock(state_.link_accel_bias[j].data(), 3);
      if (j == 0) {
        record(ceres_.AddResidualBlock(
                   maskedPrior(3, {0, 1, 2}, std::vector<double>(3, p.accel_bias_m_s2)), nullptr,
                   state_.link_accel_bias[j].data()),
               -1, -1, 3);
        continue;
      }
      const double dt = std::max(
          startOf(problem_.accel_links[j]) - startOf(problem_.accel_links[j - 1]), kMinWalkDt);
      auto* walk = new ceres::AutoDiffCostFunction<BiasWalkResidual, 3, 3, 3>(
          new BiasWalkResidual{1.0 / (p.accel_bias_walk_m_s2_sqrt_s *
                                      sigmaFactor(NoiseKind::kAccelWalk) * std::sqrt(dt))});
      record(ceres_.AddResidualBlock(walk, nullptr, state_.link_accel_bias[j - 1].data(),
                                     state_.link_accel_bias[j].data()),
             -1, -1, 3);
      learned(NoiseKind::kAccelWalk);
    }
    addBlock(state_.lever_arm_m.data(), 3);
    record(ceres_.AddResidualBlock(
               maskedPrior(3, {0, 1, 2}, std::vector<double>(3, settings_.lever_arm_prior_m)),
               nullptr, state_.lever_arm_m.data()),
           -1, -1, 3);
    const double g = settings_.gravity_m_s2;
    for (size_t j = 0; j < links; ++j) {
      const AccelLink& link = problem_.accel_links[j];
      const AccelLinkIntegral& in = integrals[j];
      const size_t from = static_cast<size_t>(link.from_pose),
                   to = static_cast<size_t>(link.to_pose);
      measure(link.from_pose, link.p_from_target_m);
      measure(link.to_pose, link.p_to_target_m);
      // Per axis, [r_v, r_p]: the accelerometer's white noise integrated once and twice, and the
      // gyro's turning the integrated specific force (about g; across it, counted on every axis).
      const double T = in.duration_s;
      const double a2 = std::pow(
          link.samples.accel_noise_density_m_s2_sqrt_hz * sigmaFactor(NoiseKind::kAccelWhite), 2);
      const double r2 = std::pow(
          link.samples.noise_density_rad_s_sqrt_hz * sigmaFactor(NoiseKind::kGyroWhite) * g, 2);
      Eigen::Matrix2d covariance;
      covariance << a2 * T + r2 * std::pow(T, 3) / 3.0,
          a2 * T * T / 2.0 + r2 * std::pow(T, 4) / 8.0,
          a2 * T * T / 2.0 + r2 * std::pow(T, 4) / 8.0,
          a2 * std::pow(T, 3) / 3.0 + r2 * std::pow(T, 5) / 20.0;
      const Eigen::Matrix2d L = covariance.llt().matrixL();
      auto* residual = new AccelLinkResidual{targetCam(from),
                                             cameraImu0(from),
                                             state_.R_world_target_0,
                                             {in.d0[0], in.d0[1]},
                                             {in.bias_jacobian[0], in.bias_jacobian[1]},
                                             {in.per_entry[0], in.per_entry[1]},
                                             {in.gyro_jacobian[0], in.gyro_jacobian[1]},
                                             in.theta0_minus_identity,
                                             projectToSO3(problem_.poses[from].R_target_cam),
                                             projectToSO3(problem_.poses[to].R_target_cam),
                                             g,
                                             T,
                                             L.inverse(),
                                             settings_.accel_matrix_form};
      auto* cost = new ceres::DynamicAutoDiffCostFunction<AccelLinkResidual, 16>(residual);
      for (int size : AccelLinkResidual::kBlockSizes) cost->AddParameterBlock(size);
      cost->SetNumResiduals(6);
      const std::vector<double*> blocks = {state_.e_T.data(),
                                           cameraImuIncrement(from),
                                           state_.delta[from].data(),
                                           state_.accel_matrix.data(),
                                           state_.link_accel_bias[j].data(),
                                           state_.lever_arm_m.data(),
                                           state_.gyro_matrix.data(),
                                           state_.gyro_bias[from].data(),
                                           state_.gyro_bias[to].data(),
                                           state_.keyframe_pv[from].data(),
                                           state_.keyframe_pv[to].data()};
      record(ceres_.AddResidualBlock(cost, loss_, blocks), static_cast<int>(from),
             static_cast<int>(to), 6);
      learned(NoiseKind::kAccelWhite);
    }
  }

  double startOf(const AccelLink& link) const {
    return problem_.poses[static_cast<size_t>(link.from_pose)].start_s;
  }

  void setKeyframe(int pose, const Eigen::Vector3d& p_target_m, const Eigen::Vector3d& v_m_s) {
    std::array<double, 6>& pv = state_.keyframe_pv[static_cast<size_t>(pose)];
    for (int i = 0; i < 3; ++i) {
      pv[static_cast<size_t>(i)] = p_target_m(i);
      pv[static_cast<size_t>(3 + i)] = v_m_s(i);
    }
  }

  /// The time offset's block and its prior, once (motion nodes).
  void addTimeshift() {
    if (timeshift_added_) return;
    timeshift_added_ = true;
    addBlock(state_.timeshift.data(), 1);
    ceres::Matrix A(1, 1);
    A(0, 0) = 1.0 / problem_.timeshift_prior_sigma_s;
    ceres::Vector b(1);
    b(0) = problem_.timeshift_initial_s;
    record(ceres_.AddResidualBlock(new ceres::NormalPrior(A, b), nullptr, state_.timeshift.data()),
           -1, -1, 1);
  }

  std::vector<size_t> rests_;  // indices of the poses at rest (not motion nodes)
  bool timeshift_added_ = false;
  const JointProblem& problem_;
  const Whitening& whitening_;
  const JointObservability& observability_;
  const JointSettings& settings_;
  State& state_;
  ceres::Problem& ceres_;
  ceres::LossFunction* loss_;
  const bool pin_;                // hold what is not excited constant (else it keeps its prior)
  const bool identity_matrices_;  // T_g and T_a held at I (ImuMatrixModel::kIdentity)
  BuiltProblem built_;
};

}  // namespace

BuiltProblem buildProblem(const JointProblem& problem, const std::vector<GyroPreintegration>& gyro,
                          const std::vector<Eigen::Vector3d>& rates_from,
                          const std::vector<Eigen::Vector3d>& rates_to,
                          const std::vector<AccelLinkIntegral>& accel_links,
                          const Whitening& whitening, const JointObservability& observability,
                          const JointSettings& settings, State* state,
                          ceres::Problem* ceres_problem) {
  return Builder(problem, whitening, observability, settings, state, ceres_problem)
      .build(gyro, rates_from, rates_to, accel_links);
}

}  // namespace joint
}  // namespace camera_imu_alignment
