// The mount-change test on continuous motion (mount_change.h: testMountChangeOnMotion).
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <vector>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/estimation/mount_change.h"
#include "camera_imu_alignment/estimation/time_offset.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// Motion nodes needed for the test (each side's mean of the camera correction).
constexpr std::size_t kMinNodes = 20;
/// 1-sigma (s) of the time offset's prior around the one-mount estimate's value.
constexpr double kTimeshiftSigmaS = 0.01;

/// The split (index of the first node after it) maximising m (N - m) / N |mean_a - mean_b|^2 with
/// `min_s` of motion each side; -1 when none has.
int stepLocation(const std::vector<double>& stamps, const std::vector<Eigen::Vector3d>& residuals,
                 double min_s) {
  const std::size_t n = stamps.size();
  std::vector<Eigen::Vector3d> prefix(n + 1, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + residuals[i];
  int best = -1;
  double best_statistic = -1.0;
  for (std::size_t m = 1; m < n; ++m) {
    if (stamps[m - 1] - stamps.front() < min_s || stamps.back() - stamps[m] < min_s) continue;
    const double a = static_cast<double>(m), b = static_cast<double>(n - m);
    const Eigen::Vector3d difference = prefix[m] / a - (prefix[n] - prefix[m]) / b;
    const double statistic = a * b / static_cast<double>(n) * difference.squaredNorm();
    if (statistic > best_statistic) {
      best_statistic = statistic;
      best = static_cast<int>(m);
    }
  }
  return best;
}

/// Motion each half of a side needs for the scatter of the recording's own segments (s).
constexpr double kMinHalfS = 2.0;

/// How much more the recording's own segments differ than their 1-sigma says, under the noise
// learned: each side of the split cut into two halves, each half solved alone (its R_cam_imu and
// covariance), and the halves' differences judged against their summed covariances,
// phi = sum_sides d^T (C_a + C_b)^-1 d / (3 x sides). Without a change both sides' halves
// share a mount, so phi measures only the misfit a real recording has beyond its noise (a PnP
// error that lasts, a gyro that is not the model): about 1 on a recording the model fits. 1 when
// it cannot be measured (too little motion, rests in the window, a failed solve).
double segmentScatter(const JointProblem& gapped, double split_s, double half_gap,
                      const JointSettings& settings, const Eigen::Matrix3d& R_cam_imu_start) {
  if (!gapped.poses.empty() || gapped.motion_frames.empty()) return 1.0;
  const double first = gapped.motion_frames.front().stamp_s;
  const double last = gapped.motion_frames.back().stamp_s;
  const double sides[2][2] = {{first, split_s - half_gap}, {split_s + half_gap, last}};
  JointSettings segment_settings = settings;
  segment_settings.compute_covariance = true;
  segment_settings.learn_noise = false;  // the noise the whole window showed
  segment_settings.solver_threads = 1;
  const JointEstimator estimator(segment_settings);
  double sum = 0.0;
  int compared = 0;
  for (const auto& side : sides) {
    const double middle = 0.5 * (side[0] + side[1]);
    if (middle - side[0] < kMinHalfS) continue;
    JointResult halves[2];
    bool solved = true;
    for (int h = 0; h < 2 && solved; ++h) {
      JointProblem half = gapped;
      half.motion_frames.clear();
      const double from = h == 0 ? side[0] : middle, to = h == 0 ? middle : side[1];
      for (const MotionFrame& frame : gapped.motion_frames) {
        if (frame.stamp_s >= from && frame.stamp_s <= to) half.motion_frames.push_back(frame);
      }
      halves[h] = estimator.solve(half, R_cam_imu_start);
      solved = halves[h].ok;
    }
    if (!solved) continue;
    const Eigen::Matrix3d covariance = halves[0].covariance_rad2 + halves[1].covariance_rad2;
    const Eigen::Vector3d d = logSO3(halves[1].R_cam_imu * halves[0].R_cam_imu.transpose());
    const double chi2 = d.dot(covariance.ldlt().solve(d));
    if (!std::isfinite(chi2)) continue;
    sum += chi2;
    ++compared;
  }
  return compared > 0 ? std::max(1.0, sum / (3.0 * compared)) : 1.0;
}

}  // namespace

