// The report's figures (report_figures.h): the error to the truth, the reprojection error, the
// pairs' and the joint estimate's residuals and the mount offset per pose against independent
// computations on constructed inputs; then on simulated recordings run through the pipeline as
// calibrate_bag runs it (camera orientations given, no images rendered): a mount that moves
// halfway shows as a step in the mount offsets at the first pose after the move, of the move's
// size and direction, for the joint and the pair estimate alike; a mount that holds still shows
// none. The page with these figures and the truth is written at its size.
#include "camera_imu_alignment/io/report_figures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "camera_imu_alignment/io/calibration_report.h"
#include "camera_imu_alignment/solver/pose_window.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"
#include "report_inputs.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;
using test::axisAngle;
using test::randomRotation;
using test::realisticInput;

constexpr double kDeg = test::kPiTest / 180.0;

// ---------------------------------------------------------------------------------------------
// Against independent computations on constructed inputs
// ---------------------------------------------------------------------------------------------

TEST(ReportFigures, TruthErrorIsTheAngleToTheTruthWithPerAxisErrorsInSigmas) {
  std::mt19937_64 rng(21);
  const Eigen::Matrix3d R_cam_imu = randomRotation(rng);
  ReportInput in = realisticInput(rng, R_cam_imu, 8, 0.003);
  ASSERT_EQ(in.result.status, SolveStatus::kOk) << in.result.message;
  in.truth = KnownTruth{R_cam_imu, "rig.truth.yaml"};
  const ReportFigures figures = reportFigures(in);
  ASSERT_TRUE(figures.truth_error);
  const TruthError& e = *figures.truth_error;
  const Eigen::Matrix3d& R_est = in.result.R_cam_imu;
  // Independently: Eigen's angle-axis (test helpers), error = estimate relative to the truth.
  EXPECT_NEAR(e.angle_deg, test::angleBetweenDeg(R_est, R_cam_imu), 1e-9);
  const Eigen::Vector3d error_deg = test::leftError(R_est, R_cam_imu) * (180.0 / test::kPiTest);
  EXPECT_LE((e.error_deg - error_deg).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(e.error_deg.norm(), e.angle_deg, 1e-9);
  EXPECT_EQ(e.sigma_deg, in.result.quality.std_dev_deg);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(e.error_over_sigma(a), error_deg(a) / in.result.quality.std_dev_deg(a), 1e-9);
  }
  EXPECT_EQ(e.source, "rig.truth.yaml");

  // The summary prints it, as the angle rounded to 4 decimals, not beyond 3 sigma here.
  const std::string text = formatSummary(in);
  std::ostringstream angle;
  angle << std::fixed << std::setprecision(4) << test::angleBetweenDeg(R_est, R_cam_imu);
  EXPECT_NE(text.find("truth (rig.truth.yaml): error " + angle.str() + " deg"), std::string::npos)
      << text;
  EXPECT_LE(e.largestErrorInSigmas(), 3.0);
  EXPECT_EQ(text.find("beyond 3 sigma"), std::string::npos) << text;

  // A truth 1 deg away from the estimate is many sigmas off and said so.
  in.truth->R_cam_imu = axisAngle(Eigen::Vector3d::UnitX(), kDeg) * R_est;
  const TruthError far = *reportFigures(in).truth_error;
  EXPECT_NEAR(far.angle_deg, 1.0, 1e-9);
  EXPECT_NEAR(far.error_deg.x(), -1.0, 1e-9);  // the estimate is -1 deg about camera x from it
  EXPECT_GT(far.largestErrorInSigmas(), 3.0);
  EXPECT_NE(formatSummary(in).find("(beyond 3 sigma)"), std::string::npos);
}

