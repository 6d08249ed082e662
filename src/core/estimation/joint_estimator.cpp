#include "camera_imu_alignment/estimation/joint_estimator.h"

#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "camera_excess.h"
#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/estimation/joint_observability.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "joint_motion.h"
#include "joint_state.h"
#include "noise_components.h"

namespace camera_imu_alignment {
namespace {

/// The gyro linearisation is redone until the gyro model moves less than this between passes
/// (T_g entries, rad/s for the biases): the first-order preintegration error, ~change^2 x the
/// rotation angle, is then ~1e-8 rad per radian turned.
constexpr double kRelinearisationThreshold = 1e-4;
/// Passes beyond max_relinearisations that learning the noise may take (JointSettings::
/// learn_noise).
constexpr int kMaxNoisePasses = 6;

GyroExcitation excitationOf(const std::vector<GyroPreintegration>& segments) {
  GyroExcitation excitation;
  excitation.has_segments = !segments.empty();
  for (const GyroPreintegration& segment : segments) {
    const Eigen::Vector3d phi = logSO3(segment.delta_R);
    excitation.accumulated_abs_angle_rad += phi.cwiseAbs();
    if (phi.norm() > 0.0) excitation.excitation_rad += phi * phi.transpose() / phi.norm();
  }
  return excitation;
}

/// Largest change of the gyro model (T_g entries, biases) since the segments were preintegrated;
/// a change of the time offset counts as the rotation it makes at 1 rad/s.
double gyroModelChange(const JointProblem& problem, const joint::State& state,
                       const std::vector<GyroPreintegration>& segments) {
  double change = std::abs(state.timeshift[0] - state.timeshift_0);
  const Eigen::Matrix3d T_g = state.gyroMatrix();
  for (size_t j = 0; j < segments.size(); ++j) {
    const GyroSegment& segment = problem.segments[j];
    const GyroModelVector theta =
        gyroModelVector(T_g, state.gyroBias(segment.from_pose), state.gyroBias(segment.to_pose));
    change = std::max(change, (theta - segments[j].theta0).cwiseAbs().maxCoeff());
  }
  return change;
}

ceres::Solver::Options solverOptions(const JointSettings& settings) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  // Eigen's sparse Cholesky, not CHOLMOD: CHOLMOD's supernodal factorisation calls a threaded
  // BLAS whose threads spent about a third of the solve waiting on each other in these problems
  // (the acceleration model's keyframe states; bench_motion's window solve 745 -> 466 ms).
  options.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  options.max_num_iterations = settings.max_iterations;
  // Converged when the cost changes by less than 1e-6 of itself: at chi2 ~ dof ~ 2000 a step of
  // 1e-3 in the cost, a few hundredths of a sigma from the minimum in the slowest direction (the
  // passes that follow go on from there). Tighter chases the robust loss's slow tail.
  options.function_tolerance = 1e-6;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-10;
  options.num_threads = std::max(1, settings.solver_threads);
  options.logging_type = ceres::SILENT;
  return options;
}

std::string summary(const JointProblem& problem, const JointResult& result) {
  const auto rests = std::count_if(problem.poses.begin(), problem.poses.end(),
                                   [](const JointPose& pose) { return pose.at_rest; });
  const size_t nodes = problem.poses.size() - static_cast<size_t>(rests);
  char motion[96] = "";
  if (nodes > 0) {
    std::snprintf(motion, sizeof(motion), ", %zu motion nodes, timeshift_cam_imu %.2f +- %.2f ms",
                  nodes, 1e3 * result.timeshift_cam_imu_s, 1e3 * result.timeshift_sigma_s);
  }
  char buffer[320];
  std::snprintf(buffer, sizeof(buffer),
                "joint estimate: %zu poses%s, %zu gyro segments, magnetometer %s; chi2/dof %.2f "
                "(p %.3f); 1-sigma [%.4f %.4f %.4f] deg",
                static_cast<size_t>(rests), motion, problem.segments.size(),
                result.intrinsics.magnetometer_used ? "used" : "not used",
                result.dof > 0 ? result.chi2 / result.dof : 0.0, result.chi2_p_value,
                result.std_dev_deg(0), result.std_dev_deg(1), result.std_dev_deg(2));
  return buffer;
}

/// What a solve with every parameter estimated found undetermined, as the parameters to hold
/// (pin_unexcited_parameters).
JointObservability heldByInformation(JointObservability observability, const JointResult& free) {
  const ImuIntrinsics& in = free.intrinsics;
  for (int c = 0; c < 3; ++c) {
    observability.gyro_column_estimated[c] =
        observability.gyro_column_estimated[c] && in.gyro_matrix_column_estimated[c];
  }
  observability.accel_matrix_estimated = in.accel_matrix_estimated;
  observability.accel_bias_estimated = in.accel_bias_estimated;
  observability.hard_iron_estimated = in.hard_iron_estimated;
  observability.soft_iron_estimated = in.soft_iron_estimated;
  return observability;
}

/// One solve with the matrices' model of `settings` (kEstimate or kIdentity). With
/// pin_unexcited_parameters: a first solve with every parameter free finds what the data do not
/// determine (`held` null), a second one holds it (`held`: what to estimate).
JointResult solveModel(const JointProblem& given, const Eigen::Matrix3d& R_cam_imu_initial,
                       const JointSettings& settings, const JointObservability* held = nullptr) {
  const auto start = std::chrono::steady_clock::now();
  // Learning the noise changes the problem's factors between passes: a copy then.
  const bool learn = settings.learn_noise && settings.compute_covariance;
  std::optional<JointProblem> learning;
  if (learn) learning = given;
  const JointProblem& problem = learn ? *learning : given;
  JointResult result;
  const auto finish = [&](JointResult& r) -> JointResult {
    r.solve_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!r.ok) {
      r.R_cam_imu = Eigen::Matrix3d::Identity();
      r.covariance_rad2.setZero();
      r.std_dev_deg.setZero();
    }
    return r;
  };
  result.message = joint::validateProblem(problem, R_cam_imu_initial, settings);
  if (!result.message.empty()) return finish(result);

