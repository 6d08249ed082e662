// Each camera link's solution chosen by the gyro's consensus (camera_link_consensus.h).
#include "camera_imu_alignment/estimation/camera_link_consensus.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
/// The RANSAC gate: the uncalibrated gyro's scale and cross-axis errors (a few percent of the
/// angle) plus the cameras' and the bias's share.
constexpr double kLooseGateRel = 0.05;
constexpr double kLooseGateDeg = 0.5;
/// Links of one chain needed to fit the 9 parameters of M and judge them.
constexpr int kMinConsensusLinks = 6;
/// Rotations smaller than this (deg) tell little of an axis: not used to hypothesise R_cam_imu.
constexpr double kMinHypothesisAngleDeg = 5.0;
/// Two links' axes closer than this (deg) do not fix R_cam_imu.
constexpr double kMinAxisSeparationDeg = 15.0;
/// sqrt of chi-square(3) at 99.9 %: the gate in units of the per-axis residual scale.
constexpr double kSwapSigmas = 4.03;
/// The median norm of a 3-vector of unit-variance Gaussians (per-axis sigma from a median norm).
constexpr double kMedianNormPerSigma = 1.538;
/// Floor of the per-axis residual scale (deg): the cameras' own noise is about this.
constexpr double kMinScaleDeg = 0.01;
/// Weight of M's pull towards the hypothesis' rotation (rad^2 per squared element): keeps an axis
/// the window's rotations never turned about at the hypothesis.
constexpr double kRidge = 0.05;
constexpr int kRounds = 3;

/// A link within one gyro chain: the IMU's rotation vector and the camera's solutions.
struct JudgedLink {
  int index = 0;                       ///< into JointProblem::camera_links
  Eigen::Vector3d theta_imu;           ///< rad, IMU axes (R_imu_from_to)
  std::vector<Eigen::Vector3d> phi;    ///< rad, camera axes: [0] measured, then alternatives
  std::vector<Eigen::Matrix3d> R_cam;  ///< the same solutions as rotations
};

/// Per pose: its gyro chain (-1 when none) and its IMU orientation in the chain's first pose's
/// frame, from the gyro with T_g = I and the rests' mean rates as biases.
void gyroChains(const JointProblem& problem, std::vector<int>* chain,
                std::vector<Eigen::Matrix3d>* R_chain_imu) {
  const std::size_t n = problem.poses.size();
  chain->assign(n, -1);
  R_chain_imu->assign(n, Eigen::Matrix3d::Identity());
  std::vector<const GyroSegment*> into(n, nullptr);  // the segment ending at each pose
  for (const GyroSegment& s : problem.segments) {
    if (s.to_pose == s.from_pose + 1 && s.from_pose >= 0 && s.to_pose < static_cast<int>(n) &&
        !s.stamps_s.empty() && s.stamps_s.size() == s.gyro_rad_s.size()) {
      into[s.to_pose] = &s;
    }
  }
  int chains = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const GyroSegment* s = into[k];
    if (k == 0 || s == nullptr || problem.poses[k - 1].group != problem.poses[k].group) {
      (*chain)[k] = chains++;
      continue;
    }
    const JointPose& from = problem.poses[k - 1];
    const JointPose& to = problem.poses[k];
    const GyroPreintegration p =
        preintegrateGyro(s->stamps_s, s->gyro_rad_s, from.end_s, to.start_s,
                         Eigen::Matrix3d::Identity(), from.gyro_mean_rad_s, to.gyro_mean_rad_s);
    if (!p.delta_R.allFinite()) {
      (*chain)[k] = chains++;
      continue;
    }
    (*chain)[k] = (*chain)[k - 1];
    (*R_chain_imu)[k] = (*R_chain_imu)[k - 1] * p.delta_R;
  }
}

/// R_cam_imu taking the two IMU rotation vectors' axes onto the two camera ones (least squares
/// over the axes and their cross product).
bool hypothesis(const Eigen::Vector3d& t1, const Eigen::Vector3d& p1, const Eigen::Vector3d& t2,
                const Eigen::Vector3d& p2, Eigen::Matrix3d* R_cam_imu) {
  const Eigen::Vector3d u1 = t1.normalized(), u2 = t2.normalized();
  const Eigen::Vector3d v1 = p1.normalized(), v2 = p2.normalized();
  const Eigen::Vector3d u3 = u1.cross(u2), v3 = v1.cross(v2);
  if (u3.norm() < std::sin(kMinAxisSeparationDeg * kDegToRad) ||
      v3.norm() < std::sin(kMinAxisSeparationDeg * kDegToRad)) {
    return false;
  }
  const Eigen::Matrix3d H =
      v1 * u1.transpose() + v2 * u2.transpose() + v3.normalized() * u3.normalized().transpose();
  *R_cam_imu = projectToSO3(H);
  return R_cam_imu->allFinite();
}

