// The calibrator's broadcast policy (judgeEstimate): quality gates (pair residual for pair modes,
// chi-square consistency for the joint estimate), no silent regression (by 1-sigma and pose
// count, unless the difference to the broadcast estimate is significant), change threshold.
// ROS-free.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "camera_imu_alignment/online/broadcast_gate.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

AlignmentResult goodResult(double sigma_deg,
                           const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  AlignmentResult r;
  r.status = SolveStatus::kOk;
  r.R_cam_imu = R;
  r.quality.residual_rms_deg = 0.1;
  r.quality.std_dev_deg = Eigen::Vector3d(0.5 * sigma_deg, sigma_deg, 0.7 * sigma_deg);
  return r;
}

/// A joint estimate with isotropic 1-sigma and the given chi-square p-value.
AlignmentResult jointResult(double sigma_deg, const Eigen::Matrix3d& R, double p_value) {
  AlignmentResult r = goodResult(sigma_deg, R);
  r.quality.std_dev_deg = Eigen::Vector3d::Constant(sigma_deg);
  r.quality.residual_rms_deg = 3.0;  // the pair residual: not a gate for the joint estimate
  JointResult joint;
  joint.ok = true;
  joint.R_cam_imu = R;
  joint.covariance_rad2 = std::pow(deg2rad(sigma_deg), 2) * Eigen::Matrix3d::Identity();
  joint.chi2 = 50;
  joint.dof = 50;
  joint.chi2_p_value = p_value;
  r.joint = joint;
  return r;
}

BroadcastEstimate broadcastOf(const AlignmentResult& r, int poses) {
  BroadcastEstimate b;
  b.R_cam_imu = r.R_cam_imu;
  b.std_dev_deg = r.quality.std_dev_deg;
  if (r.joint) b.covariance_rad2 = r.joint->covariance_rad2;
  b.poses = poses;
  b.source = "estimated";
  return b;
}

Eigen::Matrix3d turned(double deg) { return expSO3(Eigen::Vector3d(0, 0, deg2rad(deg))); }

