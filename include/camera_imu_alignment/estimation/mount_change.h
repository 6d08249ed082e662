// Change-point test for the camera-IMU mount: is the window better explained by two mounts, the
// later poses from some pose s on with an R_cam_imu of their own, than by one?
//
// For each candidate s (the newest poses only: a change is looked for as the poses after it
// arrive) the joint estimator solves the two-mount model (JointProblem::mount_change_pose = s:
// a second R_cam_imu for poses s.., the IMU's parameters shared, the gyro motion into pose s
// the IMU's turn from the first mount to the second). The statistic is the drop of the chi-square,
//   D(s) = chi2(one mount) - chi2(two mounts, split at s),
// which without a change is chi-square distributed with dof(one) - dof(two) = 3 degrees of
// freedom (the second rotation). The gyro motion into pose s was once left out (3 more dof): it
// then left the second mount's rotation about the vertical to a weak prior where the poses after
// turn about the vertical only and no magnetometer is used. Both fits have the same model of
// T_g and T_a: the one-mount estimate's, except that where its model selection held them at
// identity (ImuMatrixModel::kSelect) both are fitted with them estimated, since a window that
// mixes two mounts can make the selection drop matrices the unit needs. It is judged as an F
// statistic,
//   F = (D / dof_D) / max(1, chi2_two / dof_two),
// so that a unit whose noise the priors understate (chi2/dof > 1) does not read as a remount; the
// p-value is Bonferroni-corrected for the number of candidates. A candidate counts only when the
// two-mount model fits every pose: no pose's RMS whitened residual (JointResult::
// pose_residual_norm) above max(1.5, 2.5 x the median pose's). A pose that is merely bad leaves
// a pose unfitted however large D is.
//
// The camera's noise as the recording shows it (JointSettings::camera_excess_level): real PnP's
// errors beyond its stated covariance on every pose (ViSP's real images: 0.31 deg per axis) would
// read as a remount of the newest poses. Both fits of a candidate get the excess the one-mount
// estimate measured on the whole window when the poses before the candidate show an excess of
// their own (their chi-square test at 0.05, with the model of T_g and T_a the one-mount estimate
// selected); otherwise they are compared at the stated noise: fitted with one mount, a remount's
// misfit spreads over the whole window and would pass for noise.
//
// Where the change is: the candidate with the largest D that fits every pose is the
// maximum-likelihood split (first_pose_after). Candidates run up to the newest pose; those with
// fewer than min_poses_after poses after them compete for the location but are never declared.
// Without them, a change before the newest pose was taken for one a pose earlier on noisy units:
// the split one pose early, with an old-mount pose and the new one under the second mount, was
// the best candidate on offer and its misfit spread over the shared IMU parameters (their wide
// priors) instead of showing at one pose. Neighbouring splits can fit nearly equally well; the
// window restarts from the latest candidate whose chi-square is within the chi-square(1) 95 %
// quantile (times the best fit's chi2/dof when above 1) of the best (first_pose_kept): dropping a
// new-mount pose costs a pose, keeping an old-mount pose biases the new estimate. A change is
// declared when the corrected p-value of the best candidate is below `level` and that restart
// candidate has min_poses_after poses after it; with fewer, it is `pending` (the next pose
// decides; meanwhile nothing of the window should be broadcast).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {

struct MountChangeSettings {
  /// False-alarm probability per test (one test per new pose): corrected p-value below it = change.
  double level = 1e-4;
  /// Poses needed after a split (2: one pose after a split is indistinguishable from a bad pose).
  int min_poses_after = 2;
  /// The newest this many poses are candidate first poses of a new mount (bounds the solves).
  int max_poses_after = 4;
  /// Poses needed before a split.
  int min_poses_before = 2;
  /// Continuous motion (testMountChangeOnMotion): motion needed on each side of a split (s), and
  /// the motion left out around it (s), where the mount moved. Not setting keys.
  double min_motion_s = 3.0;
  double motion_gap_s = 1.0;
};