/// The nearest solution of a link to M theta and its distance (rad).
std::pair<int, double> nearest(const JudgedLink& link, const Eigen::Matrix3d& M) {
  const Eigen::Vector3d predicted = M * link.theta_imu;
  std::pair<int, double> best{0, std::numeric_limits<double>::infinity()};
  for (std::size_t c = 0; c < link.phi.size(); ++c) {
    const double d = (predicted - link.phi[c]).norm();
    if (d < best.second) best = {static_cast<int>(c), d};
  }
  return best;
}

/// M fitted to the links' chosen solutions, pulled towards R_prior (kRidge).
Eigen::Matrix3d fitMap(const std::vector<JudgedLink>& links, const std::vector<int>& chosen,
                       const std::vector<bool>& use, const Eigen::Matrix3d& R_prior) {
  Eigen::Matrix3d A = kRidge * Eigen::Matrix3d::Identity();  // sum theta theta^T + ridge
  Eigen::Matrix3d B = kRidge * R_prior;                      // sum phi theta^T + ridge prior
  for (std::size_t k = 0; k < links.size(); ++k) {
    if (!use[k]) continue;
    A += links[k].theta_imu * links[k].theta_imu.transpose();
    B += links[k].phi[chosen[k]] * links[k].theta_imu.transpose();
  }
  return B * A.inverse();
}

/// A link whose measured solution (`measured` rad from the prediction M theta, within `gate`) and
/// a nearer one both lie within `gate` of `predicted`: the gyro cannot tell which is right, so the
/// link's covariance spans them (each such solution's difference d from the measured one, as
/// d d^T, added to the link's and the alternatives' covariances; CameraLink::undecided_rad2).
/// True when the link was widened.
bool widenUndecided(const JudgedLink& l, const Eigen::Vector3d& predicted, double measured,
                    double gate, CameraLink* link) {
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  for (std::size_t c = 1; c < l.R_cam.size(); ++c) {
    const double distance = (predicted - l.phi[c]).norm();
    if (distance >= gate || distance >= measured) continue;
    const Eigen::Vector3d d = logSO3(l.R_cam[0].transpose() * l.R_cam[c]);  // `to` camera axes
    if (d.allFinite()) spread += d * d.transpose();
  }
  if (!(spread.trace() > 0)) return false;
  link->undecided_rad2 = spread;
  link->cov_rad2 += spread;
  for (CameraLink::Alternative& a : link->alternatives) a.cov_rad2 += spread;
  return true;
}

}  // namespace