TEST(BroadcastGate, QualityGatesInOrder) {
  const OnlineSettings s;  // min_poses 3, max_residual 1 deg, max_std_dev 0.5 deg
  EXPECT_EQ(judgeEstimate(goodResult(0.05), 3, s, std::nullopt, false).decision,
            GateDecision::kBroadcast);
  AlignmentResult not_observable = goodResult(0.05);
  not_observable.status = SolveStatus::kNotObservable;
  not_observable.message = "not observable: rotate about camera x";
  const GateOutcome o = judgeEstimate(not_observable, 10, s, std::nullopt, false);
  EXPECT_EQ(o.decision, GateDecision::kReject);
  EXPECT_NE(o.why.find("camera x"), std::string::npos);
  EXPECT_NE(judgeEstimate(goodResult(0.05), 2, s, std::nullopt, false).why.find("min_poses"),
            std::string::npos);
  AlignmentResult noisy = goodResult(0.05);
  noisy.quality.residual_rms_deg = 1.5;
  EXPECT_NE(judgeEstimate(noisy, 5, s, std::nullopt, false).why.find("max_residual_deg"),
            std::string::npos);
  EXPECT_NE(judgeEstimate(goodResult(0.6), 5, s, std::nullopt, false).why.find("max_std_dev_deg"),
            std::string::npos);
  AlignmentResult nan = goodResult(0.05);
  nan.quality.std_dev_deg(1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(judgeEstimate(nan, 5, s, std::nullopt, false).decision, GateDecision::kReject);
}

TEST(BroadcastGate, JointEstimateJudgedByChiSquareNotByThePairResidual) {
  const OnlineSettings s;  // consistency_level 1e-3
  // A large pair residual (a consumer gyro chain) does not matter for a consistent joint estimate.
  EXPECT_EQ(judgeEstimate(jointResult(0.05, turned(0), 0.3), 10, s, std::nullopt, false).decision,
            GateDecision::kBroadcast);
  // An inconsistent one (the test fails and the residuals are 1.41x their noise) is refused,
  // naming the effect size, the test and the parameter.
  AlignmentResult misfit = jointResult(0.05, turned(0), 1e-5);
  misfit.joint->chi2 = 100;
  const GateOutcome inconsistent = judgeEstimate(misfit, 10, s, std::nullopt, false);
  EXPECT_EQ(inconsistent.decision, GateDecision::kReject);
  EXPECT_NE(inconsistent.why.find("consistency_level"), std::string::npos) << inconsistent.why;
  EXPECT_NE(inconsistent.why.find("1.41x their measured noise (fair"), std::string::npos)
      << inconsistent.why;
  // With thousands of degrees of freedom the test rejects a misfit that moves nothing (5 %
  // over the noise): the p-value alone does not fail the estimate.
  AlignmentResult large = jointResult(0.05, turned(0), 1e-9);
  large.joint->dof = 5000;
  large.joint->chi2 = 5000 * 1.1;
  EXPECT_EQ(judgeEstimate(large, 10, s, std::nullopt, false).decision, GateDecision::kBroadcast);
  large.joint->chi2 = 5000 * 1.5;  // 1.22x: beyond the band
  EXPECT_EQ(judgeEstimate(large, 10, s, std::nullopt, false).decision, GateDecision::kReject);
  AlignmentResult failed = jointResult(0.05, turned(0), 0.3);
  failed.joint->ok = false;
  failed.joint->message = "the solver failed";
  EXPECT_NE(judgeEstimate(failed, 10, s, std::nullopt, false).why.find("joint estimate failed"),
            std::string::npos);
}

TEST(BroadcastGate, MotionStandsInForPosesOnlyWhenItIsLongAndTurnsEveryAxis) {
  const OnlineSettings s;  // min_motion_s 15, min_motion_rotation_deg 180
  AlignmentResult motion = jointResult(0.05, turned(0), 0.3);
  motion.joint->motion_nodes = 60;
  motion.joint->motion.excitation_duration_s = 6.0;  // a few seconds of waving
  motion.joint->motion.excitation_rad = Eigen::Vector3d::Constant(deg2rad(300.0));
  const GateOutcome short_motion = judgeEstimate(motion, 0, s, std::nullopt, false);
  EXPECT_EQ(short_motion.decision, GateDecision::kReject);
  EXPECT_FALSE(short_motion.enough_data);
  EXPECT_NE(short_motion.why.find("min_motion_s 15"), std::string::npos) << short_motion.why;
  motion.joint->motion.excitation_duration_s = 20.0;
  motion.joint->motion.excitation_rad(1) = deg2rad(100.0);  // camera y barely turned
  const GateOutcome one_axis_short = judgeEstimate(motion, 0, s, std::nullopt, false);
  EXPECT_EQ(one_axis_short.decision, GateDecision::kReject);
  EXPECT_NE(one_axis_short.why.find("min_motion_rotation_deg 180"), std::string::npos);
  motion.joint->motion.excitation_rad(1) = deg2rad(200.0);
  const GateOutcome enough = judgeEstimate(motion, 0, s, std::nullopt, false);
  EXPECT_EQ(enough.decision, GateDecision::kBroadcast) << enough.why;
  EXPECT_TRUE(enough.enough_data);
}

TEST(BroadcastGate, NoSilentRegressionUnlessMorePosesOrADifferentMount) {
  const OnlineSettings s;
  const BroadcastEstimate published = broadcastOf(jointResult(0.05, turned(0.0), 0.5), 10);
  // Less precise, from no more poses, not significantly different: kept back ...
  const GateOutcome worse =
      judgeEstimate(jointResult(0.08, turned(0.1), 0.5), 10, s, published, false);
  EXPECT_EQ(worse.decision, GateDecision::kKeep);
  EXPECT_NE(worse.why.find("regression"), std::string::npos) << worse.why;
  // ... but more poses of the same mount never lose to fewer ...
  EXPECT_EQ(judgeEstimate(jointResult(0.08, turned(0.1), 0.5), 11, s, published, false).decision,
            GateDecision::kBroadcast);
  // ... nor after a remount or reset (fresh start) ...
  EXPECT_EQ(judgeEstimate(jointResult(0.08, turned(10.0), 0.5), 3, s, published, true).decision,
            GateDecision::kBroadcast);
  // ... nor when it differs from the broadcast one by far more than both 1-sigmas allow (2 deg
  // against 0.05 and 0.08 deg: the mount moved while nothing watched).
  EXPECT_EQ(judgeEstimate(jointResult(0.08, turned(2.0), 0.5), 5, s, published, false).decision,
            GateDecision::kBroadcast);
  // At least as precise and moved: broadcast.
  EXPECT_EQ(judgeEstimate(jointResult(0.04, turned(0.2), 0.5), 10, s, published, false).decision,
            GateDecision::kBroadcast);
  // A calibration loaded from a file without a 1-sigma: any good estimate replaces it.
  BroadcastEstimate loaded;
  loaded.source = "loaded: x.yaml";
  EXPECT_EQ(judgeEstimate(goodResult(0.3, turned(0.2)), 3, s, loaded, false).decision,
            GateDecision::kBroadcast);
}

// Recordings without rests have no poses to count: the camera orientations during motion count
// instead (an estimate from more motion was kept back as "from 0 poses" against "0").
TEST(BroadcastGate, NoSilentRegressionCountsTheMotionWithoutRests) {
  OnlineSettings s;
  s.min_motion_s = 0.0;
  s.min_motion_rotation_deg = 0.0;
  const auto motionResult = [](double sigma_deg, double turn_deg, int nodes) {
    AlignmentResult r = jointResult(sigma_deg, turned(turn_deg), 0.5);
    r.joint->motion_nodes = nodes;
    r.joint->motion.excitation_duration_s = 30.0;
    r.joint->motion.excitation_rad = Eigen::Vector3d::Constant(10.0);
    return r;
  };
  BroadcastEstimate published = broadcastOf(motionResult(0.05, 0.0, 200), 0);
  published.result = motionResult(0.05, 0.0, 200);
  const GateOutcome less = judgeEstimate(motionResult(0.06, 0.1, 150), 0, s, published, false);
  EXPECT_EQ(less.decision, GateDecision::kKeep);
  EXPECT_NE(less.why.find("from 150 camera orientations during motion is larger than the "
                          "broadcast estimate's 0.05 deg from 200 camera orientations"),
            std::string::npos)
      << less.why;
  EXPECT_EQ(less.why.find("0 poses"), std::string::npos) << less.why;
  EXPECT_EQ(judgeEstimate(motionResult(0.06, 0.1, 300), 0, s, published, false).decision,
            GateDecision::kBroadcast);
}

TEST(BroadcastGate, DifferenceSignificance) {
  const BroadcastEstimate published = broadcastOf(jointResult(0.05, turned(0.0), 0.5), 10);
  // 0.05 deg apart with 1-sigma 0.05 each: chi2 = 0.05^2 / (2 x 0.05^2) = 0.5 -> p ~ 0.92.
  EXPECT_NEAR(differenceSignificance(jointResult(0.05, turned(0.05), 0.5), published), 0.919,
              0.005);
  EXPECT_LT(differenceSignificance(jointResult(0.05, turned(1.0), 0.5), published), 1e-10);
  BroadcastEstimate unknown;
  EXPECT_EQ(differenceSignificance(jointResult(0.05, turned(1.0), 0.5), unknown), 1.0);
}

TEST(BroadcastGate, ChangesBelowTheThresholdKeepTheTf) {
  OnlineSettings s;
  s.min_change_deg = 0.05;
  const BroadcastEstimate published = broadcastOf(goodResult(0.05, turned(0.0)), 10);
  EXPECT_EQ(judgeEstimate(goodResult(0.04, turned(0.03)), 10, s, published, false).decision,
            GateDecision::kKeep);
  EXPECT_EQ(judgeEstimate(goodResult(0.04, turned(0.08)), 10, s, published, false).decision,
            GateDecision::kBroadcast);
}

// The check of a current calibration: the difference in degrees and in sigmas under both
// covariances (analytic: 0.1 deg about z with 1-sigma 0.03 deg on each side is 0.1 / sqrt(2 *
// 0.03^2) = 2.357 sigma, chi2 5.56 on 3 dof, p 0.135).
TEST(BroadcastGate, CheckOfACurrentCalibrationInDegreesAndSigmas) {
  const AlignmentResult estimate = jointResult(0.03, turned(0.1), 0.5);
  const BroadcastEstimate current = broadcastOf(jointResult(0.03, turned(0.0), 0.5), 12);
  const auto check = checkCalibration(estimate, current, 1e-3);
  ASSERT_TRUE(check);
  EXPECT_NEAR(check->error_deg, 0.1, 1e-9);
  EXPECT_NEAR(check->sigmas, 0.1 / std::sqrt(2.0 * 0.03 * 0.03), 1e-6);
  EXPECT_NEAR(check->chi2, check->sigmas * check->sigmas, 1e-9);
  EXPECT_NEAR(check->p_value, 0.1353, 1e-3);
  EXPECT_TRUE(check->consistent);
  EXPECT_FALSE(checkCalibration(estimate, current, 0.2)->consistent);
  // A calibration 1 deg off is tens of sigma away.
  const auto far = checkCalibration(jointResult(0.03, turned(1.0), 0.5), current, 1e-3);
  ASSERT_TRUE(far);
  EXPECT_FALSE(far->consistent);
  EXPECT_GT(far->sigmas, 20.0);
  EXPECT_NE(far->text.find("recalibrate"), std::string::npos) << far->text;
  // No joint estimate (pair modes): no check.
  EXPECT_FALSE(checkCalibration(goodResult(0.03), current, 1e-3));
}

// The warning about a broadcast tf the latest estimate disagrees with (analytic: 1-sigma 0.03 deg
// on each side, so 1 sigma of the difference is 0.0424 deg): 0.15 deg is 3.54 sigma, consistent at
// the default consistency_level 0.001 (4.0 sigma) yet warned; 0.12 deg (2.83 sigma) is not; the
// broadcast estimate itself, or no check, never.
TEST(BroadcastGate, ABroadcastBeyondThreeSigmaOfTheLatestEstimateIsWarnedAbout) {
  const BroadcastEstimate current = broadcastOf(jointResult(0.03, turned(0.0), 0.5), 12);
  const auto far = checkCalibration(jointResult(0.03, turned(0.15), 0.5), current, 1e-3);
  ASSERT_TRUE(far);
  EXPECT_TRUE(far->consistent);
  EXPECT_NEAR(far->sigmas, 0.15 / std::sqrt(2.0 * 0.03 * 0.03), 1e-6);
  const std::string warning = broadcastWarning(far, false, "min_change_deg 0.5: 0.15 deg");
  EXPECT_NE(warning.find("0.15 deg (3.5 sigma)"), std::string::npos) << warning;
  EXPECT_NE(warning.find("min_change_deg 0.5"), std::string::npos) << warning;
  EXPECT_EQ(broadcastWarning(far, true, "x"), "");  // the tf is the latest estimate
  const auto near = checkCalibration(jointResult(0.03, turned(0.12), 0.5), current, 1e-3);
  ASSERT_TRUE(near);
  EXPECT_LT(near->sigmas, kBroadcastWarningSigmas);
  EXPECT_EQ(broadcastWarning(near, false, "x"), "");
  // Inconsistent at a stricter level than 3 sigma: warned too.
  const auto strict = checkCalibration(jointResult(0.03, turned(0.12), 0.5), current, 0.05);
  ASSERT_TRUE(strict);
  EXPECT_FALSE(strict->consistent);
  EXPECT_NE(broadcastWarning(strict, false, ""), "");
  EXPECT_EQ(broadcastWarning(std::nullopt, false, "x"), "");
}

// Which camera axes the motion has not turned about enough (min_motion_rotation_deg), in words.
TEST(BroadcastGate, TheAxesTheMotionHasNotTurnedAboutAreNamed) {
  OnlineSettings settings;
  settings.min_motion_rotation_deg = 180.0;
  MotionFigures m;
  m.excitation_rad = Eigen::Vector3d(deg2rad(400), deg2rad(250), deg2rad(30));
  EXPECT_EQ(unexcitedAxes(m, settings), "camera z");
  m.excitation_rad = Eigen::Vector3d(deg2rad(10), deg2rad(250), deg2rad(30));
  EXPECT_EQ(unexcitedAxes(m, settings), "camera x and camera z");
  m.excitation_rad = Eigen::Vector3d::Zero();
  EXPECT_EQ(unexcitedAxes(m, settings), "camera x, camera y and camera z");
  m.excitation_rad = Eigen::Vector3d::Constant(deg2rad(180.0));
  EXPECT_EQ(unexcitedAxes(m, settings), "");
  m.excitation_rad(1) = std::nan("");
  EXPECT_EQ(unexcitedAxes(m, settings), "camera y");
}

}  // namespace
}  // namespace camera_imu_alignment