TEST(ReportFigures, ReprojectionAndFramesPerPoseAreThePosesOwnInOrder) {
  std::mt19937_64 rng(22);
  const ReportInput in = realisticInput(rng, randomRotation(rng), 7, 0.002);
  const ReportFigures figures = reportFigures(in);
  ASSERT_EQ(figures.poses.size(), in.poses.size());
  EXPECT_EQ(figures.window_poses, in.poses.size());  // inferred from the pairs
  const std::string text = formatSummary(in);
  for (std::size_t i = 0; i < in.poses.size(); ++i) {
    const PoseFigure& f = figures.poses[i];
    EXPECT_EQ(f.index, in.poses[i].index);
    EXPECT_EQ(f.reprojection_rms_px, in.poses[i].reprojection_rms_px);
    EXPECT_EQ(f.num_frames, in.poses[i].num_frames);
    EXPECT_NEAR(f.time_s, 0.5 * (in.poses[i].start_s + in.poses[i].end_s) - in.start_s, 1e-9);
    EXPECT_TRUE(f.in_window);
    EXPECT_TRUE(std::isnan(f.joint_residual_sigma));  // no joint estimate here
    std::ostringstream reprojection;
    reprojection << std::fixed << std::setprecision(3) << in.poses[i].reprojection_rms_px;
    std::ostringstream pose_line;
    pose_line << "  pose " << std::setw(3) << in.poses[i].index;
    const std::size_t at = text.find(pose_line.str());
    ASSERT_NE(at, std::string::npos) << pose_line.str() << "\n" << text;
    const std::string line = text.substr(at, text.find('\n', at) - at);
    EXPECT_NE(line.find("reprojection " + reprojection.str()), std::string::npos) << line;
  }
}

TEST(ReportFigures, PairResidualsPerPoseAreTheRmsOfItsPairsInTheWindowOnly) {
  std::mt19937_64 rng(23);
  ReportInput in = realisticInput(rng, randomRotation(rng), 9, 0.004);
  // Three older poses before the window: the pairs (and their indices) are the window's alone.
  std::vector<StationaryPose> older(3, in.poses.front());
  for (int k = 0; k < 3; ++k) older[k].index = k;
  for (StationaryPose& p : in.poses) p.index += 3;
  in.poses.insert(in.poses.begin(), older.begin(), older.end());
  in.window_poses = 9;
  const ReportFigures figures = reportFigures(in);
  ASSERT_EQ(figures.poses.size(), 12u);
  EXPECT_EQ(figures.window_poses, 9u);
  const Eigen::Matrix3d& X = in.result.R_cam_imu;
  for (int k = 0; k < 12; ++k) {
    const PoseFigure& f = figures.poses[k];
    EXPECT_EQ(f.index, k);
    if (k < 3) {
      EXPECT_FALSE(f.in_window);
      EXPECT_TRUE(std::isnan(f.pair_residual_rms_deg));
      continue;
    }
    EXPECT_TRUE(f.in_window);
    // Independently: the residual angle is the angle between A X and X B.
    double sum_sq = 0.0;
    int count = 0;
    for (const RotationPair& p : in.pairs) {
      if (p.pose_k != k - 3 && p.pose_t != k - 3) continue;
      const double r = test::angleBetweenDeg(p.A_cam * X, X * p.B_imu);
      sum_sq += r * r;
      ++count;
    }
    ASSERT_EQ(count, 8);
    EXPECT_NEAR(f.pair_residual_rms_deg, std::sqrt(sum_sq / count), 1e-7) << "pose " << k;
  }
  EXPECT_NE(formatSummary(in).find("(not in the window)"), std::string::npos);
}