MountChangeTest testMountChangeOnMotion(const JointProblem& problem, const JointResult& one_mount,
                                        const JointSettings& joint_settings,
                                        const MountChangeSettings& settings) {
  MountChangeTest test;
  const std::vector<double>& stamps = one_mount.motion.node_stamps_s;
  const std::vector<Eigen::Vector3d>& residuals = one_mount.motion.node_camera_residual_rad;
  if (!one_mount.ok || problem.motion_frames.empty()) {
    test.message = one_mount.ok ? "no motion for the mount-change test"
                                : "no one-mount estimate to test against";
    return test;
  }
  const int split = stamps.size() == residuals.size() && stamps.size() >= kMinNodes
                        ? stepLocation(stamps, residuals, settings.min_motion_s)
                        : -1;
  if (split < 0) {
    char buffer[160];
    std::snprintf(buffer, sizeof(buffer),
                  "too little motion for the mount-change test (%.1f s of motion nodes; %.1f s "
                  "needed each side of a change)",
                  stamps.empty() ? 0.0 : stamps.back() - stamps.front(), settings.min_motion_s);
    test.message = buffer;
    return test;
  }
  test.tested = true;
  const double change_s = 0.5 * (stamps[split - 1] + stamps[split]);
  const double half_gap = 0.5 * settings.motion_gap_s;
  // The data both fits see: the motion around the change left out (the mount moved there), the
  // frames' covariance as the estimate weighed them, its time offset as the start.
  JointProblem gapped = problem;
  gapped.motion_frames.clear();
  for (MotionFrame frame : problem.motion_frames) {
    if (std::abs(frame.stamp_s - change_s) < half_gap) continue;
    gapped.motion_frames.push_back(frame);
  }
  gapped.noise = one_mount.noise.variance_factor;  // both fits under the noise learned
  gapped.timeshift_initial_s = one_mount.timeshift_cam_imu_s;
  gapped.timeshift_prior_sigma_s = kTimeshiftSigmaS;
  if (!(gapped.motion_gyro.noise_density_rad_s_sqrt_hz > 0.0)) {
    gapped.motion_gyro.noise_density_rad_s_sqrt_hz = gyroNoiseDensityOf(gapped.motion_gyro);
  }
  addCameraExcessVariance(one_mount.camera_excess_variance_rad2, &gapped);
  JointSettings fit_settings = joint_settings;
  fit_settings.imu_matrices = one_mount.imu_matrices;
  fit_settings.compute_covariance = false;  // the fits alone
  fit_settings.use_magnetometer =
      one_mount.intrinsics.magnetometer_used ? MagnetometerUse::kOn : MagnetometerUse::kOff;
  JointProblem two_mounts = gapped;
  two_mounts.mount_change_stamp_s = change_s + half_gap;
  // The two fits are independent: side by side when the settings allow more than one thread.
  const bool side_by_side = fit_settings.solver_threads >= 2;
  if (side_by_side) fit_settings.solver_threads = 1;
  const JointEstimator estimator(fit_settings);
  std::future<JointResult> one_fit =
      std::async(side_by_side ? std::launch::async : std::launch::deferred,
                 [&] { return estimator.solve(gapped, one_mount.R_cam_imu); });
  const JointResult two = estimator.solve(two_mounts, one_mount.R_cam_imu);
  const JointResult one = one_fit.get();
  test.change_stamp_s = change_s;
  if (!one.ok || !two.ok || !two.R_cam_imu_after_change || two.dof <= 0 || one.dof <= two.dof) {
    test.tested = false;
    test.message =
        "the mount-change fits on the motion failed (" + (one.ok ? two.message : one.message) + ")";
    return test;
  }
  MountChangeCandidate c;
  c.solved = true;
  c.declarable = true;
  c.statistic = std::max(0.0, one.chi2 - two.chi2);
  c.dof = one.dof - two.dof;
  c.scale = std::max(1.0, two.chi2 / two.dof);
  c.p_value = fisherUpperTail(c.statistic / c.dof / c.scale, c.dof, two.dof);
  // Significant against the noise alone: judged again against how much the recording's own
  // unchanged segments differ (a real recording's misfit lasts, and a split explains some of it).
  const double locations_allowed =
      std::max(1.0, std::floor((stamps.back() - stamps.front() - 2.0 * settings.min_motion_s) /
                               settings.motion_gap_s) +
                        1.0);
  if (c.p_value * locations_allowed < settings.level) {
    test.segment_scatter =
        segmentScatter(gapped, change_s, half_gap, fit_settings, one_mount.R_cam_imu);
    c.scale = std::max(c.scale, test.segment_scatter);
    c.p_value = fisherUpperTail(c.statistic / c.dof / c.scale, c.dof, two.dof);
  }
  c.change_deg = rad2deg(rotationAngle(two.R_cam_imu.transpose() * *two.R_cam_imu_after_change));
  c.fits_every_pose = true;
  test.candidates.push_back(c);
  // Bonferroni over the locations the window allows, one per gap width.
  const double locations = locations_allowed;
  test.p_value = std::min(1.0, c.p_value * locations);
  test.change_deg = c.change_deg;
  test.R_cam_imu_before = two.R_cam_imu;
  test.R_cam_imu_after = *two.R_cam_imu_after_change;
  // A change located at the edge of the splits allowed may lie beyond it (a change in the newest
  // min_motion_s is found at the latest split allowed, with the mount's movement after it): it is
  // pending until the motion after it is long enough to place it.
  const bool at_edge = stamps.back() - change_s < settings.min_motion_s + settings.motion_gap_s ||
                       change_s - stamps.front() < settings.min_motion_s + settings.motion_gap_s;
  const bool significant = test.p_value < settings.level;
  test.pending = significant && at_edge;
  test.detected = significant && !at_edge;
  char buffer[360];
  std::snprintf(buffer, sizeof(buffer),
                "%s: during the motion at %.2f s (camera clock), mounts %.2f deg apart, chi2 drop "
                "%.1f (dof %d, over %.2f x the noise: the recording's own segments), p %.2g "
                "(level %.2g, %d locations)%s",
                test.detected  ? "mount changed"
                : test.pending ? "mount change suspected"
                               : "one mount",
                change_s, test.change_deg, c.statistic, c.dof, c.scale, test.p_value,
                settings.level, static_cast<int>(locations),
                test.pending ? ": at the edge of the motion, waiting for more" : "");
  test.message = buffer;
  return test;
}

}  // namespace camera_imu_alignment