  // Preintegrate with the ideal gyro and the rests' biases.
  const size_t n = problem.poses.size();
  std::vector<Eigen::Vector3d> biases(n), rates_from, rates_to;
  for (size_t k = 0; k < n; ++k) biases[k] = problem.poses[k].gyro_mean_rad_s;
  std::vector<GyroPreintegration> gyro =
      joint::preintegrateSegments(problem, Eigen::Matrix3d::Identity(), biases,
                                  problem.timeshift_initial_s, &rates_from, &rates_to);
  const bool motion = joint::hasMotionSegments(problem);
  if (settings.pin_unexcited_parameters && held == nullptr) {
    JointSettings free_settings = settings;
    free_settings.pin_unexcited_parameters = false;
    const JointResult free = solveModel(problem, R_cam_imu_initial, free_settings);
    if (!free.ok) return free;
    const JointObservability hold =
        heldByInformation(decideObservability(problem, excitationOf(gyro), settings), free);
    JointResult pinned = solveModel(problem, free.R_cam_imu, settings, &hold);
    pinned.solve_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return pinned;
  }
  JointObservability observability =
      held ? *held : decideObservability(problem, excitationOf(gyro), settings);
  joint::State state = joint::initialState(problem, R_cam_imu_initial, observability, settings);
  if (held) state.holdUnexcitedGyroColumns(observability);
  if (motion) {  // the motion nodes' biases start from the rests'
    for (size_t k = 0; k < n; ++k) biases[k] = state.gyroBias(static_cast<int>(k));
    gyro = joint::preintegrateSegments(problem, Eigen::Matrix3d::Identity(), biases,
                                       state.timeshift[0], &rates_from, &rates_to);
  }
  joint::Whitening whitening;
  if (!joint::computeWhitening(problem, gyro, settings, &whitening, &result.message)) {
    return finish(result);
  }

