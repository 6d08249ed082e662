// The pipeline's window of stationary poses and the pairs it forms (doc/CONVENTIONS.md: A =
// R_target_cam_k^T R_target_cam_t, B = R_world_imu_k^T R_world_imu_t, A X = X B with X =
// R_cam_imu).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>

#include "camera_imu_alignment/pipeline/stationary_window.h"
#include "camera_imu_alignment/solver/alignment_solver.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

/// Noise-free poses of a rig with R_cam_imu = X: R_target_cam_k = C R_world_imu_k X^T for a fixed,
/// arbitrary C = R_target_world.
std::vector<PoseOrientation> exactPoses(std::mt19937_64& rng, const Eigen::Matrix3d& X, int count) {
  const Eigen::Matrix3d C = test::randomRotation(rng);
  std::vector<PoseOrientation> poses;
  for (int k = 0; k < count; ++k) {
    PoseOrientation p;
    p.stamp_s = k;
    p.R_world_imu = test::randomRotation(rng);
    p.R_target_cam = C * p.R_world_imu * X.transpose();
    poses.push_back(p);
  }
  return poses;
}

/// A window entry whose pose has `o`'s orientations, its stamp as a zero-length rest and the
/// index `index`.
StationaryWindow::Entry entryOf(const PoseOrientation& o, int index = 0) {
  StationaryWindow::Entry e;
  e.pose.index = index;
  e.pose.start_s = e.pose.end_s = o.stamp_s;
  e.pose.R_target_cam = o.R_target_cam;
  e.pose.R_world_imu = o.R_world_imu;
  e.pose.group = o.group;
  e.joint.R_target_cam = o.R_target_cam;
  e.joint.group = o.group;
  return e;
}

TEST(StationaryWindow, KeepsTheMostRecentPoses) {
  std::mt19937_64 rng(41);
  StationaryWindow window(5);
  EXPECT_EQ(window.maxPoses(), 5u);
  const auto poses = exactPoses(rng, test::randomRotation(rng), 8);
  for (size_t k = 0; k < poses.size(); ++k) {
    EXPECT_TRUE(window.add(entryOf(poses[k], static_cast<int>(k))));
    EXPECT_EQ(window.size(), std::min<size_t>(k + 1, 5));
    EXPECT_EQ(window.orientations().back().stamp_s, poses[k].stamp_s);
  }
  ASSERT_EQ(window.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(window.orientations()[i].stamp_s, poses[i + 3].stamp_s);
    EXPECT_EQ(window.orientations()[i].R_target_cam, poses[i + 3].R_target_cam);
    EXPECT_EQ(window.orientations()[i].R_world_imu, poses[i + 3].R_world_imu);
  }
  window.clear();
  EXPECT_EQ(window.size(), 0u);
  EXPECT_TRUE(window.pairs().empty());
}

TEST(StationaryWindow, RejectsNonRotationsAndKeepsWhatItHad) {
  std::mt19937_64 rng(42);
  StationaryWindow window(3);
  const auto poses = exactPoses(rng, test::randomRotation(rng), 3);
  for (const auto& p : poses) ASSERT_TRUE(window.add(entryOf(p)));
  std::vector<PoseOrientation> bad(6, poses[0]);
  bad[0].R_target_cam(0, 0) = std::nan("");
  bad[1].R_world_imu(2, 1) = INFINITY;
  bad[2].R_world_imu *= 1.1;                     // scaled
  bad[3].R_target_cam *= 0.9;                    // scaled
  bad[4].R_target_cam = -poses[0].R_target_cam;  // det -1
  bad[5].R_world_imu = Eigen::Matrix3d::Zero();  // not a rotation at all
  for (size_t i = 0; i < bad.size(); ++i) {
    EXPECT_FALSE(window.add(entryOf(bad[i]))) << i;
    // The window is full: a rejected pose must not push the oldest out either.
    ASSERT_EQ(window.size(), 3u) << i;
    for (size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(window.orientations()[k].stamp_s, poses[k].stamp_s);
      EXPECT_EQ(window.orientations()[k].R_target_cam, poses[k].R_target_cam);
      EXPECT_EQ(window.orientations()[k].R_world_imu, poses[k].R_world_imu);
    }
  }
  EXPECT_EQ(window.pairs().size(), 3u);
}

TEST(StationaryWindow, FormsAllPairsWithTheConventionsRelativeRotations) {
  std::mt19937_64 rng(43);
  const Eigen::Matrix3d X = test::randomRotation(rng);
  for (int P : {0, 1, 2, 3, 7}) {
    const auto poses = exactPoses(rng, X, P);
    StationaryWindow window(10);
    for (const auto& p : poses) ASSERT_TRUE(window.add(entryOf(p)));
    const RotationPairs pairs = window.pairs();
    ASSERT_EQ(pairs.size(), static_cast<size_t>(P * (P - 1) / 2)) << P;
    std::set<std::pair<int, int>> seen;
    for (const auto& pair : pairs) {
      ASSERT_GE(pair.pose_k, 0);
      ASSERT_LT(pair.pose_k, pair.pose_t);
      ASSERT_LT(pair.pose_t, P);
      EXPECT_TRUE(seen.insert({pair.pose_k, pair.pose_t}).second) << "duplicate pair";
      const auto& k = poses[pair.pose_k];
      const auto& t = poses[pair.pose_t];
      EXPECT_LT((pair.A_cam - k.R_target_cam.transpose() * t.R_target_cam).norm(), 1e-13);
      EXPECT_LT((pair.B_imu - k.R_world_imu.transpose() * t.R_world_imu).norm(), 1e-13);
      EXPECT_LT((pair.A_cam * X - X * pair.B_imu).norm(), 1e-12);  // A X = X B
    }
    // makeAllPairs over the same poses gives the same pairs.
    const RotationPairs direct = makeAllPairs(poses);
    ASSERT_EQ(direct.size(), pairs.size());
    for (size_t j = 0; j < pairs.size(); ++j) {
      EXPECT_EQ(direct[j].pose_k, pairs[j].pose_k);
      EXPECT_EQ(direct[j].pose_t, pairs[j].pose_t);
      EXPECT_EQ(direct[j].A_cam, pairs[j].A_cam);
      EXPECT_EQ(direct[j].B_imu, pairs[j].B_imu);
    }
  }
}

