// Input checks and measurement whitening of the joint estimator.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "joint_state.h"

namespace camera_imu_alignment {
namespace joint {
namespace {

std::string poseName(size_t k) { return "pose " + std::to_string(k); }

bool finitePositive(double x) { return std::isfinite(x) && x > 0.0; }

bool usableCovariance(const Eigen::Matrix3d& covariance, double floor_sigma) {
  Eigen::Matrix3d unused;
  if (!covariance.allFinite()) return false;
  const double scale = covariance.cwiseAbs().maxCoeff();
  if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale + 1e-300) {
    return false;
  }
  return whiteningMatrix(covariance, floor_sigma, &unused);
}

std::string validateSettings(const JointSettings& s) {
  const ImuModelPriors& p = s.priors;
  for (double sigma :
       {p.gyro_scale, p.gyro_cross_axis, p.gyro_bias_walk_rad_s_sqrt_s, p.accel_scale,
        p.accel_cross_axis, p.accel_bias_m_s2, p.accel_bias_walk_m_s2_sqrt_s, p.soft_iron_scale,
        p.soft_iron_cross, p.hard_iron_t}) {
    if (!finitePositive(sigma)) return "settings: every prior sigma must be finite and > 0";
  }
  for (double floor :
       {s.accel_mean_sigma_floor_m_s2, s.gyro_mean_sigma_floor_rad_s, s.mag_mean_sigma_floor_t,
        s.camera_sigma_floor_rad, s.gyro_integration_sigma_floor_rad}) {
    if (!finitePositive(floor)) return "settings: every noise floor must be finite and > 0";
  }
  if (!finitePositive(s.gravity_m_s2)) return "settings: gravity_m_s2 must be finite and > 0";
  if (!finitePositive(s.robust_loss_scale)) return "settings: robust_loss_scale must be > 0";
  if (!finitePositive(s.undetermined_std_dev_deg))
    return "settings: undetermined_std_dev_deg must be > 0";
  if (!(s.model_selection_level > 0.0 && s.model_selection_level < 1.0)) {
    return "settings: model_selection_level must be within (0, 1)";
  }
  if (s.max_iterations < 1 || s.max_relinearisations < 2) {
    return "settings: max_iterations must be >= 1 and max_relinearisations >= 2";
  }
  if (s.min_mag_poses_hard_iron < 0) return "settings: min_mag_poses_hard_iron must be >= 0";
  return "";
}

std::string validatePose(const JointPose& pose, size_t k, const JointSettings& s) {
  const std::string name = poseName(k);
  if (!std::isfinite(pose.start_s) || !std::isfinite(pose.end_s) || pose.end_s < pose.start_s) {
    return name + ": the rest's start_s and end_s must be finite with start_s <= end_s";
  }
  if (!isRotationMatrix(pose.R_target_cam, 1e-3)) {
    return name + ": R_target_cam is not a rotation matrix";
  }
  if (!usableCovariance(pose.cov_cam_rad2, s.camera_sigma_floor_rad)) {
    return name + ": cov_cam_rad2 is not a finite symmetric positive semi-definite matrix";
  }
  if (!pose.at_rest) return "";  // a motion node: the camera only
  if (!pose.accel_mean_m_s2.allFinite()) return name + ": accelerometer mean is not finite";
  const double accel_norm = pose.accel_mean_m_s2.norm();
  if (accel_norm < 0.5 * s.gravity_m_s2 || accel_norm > 2.0 * s.gravity_m_s2) {
    return name + ": accelerometer mean of " + std::to_string(accel_norm) +
           " m/s^2 is not gravity (not at rest, or not in m/s^2)";
  }
  if (!usableCovariance(pose.accel_mean_cov, s.accel_mean_sigma_floor_m_s2)) {
    return name + ": accel_mean_cov is not a finite symmetric positive semi-definite matrix";
  }
  if (!pose.gyro_mean_rad_s.allFinite()) return name + ": gyro mean is not finite";
  if (!usableCovariance(pose.gyro_mean_cov, s.gyro_mean_sigma_floor_rad_s)) {
    return name + ": gyro_mean_cov is not a finite symmetric positive semi-definite matrix";
  }
  if (pose.mag_mean_t) {
    const double norm = pose.mag_mean_t->norm();
    if (!pose.mag_mean_t->allFinite() || !(norm > 0.0)) {
      return name + ": magnetometer mean is not finite and non-zero";
    }
    if (norm > 1e-2) {
      return name + ": magnetometer mean of " + std::to_string(norm) +
             " T is not in tesla (the earth's field is ~5e-5 T)";
    }
    if (!usableCovariance(pose.mag_mean_cov, s.mag_mean_sigma_floor_t)) {
      return name + ": mag_mean_cov is not a finite symmetric positive semi-definite matrix";
    }
  }
  return "";
}

std::string validateCameraLinks(const JointProblem& problem, const JointSettings& s) {
  const int n = static_cast<int>(problem.poses.size());
  for (size_t j = 0; j < problem.camera_links.size(); ++j) {
    const CameraLink& link = problem.camera_links[j];
    const std::string name = "camera link " + std::to_string(j);
    if (link.from_pose < 0 || link.from_pose >= n || link.to_pose < 0 || link.to_pose >= n ||
        link.from_pose == link.to_pose) {
      return name + ": needs two different poses in 0.." + std::to_string(n - 1);
    }
    if (problem.poses[link.from_pose].camera_absolute ||
        problem.poses[link.to_pose].camera_absolute) {
      return name + ": links poses whose camera orientation is absolute (camera_absolute)";
    }
    if (!isRotationMatrix(link.R_from_to, 1e-3)) return name + ": R_from_to is not a rotation";
    if (!usableCovariance(link.cov_rad2, s.camera_sigma_floor_rad)) {
      return name + ": cov_rad2 is not a finite symmetric positive semi-definite matrix";
    }
  }
  return "";
}

std::string validateSegment(const GyroSegment& segment, size_t j, const JointProblem& problem) {
  const std::string name = "gyro segment " + std::to_string(j);
  const int n = static_cast<int>(problem.poses.size());
  if (segment.from_pose < 0 || segment.from_pose >= n || segment.to_pose != segment.from_pose + 1 ||
      segment.to_pose >= n) {
    return name + ": needs 0 <= from_pose and to_pose = from_pose + 1 < number of poses";
  }
  const JointPose& from = problem.poses[segment.from_pose];
  const JointPose& to = problem.poses[segment.to_pose];
  if (from.group != to.group) return name + ": joins poses of different groups";
  if (to.start_s < from.end_s) return name + ": its second rest starts before the first one ends";
  if (segment.stamps_s.size() < 2) return name + ": fewer than 2 gyro samples";
  if (segment.stamps_s.size() != segment.gyro_rad_s.size()) {
    return name + ": stamps_s and gyro_rad_s differ in length";
  }
  for (size_t i = 0; i < segment.stamps_s.size(); ++i) {
    if (!std::isfinite(segment.stamps_s[i]) || !segment.gyro_rad_s[i].allFinite()) {
      return name + ": sample " + std::to_string(i) + " is not finite";
    }
    if (i > 0 && !(segment.stamps_s[i] > segment.stamps_s[i - 1])) {
      return name + ": stamps are not strictly increasing at sample " + std::to_string(i);
    }
  }
  if (segment.interval &&
      (segment.stamps_s.front() > linkTime(from) || segment.stamps_s.back() < linkTime(to))) {
    return name + ": its samples do not cover the interval between its poses";
  }
  if (segment.stamps_s.back() - segment.stamps_s.front() > 3600.0) {
    return name + ": longer than an hour";
  }
  // A sample holds until the next one: a gap (lost samples) would stretch one rate over it.
  const std::vector<double> dt = sampleIntervals(segment.stamps_s);
  const double longest_allowed = std::max(0.1, 10.0 * dt.back());  // dt.back(): the median
  for (size_t i = 0; i + 1 < dt.size(); ++i) {
    if (dt[i] > longest_allowed) {
      return name + ": a gap of " + std::to_string(dt[i]) + " s after sample " + std::to_string(i) +
             " (samples are " + std::to_string(dt.back()) + " s apart)";
    }
  }
  if (!std::isfinite(segment.noise_density_rad_s_sqrt_hz) ||
      segment.noise_density_rad_s_sqrt_hz < 0.0) {
    return name + ": noise_density_rad_s_sqrt_hz must be finite and >= 0";
  }
  return "";
}

}  // namespace

std::string validateProblem(const JointProblem& problem, const Eigen::Matrix3d& R_cam_imu_initial,
                            const JointSettings& settings) {
  std::string error = validateSettings(settings);
  if (!error.empty()) return error;
  if (problem.poses.size() < 3) {
    return "needs at least 3 poses (got " + std::to_string(problem.poses.size()) + ")";
  }
  if (problem.mount_change_pose != -1 &&
      (problem.mount_change_pose < 1 ||
       problem.mount_change_pose >= static_cast<int>(problem.poses.size()))) {
    return "mount_change_pose " + std::to_string(problem.mount_change_pose) +
           " is not a pose with poses before it (1.." + std::to_string(problem.poses.size() - 1) +
           ", or -1)";
  }
  if (!std::isnan(problem.mount_change_stamp_s)) {  // expandMotion turns it into a pose index
    return "mount_change_stamp_s: set without motion frames, or together with mount_change_pose";
  }
  if (!isRotationMatrix(R_cam_imu_initial, 1e-3)) {
    return "R_cam_imu_initial is not a rotation matrix";
  }
  for (size_t k = 0; k < problem.poses.size(); ++k) {
    error = validatePose(problem.poses[k], k, settings);
    if (!error.empty()) return error;
  }
  error = validateCameraLinks(problem, settings);
  if (!error.empty()) return error;
  std::set<int> from_poses;
  for (size_t j = 0; j < problem.segments.size(); ++j) {
    error = validateSegment(problem.segments[j], j, problem);
    if (!error.empty()) return error;
    if (!from_poses.insert(problem.segments[j].from_pose).second) {
      return "gyro segment " + std::to_string(j) + ": a second segment between poses " +
             std::to_string(problem.segments[j].from_pose) + " and " +
             std::to_string(problem.segments[j].to_pose);
    }
  }
  return "";
}

bool whiteningMatrix(const Eigen::Matrix3d& covariance, double floor_sigma,
                     Eigen::Matrix3d* whitening) {
  const Eigen::Matrix3d C = 0.5 * (covariance + covariance.transpose()) +
                            floor_sigma * floor_sigma * Eigen::Matrix3d::Identity();
  if (!C.allFinite()) return false;
  Eigen::LLT<Eigen::Matrix3d> llt(C);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::Matrix3d L = llt.matrixL();
  if (!(L.diagonal().minCoeff() > 0.0)) return false;
  *whitening = L.triangularView<Eigen::Lower>().solve(Eigen::Matrix3d::Identity());
  return whitening->allFinite();
}

bool computeWhitening(const JointProblem& problem, const std::vector<GyroPreintegration>& segments,
                      const JointSettings& settings, Whitening* w, std::string* error) {
  const size_t n = problem.poses.size();
  w->accel.assign(n, Eigen::Matrix3d::Zero());
  w->gyro_mean.assign(n, Eigen::Matrix3d::Zero());
  w->mag_ut.assign(n, Eigen::Matrix3d::Zero());
  w->camera.assign(n, Eigen::Matrix3d::Zero());
  const double walk = settings.priors.gyro_bias_walk_rad_s_sqrt_s *
                      std::sqrt(problem.noise[static_cast<size_t>(NoiseKind::kGyroWalk)]);
  const double camera_factor = problem.noise[static_cast<size_t>(NoiseKind::kCameraMotion)];
  for (size_t k = 0; k < n; ++k) {
    const JointPose& pose = problem.poses[k];
    if (!pose.at_rest) {  // a motion node: the camera only
      if (!whiteningMatrix(camera_factor * pose.cov_cam_rad2, settings.camera_sigma_floor_rad,
                           &w->camera[k])) {
        *error = "motion node " + std::to_string(k) + ": its camera covariance is not usable";
        return false;
      }
      continue;
    }
    // The bias at the rest's ends differs from its mean by the walk: variance walk^2 T / 3.
    const double rest_s = pose.end_s - pose.start_s;
    const Eigen::Matrix3d gyro_cov =
        pose.gyro_mean_cov + (walk * walk * rest_s / 3.0) * Eigen::Matrix3d::Identity();
    const double ut2 = kMicroteslaPerTesla * kMicroteslaPerTesla;
    bool ok =
        whiteningMatrix(pose.accel_mean_cov, settings.accel_mean_sigma_floor_m_s2, &w->accel[k]) &&
        whiteningMatrix(gyro_cov, settings.gyro_mean_sigma_floor_rad_s, &w->gyro_mean[k]) &&
        whiteningMatrix(pose.cov_cam_rad2, settings.camera_sigma_floor_rad, &w->camera[k]);
    if (ok && pose.mag_mean_t) {
      ok = whiteningMatrix(pose.mag_mean_cov * ut2,
                           settings.mag_mean_sigma_floor_t * kMicroteslaPerTesla, &w->mag_ut[k]);
    }
    if (!ok) {
      *error = "pose " + std::to_string(k) + ": a measurement covariance is not usable";
      return false;
    }
  }
  w->camera_link.assign(problem.camera_links.size(), Eigen::Matrix3d::Zero());
  for (size_t j = 0; j < problem.camera_links.size(); ++j) {
    if (!whiteningMatrix(problem.camera_links[j].cov_rad2, settings.camera_sigma_floor_rad,
                         &w->camera_link[j])) {
      *error = "camera link " + std::to_string(j) + ": its covariance is not usable";
      return false;
    }
  }
  w->gyro_relative.assign(problem.segments.size(), Eigen::Matrix3d::Zero());
  for (size_t j = 0; j < problem.segments.size(); ++j) {
    const double density = problem.segments[j].noise_density_rad_s_sqrt_hz *
                           std::sqrt(problem.noise[static_cast<size_t>(NoiseKind::kGyroWhite)]);
    const double T = segments[j].duration_s;
    // White noise integrated over T, plus the walk's deviation from the linear bias ramp (a
    // Brownian bridge: the integral's variance is walk^2 T^3 / 12).
    const double variance = density * density * T + walk * walk * T * T * T / 12.0;
    if (!whiteningMatrix(variance * Eigen::Matrix3d::Identity(),
                         settings.gyro_integration_sigma_floor_rad, &w->gyro_relative[j])) {
      *error = "gyro segment " + std::to_string(j) + ": its noise is not usable";
      return false;
    }
  }
  return true;
}

bool hasMotionSegments(const JointProblem& problem) {
  for (const GyroSegment& segment : problem.segments) {
    if (segment.interval) return true;
  }
  return false;
}

std::vector<GyroPreintegration> preintegrateSegments(const JointProblem& problem,
                                                     const Eigen::Matrix3d& T_g,
                                                     const std::vector<Eigen::Vector3d>& biases,
                                                     double timeshift,
                                                     std::vector<Eigen::Vector3d>* rates_from,
                                                     std::vector<Eigen::Vector3d>* rates_to) {
  std::vector<GyroPreintegration> out;
  out.reserve(problem.segments.size());
  rates_from->assign(problem.segments.size(), Eigen::Vector3d::Zero());
  rates_to->assign(problem.segments.size(), Eigen::Vector3d::Zero());
  const double shift = timeshift - problem.timeshift_initial_s;
  for (size_t j = 0; j < problem.segments.size(); ++j) {
    const GyroSegment& segment = problem.segments[j];
    const JointPose& from = problem.poses[segment.from_pose];
    const JointPose& to = problem.poses[segment.to_pose];
    if (!segment.interval) {
      out.push_back(preintegrateGyro(segment.stamps_s, segment.gyro_rad_s, from.end_s, to.start_s,
                                     T_g, biases[segment.from_pose], biases[segment.to_pose]));
      continue;
    }
    const double t_from = linkTime(from) + (from.at_rest ? 0.0 : shift);
    const double t_to = linkTime(to) + (to.at_rest ? 0.0 : shift);
    Eigen::Vector3d rate_from, rate_to;
    out.push_back(preintegrateGyroInterval(segment.stamps_s, segment.gyro_rad_s, t_from, t_to, T_g,
                                           biases[segment.from_pose], biases[segment.to_pose],
                                           &rate_from, &rate_to));
    if (!from.at_rest) (*rates_from)[j] = rate_from;
    if (!to.at_rest) (*rates_to)[j] = rate_to;
  }
  return out;
}

std::vector<AccelLinkIntegral> integrateAccelLinks(const JointProblem& problem,
                                                   const Eigen::Matrix3d& T_g,
                                                   const std::vector<Eigen::Vector3d>& biases,
                                                   double timeshift) {
  std::vector<AccelLinkIntegral> out;
  const double shift = timeshift - problem.timeshift_initial_s;
  for (const AccelLink& link : problem.accel_links) {
    out.push_back(integrateAccelLink(link.samples, problem.poses[link.from_pose].start_s + shift,
                                     problem.poses[link.to_pose].start_s + shift, T_g,
                                     biases[link.from_pose], biases[link.to_pose]));
  }
  return out;
}

std::vector<bool> posesWithGyro(const JointProblem& problem) {
  std::vector<bool> used(problem.poses.size(), false);
  for (const GyroSegment& segment : problem.segments) {
    used[segment.from_pose] = true;
    used[segment.to_pose] = true;
  }
  return used;
}

Eigen::Matrix3d State::gyroMatrix() const {
  Eigen::Matrix3d T_g;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T_g(r, c) = (r == c ? 1.0 : 0.0) + gyro_matrix[3 * r + c];
  }
  return T_g;
}