  const ceres::Solver::Options options = solverOptions(settings);
  bool converged = false, gyro_settled = true, noise_settled = true;
  // While the noise is learned, no robust loss: scaled by the stated noise, most residuals lie
  // in Huber's linear tail, where Gauss-Newton converges slowly (tens of iterations a pass).
  std::optional<joint::NoiseLearner> learner;
  if (learn) learner.emplace(problem.noise);
  bool robust_pass = !learn;
  JointSettings unrobust_settings = settings;
  unrobust_settings.robust_loss = RobustLossKind::kNone;
  const int max_passes = settings.max_relinearisations + (learn ? kMaxNoisePasses : 0);
  for (int pass = 0; pass < max_passes; ++pass) {
    if (pass > 0) {
      const Eigen::Matrix3d T_g = state.gyroMatrix();
      if (!T_g.allFinite() || !(std::abs(T_g.determinant()) > 0.5)) {
        result.message = "the gyro matrix estimate diverged (det T_g far from 1)";
        return finish(result);
      }
      for (size_t k = 0; k < n; ++k) biases[k] = state.gyroBias(static_cast<int>(k));
      gyro = joint::preintegrateSegments(problem, T_g, biases, state.timeshift[0], &rates_from,
                                         &rates_to);
      state.timeshift_0 = state.timeshift[0];
    }
    ceres::Problem ceres_problem;
    // biases holds the state's (set above, or before the first pass).
    const std::vector<joint::AccelLinkIntegral> accel_links =
        joint::integrateAccelLinks(problem, state.gyroMatrix(), biases, state.timeshift[0]);
    const joint::BuiltProblem built = joint::buildProblem(
        problem, gyro, rates_from, rates_to, accel_links, whitening, observability,
        robust_pass ? settings : unrobust_settings, &state, &ceres_problem);
    ceres::Solver::Summary solver_summary;
    ceres::Solve(options, &ceres_problem, &solver_summary);
    result.iterations += static_cast<int>(solver_summary.iterations.size());
    result.relinearisations = pass + 1;
    if (!solver_summary.IsSolutionUsable()) {
      result.message = "the solver failed: " + solver_summary.message;
      return finish(result);
    }
    converged = solver_summary.termination_type == ceres::CONVERGENCE;
    // With gyro segments at least two passes: the first is linearised about the ideal gyro.
    const bool judged = problem.segments.empty() || pass >= 1;
    gyro_settled = gyroModelChange(problem, state, gyro) < kRelinearisationThreshold;
    if (learner && !robust_pass) {
      const bool moved = learner->update(problem, whitening, built, &state, &ceres_problem);
      noise_settled = !moved;
      if (pass + 1 < max_passes && (moved || settings.robust_loss != RobustLossKind::kNone)) {
        // Solved again: under the new factors, or (settled) once more with the robust loss.
        if (moved) {
          learner->advance();
          learning->noise = learner->factors();
          if (!joint::computeWhitening(problem, gyro, settings, &whitening, &result.message)) {
            return finish(result);
          }
        } else {
          robust_pass = true;
        }
        state.foldRotationIncrements();
        continue;
      }
    }
    const bool last = pass + 1 == max_passes || (judged && gyro_settled);
    if (last) {
      if (!joint::fillResult(problem, state, built, whitening, observability, settings,
                             &ceres_problem, &result)) {
        return finish(result);
      }
      state.foldRotationIncrements();
      break;
    }
    state.foldRotationIncrements();
  }

  result.R_cam_imu = state.R_cam_imu_0;
  if (problem.mount_change_pose >= 0) result.R_cam_imu_after_change = state.R_cam_imu_after_0;
  result.R_world_target = state.R_world_target_0;
  if (!isRotationMatrix(result.R_cam_imu, 1e-6) || !result.covariance_rad2.allFinite()) {
    result.message = "the estimate is not finite";
    return finish(result);
  }
  result.notes = observability.notes;
  if (learner) {
    result.noise = learner->noise();
    result.noise.settled = noise_settled;
  } else {
    result.noise.variance_factor = problem.noise;
  }
  if (!noise_settled) {
    result.notes.push_back("the measured noise still changed in the last of " +
                           std::to_string(max_passes) + " passes");
  }
  result.imu_matrices = settings.imu_matrices;
  describeInformation(observability, settings, &result);
  if (!(result.std_dev_deg.maxCoeff() <= settings.undetermined_std_dev_deg)) {
    char buffer[256];
    std::snprintf(buffer, sizeof(buffer),
                  "R_cam_imu is not determined: 1-sigma [%.2f %.2f %.2f] deg > %.2f deg (the "
                  "poses barely rotate)",
                  result.std_dev_deg(0), result.std_dev_deg(1), result.std_dev_deg(2),
                  settings.undetermined_std_dev_deg);
    result.message = buffer;
    return finish(result);
  }
  if (!converged) {
    result.notes.push_back("the solver stopped before converging (max_iterations " +
                           std::to_string(settings.max_iterations) + ")");
  }
  if (!gyro_settled) {
    result.notes.push_back("the gyro model still moved in the last of " +
                           std::to_string(settings.max_relinearisations) +
                           " preintegration passes (max_relinearisations)");
  }
  if (result.covariance_scale > 1.0) {
    char buffer[128];
    std::snprintf(buffer, sizeof(buffer),
                  "covariances scaled by chi2/dof = %.2f (the residuals exceed their noise)",
                  result.covariance_scale);
    result.notes.push_back(buffer);
  }
  result.ok = true;
  result.imu_matrices = settings.imu_matrices;
  result.message = summary(problem, result);
  return finish(result);
}

