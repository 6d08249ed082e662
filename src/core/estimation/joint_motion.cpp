#include "joint_motion.h"

#include "joint_state.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "gyro_accumulator.h"

namespace camera_imu_alignment {
namespace joint {
namespace {

/// Gyro kept beyond each end of an interval segment (s): the time offset may move by this much
/// from its initial value before an end runs out of samples.
constexpr double kSampleMargin = 0.25;
/// Motion frames this close (s, IMU clock) to a rest are left out: the rest's own camera average
/// already holds them.
constexpr double kRestGuard = 0.05;
/// Stamps differing by less than this (s) from a node spacing count as that spacing: a 10 Hz
/// camera's frames 0.1 s apart (in floating point, 0.0999999...) are all nodes, not every other.
constexpr double kSpacingToleranceS = 1e-4;

/// The samples of `gyro` (gyro and, when given, accelerometer) within [from - margin, to + margin].
void copyStream(const GyroStream& gyro, double from, double to, GyroStream* out) {
  const auto first =
      std::lower_bound(gyro.stamps_s.begin(), gyro.stamps_s.end(), from - kSampleMargin);
  const auto last = std::upper_bound(first, gyro.stamps_s.end(), to + kSampleMargin);
  const size_t a = static_cast<size_t>(first - gyro.stamps_s.begin());
  const size_t b = static_cast<size_t>(last - gyro.stamps_s.begin());
  out->stamps_s.assign(gyro.stamps_s.begin() + a, gyro.stamps_s.begin() + b);
  out->gyro_rad_s.assign(gyro.gyro_rad_s.begin() + a, gyro.gyro_rad_s.begin() + b);
  if (gyro.accel_m_s2.size() == gyro.stamps_s.size()) {
    out->accel_m_s2.assign(gyro.accel_m_s2.begin() + a, gyro.accel_m_s2.begin() + b);
  }
  out->noise_density_rad_s_sqrt_hz = gyro.noise_density_rad_s_sqrt_hz;
  out->accel_noise_density_m_s2_sqrt_hz = gyro.accel_noise_density_m_s2_sqrt_hz;
}

/// The gyro samples of a segment around a motion node.
void copySamples(const GyroStream& gyro, double from, double to, GyroSegment* segment) {
  GyroStream samples;
  copyStream(gyro, from, to, &samples);
  segment->stamps_s = std::move(samples.stamps_s);
  segment->gyro_rad_s = std::move(samples.gyro_rad_s);
  segment->noise_density_rad_s_sqrt_hz = gyro.noise_density_rad_s_sqrt_hz;
  segment->interval = true;
}

/// True when the stream covers [from, to] (IMU clock) without a gap longer than max_gap.
bool covers(const GyroStream& gyro, double from, double to, double max_gap) {
  if (gyro.stamps_s.size() < 2 || gyro.stamps_s.front() > from || gyro.stamps_s.back() < to) {
    return false;
  }
  auto it = std::upper_bound(gyro.stamps_s.begin(), gyro.stamps_s.end(), from);
  if (it != gyro.stamps_s.begin()) --it;
  for (; it + 1 != gyro.stamps_s.end() && *it < to; ++it) {
    if (*(it + 1) - *it > max_gap) return false;
  }
  return true;
}

double medianInterval(const std::vector<double>& stamps) {
  if (stamps.size() < 2) return 0.0;
  std::vector<double> dt(stamps.size() - 1);
  for (size_t i = 0; i + 1 < stamps.size(); ++i) dt[i] = stamps[i + 1] - stamps[i];
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return dt[dt.size() / 2];
}

/// Accelerometer links between consecutive keyframes of each chain of motion nodes (AccelLink):
/// nodes with a camera position about motion_accel_link_s apart (at most twice that).
void addAccelLinks(const JointProblem& problem, const std::vector<int>& frame_of_pose,
                   const JointSettings& settings, JointProblem* expanded) {
  const GyroStream& gyro = problem.motion_gyro;
  if (!(settings.motion_accel_link_s > 0.0) || gyro.accel_m_s2.size() != gyro.stamps_s.size() ||
      !(gyro.accel_noise_density_m_s2_sqrt_hz > 0.0)) {
    return;
  }
  const double max_gap = std::max(0.1, 10.0 * medianInterval(gyro.stamps_s));
  const std::vector<JointPose>& poses = expanded->poses;
  const auto positionOf = [&](size_t k) -> std::optional<Eigen::Vector3d> {
    if (poses[k].at_rest || frame_of_pose[k] < 0) return std::nullopt;
    return problem.motion_frames[static_cast<size_t>(frame_of_pose[k])].p_target_cam_m;
  };
  // The first node after `from` at least motion_accel_link_s later (at most twice that) in the
  // same chain, with a position and the IMU's samples between; poses.size() when there is none.
  const auto nextKeyframe = [&](size_t from) {
    for (size_t k = from + 1; k < poses.size(); ++k) {
      const double dt = poses[k].start_s - poses[from].start_s;
      if (poses[k].at_rest || poses[k].group != poses[from].group ||
          dt > 2.0 * settings.motion_accel_link_s) {
        break;
      }
      if (dt < settings.motion_accel_link_s || !positionOf(k)) continue;
      return covers(gyro, poses[from].start_s - kSampleMargin, poses[k].start_s + kSampleMargin,
                    max_gap)
                 ? k
                 : poses.size();
    }
    return poses.size();
  };
  // Chains of keyframes, then a link between each two consecutive ones.
  size_t start = 0;
  while (start < poses.size()) {
    if (!positionOf(start)) {
      ++start;
      continue;
    }
    std::vector<size_t> chain = {start};
    for (size_t next = nextKeyframe(start); next < poses.size(); next = nextKeyframe(next)) {
      chain.push_back(next);
    }
    if (chain.size() < 2) {
      ++start;
      continue;
    }
    std::vector<Eigen::Vector3d> p(chain.size()), v(chain.size());
    for (size_t i = 0; i < chain.size(); ++i) p[i] = *positionOf(chain[i]);
    for (size_t i = 0; i < chain.size(); ++i) {
      const size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, chain.size() - 1);
      v[i] = (p[b] - p[a]) / (poses[chain[b]].start_s - poses[chain[a]].start_s);
    }
    for (size_t i = 0; i + 1 < chain.size(); ++i) {
      AccelLink link;
      link.from_pose = static_cast<int>(chain[i]);
      link.to_pose = static_cast<int>(chain[i + 1]);
      copyStream(gyro, poses[chain[i]].start_s, poses[chain[i + 1]].start_s, &link.samples);
      link.p_from_target_m = p[i];
      link.p_to_target_m = p[i + 1];
      link.v_from_target_m_s = v[i];
      link.v_to_target_m_s = v[i + 1];
      expanded->accel_links.push_back(link);
    }
    start = chain.back() + 1;
  }
}

}  // namespace

std::string validateMotion(const JointProblem& problem) {
  const std::vector<MotionFrame>& frames = problem.motion_frames;
  for (size_t i = 0; i < frames.size(); ++i) {
    const std::string name = "motion frame " + std::to_string(i);
    if (!std::isfinite(frames[i].stamp_s)) return name + ": stamp is not finite";
    if (i > 0 && !(frames[i].stamp_s > frames[i - 1].stamp_s)) {
      return name + ": stamps are not strictly increasing";
    }
    if (!isRotationMatrix(frames[i].R_target_cam, 1e-3)) {
      return name + ": R_target_cam is not a rotation matrix";
    }
    if (!frames[i].cov_cam_rad2.allFinite()) return name + ": cov_cam_rad2 is not finite";
  }
  if (std::isfinite(problem.mount_change_stamp_s) && problem.mount_change_pose != -1) {
    return "mount_change_stamp_s and mount_change_pose both set: one mount change at a time";
  }
  if (frames.empty()) return "";
  const GyroStream& gyro = problem.motion_gyro;
  if (gyro.stamps_s.size() != gyro.gyro_rad_s.size()) {
    return "motion gyro: stamps_s and gyro_rad_s differ in length";
  }
  for (size_t i = 0; i < gyro.stamps_s.size(); ++i) {
    if (!std::isfinite(gyro.stamps_s[i]) || !gyro.gyro_rad_s[i].allFinite()) {
      return "motion gyro: sample " + std::to_string(i) + " is not finite";
    }
    if (i > 0 && !(gyro.stamps_s[i] > gyro.stamps_s[i - 1])) {
      return "motion gyro: stamps are not strictly increasing at sample " + std::to_string(i);
    }
  }
  if (!std::isfinite(gyro.noise_density_rad_s_sqrt_hz) || gyro.noise_density_rad_s_sqrt_hz < 0) {
    return "motion gyro: noise_density_rad_s_sqrt_hz must be finite and >= 0";
  }
  if (!std::isfinite(problem.timeshift_initial_s) ||
      !(problem.timeshift_prior_sigma_s > 0.0 && std::isfinite(problem.timeshift_prior_sigma_s))) {
    return "timeshift_initial_s must be finite and timeshift_prior_sigma_s finite and > 0";
  }
  return "";
}

ExpandedProblem expandMotion(const JointProblem& problem, const JointSettings& settings) {
  ExpandedProblem out;
  const size_t n = problem.poses.size();
  out.expanded_pose.resize(n);
  if (problem.motion_frames.empty()) {
    out.problem = problem;
    for (size_t k = 0; k < n; ++k) {
      out.caller_pose.push_back(static_cast<int>(k));
      out.expanded_pose[k] = static_cast<int>(k);
    }
    return out;
  }
  // Nodes: frames at least motion_node_spacing_s apart, away from the rests (IMU clock).
  const double shift = problem.timeshift_initial_s;
  std::vector<JointPose> nodes;
  std::vector<size_t> node_frame;  // the frame each node is
  double last = -1e300;
  for (size_t f = 0; f < problem.motion_frames.size(); ++f) {
    const MotionFrame& frame = problem.motion_frames[f];
    const double t = frame.stamp_s + shift;
    if (t - last < settings.motion_node_spacing_s - kSpacingToleranceS) continue;
    bool in_rest = false;
    for (const JointPose& rest : problem.poses) {
      in_rest = in_rest || (t > rest.start_s - kRestGuard && t < rest.end_s + kRestGuard);
    }
    if (in_rest) continue;
    JointPose node;
    node.at_rest = false;
    node.start_s = node.end_s = t;
    node.R_target_cam = frame.R_target_cam;
    node.cov_cam_rad2 = 0.5 * (frame.cov_cam_rad2 + frame.cov_cam_rad2.transpose());
    nodes.push_back(node);
    node_frame.push_back(f);
    last = t;
  }
  // Interleave by time.
  std::vector<std::pair<double, int>> order;  // (time, caller rest index or -1 - node index)
  for (size_t k = 0; k < n; ++k) order.emplace_back(problem.poses[k].start_s, static_cast<int>(k));
  for (size_t i = 0; i < nodes.size(); ++i) {
    order.emplace_back(nodes[i].start_s, -1 - static_cast<int>(i));
  }
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  JointProblem& expanded = out.problem;
  expanded.mount_change_pose = -1;
  expanded.timeshift_initial_s = problem.timeshift_initial_s;
  expanded.timeshift_prior_sigma_s = problem.timeshift_prior_sigma_s;
  expanded.noise = problem.noise;
  std::vector<int> frame_of_pose;  // per expanded pose: its motion frame, -1 for a rest
  for (const auto& [time, index] : order) {
    frame_of_pose.push_back(index >= 0 ? -1 : static_cast<int>(node_frame[-1 - index]));
    if (index >= 0) {
      out.expanded_pose[index] = static_cast<int>(expanded.poses.size());
      if (index == problem.mount_change_pose) {
        expanded.mount_change_pose = static_cast<int>(expanded.poses.size());
      }
      expanded.poses.push_back(problem.poses[index]);
    } else {
      expanded.poses.push_back(nodes[-1 - index]);
      ++out.motion_nodes;
    }
    out.caller_pose.push_back(index);
  }
  if (std::isfinite(problem.mount_change_stamp_s)) {  // the first pose at or after it, IMU clock
    const double change_s = problem.mount_change_stamp_s + shift;
    for (size_t k = 0; k < expanded.poses.size(); ++k) {
      if (expanded.poses[k].start_s >= change_s) {
        expanded.mount_change_pose = static_cast<int>(k);
        break;
      }
    }
  }
  expanded.mount_change_stamp_s = std::numeric_limits<double>::quiet_NaN();
  for (CameraLink link : problem.camera_links) {
    // An index out of range stays invalid (-1) for validateProblem to name.
    const auto map = [&](int k) {
      return k >= 0 && static_cast<size_t>(k) < n ? out.expanded_pose[static_cast<size_t>(k)] : -1;
    };
    link.from_pose = map(link.from_pose);
    link.to_pose = map(link.to_pose);
    expanded.camera_links.push_back(link);
  }
  // Segments between neighbours; groups follow the chains.
  const GyroStream& gyro = problem.motion_gyro;
  const double max_gap = std::max(0.1, 10.0 * medianInterval(gyro.stamps_s));
  int next_group = 1;
  for (const JointPose& rest : problem.poses) next_group = std::max(next_group, rest.group + 1);
  std::vector<int> rest_segment(n, -1);
  for (size_t j = 0; j < problem.segments.size(); ++j) {
    rest_segment[problem.segments[j].from_pose] = static_cast<int>(j);
  }
  const size_t m = expanded.poses.size();
  if (m > 0 && !expanded.poses[0].at_rest) expanded.poses[0].group = next_group++;
  size_t chain_start = 0;  // first pose of the chain that ends at pose k
  for (size_t k = 0; k + 1 < m; ++k) {
    JointPose& a = expanded.poses[k];
    JointPose& b = expanded.poses[k + 1];
    const int ca = out.caller_pose[k], cb = out.caller_pose[k + 1];
    if (ca >= 0 && cb >= 0) {  // two rests: the caller's segment, if any
      const int j = rest_segment[ca];
      if (j >= 0 && problem.segments[j].to_pose == cb) {
        GyroSegment segment = problem.segments[j];
        segment.from_pose = static_cast<int>(k);
        segment.to_pose = static_cast<int>(k + 1);
        expanded.segments.push_back(segment);
      } else {
        chain_start = k + 1;
      }
      continue;
    }
    const double from = linkTime(a), to = linkTime(b);
    const bool linked = to - from <= settings.motion_max_link_s &&
                        covers(gyro, from - kSampleMargin, to + kSampleMargin, max_gap);
    if (!linked) {
      if (!b.at_rest) b.group = next_group++;
      chain_start = k + 1;
      continue;
    }
    if (!b.at_rest) {
      b.group = a.group;
    } else if (b.group != a.group) {
      // A chain of nodes only joins the rest's group; a chain from another group's rest breaks.
      bool chain_has_rest = false;
      for (size_t i = chain_start; i <= k; ++i) chain_has_rest |= expanded.poses[i].at_rest;
      if (chain_has_rest) {
        chain_start = k + 1;
        continue;
      }
      for (size_t i = chain_start; i <= k; ++i) expanded.poses[i].group = b.group;
    }
    GyroSegment segment;
    segment.from_pose = static_cast<int>(k);
    segment.to_pose = static_cast<int>(k + 1);
    copySamples(gyro, from, to, &segment);
    expanded.segments.push_back(segment);
  }
  addAccelLinks(problem, frame_of_pose, settings, &expanded);
  return out;
}

AccelLinkIntegral integrateAccelLink(const GyroStream& samples, double t_from_s, double t_to_s,
                                     const Eigen::Matrix3d& T_g, const Eigen::Vector3d& b_from,
                                     const Eigen::Vector3d& b_to) {
  AccelLinkIntegral out;
  const std::vector<double>& stamps = samples.stamps_s;
  const size_t n = std::min({stamps.size(), samples.gyro_rad_s.size(), samples.accel_m_s2.size()});
  const double span = t_to_s - t_from_s;
  if (n < 2 || !(span > 0.0)) return out;
  const auto interpolate = [&](const std::vector<Eigen::Vector3d>& values, double t) {
    return interpolateSamples(stamps, values, n, t);
  };
  // The rotation and its derivative, as the gyro's preintegration takes them; each sub-interval
  // between samples is integrated at its midpoint, where the accelerometer is turned by the
  // rotation half-way through it.
  GyroAccumulator rotation{T_g.inverse(), b_from, b_to};
  double t = t_from_s;
  size_t i = static_cast<size_t>(std::upper_bound(stamps.begin(), stamps.begin() + n, t_from_s) -
                                 stamps.begin());
  while (t < t_to_s) {
    const double next = i < n ? std::min(stamps[i], t_to_s) : t_to_s;
    if (next > t) {
      const double dt = next - t, mid = 0.5 * (t + next);
      const double s = std::clamp((mid - t_from_s) / span, 0.0, 1.0);
      const Eigen::Vector3d raw = interpolate(samples.gyro_rad_s, mid);
      GyroAccumulator half = rotation;
      half.step(raw, s, 0.5 * dt);
      const Eigen::Matrix3d& R_mid = half.delta_R;
      const Eigen::Vector3d a = interpolate(samples.accel_m_s2, mid);
      // d(R_mid a) = -R_mid [a]x J_mid d.
      const Eigen::Matrix<double, 3, 15> turned = -R_mid * skew(a) * half.J;
      // Velocity: weight 1; position: the double integral, weight (to - t).
      const double w[2] = {1.0, t_to_s - mid};
      for (int k = 0; k < 2; ++k) {
        out.d0[k] += w[k] * dt * R_mid * a;
        out.bias_jacobian[k] += w[k] * dt * R_mid;
        out.gyro_jacobian[k] += w[k] * dt * turned;
        for (int r = 0; r < 3; ++r) {
          for (int u = 0; u < 3; ++u) {
            out.per_entry[k].col(3 * r + u) += w[k] * dt * R_mid.col(r) * a(u);
          }
        }
      }
      rotation.step(raw, s, dt);
    }
    t = next;
    ++i;
  }
  out.duration_s = span;
  out.theta0_minus_identity = gyroModelVector(T_g - Eigen::Matrix3d::Identity(), b_from, b_to);
  return out;
}

void mapResultToCaller(const ExpandedProblem& expanded, JointResult* result) {
  result->motion_nodes = expanded.motion_nodes;
  result->rests_used = static_cast<int>(expanded.expanded_pose.size());
  if (expanded.motion_nodes == 0) return;
  // The nodes' residuals for the report, on the camera clock (their stamps are shifted by the
  // initial offset, expandMotion).
  result->motion.node_stamps_s.clear();
  result->motion.node_residual_sigma.clear();
  if (result->pose_residual_norm.size() == expanded.caller_pose.size()) {
    for (size_t k = 0; k < expanded.caller_pose.size(); ++k) {
      if (expanded.caller_pose[k] >= 0) continue;
      result->motion.node_stamps_s.push_back(expanded.problem.poses[k].start_s -
                                             expanded.problem.timeshift_initial_s);
      result->motion.node_residual_sigma.push_back(result->pose_residual_norm[k]);
    }
  }
  result->motion.node_camera_residual_rad.clear();
  if (result->camera_residual_rad.size() == expanded.caller_pose.size()) {
    for (size_t k = 0; k < expanded.caller_pose.size(); ++k) {
      if (expanded.caller_pose[k] < 0) {
        result->motion.node_camera_residual_rad.push_back(result->camera_residual_rad[k]);
      }
    }
  }
  const auto select = [&](auto& per_pose) {
    if (per_pose.size() != expanded.caller_pose.size()) return;
    std::remove_reference_t<decltype(per_pose)> kept;
    for (int k : expanded.expanded_pose) kept.push_back(per_pose[k]);
    per_pose = std::move(kept);
  };
  select(result->pose_residual_norm);
  select(result->mag_residual_chi2);
  select(result->camera_residual_rad);
  select(result->intrinsics.gyro_bias_per_pose_rad_s);
  select(result->intrinsics.accel_bias_per_pose_m_s2);
  for (int& k : result->mag_poses_left_out) k = expanded.caller_pose[k];
}

}  // namespace joint
}  // namespace camera_imu_alignment
