// Robust average of a set of rotations (e.g. the camera orientations of the frames of one
// stationary segment).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace camera_imu_alignment {

struct RotationAverage {
  Eigen::Matrix3d mean = Eigen::Matrix3d::Identity();
  double spread_rms_deg = 0.0;  ///< RMS geodesic distance of the inliers to the mean
  double spread_max_deg = 0.0;  ///< largest geodesic distance of an inlier to the mean
  int num_inliers = 0;
  int num_outliers = 0;
};

/// Geodesic L1 mean (Weiszfeld on SO(3), started from the medoid input) followed by the L2 mean
/// of the rotations within `outlier_deg` of it. Empty input gives num_inliers = 0.
RotationAverage averageRotations(const std::vector<Eigen::Matrix3d>& rotations,
                                 double outlier_deg = 2.0);

}  // namespace camera_imu_alignment
