// The nodelet's broadcast policy (judgeEstimate): quality gates, no silent regression, change
// threshold. ROS-free: no roscore needed.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>

#include "camera_imu_alignment/ros/broadcast_gate.h"
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

Eigen::Matrix3d turned(double deg) { return expSO3(Eigen::Vector3d(0, 0, deg2rad(deg))); }

TEST(BroadcastGate, QualityGatesInOrder) {
  const WrapperSettings s;  // min_poses 3, max_residual 1 deg, max_std_dev 0.5 deg
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

TEST(BroadcastGate, NoSilentRegressionUnlessTheMountChanged) {
  const WrapperSettings s;
  const PublishedEstimate published{turned(0.0), 0.05};
  // Less precise than what is broadcast: kept back ...
  const GateOutcome worse = judgeEstimate(goodResult(0.08, turned(0.2)), 10, s, published, false);
  EXPECT_EQ(worse.decision, GateDecision::kKeep);
  EXPECT_NE(worse.why.find("regression"), std::string::npos) << worse.why;
  // ... unless the remount test restarted the window: then the old estimate is wrong.
  EXPECT_EQ(judgeEstimate(goodResult(0.08, turned(10.0)), 3, s, published, true).decision,
            GateDecision::kBroadcast);
  // At least as precise and moved: broadcast.
  EXPECT_EQ(judgeEstimate(goodResult(0.04, turned(0.2)), 10, s, published, false).decision,
            GateDecision::kBroadcast);
  // A calibration loaded from a file has no known sigma: any good estimate replaces it.
  const PublishedEstimate loaded{turned(0.0), std::numeric_limits<double>::infinity()};
  EXPECT_EQ(judgeEstimate(goodResult(0.3, turned(0.2)), 3, s, loaded, false).decision,
            GateDecision::kBroadcast);
}

TEST(BroadcastGate, ChangesBelowTheThresholdKeepTheTf) {
  WrapperSettings s;
  s.min_change_deg = 0.05;
  const PublishedEstimate published{turned(0.0), 0.05};
  EXPECT_EQ(judgeEstimate(goodResult(0.04, turned(0.03)), 10, s, published, false).decision,
            GateDecision::kKeep);
  EXPECT_EQ(judgeEstimate(goodResult(0.04, turned(0.08)), 10, s, published, false).decision,
            GateDecision::kBroadcast);
}

}  // namespace
}  // namespace camera_imu_alignment