TEST(ReportFigures, MountOffsetsAreZeroForConsistentPosesInEveryGroupAndFollowTheMountPerPose) {
  std::mt19937_64 rng(24);
  const Eigen::Matrix3d R_cam_imu = randomRotation(rng);
  const Eigen::Vector3d moved_by(0.02, -0.15, 0.05);  // rad, camera axes: a remount at pose 12
  ReportInput in;
  std::vector<PoseOrientation> orientations;
  for (int k = 0; k < 24; ++k) {
    const int group = k % 2;  // two worlds with unrelated headings, never paired with each other
    const Eigen::Matrix3d R_target_world =
        group == 0 ? Eigen::Matrix3d::Identity() : axisAngle(Eigen::Vector3d(1, 2, 3), 2.0);
    const Eigen::Matrix3d mount =
        k < 12 ? R_cam_imu : Eigen::Matrix3d(test::rotationFromVector(moved_by) * R_cam_imu);
    StationaryPose pose;
    pose.index = k;
    pose.group = group;
    pose.R_world_imu = randomRotation(rng);
    pose.R_target_cam = R_target_world * pose.R_world_imu * mount.transpose();
    in.poses.push_back(pose);
    orientations.push_back({10.0 * k, pose.R_target_cam, pose.R_world_imu, group});
  }
  in.pairs = makeAllPairs(orientations);
  in.window_poses = 24;
  in.result.status = SolveStatus::kOk;

  // The first twelve poses alone (no remount) and the estimate exact: every offset is zero.
  ReportInput still = in;
  still.poses.resize(12);
  still.window_poses = 12;
  still.result.R_cam_imu = R_cam_imu;
  for (const PoseFigure& f : reportFigures(still).poses) {
    EXPECT_LE(f.mount_offset_deg.norm(), 1e-9) << "pose " << f.index;
  }
  // All poses, estimate = the first mount: the moved poses are offset by about the move (the
  // target's orientation in each world is fitted to all poses of the group, moved ones included,
  // which the varied orientations average out).
  in.result.R_cam_imu = R_cam_imu;
  const ReportFigures figures = reportFigures(in);
  const Eigen::Vector3d moved_deg = moved_by * (180.0 / test::kPiTest);
  Eigen::Vector3d before = Eigen::Vector3d::Zero(), after = Eigen::Vector3d::Zero();
  for (const PoseFigure& f : figures.poses) {
    (f.index < 12 ? before : after) += f.mount_offset_deg / 12.0;
  }
  EXPECT_LE((after - before - moved_deg).norm(), 0.25 * moved_deg.norm())
      << (after - before).transpose() << " vs " << moved_deg.transpose();
}

TEST(ReportFigures, JointResidualsPerPoseComeFromTheJointEstimateOfTheWindow) {
  std::mt19937_64 rng(25);
  ReportInput in = realisticInput(rng, randomRotation(rng), 6, 0.002);
  JointResult joint;
  joint.ok = true;
  joint.R_cam_imu = in.result.R_cam_imu;
  joint.pose_residual_norm = {0.5, 0.9, 1.2, 7.5, 0.8, 1.1};
  joint.chi2 = 153.0;
  joint.dof = 150;
  joint.chi2_p_value = 0.42;
  joint.ok = true;
  in.result.joint = joint;
  const ReportFigures figures = reportFigures(in);
  ASSERT_EQ(figures.poses.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(figures.poses[k].joint_residual_sigma, joint.pose_residual_norm[k]);
  }
  EXPECT_EQ(jointConsistencyText(joint),
            "chi2/dof 1.02 (150 dof, p 0.420; residuals 1.01x their noise, good: consistent)");
  joint.chi2_p_value = 0.001;
  joint.consistency_level = 0.01;  // the level the gate judged it at (consistency_level)
  // Failed by the test but within kConsistentMisfitRatio of the noise: the effect size decides.
  EXPECT_EQ(jointConsistencyText(joint),
            "chi2/dof 1.02 (150 dof, p 0.001; residuals 1.01x their noise, good: consistent)");
  joint.chi2 = 300.0;
  joint.chi2_p_value = 1e-12;
  EXPECT_EQ(jointConsistencyText(joint),
            "chi2/dof 2.00 (150 dof, p 0.000; residuals 1.41x their noise, fair: INCONSISTENT)");
  // A joint estimate over another number of poses than the window is not matched to poses.
  in.result.joint->pose_residual_norm.pop_back();
  in.window_poses = 6;
  for (const PoseFigure& f : reportFigures(in).poses) {
    EXPECT_TRUE(std::isnan(f.joint_residual_sigma));
  }
}

