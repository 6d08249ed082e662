// The per-pose figures and the error to the truth that the report and the summary show.
#include "camera_imu_alignment/io/report_figures.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "camera_imu_alignment/io/joint_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/solver/solution_quality.h"
#include "report_text.h"

namespace camera_imu_alignment {
namespace {

using report_text::fixed;
using report_text::fixedList;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool finiteRotation(const Eigen::Matrix3d& R) { return R.allFinite() && isRotationMatrix(R, 1e-3); }

/// How many of the newest poses the estimate used: the caller's count, else inferred from the
/// pairs' pose indices and the joint estimate's per-pose residuals; at most input.poses.size().
std::size_t windowPoseCount(const ReportInput& in) {
  std::size_t count = in.window_poses;
  if (count == 0) {
    for (const RotationPair& p : in.pairs) {
      const int newest = std::max(p.pose_k, p.pose_t);
      if (newest >= 0) count = std::max(count, static_cast<std::size_t>(newest) + 1);
    }
    if (in.result.joint && in.result.joint->ok) {
      count = std::max(count, in.result.joint->pose_residual_norm.size());
    }
  }
  return std::min(count, in.poses.size());
}

/// Per window pose: RMS of |residual| (deg) over the pairs with that pose, at R_cam_imu.
std::vector<double> pairResidualRmsDeg(const RotationPairs& pairs, const Eigen::Matrix3d& R_cam_imu,
                                       std::size_t window) {
  std::vector<double> sum_sq(window, 0.0);
  std::vector<int> count(window, 0);
  if (!finiteRotation(R_cam_imu)) return std::vector<double>(window, kNaN);
  for (const RotationPair& p : pairs) {
    if (p.pose_k < 0 || p.pose_t < 0) continue;  // an independent pair: no pose
    const std::size_t k = p.pose_k, t = p.pose_t;
    if (k >= window || t >= window) continue;
    const double r = rad2deg(pairResidual(p, R_cam_imu).norm());
    for (std::size_t pose : {k, t}) {
      sum_sq[pose] += std::isfinite(r) ? r * r : kNaN;
      ++count[pose];
    }
  }
  std::vector<double> rms(window, kNaN);
  for (std::size_t i = 0; i < window; ++i) {
    if (count[i] > 0) rms[i] = std::sqrt(sum_sq[i] / count[i]);
  }
  return rms;
}

/// R_target_world of each group: chordal mean over the window poses of
/// R_target_cam_j R_cam_imu R_world_imu_j^T.
std::map<int, Eigen::Matrix3d> targetInWorldByGroup(const ReportInput& in, std::size_t first,
                                                    const Eigen::Matrix3d& R_cam_imu) {
  std::map<int, Eigen::Matrix3d> sums;
  for (std::size_t i = first; i < in.poses.size(); ++i) {
    const StationaryPose& p = in.poses[i];
    const Eigen::Matrix3d implied = p.R_target_cam * R_cam_imu * p.R_world_imu.transpose();
    if (!implied.allFinite()) continue;
    auto [it, inserted] = sums.emplace(p.group, Eigen::Matrix3d::Zero());
    it->second += implied;
  }
  std::map<int, Eigen::Matrix3d> means;
  for (const auto& [group, sum] : sums) {
    if (sum.allFinite() && sum.norm() > 1e-9) means.emplace(group, projectToSO3(sum));
  }
  return means;
}

}  // namespace

double TruthError::largestErrorInSigmas() const {
  double worst = kNaN;
  for (int a = 0; a < 3; ++a) {
    const double v = std::abs(error_over_sigma(a));
    if (std::isfinite(v) && !(worst >= v)) worst = v;
  }
  return worst;
}

ReportFigures reportFigures(const ReportInput& in) {
  ReportFigures figures;
  const Eigen::Matrix3d& X = in.result.R_cam_imu;
  const std::size_t window = windowPoseCount(in);
  const std::size_t first = in.poses.size() - window;
  figures.window_poses = window;
  // No estimate (its rotation a placeholder): no residual or mount is measured against it.
  const bool estimate = hasEstimate(in.result) && finiteRotation(X);
  const std::vector<double> pair_rms =
      estimate ? pairResidualRmsDeg(in.pairs, X, window) : std::vector<double>(window, kNaN);
  const std::map<int, Eigen::Matrix3d> R_target_world =
      estimate ? targetInWorldByGroup(in, first, X) : std::map<int, Eigen::Matrix3d>{};
  const std::vector<double>* joint_residuals = nullptr;
  if (in.result.joint && in.result.joint->ok &&
      in.result.joint->pose_residual_norm.size() == window) {
    joint_residuals = &in.result.joint->pose_residual_norm;
  }
  for (std::size_t i = 0; i < in.poses.size(); ++i) {
    const StationaryPose& p = in.poses[i];
    PoseFigure f;
    f.index = p.index;
    f.group = p.group;
    f.time_s = 0.5 * (p.start_s + p.end_s) - in.start_s;
    f.in_window = i >= first;
    f.num_frames = p.num_frames;
    f.reprojection_rms_px = p.reprojection_rms_px;
    f.pair_residual_rms_deg = f.in_window ? pair_rms[i - first] : kNaN;
    f.joint_residual_sigma = f.in_window && joint_residuals ? (*joint_residuals)[i - first] : kNaN;
    f.mount_offset_deg = Eigen::Vector3d::Constant(kNaN);
    const auto G = R_target_world.find(p.group);
    if (G != R_target_world.end()) {
      const Eigen::Matrix3d X_k = p.R_target_cam.transpose() * G->second * p.R_world_imu;
      if (X_k.allFinite()) f.mount_offset_deg = rad2deg(1.0) * logSO3(X_k * X.transpose());
    }
    figures.poses.push_back(f);
  }
  if (in.truth) {
    TruthError e;
    e.source = in.truth->source;
    e.sigma_deg = in.result.quality.std_dev_deg;
    e.angle_deg = kNaN;
    e.error_deg = Eigen::Vector3d::Constant(kNaN);
    // Bad input: no estimate to compare (its rotation is a placeholder): the error is n/a.
    if (estimate && finiteRotation(in.truth->R_cam_imu)) {
      e.angle_deg = rad2deg(geodesicDistance(X, in.truth->R_cam_imu));
      e.error_deg = rad2deg(1.0) * logSO3(X * in.truth->R_cam_imu.transpose());
    }
    for (int a = 0; a < 3; ++a) {
      const double sigma = e.sigma_deg(a);
      e.error_over_sigma(a) = std::isfinite(sigma) && sigma > 0.0 ? e.error_deg(a) / sigma : kNaN;
    }
    figures.truth_error = e;
  }
  return figures;
}

std::string jointConsistencyText(const JointResult& j) {
  const double per_dof = j.dof > 0 ? j.chi2 / j.dof : 0.0;
  return "chi2/dof " + fixed(per_dof, 2) + " (" + std::to_string(j.dof) + " dof, p " +
         fixed(j.chi2_p_value, 3) + "; residuals " + fixed(j.misfitRatio(), 2) + "x their noise, " +
         misfitBand(j.misfitRatio()) + ": " + (j.consistent() ? "consistent" : "INCONSISTENT") +
         ")";
}

std::string truthErrorText(const TruthError& e) {
  const double worst = e.largestErrorInSigmas();
  return "truth" + (e.source.empty() ? std::string() : " (" + e.source + ")") + ": error " +
         fixed(e.angle_deg, 4) + " deg, about camera x, y, z " + fixedList(e.error_deg, 4) +
         " deg = " + fixedList(e.error_over_sigma, 2) + " x 1-sigma" +
         (std::isfinite(worst) && worst > 3.0 ? " (beyond 3 sigma)" : "");
}

}  // namespace camera_imu_alignment
