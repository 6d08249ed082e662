// Rendered checkerboards: OpenCV's detector finds the inner corners within 0.1 px of the exact
// pinhole projection of the true corners (issue 3's criterion), at several viewpoints.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "camera_imu_alignment/simulation/target_renderer.h"

namespace camera_imu_alignment {
namespace simulation {
namespace {

/// Camera `distance_m` in front of the board centre, looking at it, tilted by (roll, pitch, yaw).
void viewpoint(const CheckerboardTarget& target, double distance_m, double roll, double pitch,
               double yaw, Eigen::Matrix3d* R_cam_target, Eigen::Vector3d* t_cam_target) {
  const Eigen::Vector3d centre((target.cols - 1) * target.col_spacing_m / 2,
                               (target.rows - 1) * target.row_spacing_m / 2, 0.0);
  const Eigen::Matrix3d R_target_cam = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                        Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                        Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                           .toRotationMatrix();
  const Eigen::Vector3d camera_position =
      centre - distance_m * R_target_cam.col(2);  // looks at centre
  *R_cam_target = R_target_cam.transpose();
  *t_cam_target = -*R_cam_target * camera_position;
}

TEST(TargetRenderer, DetectedCornersMatchTheTrueProjectionsToATenthOfAPixel) {
  const PinholeCamera camera;
  const CheckerboardTarget target;
  const std::vector<std::array<double, 4>> views = {
      {0.5, 0.0, 0.0, 0.1}, {0.45, 0.35, 0.0, -0.3}, {0.55, -0.2, 0.4, 0.8}, {0.6, 0.3, -0.3, 2.5}};
  for (const auto& view : views) {
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    viewpoint(target, view[0], view[1], view[2], view[3], &R, &t);
    const cv::Mat image = renderCheckerboard(camera, target, R, t, 6);
    std::vector<cv::Point2f> detected;
    ASSERT_TRUE(
        cv::findChessboardCorners(image, cv::Size(target.cols, target.rows), detected,
                                  cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE))
        << "view " << view[3];
    cv::cornerSubPix(image, detected, cv::Size(5, 5), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
    std::vector<Eigen::Vector2d> truth;
    for (const auto& p : target.corners()) {
      Eigen::Vector2d px;
      ASSERT_TRUE(camera.project(R * p + t, &px));
      truth.push_back(px);
    }
    ASSERT_EQ(detected.size(), truth.size());
    double worst = 0.0;
    for (const auto& d : detected) {  // order may be reversed by the detector: nearest true corner
      double best = 1e9;
      for (const auto& p : truth) best = std::min(best, (p - Eigen::Vector2d(d.x, d.y)).norm());
      worst = std::max(worst, best);
    }
    std::cout << "view yaw " << view[3] << ": worst corner error " << worst << " px\n";
    EXPECT_LT(worst, 0.1) << "view with yaw " << view[3];
  }
}

TEST(TargetRenderer, OffBoardIsBackgroundAndBorderIsWhite) {
  const CheckerboardTarget target;
  EXPECT_EQ(target.reflectance(-10.0, 0.0), -1.0);
  EXPECT_EQ(target.reflectance(-1.5 * target.col_spacing_m, 0.01), 1.0);  // border
  EXPECT_EQ(target.reflectance(0.5 * target.col_spacing_m, 0.5 * target.row_spacing_m), 0.0);
  EXPECT_EQ(target.reflectance(1.5 * target.col_spacing_m, 0.5 * target.row_spacing_m), 1.0);
  const PinholeCamera camera;
  Eigen::Vector2d px;
  EXPECT_FALSE(camera.project(Eigen::Vector3d(0, 0, -1), &px));
  ASSERT_TRUE(camera.project(Eigen::Vector3d(0, 0, 2), &px));
  EXPECT_EQ(px, Eigen::Vector2d(camera.cx, camera.cy));
}

}  // namespace
}  // namespace simulation
}  // namespace camera_imu_alignment