// ---------------------------------------------------------------------------------------------
// Simulated recordings through the pipeline
// ---------------------------------------------------------------------------------------------

struct Recording {
  std::unique_ptr<sim::SimulationRun> run;
  ReportInput report;
};

/// `scenario` simulated with `seed` and run through a pipeline; the report input filled as
/// calibrate_bag fills it, with the simulated final mount as the truth.
Recording record(const std::string& scenario, int seed, ImuOrientationSource source) {
  sim::SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(sim::applyScenario(scenario, &c)) << scenario;
  c.camera_rate_hz = 1.0;  // frames are given by the harness, not rendered
  Recording out;
  out.run = std::make_unique<sim::SimulationRun>(c);
  PipelineSettings settings;
  settings.imu_orientation = source;
  const auto pipeline = test::feedWithoutImages(*out.run, settings, 0.03, false, 100 + seed);
  ReportInput& in = out.report;
  in.result = test::solveFinalWindow(*pipeline);
  in.poses = pipeline->poses();
  in.rejected = pipeline->rejectedPoses();
  in.segments = pipeline->segments();
  in.rejections = pipeline->rejections();
  in.pairs = pipeline->windowPairs();
  in.window_poses = pipeline->windowSize();
  in.start_s = 0.0;
  in.end_s = out.run->trajectory.duration();
  in.source = scenario + " seed " + std::to_string(seed);
  in.truth = KnownTruth{out.run->trajectory.R_cam_imu_final(), "simulated truth"};
  return out;
}

/// Index (into poses) of the first pose whose rest starts after `time_s`; poses.size() if none.
std::size_t firstPoseAfter(const std::vector<StationaryPose>& poses, double time_s) {
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (poses[i].start_s > time_s) return i;
  }
  return poses.size();
}

Eigen::Vector3d meanOffset(const std::vector<PoseFigure>& poses, std::size_t from, std::size_t to) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = from; i < to; ++i) sum += poses[i].mount_offset_deg;
  return sum / static_cast<double>(to - from);
}

/// The step: the largest change of the mount offset between consecutive poses is at the first
/// pose after the remount, and the halves' means differ by the remount rotation (camera axes).
void expectStepAtTheRemount(const Recording& r, const std::string& what) {
  const sim::Trajectory& truth = r.run->trajectory;
  ASSERT_TRUE(truth.remount());
  const ReportFigures figures = reportFigures(r.report);
  const std::vector<PoseFigure>& poses = figures.poses;
  ASSERT_EQ(poses.size(), truth.poses().size()) << what << ": every rest became a pose";
  ASSERT_EQ(figures.window_poses, poses.size()) << what;
  const std::size_t moved = firstPoseAfter(r.report.poses, truth.remountTime());
  ASSERT_GT(moved, 1u);
  ASSERT_LT(moved + 1, poses.size());

  std::size_t largest_jump_at = 0;
  double largest_jump_deg = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    ASSERT_TRUE(poses[i].mount_offset_deg.allFinite()) << what << " pose " << i;
    const double jump = (poses[i].mount_offset_deg - poses[i - 1].mount_offset_deg).norm();
    if (jump > largest_jump_deg) {
      largest_jump_deg = jump;
      largest_jump_at = i;
    }
  }
  EXPECT_EQ(largest_jump_at, moved) << what << ": the step is at pose " << poses[moved].index;
  EXPECT_EQ(poses[moved].index, r.report.poses[moved].index);
  const Eigen::Vector3d remount_deg = rad2deg(1.0) * r.run->config.remount_rotvec_cam;
  const Eigen::Vector3d step_deg =
      meanOffset(poses, moved, poses.size()) - meanOffset(poses, 0, moved);
  EXPECT_LE((step_deg - remount_deg).norm(), 1.5)
      << what << ": step " << step_deg.transpose() << " deg, remount " << remount_deg.transpose();
}

