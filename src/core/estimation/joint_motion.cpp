#include "joint_motion.h"

#include "joint_state.h"

#include <algorithm>
#include <cmath>

#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/solver/rotation_math.h"

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

/// The samples of `gyro` within [from - margin, to + margin].
void copySamples(const GyroStream& gyro, double from, double to, GyroSegment* segment) {
  const auto first =
      std::lower_bound(gyro.stamps_s.begin(), gyro.stamps_s.end(), from - kSampleMargin);
  const auto last = std::upper_bound(first, gyro.stamps_s.end(), to + kSampleMargin);
  const size_t a = static_cast<size_t>(first - gyro.stamps_s.begin());
  const size_t b = static_cast<size_t>(last - gyro.stamps_s.begin());
  segment->stamps_s.assign(gyro.stamps_s.begin() + a, gyro.stamps_s.begin() + b);
  segment->gyro_rad_s.assign(gyro.gyro_rad_s.begin() + a, gyro.gyro_rad_s.begin() + b);
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
  double last = -1e300;
  for (const MotionFrame& frame : problem.motion_frames) {
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
  for (const auto& [time, index] : order) {
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
  return out;
}

void mapResultToCaller(const ExpandedProblem& expanded, JointResult* result) {
  result->motion_nodes = expanded.motion_nodes;
  result->rests_used = static_cast<int>(expanded.expanded_pose.size());
  if (expanded.motion_nodes == 0) return;
  const auto select = [&](auto& per_pose) {
    if (per_pose.size() != expanded.caller_pose.size()) return;
    std::remove_reference_t<decltype(per_pose)> kept;
    for (int k : expanded.expanded_pose) kept.push_back(per_pose[k]);
    per_pose = std::move(kept);
  };
  select(result->pose_residual_norm);
  select(result->mag_residual_chi2);
  select(result->intrinsics.gyro_bias_per_pose_rad_s);
  select(result->intrinsics.accel_bias_per_pose_m_s2);
  for (int& k : result->mag_poses_left_out) k = expanded.caller_pose[k];
}

}  // namespace joint
}  // namespace camera_imu_alignment
