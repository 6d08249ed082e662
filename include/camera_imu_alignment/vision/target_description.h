// Planar calibration targets as described by Kalibr's target YAML files (doc/CONVENTIONS.md),
// and the 3-D positions of their feature points in the target frame.
//
// Target frame: z = 0 on the printed face, metres; the point order and origin follow Kalibr:
//  - checkerboard: inner corner (r, c), r < targetRows, c < targetCols, at
//    (c * colSpacingMeters, r * rowSpacingMeters, 0); index r * targetCols + c.
//  - aprilgrid (tag36h11): tag id = row * tagCols + col; tag lower-left corner at
//    (col, row) * tagSize * (1 + tagSpacing); each tag contributes its 4 corners, and the points of
//    the grid are indexed as Kalibr's: point (2 * row + i, 2 * col + j), i, j in {0, 1}, over a
//    (2 tagRows) x (2 tagCols) grid, row-major from the lower left.
//  - circlegrid: circle (r, c) centred at (c * s, r * s), asymmetric: ((2 c + r % 2) * s, r * s).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace camera_imu_alignment {

struct TargetDescription {
  enum class Type { kCheckerboard, kAprilGrid, kCircleGrid };
  Type type = Type::kCheckerboard;
  int cols = 0;                ///< targetCols (inner corners / circles) or tagCols
  int rows = 0;                ///< targetRows or tagRows
  double row_spacing_m = 0.0;  ///< checkerboard rowSpacingMeters; circlegrid spacingMeters
  double col_spacing_m = 0.0;  ///< checkerboard colSpacingMeters; circlegrid spacingMeters
  double tag_size_m = 0.0;     ///< aprilgrid tagSize
  double tag_spacing = 0.0;    ///< aprilgrid tagSpacing (ratio of tagSize)
  bool asymmetric = false;     ///< circlegrid asymmetricGrid

  /// Number of feature points (checkerboard corners, 4 x tags, circles).
  int numPoints() const;
  /// Position of point `index` in the target frame (m), index as above.
  Eigen::Vector3d point(int index) const;
  /// "checkerboard 8x6, 0.04 m" etc.
  std::string describe() const;
};

/// Parses a Kalibr target YAML file. Throws InputError ("file: key 'targetCols' missing", ...) on
/// a missing file, an unknown target_type, a missing key or a non-positive size.
TargetDescription loadTargetYaml(const std::string& path);
/// Same from YAML text; `source` names it in messages.
TargetDescription parseTargetYaml(const std::string& text, const std::string& source);

}  // namespace camera_imu_alignment