TEST(StationaryWindow, PosesOfDifferentGroupsAreNeverPaired) {
  // Two groups whose IMU world frames differ by an unknown heading: pairs across them would be
  // wrong, pairs within each are exact.
  std::mt19937_64 rng(47);
  const Eigen::Matrix3d X = test::randomRotation(rng);
  auto poses = exactPoses(rng, X, 6);
  const Eigen::Matrix3d heading = test::axisAngle(Eigen::Vector3d::UnitZ(), 1.0);
  for (int k = 3; k < 6; ++k) {
    poses[k].group = 1;
    poses[k].R_world_imu = heading * poses[k].R_world_imu;
  }
  const RotationPairs pairs = makeAllPairs(poses);
  ASSERT_EQ(pairs.size(), 6u);  // 3 + 3, none of the 9 across
  for (const auto& pair : pairs) {
    EXPECT_EQ(poses[pair.pose_k].group, poses[pair.pose_t].group);
    EXPECT_LT((pair.A_cam * X - X * pair.B_imu).norm(), 1e-12);
  }
  const PairSolveResult result = solveAlignment(pairs);
  EXPECT_LT(test::angleBetweenDeg(result.R_cam_imu, X), 1e-6);
}

TEST(StationaryWindow, PairIndicesReferToTheWindowAfterOldPosesLeft) {
  std::mt19937_64 rng(44);
  const Eigen::Matrix3d X = test::randomRotation(rng);
  const auto poses = exactPoses(rng, X, 9);
  StationaryWindow window(4);
  for (const auto& p : poses) window.add(entryOf(p));
  const RotationPairs pairs = window.pairs();
  ASSERT_EQ(pairs.size(), 6u);
  for (const auto& pair : pairs) {
    ASSERT_LT(pair.pose_t, 4);
    const auto& k = poses[5 + pair.pose_k];  // the window holds poses 5..8
    const auto& t = poses[5 + pair.pose_t];
    EXPECT_LT((pair.A_cam - k.R_target_cam.transpose() * t.R_target_cam).norm(), 1e-13);
    EXPECT_LT((pair.B_imu - k.R_world_imu.transpose() * t.R_world_imu).norm(), 1e-13);
  }
}

TEST(StationaryWindow, NoiseFreePosesAreSolvedExactly) {
  std::mt19937_64 rng(45);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Matrix3d X = test::randomRotation(rng);
    StationaryWindow window(8);
    for (const auto& p : exactPoses(rng, X, 8)) ASSERT_TRUE(window.add(entryOf(p)));
    const RotationPairs pairs = window.pairs();
    ASSERT_EQ(pairs.size(), 28u);
    const PairSolveResult r = solveAlignment(pairs);
    ASSERT_EQ(r.status, SolveStatus::kOk) << r.message;
    EXPECT_LT(test::angleBetweenDeg(r.R_cam_imu, X), 1e-9) << "trial " << trial;
    EXPECT_TRUE(r.quality.observable);
    EXPECT_EQ(r.quality.num_pairs, 28);
    EXPECT_EQ(r.quality.num_inliers, 28);
  }
}

TEST(StationaryWindow, KeepsFromAPoseIndexAndGivesBothEstimatorsTheSamePoses) {
  std::mt19937_64 rng(45);
  const auto poses = exactPoses(rng, test::randomRotation(rng), 6);
  StationaryWindow window(10);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    StationaryWindow::Entry e = entryOf(poses[k], static_cast<int>(k) + 10);
    if (k > 0) e.gyro_from_previous = GyroSegment{0, 0, {0.0, 0.5}, {}};
    if (k > 0) e.gyro_from_previous->gyro_rad_s.assign(2, Eigen::Vector3d::Zero());
    ASSERT_TRUE(window.add(e));
  }
  window.keepFrom(12);  // pose indices 12..15 stay
  ASSERT_EQ(window.size(), 4u);
  EXPECT_EQ(window.poses().front().index, 12);
  const JointProblem problem = window.problem();
  ASSERT_EQ(problem.poses.size(), window.size());
  for (std::size_t i = 0; i < window.size(); ++i) {
    EXPECT_EQ(problem.poses[i].R_target_cam, window.poses()[i].R_target_cam);
  }
  // The gyro from before the window's first pose is not used; the three between its poses are.
  ASSERT_EQ(problem.segments.size(), 3u);
  EXPECT_EQ(problem.segments.front().from_pose, 0);
  EXPECT_EQ(window.pairs().size(), 6u);
  window.keepFrom(100);
  EXPECT_EQ(window.size(), 0u);
}

}  // namespace
}  // namespace camera_imu_alignment