/// Free entries of T_g and T_a in the estimated model (the likelihood ratio's degrees of freedom).
int freeMatrixEntries(const JointProblem& problem, const JointResult& estimated,
                      const JointSettings& settings) {
  const ImuIntrinsics& in = estimated.intrinsics;
  const bool pin = settings.pin_unexcited_parameters;
  int count = 0;
  for (int c = 0; c < 3; ++c) {
    if (!problem.segments.empty() && (in.gyro_matrix_column_estimated[c] || !pin)) count += 3;
  }
  if (in.accel_matrix_estimated || !pin) count += 6;
  return count;
}

/// Largest |entry of T - I| / its 1-sigma over the entries the estimated model freed.
double largestMatrixDeviation(const JointResult& estimated) {
  const ImuIntrinsics& in = estimated.intrinsics;
  double largest = 0.0;
  auto consider = [&](const Eigen::Matrix3d& T, const Eigen::Matrix3d& sigma) {
    const Eigen::Matrix3d deviation = T - Eigen::Matrix3d::Identity();
    for (int i = 0; i < 9; ++i) {
      if (sigma(i) > 0.0) largest = std::max(largest, std::abs(deviation(i)) / sigma(i));
    }
  };
  consider(in.gyro_matrix, in.gyro_matrix_sigma);
  consider(in.accel_matrix, in.accel_matrix_sigma);
  return largest;
}

/// A chi-square tail probability for a note: "%.3g", or "< 1e-300" where it underflowed to 0 (a
/// "p 0" or "p < 0" would read as a bug).
std::string tailText(double p) {
  if (!(p > 0.0)) return "< 1e-300";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", p);
  return buffer;
}

std::string likelihoodRatioNote(double ratio, int dof, double p, const char* decision) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "T_g and T_a %s: likelihood ratio against holding them at identity chi2 %.1f on "
                "%d dof, p %s",
                decision, ratio, dof, tailText(p).c_str());
  return buffer;
}

/// ImuMatrixModel::kSelect: the estimated model, and the identity model unless the estimate alone
/// already rejects it; the identity model is kept unless the likelihood ratio rejects it.
JointResult selectModel(const JointProblem& problem, const Eigen::Matrix3d& R_cam_imu_initial,
                        const JointSettings& settings) {
  JointSettings estimate_settings = settings, identity_settings = settings;
  estimate_settings.imu_matrices = ImuMatrixModel::kEstimate;
  identity_settings.imu_matrices = ImuMatrixModel::kIdentity;
  JointResult estimated = solveModel(problem, R_cam_imu_initial, estimate_settings);
  const int dof = estimated.ok ? freeMatrixEntries(problem, estimated, settings) : 0;
  if (estimated.ok && dof > 0) {
    // Linearised, the likelihood ratio is at least the square of any one entry's deviation in
    // sigma units; far beyond the level (1e-3 of it) the identity model need not be solved.
    const double z = largestMatrixDeviation(estimated);
    const double p_bound = joint::chiSquareUpperTail(z * z, dof);
    if (p_bound < 1e-3 * settings.model_selection_level) {
      char buffer[160];
      std::snprintf(buffer, sizeof(buffer),
                    "T_g and T_a estimated: an entry is %.1f sigma from identity (likelihood ratio "
                    "against identity p %s)",
                    z, (p_bound > 0.0 ? "< " + tailText(p_bound) : tailText(p_bound)).c_str());
      estimated.notes.push_back(buffer);
      return estimated;
    }
  }
  // Compared under one noise model: the identity model is fitted under the noise the estimated
  // one learned (learning its own, its misfit would pass for noise).
  JointResult identity;
  if (estimated.ok && settings.learn_noise && settings.compute_covariance) {
    JointProblem same_noise = problem;
    same_noise.noise = estimated.noise.variance_factor;
    identity_settings.learn_noise = false;
    identity = solveModel(same_noise, R_cam_imu_initial, identity_settings);
    identity.noise = estimated.noise;
  } else {
    identity = solveModel(problem, R_cam_imu_initial, identity_settings);
  }
  if (!identity.ok) return estimated;
  if (!estimated.ok) {
    identity.notes.push_back("T_g and T_a held at identity: estimating them failed (" +
                             estimated.message + ")");
    return identity;
  }
  const double ratio = std::max(0.0, identity.chi2 - estimated.chi2);
  const double p = joint::chiSquareUpperTail(ratio, dof);
  if (dof > 0 && p < settings.model_selection_level) {
    estimated.notes.push_back(likelihoodRatioNote(ratio, dof, p, "estimated"));
    return estimated;
  }
  identity.notes.push_back(
      likelihoodRatioNote(ratio, dof, p, "held at identity (the data do not call for them)"));
  return identity;
}