/// One candidate split.
struct MountChangeCandidate {
  int first_pose_after = 0;  ///< index into JointProblem::poses
  double statistic = 0;      ///< D = chi2(one) - chi2(two)
  int dof = 0;               ///< dof_D
  double p_value = 1;        ///< of F, not corrected
  double scale = 1;          ///< max(1, chi2 / dof) of the two-mount fit
  /// Camera variance added to every rest (rad^2 per axis) in both fits: the one-mount estimate's
  /// camera_excess_variance_rad2 when the poses before the split show an excess, else 0.
  double camera_excess_variance_rad2 = 0;
  /// At least min_poses_after poses after it: can be declared (else it competes for the location).
  bool declarable = false;
  double change_deg = 0;  ///< angle between the two mounts' R_cam_imu
  bool solved = false;    ///< the two-mount solve succeeded
  /// The camera's measurements determine the mounts well enough to test it: the mount before it
  /// over-determined by that side's own (3 residuals per absolute orientation, 2 per relative
  /// rotation within the side; more than 3), the one after a declarable split by its own and the
  /// rotations across it (3 each). False: not solved (two natural-scene rests with one rotation
  /// between them would take a wrong rotation for a mount of their own).
  bool camera_overdetermined = true;
  /// Worst pose residual over max(1.5, 2.5 x median) in the two-mount solve; <= 1: fits every pose.
  double worst_pose_misfit = 0;
  bool fits_every_pose = false;
};

struct MountChangeTest {
  bool tested = false;    ///< enough poses and a usable one-mount estimate
  bool detected = false;  ///< a change at `first_pose_after`: restart from `first_pose_kept`
  /// A significant change whose restart candidate has fewer than min_poses_after poses after it:
  /// not declared yet; the window mixes mounts (or its newest pose is bad).
  bool pending = false;
  int first_pose_after = -1;  ///< the maximum-likelihood split (index into JointProblem::poses)
  /// The latest split as likely as it: the first pose a restarted window keeps (>= the above).
  int first_pose_kept = -1;
  double p_value = 1;  ///< Bonferroni-corrected, of the best candidate
  double change_deg = 0;
  /// Both mounts' estimates at the maximum-likelihood split.
  Eigen::Matrix3d R_cam_imu_before = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_cam_imu_after = Eigen::Matrix3d::Identity();
  std::vector<MountChangeCandidate> candidates;
  std::string message;  ///< one line: what was found
  /// The change during continuous motion (testMountChangeOnMotion; camera clock, s): the middle
  /// of the motion left out; the new mount's data start motion_gap_s / 2 after it. NaN: a change
  /// between rests (first_pose_after) or none.
  double change_stamp_s = std::numeric_limits<double>::quiet_NaN();
  /// testMountChangeOnMotion: how much more the recording's own unchanged segments differ than
  /// their 1-sigma says (>= 1; 1 when not measured), the least scale its F statistic is judged
  /// at: measured when the test is significant against the noise alone.
  double segment_scatter = 1.0;
};

/// Tests `problem` (its mount_change_pose ignored) against `one_mount`, the joint estimate of
/// the same problem with one mount (must be ok; with camera links, screened as
/// solveScreeningCameraLinks does, camera_link_screening.h). With camera links (the natural
/// scene) every two-mount fit screens them on its own, and the chi-square values compared are
/// trimmed: a link left out counts at the outlier level (trimmedChi2, trimmedDof).
MountChangeTest testMountChange(const JointProblem& problem, const JointResult& one_mount,
                                const JointSettings& joint_settings,
                                const MountChangeSettings& settings);

/// The change test on continuous motion, for a window with too few rests for the rest test
/// (testMountChange calls it then). Where: the one-mount estimate's motion nodes carry a camera
/// correction (MotionFigures::node_camera_residual_rad) that steps where the mount moved (the one
/// fit splits the difference between the mounts); the split maximising the between-sides
/// statistic m (N - m) / N |mean_before - mean_after|^2, with min_motion_s of motion each side,
/// locates it. Whether: the motion within motion_gap_s around it is left out and the one-mount
/// and two-mount fits (JointProblem::mount_change_stamp_s) compared as in testMountChange (F
/// statistic, p Bonferroni-corrected for the window's possible locations, one per gap width). A
/// A change significant against the noise alone is judged again with the scale raised to the
/// recording's own segment scatter (MountChangeTest::segment_scatter: each side's two halves
/// solved alone, under the noise learned, against their covariances): a remount must explain the
/// data better than an unchanged recording's segments differ from each other. A
/// significant change within min_motion_s + motion_gap_s of either end of the motion is pending:
/// a change in the newest seconds is located at the latest split allowed, before where it was.
MountChangeTest testMountChangeOnMotion(const JointProblem& problem, const JointResult& one_mount,
                                        const JointSettings& joint_settings,
                                        const MountChangeSettings& settings);

/// P(F > f) for an F(d1, d2) distribution (1 when an argument is not usable).
double fisherUpperTail(double f, int d1, int d2);

}  // namespace camera_imu_alignment
