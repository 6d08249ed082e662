// The online calibrator's settings (online/online_calibrator.h says what it does with them):
// quality gates, change detection and capture. Their keys, ranges and defaults are one table
// (config/online_config.h); config/default.yaml documents every key; the one check of a struct is
// findProblem (config/online_config.h, config/settings_checks.h).
#pragma once

#include "camera_imu_alignment/estimation/joint_result.h"
#include "camera_imu_alignment/estimation/mount_change.h"

namespace camera_imu_alignment {

/// Quality gates, change detection and capture policy (config/default.yaml documents each key).
struct OnlineSettings {
  int min_poses = 3;  ///< stationary poses in the window before anything is broadcast
  /// A recording without enough poses (continuous motion) stands in for min_poses with this
  /// much motion in the window (s, the motion frames' intervals summed) that turned the camera at
  /// least min_motion_rotation_deg about each of its axes: a first broadcast from a few seconds of
  /// motion would rest on noise the recording has not yet shown (its 1-sigma too).
  double min_motion_s = 15.0;
  double min_motion_rotation_deg = 180.0;
  /// Largest 1-sigma (deg) of a broadcast estimate: the joint estimate's own covariance, scaled
  /// by chi2/dof when the residuals exceed their noise.
  double max_std_dev_deg = 0.5;
  /// Chi-square test of the joint estimate: its p-value must be at least this (probability of
  /// refusing a correct estimate); a smaller p means the data do not fit one mount with the
  /// modelled noise.
  double consistency_level = kDefaultConsistencyLevel;
  /// Pair modes only (imu_orientation auto or message; the joint modes have the chi-square test):
  /// the RMS pair residual (deg) a broadcast estimate may have.
  double max_residual_deg = 1.0;
  double min_change_deg = 0.01;  ///< re-broadcast only when the estimate moved more (deg)
  bool manual_capture = false;   ///< poses only from rests during which capture was armed
  /// Change-point test of the joint estimate (remount_level, remount_max_poses_after, ...).
  MountChangeSettings remount;
  /// Pair modes only: this many consecutive new poses whose pairs disagree with the broadcast
  /// estimate by more than remount_residual_deg (RMS) restart the window from them.
  int remount_poses = 3;
  double remount_residual_deg = 1.5;
  /// Solve on a worker thread (the nodelet); false: on the caller's thread (tests).
  bool threaded = true;
  /// With threaded (calibrate_bag): every window requested is solved, none skipped, while the
  /// input goes on, and its result is applied when the next solve is requested (or at finish(),
  /// waitForSolves(), calibrateNow()), not whenever it finishes: the results and verdicts do not
  /// depend on the threads' timing. False (the nodelet): the newest window waiting replaces older
  /// ones and results are applied as they finish.
  bool solves_in_order = false;
  /// Continuous motion: a window is solved after every 100 new camera frames during motion (5 s
  /// at 20 Hz; the nodelet, whose worker skips windows when it is busy). True (calibrate_bag, which
  /// reads faster than real time): after as many new frames as the window had at its last solve
  /// (and at least 100), so that the solves of a growing window cost about twice its last one, not
  /// in proportion to its square. Set by the tool, not a parameter.
  bool motion_solves_double = false;
};

}  // namespace camera_imu_alignment