/// The matrices' model of the settings (kSelect: chosen by the likelihood ratio).
JointResult solveMatrices(const JointProblem& problem, const Eigen::Matrix3d& R_cam_imu_initial,
                          const JointSettings& settings) {
  return settings.imu_matrices == ImuMatrixModel::kSelect
             ? selectModel(problem, R_cam_imu_initial, settings)
             : solveModel(problem, R_cam_imu_initial, settings);
}

/// Per-pose level of the magnetometer screening (Bonferroni over the poses with a field).
constexpr double kMagOutlierLevel = 1e-3;
/// The hard iron is calibrated by the poses when its posterior 1-sigma is below this fraction of
/// its prior's on every axis.
constexpr double kMaxHardIronSigmaOfPrior = 0.2;

/// The pose whose field fits worst when it fails the per-pose chi-square test (3 dof), else -1.
/// The residuals are scaled by their own median against chi-square(3)'s (2.366) when that is
/// larger: robust to the outliers sought, and a unit whose field noise the rests understate does
/// not lose every field.
int worstMagnetometerPose(const JointResult& result) {
  std::vector<double> used;
  for (double chi2 : result.mag_residual_chi2) {
    if (chi2 > 0.0) used.push_back(chi2);
  }
  if (used.empty()) return -1;
  std::nth_element(used.begin(), used.begin() + used.size() / 2, used.end());
  const double scale = std::max(1.0, used[used.size() / 2] / 2.366);
  int worst = -1;
  double worst_p = kMagOutlierLevel / static_cast<double>(used.size());
  for (size_t k = 0; k < result.mag_residual_chi2.size(); ++k) {
    const double chi2 = result.mag_residual_chi2[k];
    if (!(chi2 > 0.0)) continue;
    const double p = joint::chiSquareUpperTail(chi2 / scale, 3);
    if (p < worst_p) {
      worst_p = p;
      worst = static_cast<int>(k);
    }
  }
  return worst;
}

/// Fields flagged by the raw check (JointPose::mag_flagged) are tried with the iron estimated:
/// the field that fits worst is left out while it fails its chi-square test, and the solve
/// repeated. When the iron is then not determined by the poses (its posterior 1-sigma above
/// kMaxHardIronSigmaOfPrior of the prior's) or a solve fails, the flagged fields are left out
/// unseen, as the check said.
JointResult screenMagnetometer(const JointProblem& problem,
                               const Eigen::Matrix3d& R_cam_imu_initial,
                               const JointSettings& settings, JointProblem* as_used = nullptr) {
  JointProblem unflagged = problem;
  int flagged = 0;
  for (JointPose& pose : unflagged.poses) {
    if (pose.mag_flagged && pose.mag_mean_t) {
      ++flagged;
      pose.mag_mean_t.reset();
    }
    pose.mag_flagged = false;
  }
  if (flagged == 0 || settings.use_magnetometer == MagnetometerUse::kOff) {
    if (as_used) *as_used = unflagged;
    return solveMatrices(unflagged, R_cam_imu_initial, settings);
  }
  // The hard iron counts as calibrated when the data, not its prior, determine it.
  const JointSettings& screen_settings = settings;
  JointProblem screened = problem;
  std::vector<int> left_out;
  for (int round = 0; round <= static_cast<int>(problem.poses.size()) / 2; ++round) {
    JointResult result = solveMatrices(screened, R_cam_imu_initial, screen_settings);
    if (!result.ok || !result.intrinsics.hard_iron_estimated) break;
    const int worst = worstMagnetometerPose(result);
    if (worst < 0) {
      if (!(result.intrinsics.hard_iron_sigma_t.maxCoeff() <=
            kMaxHardIronSigmaOfPrior * settings.priors.hard_iron_t)) {
        break;  // the poses do not determine the iron: the raw check's verdict stands
      }
      result.mag_poses_left_out = left_out;
      int flagged_used = 0;
      for (const JointPose& pose : screened.poses)
        flagged_used += pose.mag_flagged && pose.mag_mean_t;
      char buffer[200];
      std::snprintf(buffer, sizeof(buffer),
                    "magnetometer: %d of %d rest(s) flagged by the raw field check used (they fit "
                    "the calibrated iron); %zu rest(s) left out as disturbed",
                    flagged_used, flagged, left_out.size());
      result.notes.push_back(buffer);
      for (int k : left_out) {
        result.notes.push_back("magnetometer at pose " + std::to_string(k) +
                               " left out: its field does not fit the calibrated iron (disturbed)");
      }
      if (as_used) *as_used = screened;
      return result;
    }
    screened.poses[worst].mag_mean_t.reset();
    left_out.push_back(worst);
  }
  if (as_used) *as_used = unflagged;
  JointResult result = solveMatrices(unflagged, R_cam_imu_initial, settings);
  result.notes.push_back("magnetometer: " + std::to_string(flagged) +
                         " rest(s) flagged by the raw field check left out (the iron could not be "
                         "calibrated with them)");
  return result;
}

}  // namespace