Eigen::Vector3d State::gyroBias(int pose) const {
  return Eigen::Vector3d(gyro_bias[pose][0], gyro_bias[pose][1], gyro_bias[pose][2]);
}

Eigen::Vector3d State::accelBias(int pose) const {
  return Eigen::Vector3d(accel_bias[pose][0], accel_bias[pose][1], accel_bias[pose][2]);
}

void State::foldRotationIncrements() {
  R_cam_imu_0 = projectToSO3(expSO3(Eigen::Vector3d(e_X[0], e_X[1], e_X[2])) * R_cam_imu_0);
  R_cam_imu_after_0 = projectToSO3(
      expSO3(Eigen::Vector3d(e_X_after[0], e_X_after[1], e_X_after[2])) * R_cam_imu_after_0);
  e_X_after = {0.0, 0.0, 0.0};
  R_world_target_0 =
      projectToSO3(expSO3(Eigen::Vector3d(e_T[0], e_T[1], e_T[2])) * R_world_target_0);
  e_X = {0.0, 0.0, 0.0};
  e_T = {0.0, 0.0, 0.0};
}

void State::holdUnexcitedGyroColumns(const JointObservability& observability) {
  for (int c = 0; c < 3; ++c) {
    if (observability.gyro_column_estimated[c]) continue;
    for (int r = 0; r < 3; ++r) gyro_matrix[3 * r + c] = 0.0;
  }
}

}  // namespace joint
}  // namespace camera_imu_alignment