CameraLinkConsensus chooseCameraLinkSolutions(JointProblem* problem) {
  CameraLinkConsensus out;
  out.alternative_used.assign(problem->camera_links.size(), -1);
  std::vector<int> chain;
  std::vector<Eigen::Matrix3d> R_chain_imu;
  gyroChains(*problem, &chain, &R_chain_imu);
  // The largest chain's links (one R_cam_imu, one gyro calibration).
  std::vector<int> links_in_chain(problem->poses.size() + 1, 0);
  const auto inChain = [&](const CameraLink& l) {
    const int n = static_cast<int>(problem->poses.size());
    return l.from_pose >= 0 && l.to_pose >= 0 && l.from_pose < n && l.to_pose < n &&
           chain[l.from_pose] == chain[l.to_pose];
  };
  for (const CameraLink& l : problem->camera_links) {
    if (inChain(l)) ++links_in_chain[chain[l.from_pose]];
  }
  const int main_chain = static_cast<int>(
      std::max_element(links_in_chain.begin(), links_in_chain.end()) - links_in_chain.begin());
  std::vector<JudgedLink> links;
  for (std::size_t i = 0; i < problem->camera_links.size(); ++i) {
    const CameraLink& l = problem->camera_links[i];
    if (!inChain(l) || chain[l.from_pose] != main_chain) continue;
    JudgedLink j;
    j.index = static_cast<int>(i);
    j.theta_imu = logSO3(R_chain_imu[l.from_pose].transpose() * R_chain_imu[l.to_pose]);
    j.R_cam.push_back(l.R_from_to);
    for (const CameraLink::Alternative& a : l.alternatives) j.R_cam.push_back(a.R_from_to);
    for (const Eigen::Matrix3d& R : j.R_cam) j.phi.push_back(logSO3(R));
    if (!j.theta_imu.allFinite()) continue;
    links.push_back(std::move(j));
  }
  out.links_judged = static_cast<int>(links.size());
  if (out.links_judged < kMinConsensusLinks) return out;

  // 1. RANSAC over pairs of links and one solution of each (exhaustive: windows are small).
  const double min_angle = kMinHypothesisAngleDeg * kDegToRad;
  const auto looseGate = [&](const JudgedLink& l) {
    return kLooseGateRel * l.theta_imu.norm() + kLooseGateDeg * kDegToRad;
  };
  int best_count = -1;
  double best_sum = 0;
  Eigen::Matrix3d R_best = Eigen::Matrix3d::Identity();
  for (std::size_t a = 0; a < links.size(); ++a) {
    if (links[a].theta_imu.norm() < min_angle) continue;
    for (std::size_t b = a + 1; b < links.size(); ++b) {
      if (links[b].theta_imu.norm() < min_angle) continue;
      for (const Eigen::Vector3d& pa : links[a].phi) {
        for (const Eigen::Vector3d& pb : links[b].phi) {
          Eigen::Matrix3d R;
          if (!hypothesis(links[a].theta_imu, pa, links[b].theta_imu, pb, &R)) continue;
          int count = 0;
          double sum = 0;
          for (const JudgedLink& l : links) {
            const double d = nearest(l, R).second;
            if (d < looseGate(l)) {
              ++count;
              sum += d;
            }
          }
          if (count > best_count || (count == best_count && sum < best_sum)) {
            best_count = count;
            best_sum = sum;
            R_best = R;
          }
        }
      }
    }
  }
  if (best_count < kMinConsensusLinks) return out;

  // 2. M on the consensus, its residuals' scale, the nearest solutions again.
  std::vector<int> chosen(links.size());
  std::vector<bool> use(links.size());
  for (std::size_t k = 0; k < links.size(); ++k) {
    const auto [c, d] = nearest(links[k], R_best);
    chosen[k] = c;
    use[k] = d < looseGate(links[k]);
  }
  Eigen::Matrix3d M = R_best;
  double sigma = 0;
  for (int round = 0; round < kRounds; ++round) {
    M = fitMap(links, chosen, use, R_best);
    std::vector<double> distances;
    for (std::size_t k = 0; k < links.size(); ++k) {
      const auto [c, d] = nearest(links[k], M);
      chosen[k] = c;
      distances.push_back(d);
    }
    std::vector<double> sorted = distances;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    sigma = std::max(sorted[sorted.size() / 2] / kMedianNormPerSigma, kMinScaleDeg * kDegToRad);
    int count = 0;
    for (std::size_t k = 0; k < links.size(); ++k) {
      use[k] = distances[k] < kSwapSigmas * sigma;
      count += use[k];
    }
    if (count < kMinConsensusLinks) return out;
  }
  out.residual_scale_deg = sigma / kDegToRad;

  // 3. The swaps, and the solutions the gyro cannot choose between.
  const double gate = kSwapSigmas * sigma;
  for (std::size_t k = 0; k < links.size(); ++k) {
    out.consensus += use[k];
    if (chosen[k] == 0 || !use[k]) continue;
    const JudgedLink& l = links[k];
    const Eigen::Vector3d predicted = M * l.theta_imu;
    const double measured = (predicted - l.phi[0]).norm();
    CameraLink& link = problem->camera_links[l.index];
    if (measured < gate) {  // another solution is nearer, but the measured one fits too
      out.undecided += widenUndecided(l, predicted, measured, gate, &link);
      continue;
    }
    const int a = chosen[k] - 1;
    std::swap(link.R_from_to, link.alternatives[a].R_from_to);
    std::swap(link.cov_rad2, link.alternatives[a].cov_rad2);
    out.alternative_used[l.index] = a;
  }
  return out;
}

}  // namespace camera_imu_alignment