TEST(ReportFigures, RemountHalfwayIsAStepAtTheFirstMovedPoseWithTheJointEstimate) {
  for (int seed : {1, 2}) {
    const Recording r = record("remount", seed, ImuOrientationSource::kJoint);
    ASSERT_TRUE(r.report.result.joint && r.report.result.joint->ok);
    expectStepAtTheRemount(r, "joint, seed " + std::to_string(seed));
  }
}

TEST(ReportFigures, RemountHalfwayIsAStepAtTheFirstMovedPoseWithThePairEstimate) {
  const Recording r = record("remount", 3, ImuOrientationSource::kAuto);
  ASSERT_FALSE(r.report.result.joint);
  expectStepAtTheRemount(r, "pairs, seed 3");
  // The per-pair residuals do not show it: every pose has as many pairs across the remount.
  const ReportFigures figures = reportFigures(r.report);
  double lowest = HUGE_VAL, highest = 0.0;
  for (const PoseFigure& f : figures.poses) {
    lowest = std::min(lowest, f.pair_residual_rms_deg);
    highest = std::max(highest, f.pair_residual_rms_deg);
  }
  EXPECT_GT(lowest, 3.0);
  EXPECT_LT(highest, 2.0 * lowest);
}

TEST(ReportFigures, AMountThatHoldsStillHasNoStepAndSmallResiduals) {
  const Recording r = record("nominal", 4, ImuOrientationSource::kJoint);
  ASSERT_EQ(r.report.result.status, SolveStatus::kOk) << r.report.result.message;
  const ReportFigures figures = reportFigures(r.report);
  ASSERT_EQ(figures.poses.size(), r.run->trajectory.poses().size());
  for (const PoseFigure& f : figures.poses) {
    EXPECT_LT(f.mount_offset_deg.norm(), 0.3) << "pose " << f.index;
    EXPECT_LT(f.pair_residual_rms_deg, 0.5) << "pose " << f.index;
    EXPECT_LT(f.joint_residual_sigma, 4.0) << "pose " << f.index;
    EXPECT_TRUE(f.in_window);
  }
  ASSERT_TRUE(figures.truth_error);
  EXPECT_LT(figures.truth_error->angle_deg, 0.2);
}

TEST(ReportFigures, RemountPageIsWrittenAtItsSizeWithTheTruthError) {
  Recording r = record("remount", 1, ImuOrientationSource::kJoint);
  r.report.verdict = ReportVerdict{false, "FAILED: remount at pose 8"};
  const ReportFigures figures = reportFigures(r.report);
  ASSERT_TRUE(figures.truth_error);
  // Independent of the library: Eigen's angle-axis of R_est^T R_true.
  const Eigen::Matrix3d& R_est = r.report.result.R_cam_imu;
  const Eigen::Matrix3d R_true = r.run->trajectory.R_cam_imu_final();
  EXPECT_NEAR(figures.truth_error->angle_deg, test::angleBetweenDeg(R_est, R_true), 1e-9);
  EXPECT_GT(figures.truth_error->angle_deg, 2.0);  // the estimate mixes both mounts
  const std::string path = test::processTempDir() + "remount_report.png";
  std::string error;
  ASSERT_TRUE(writeReportPng(path, r.report, &error)) << error;
  const cv::Mat page = cv::imread(path);
  ASSERT_FALSE(page.empty());
  EXPECT_EQ(page.cols, kReportWidthPx);
  EXPECT_EQ(page.rows, kReportHeightPx);
  if (const char* keep = std::getenv("CIA_KEEP_REPORT")) cv::imwrite(keep, page);  // to look at
}

}  // namespace
}  // namespace camera_imu_alignment
