// Planar calibration targets of the simulator: geometry, Kalibr target YAML and a high-resolution
// reflectance texture (exact area coverage per texel, so rendered corners are sub-pixel exact).
//
// Target frame (all types): z = 0 on the printed face, z out of the face towards the viewer,
// x along the columns, y along the rows ("up" on the print), metres.
//  - checkerboard: inner corner (r, c) at (c * s, r * s); squares of side s; (cols + 1) x (rows +
//  1)
//    squares, the square left-below corner (0, 0) is black.
//  - aprilgrid (Kalibr's layout): tag id = row * tagCols + col, lower-left corner at
//    (col, row) * (1 + tagSpacing) * tagSize; tag36h11 with a 2-bit black border inside tagSize,
//    black squares of side tagSpacing * tagSize at every tag corner; points in Kalibr's order
//    (2 tagRows x 2 tagCols grid, row-major from the lower left).
//  - circlegrid: circle (r, c) centred at (c * s, r * s) (asymmetric: ((2c + r % 2) * s, r * s)),
//    black discs of diameter s / 2 on white.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "camera_imu_alignment/simulation/sim_config.h"

namespace camera_imu_alignment {
namespace simulation {

/// Feature points in the target frame (m), in Kalibr's order for the type.
std::vector<Eigen::Vector3d> targetPoints(const TargetSpec& target);

/// Centre of the printed pattern in the target frame (m).
Eigen::Vector3d targetCentre(const TargetSpec& target);

/// The Kalibr target YAML text (doc/CONVENTIONS.md).
std::string targetYaml(const TargetSpec& target);

/// Reflectance texture of the printed board, white margin included.
struct TargetTexture {
  cv::Mat reflectance;   ///< CV_32F, 0 = black, 1 = white; row 0 is the top (largest y)
  double texel_m = 0.0;  ///< texel side (m)
  double x_min_m = 0.0;  ///< target x of the texture's left edge
  double y_max_m = 0.0;  ///< target y of the texture's top edge
  /// Texture coordinates (texel centres at integers) of a target-frame point (x, y).
  double col(double x) const { return (x - x_min_m) / texel_m - 0.5; }
  double row(double y) const { return (y_max_m - y) / texel_m - 0.5; }
};

/// Builds the texture at `texel_m` per texel. Throws std::runtime_error if it would exceed ~50 MB.
TargetTexture makeTargetTexture(const TargetSpec& target, double texel_m = 0.25e-3);

/// tag36h11 data bits of `id` (6x6, row-major from the top-left of an upright tag, 1 = white).
std::vector<int> tag36h11Bits(int id);

}  // namespace simulation
}  // namespace camera_imu_alignment
