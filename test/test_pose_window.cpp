// Pose window and the pairs it forms.
#include <gtest/gtest.h>

#include "camera_imu_alignment/alignment_solver.h"
#include "camera_imu_alignment/pose_window.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

std::vector<PoseOrientation> exactPoses(std::mt19937_64& rng, const Eigen::Matrix3d& X, int count) {
  const Eigen::Matrix3d C = test::randomRotation(rng);  // R_target_world, arbitrary
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

TEST(PoseWindow, KeepsTheMostRecentPoses) {
  std::mt19937_64 rng(41);
  PoseWindow window(5);
  for (const auto& p : exactPoses(rng, test::randomRotation(rng), 8)) EXPECT_TRUE(window.add(p));
  ASSERT_EQ(window.size(), 5u);
  EXPECT_EQ(window.poses().front().stamp_s, 3.0);
  EXPECT_EQ(window.poses().back().stamp_s, 7.0);
  window.clear();
  EXPECT_EQ(window.size(), 0u);
  EXPECT_TRUE(window.makePairs().empty());
}

TEST(PoseWindow, RejectsNonRotationsAndKeepsWhatItHad) {
  std::mt19937_64 rng(42);
  PoseWindow window(10);
  const auto poses = exactPoses(rng, test::randomRotation(rng), 3);
  for (const auto& p : poses) window.add(p);
  PoseOrientation nan_pose = poses[0];
  nan_pose.R_target_cam(0, 0) = std::nan("");
  EXPECT_FALSE(window.add(nan_pose));
  PoseOrientation scaled = poses[0];
  scaled.R_world_imu *= 1.1;
  EXPECT_FALSE(window.add(scaled));
  EXPECT_EQ(window.size(), 3u);
}

TEST(PoseWindow, FormsAllPairsWithTheConventionsRelativeRotations) {
  std::mt19937_64 rng(43);
  const Eigen::Matrix3d X = test::randomRotation(rng);
  const auto poses = exactPoses(rng, X, 7);
  PoseWindow window(7);
  for (const auto& p : poses) window.add(p);
  const RotationPairs pairs = window.makePairs();
  ASSERT_EQ(pairs.size(), 21u);
  for (const auto& pair : pairs) {
    ASSERT_LT(pair.pose_k, pair.pose_t);
    const auto& k = poses[pair.pose_k];
    const auto& t = poses[pair.pose_t];
    EXPECT_LT((pair.A_cam - k.R_target_cam.transpose() * t.R_target_cam).norm(), 1e-15);
    EXPECT_LT((pair.B_imu - k.R_world_imu.transpose() * t.R_world_imu).norm(), 1e-15);
    EXPECT_LT((pair.A_cam * X - X * pair.B_imu).norm(), 1e-12);  // A X = X B
  }
  const AlignmentResult r = solveAlignment(pairs);
  ASSERT_EQ(r.status, SolveStatus::kOk) << r.message;
  EXPECT_LT(test::angleBetweenDeg(r.R_cam_imu, X), 1e-9);
}

}  // namespace
}  // namespace camera_imu_alignment
