// Renders a planar calibration target through an exact pinhole projection, for the simulator.
// Camera frame: optical (z forward, x right, y down). Target frame: the target plane is z = 0; the
// first inner corner of a checkerboard is at the origin, x along its columns, y along its rows
// (Kalibr's layout for `targetCols` x `targetRows` inner corners).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace camera_imu_alignment {
namespace simulation {

/// Pinhole camera without distortion (plumb_bob distortion: not yet rendered).
struct PinholeCamera {
  int width = 640;
  int height = 480;
  double fx = 520.0, fy = 520.0;  ///< focal lengths (px)
  double cx = 319.5, cy = 239.5;  ///< principal point (px), pixel centres at integer coordinates

  /// Pixel of a point in the camera frame; false behind the camera.
  bool project(const Eigen::Vector3d& p_cam, Eigen::Vector2d* pixel) const;
};

/// Kalibr checkerboard: targetCols x targetRows inner corners, squares of rowSpacingMeters x
/// colSpacingMeters, a white border of one square around the (cols + 1) x (rows + 1) squares.
struct CheckerboardTarget {
  int cols = 7;                 ///< inner corners along x (Kalibr targetCols)
  int rows = 6;                 ///< inner corners along y (Kalibr targetRows)
  double col_spacing_m = 0.04;  ///< square size along x
  double row_spacing_m = 0.04;  ///< square size along y

  /// Inner corner (row r, column c) in the target frame.
  Eigen::Vector3d corner(int r, int c) const;
  /// All inner corners, row by row.
  std::vector<Eigen::Vector3d> corners() const;
  /// Reflectance in [0, 1] at (x, y) on the target plane; -1 off the board (background).
  double reflectance(double x, double y) const;
};

/// Renders the target seen from a camera at pose (R_cam_target, t_cam_target):
/// p_cam = R_cam_target * p_target + t_cam_target. Each pixel averages supersample^2 sub-pixel
/// rays (exact area sampling of the edges); background grey. Returns mono8.
cv::Mat renderCheckerboard(const PinholeCamera& camera, const CheckerboardTarget& target,
                           const Eigen::Matrix3d& R_cam_target, const Eigen::Vector3d& t_cam_target,
                           int supersample = 4);

}  // namespace simulation
}  // namespace camera_imu_alignment
