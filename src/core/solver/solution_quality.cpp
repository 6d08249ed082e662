#include "camera_imu_alignment/solver/solution_quality.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// Sandwich covariance for pairs that share poses. Linearised, r_kt = J_kt delta + e_kt with
/// e_kt = A_kt w_t - w_k, w_p ~ N(0, s2 I) the (camera-frame) noise of pose p. With g_p the sum of
/// J^T times the coefficient of w_p over the pairs that use pose p and G = sum_p g_p g_p^T:
///   Cov(delta) = s2 H^-1 G H^-1,  E[sum |r|^2] = s2 (6 N - tr(H^-1 G)).
/// For independent pairs (e_j ~ N(0, s2 I)) the same algebra gives G = H and 3N - 3 degrees of
/// freedom.
struct NoiseModel {
  Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
  double noise_dims = 0.0;  // tr(S_e) / s2
};

bool allPairsHavePoses(const RotationPairs& pairs, const std::vector<int>& used) {
  for (int j : used) {
    if (pairs[j].pose_k < 0 || pairs[j].pose_t < 0) return false;
  }
  return !used.empty();
}

}  // namespace

Eigen::Vector3d pairResidual(const RotationPair& pair, const Eigen::Matrix3d& R_cam_imu) {
  return logSO3(pair.A_cam * R_cam_imu * pair.B_imu.transpose() * R_cam_imu.transpose());
}

Eigen::Matrix3d pairJacobian(const RotationPair& pair, const Eigen::Vector3d& residual) {
  // Jl^-1(r) = I - Phi/2 + c Phi^2 and Jr^-1(r) = Jl^-1(-r) = I + Phi/2 + c Phi^2 share
  // common = I + c Phi^2, with Phi^2 = r r^T - |r|^2 I (Phi = skew(r)); written out entry-wise.
  const double x = residual.x(), y = residual.y(), z = residual.z();
  const double angle2 = x * x + y * y + z * z;
  // c(theta): its small-angle series needs only theta^2 (no square root).
  const double c =
      angle2 < 0.01
          ? 1.0 / 12.0 + angle2 * (1.0 / 720.0 + angle2 * (1.0 / 30240.0 + angle2 / 1209600.0))
          : jacobianInverseCoefficient(std::sqrt(angle2));
  const double cxy = c * x * y, cxz = c * x * z, cyz = c * y * z;
  const double hx = 0.5 * x, hy = 0.5 * y, hz = 0.5 * z;
  Eigen::Matrix3d common;
  common << 1.0 - c * (y * y + z * z), cxy, cxz,  //
      cxy, 1.0 - c * (x * x + z * z), cyz,        //
      cxz, cyz, 1.0 - c * (x * x + y * y);
  Eigen::Matrix3d half_phi;
  half_phi << 0.0, -hz, hy,  //
      hz, 0.0, -hx,          //
      -hy, hx, 0.0;
  Eigen::Matrix3d J;
  J.noalias() = (common - half_phi).lazyProduct(pair.A_cam);
  J -= common + half_phi;
  return J;
}

void pairAnglesDeg(const RotationPair& pair, double* angle_cam_deg, double* angle_imu_deg) {
  *angle_cam_deg = rad2deg(rotationAngle(pair.A_cam));
  *angle_imu_deg = rad2deg(rotationAngle(pair.B_imu));
}

std::string axisName(const Eigen::Vector3d& axis) {
  Eigen::Index i = 0;
  axis.cwiseAbs().maxCoeff(&i);
  return std::string(1, "xyz"[i]);
}