const char* toString(ImuMatrixModel model) {
  switch (model) {
    case ImuMatrixModel::kEstimate:
      return "estimate";
    case ImuMatrixModel::kIdentity:
      return "identity";
    case ImuMatrixModel::kSelect:
      break;
  }
  return "select";
}

bool parseImuMatrixModel(const std::string& text, ImuMatrixModel* model) {
  for (ImuMatrixModel m :
       {ImuMatrixModel::kSelect, ImuMatrixModel::kEstimate, ImuMatrixModel::kIdentity}) {
    if (text == toString(m)) {
      *model = m;
      return true;
    }
  }
  return false;
}

namespace {

/// The measured camera noise is re-estimated until it grows by less than this fraction.
constexpr double kExcessSettled = 0.05;
constexpr int kMaxExcessRounds = 4;

/// The camera's measured excess noise added to the rests and to the camera links, and the window
/// solved again until both settle (JointSettings::camera_excess_level). `problem` is the window
/// with the magnetometer fields the screening kept (screenMagnetometer's as_used): the screening
/// is not repeated, and its notes and left-out fields carry over to each solve.
JointResult withCameraNoiseAsMeasured(JointProblem* problem, JointResult chosen,
                                      const JointSettings& settings) {
  if (!(settings.camera_excess_level > 0.0) || !settings.compute_covariance) return chosen;
  std::vector<std::string> magnetometer_notes;
  for (const std::string& note : chosen.notes) {
    if (note.rfind("magnetometer", 0) == 0) magnetometer_notes.push_back(note);
  }
  double excess = 0.0, link_excess = 0.0;
  for (int round = 0; round < kMaxExcessRounds && chosen.ok; ++round) {
    double more = joint::cameraExcessVariance(*problem, chosen, settings);
    double more_links = joint::cameraLinkExcessVariance(*problem, chosen, settings);
    if (!(more > kExcessSettled * excess)) more = 0.0;
    if (!(more_links > kExcessSettled * link_excess)) more_links = 0.0;
    if (more == 0.0 && more_links == 0.0) break;
    JointProblem inflated = *problem;
    addCameraExcessVariance(more, &inflated);
    addCameraLinkExcessVariance(more_links, &inflated);
    // From the estimate so far: the added variance moves it little.
    JointResult again = solveMatrices(inflated, chosen.R_cam_imu, settings);
    if (!again.ok) break;  // the last usable estimate stands
    again.notes.insert(again.notes.end(), magnetometer_notes.begin(), magnetometer_notes.end());
    again.mag_poses_left_out = chosen.mag_poses_left_out;
    *problem = std::move(inflated);
    excess += more;
    link_excess += more_links;
    chosen = std::move(again);
  }
  if (excess > 0.0) {
    char buffer[240];
    std::snprintf(buffer, sizeof(buffer),
                  "the rests' camera orientations scatter beyond their PnP covariance: %.3f deg "
                  "per axis added to each (the camera's noise as the recording shows it: lens "
                  "model, intrinsics, board flatness)",
                  rad2deg(std::sqrt(excess)));
    chosen.notes.push_back(buffer);
  }
  if (link_excess > 0.0) {
    char buffer[240];
    std::snprintf(buffer, sizeof(buffer),
                  "the natural scene's rotations scatter beyond their two-view covariance: %.3f "
                  "deg per axis added to each (features that shift with the viewpoint)",
                  rad2deg(std::sqrt(link_excess)));
    chosen.notes.push_back(buffer);
  }
  chosen.camera_excess_variance_rad2 = excess;
  chosen.camera_link_excess_variance_rad2 = link_excess;
  return chosen;
}

/// The stated noise of each learned kind (LearnedNoise::stated) and a note on what the recording
/// showed of it.
void describeLearnedNoise(const JointProblem& problem, const JointSettings& settings,
                          JointResult* result) {
  LearnedNoise& noise = result->noise;
  std::vector<double> camera_sigma;
  for (const JointPose& pose : problem.poses) {
    if (!pose.at_rest) camera_sigma.push_back(std::sqrt(pose.cov_cam_rad2.trace() / 3.0));
  }
  if (!camera_sigma.empty()) {
    std::nth_element(camera_sigma.begin(), camera_sigma.begin() + camera_sigma.size() / 2,
                     camera_sigma.end());
    noise.stated[static_cast<size_t>(NoiseKind::kCameraMotion)] =
        camera_sigma[camera_sigma.size() / 2];
  }
  const auto statedOf = [&](NoiseKind kind) -> double& {
    return noise.stated[static_cast<size_t>(kind)];
  };
  if (!problem.accel_links.empty())
    statedOf(NoiseKind::kCameraPosition) = settings.camera_position_sigma_m;
  double gyro_density = problem.motion_gyro.noise_density_rad_s_sqrt_hz;
  for (const GyroSegment& segment : problem.segments) {
    if (!(gyro_density > 0.0)) gyro_density = segment.noise_density_rad_s_sqrt_hz;
  }
  statedOf(NoiseKind::kGyroWhite) = gyro_density;
  if (!problem.accel_links.empty()) {
    statedOf(NoiseKind::kAccelWhite) =
        problem.accel_links.front().samples.accel_noise_density_m_s2_sqrt_hz;
  }
  statedOf(NoiseKind::kGyroWalk) = settings.priors.gyro_bias_walk_rad_s_sqrt_s;
  statedOf(NoiseKind::kAccelWalk) = settings.priors.accel_bias_walk_m_s2_sqrt_s;
  std::string learned;
  for (int k = 0; k < kNoiseKinds; ++k) {
    const auto kind = static_cast<NoiseKind>(k);
    if (!noise.learned[static_cast<size_t>(k)] || !(noise.stated[static_cast<size_t>(k)] > 0.0)) {
      continue;
    }
    char buffer[96];
    std::snprintf(buffer, sizeof(buffer), "%s%s %.3g (%.2fx stated)", learned.empty() ? "" : ", ",
                  toString(kind), noise.measured(kind), noise.sigmaFactor(kind));
    learned += buffer;
  }
  if (!learned.empty()) {
    result->notes.push_back("the noise as the recording shows it (variance components): " +
                            learned);
  }
}

}  // namespace

JointEstimator::JointEstimator(JointSettings settings) : settings_(std::move(settings)) {}

JointResult JointEstimator::solve(const JointProblem& problem,
                                  const Eigen::Matrix3d& R_cam_imu_initial) const {
  const auto start = std::chrono::steady_clock::now();
  const std::string motion_error = joint::validateMotion(problem);
  if (!motion_error.empty()) {
    JointResult refused;
    refused.message = motion_error;
    return refused;
  }
  joint::ExpandedProblem expanded = joint::expandMotion(problem, settings_);
  JointProblem as_used;
  JointResult first = screenMagnetometer(expanded.problem, R_cam_imu_initial, settings_, &as_used);
  // Solved again (the camera's excess noise below), the window starts from the noise learned.
  if (first.ok) as_used.noise = first.noise.variance_factor;
  JointResult chosen = withCameraNoiseAsMeasured(&as_used, std::move(first), settings_);
  if (chosen.ok) {
    expanded.problem = std::move(as_used);
    describeLearnedNoise(expanded.problem, settings_, &chosen);
  }
  joint::mapResultToCaller(expanded, &chosen);
  chosen.solve_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return chosen;
}

}  // namespace camera_imu_alignment