SolutionQuality evaluateQuality(const RotationPairs& pairs, const Eigen::Matrix3d& R_cam_imu,
                                const std::vector<bool>& inlier,
                                const std::vector<std::string>& rejection,
                                const QualityOptions& options,
                                const std::vector<Eigen::Vector3d>& given_residuals,
                                const std::vector<Eigen::Vector2d>& given_angles_rad) {
  SolutionQuality q;
  q.num_pairs = static_cast<int>(pairs.size());
  q.pairs.resize(pairs.size());
  std::vector<int> used;
  used.reserve(pairs.size());
  const bool have_angles = given_angles_rad.size() == pairs.size();
  std::vector<Eigen::Vector3d> residuals(pairs.size());
  std::vector<Eigen::Matrix3d> jacobians(pairs.size());
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  double sum_sq = 0.0;
  for (size_t j = 0; j < pairs.size(); ++j) {
    PairDiagnostics& d = q.pairs[j];
    residuals[j] = given_residuals.size() == pairs.size() ? given_residuals[j]
                                                          : pairResidual(pairs[j], R_cam_imu);
    d.residual_deg = rad2deg(residuals[j].norm());
    if (have_angles) {
      d.angle_cam_deg = rad2deg(given_angles_rad[j].x());
      d.angle_imu_deg = rad2deg(given_angles_rad[j].y());
    } else {
      pairAnglesDeg(pairs[j], &d.angle_cam_deg, &d.angle_imu_deg);
    }
    d.inlier = inlier.empty() || inlier[j];
    if (!d.inlier && j < rejection.size()) d.rejection = rejection[j];
    if (!d.inlier) continue;
    used.push_back(static_cast<int>(j));
    jacobians[j] = pairJacobian(pairs[j], residuals[j]);
    H += jacobians[j].transpose() * jacobians[j];
    sum_sq += residuals[j].squaredNorm();
  }
  q.num_inliers = static_cast<int>(used.size());
  if (used.empty()) {
    q.observability_message = "not observable: no usable pair";
    return q;
  }
  q.residual_rms_deg = rad2deg(std::sqrt(sum_sq / used.size()));

  // Observability from the spread of rotation axes: the information matrix H is about
  // sum_j 2 (1 - cos theta_j) (I - a_j a_j^T), blind along a common axis a.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(0.5 * (H + H.transpose()));  // closed-form 3x3; ample for these diagnostics
  const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(0.0);  // ascending
  const double mean_lambda = lambda.sum() / 3.0;
  q.observability = mean_lambda > 0.0 ? std::min(1.0, lambda(0) / mean_lambda) : 0.0;
  q.weak_axis_cam = eig.eigenvectors().col(0).normalized();
  q.excite_axis_cam = eig.eigenvectors().col(2).normalized();
  // Sign convention for readability: the largest component positive.
  for (Eigen::Vector3d* axis : {&q.weak_axis_cam, &q.excite_axis_cam}) {
    Eigen::Index i = 0;
    axis->cwiseAbs().maxCoeff(&i);
    if ((*axis)(i) < 0.0) *axis = -*axis;
  }
  q.weakest_excitation_deg = rad2deg(std::sqrt(lambda(0) / used.size()));

  // Noise model and covariance.
  NoiseModel model;
  // Independent noise dimensions behind the residuals, minus the 3 estimated: the degrees of
  // freedom of the noise-scale estimate (pairs sharing poses carry no more noise than the poses).
  double independent_dof = 3.0 * used.size() - 3.0;
  if (allPairsHavePoses(pairs, used)) {
    int num_poses = 0;
    for (int j : used) num_poses = std::max({num_poses, pairs[j].pose_k + 1, pairs[j].pose_t + 1});
    std::vector<Eigen::Matrix3d> g(num_poses, Eigen::Matrix3d::Zero());
    for (int j : used) {
      g[pairs[j].pose_t] += jacobians[j].transpose() * pairs[j].A_cam;
      g[pairs[j].pose_k] -= jacobians[j].transpose();
    }
    for (const auto& gp : g) model.G += gp * gp.transpose();
    model.noise_dims = 6.0 * used.size();
    int poses_used = 0;
    for (const auto& gp : g) poses_used += gp.isZero() ? 0 : 1;
    independent_dof = std::min(independent_dof, 3.0 * poses_used - 3.0);
  } else {
    model.G = H;
    model.noise_dims = 3.0 * used.size();
  }

  const double tiny = 1e-12 * std::max(1.0, lambda(2));
  double residual_var = 0.0;  // per-component noise variance s2 (rad^2)
  if (lambda(0) > tiny) {
    const Eigen::Matrix3d H_inv = H.inverse();
    const double dof = model.noise_dims - (H_inv * model.G).trace();
    if (dof > 0.5) {
      residual_var = sum_sq / dof;
      // The noise scale is itself estimated from few independent residual dimensions (n): the
      // posterior of the error is then Student-t (Jeffreys prior on the scale), whose variance is
      // n / (n - 2) times the plug-in one. Negligible for many poses; 1.5 for 3 poses (n = 6).
      // Capped at 9 (3x on the sigma) where the t variance is infinite (n <= 2.25).
      const double n = independent_dof;
      const double t_factor = n > 2.25 ? n / (n - 2.0) : 9.0;
      q.covariance_rad2 = t_factor * residual_var * H_inv * model.G * H_inv;
      for (int i = 0; i < 3; ++i) {
        q.std_dev_deg(i) =
            std::min(180.0, rad2deg(std::sqrt(std::max(0.0, q.covariance_rad2(i, i)))));
      }
    }
  }
  const double noise_deg = rad2deg(std::sqrt(residual_var));
  const double needed_deg =
      std::max(options.min_excitation_deg, options.min_excitation_noise_ratio * noise_deg);
  char msg[512];
  if (used.size() < 2 || lambda(0) <= tiny || q.weakest_excitation_deg < needed_deg) {
    q.observable = false;
    const std::string weak = axisName(q.weak_axis_cam);
    const char* others = weak == "x" ? "y or z" : weak == "y" ? "x or z" : "x or y";
    std::snprintf(
        msg, sizeof(msg),
        "not observable: the rotations were (nearly) all about camera %s (axis [%.3f %.3f "
        "%.3f]; excitation of the other axes %.3g deg, needs %.3g deg), so R_cam_imu is "
        "free about it; rotate the rig about the camera %s axis (best: camera %s)",
        weak.c_str(), q.weak_axis_cam.x(), q.weak_axis_cam.y(), q.weak_axis_cam.z(),
        q.weakest_excitation_deg, needed_deg, others, axisName(q.excite_axis_cam).c_str());
  } else {
    q.observable = true;
    // The numbers are in the fields; solveAlignment's message repeats the ones that matter.
    q.observability_message = "observable";
    return q;
  }
  q.observability_message = msg;
  return q;
}

}  // namespace camera_imu_alignment
