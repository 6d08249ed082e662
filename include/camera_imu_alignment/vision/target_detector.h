// Finds a calibration target in a grey image (the camera pose from it: vision/camera_pose.h).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/vision/camera_model.h"
#include "camera_imu_alignment/vision/target_description.h"

namespace camera_imu_alignment {

/// Detected feature points: image_points[i] (pixels, distorted, OpenCV convention: pixel (0, 0)
/// centred on (0, 0)) is target point point_ids[i] (TargetDescription::point index).
struct TargetObservation {
  std::vector<cv::Point2f> image_points;
  std::vector<int> point_ids;
  /// Set when the target was not found but a board of another size was ("a checkerboard with 8 x
  /// 6 inner corners is in view; the target file describes 7 x 6"); "" otherwise.
  std::string mismatch;
};

struct DetectorSettings {
  int min_points = 16;   ///< fewer points found: not detected (aprilgrid: >= 4 tags)
  bool subpixel = true;  ///< checkerboard corner refinement
};

/// Detects one target type in mono8 images. Checkerboard: cv::findChessboardCorners with a fast
/// rejection, then findChessboardCornersSB (blurred or oblique views; allowed to find a larger
/// board, so that a target file smaller than the board fails in well under a second and says so,
/// where the classic detector's adaptive search took seconds per frame) + cornerSubPix,
/// corners re-ordered so that index 0 is always the target origin (the 180-degree ambiguity is
/// resolved by the square colours where the board allows it, otherwise by the orientation closest
/// to `hint`); AprilGrid: tag36h11 via OpenCV aruco, Kalibr's layout, partial views allowed; circle
/// grid: cv::findCirclesGrid (symmetric/asymmetric).
class TargetDetector {
 public:
  explicit TargetDetector(const TargetDescription& target, const DetectorSettings& settings = {});
  ~TargetDetector();
  /// Detects the target in `mono8` (CV_8UC1). Returns false when not found. `R_target_cam_hint`
  /// (optional) is a recent camera orientation used to resolve symmetric boards. `near_points`
  /// (optional; pixels) are the target's image points in a recent frame: a checkerboard is looked
  /// for first in the box around them, grown by kSearchBoxMargin of their extent on each side,
  /// then (not found there) in the whole image. The corners are refined in the whole image either
  /// way: only the cost differs (the classic detector's search grows with the pixels searched).
  bool detect(const cv::Mat& mono8, TargetObservation* observation,
              const Eigen::Matrix3d* R_target_cam_hint = nullptr,
              const std::vector<cv::Point2f>* near_points = nullptr) const;
  /// The margin of the search box around `near_points` (fraction of their extent per side).
  static constexpr double kSearchBoxMargin = 0.15;
  const TargetDescription& target() const { return target_; }
  /// Rotations S of the target frame (about its z axis, through the board centre; identity
  /// excluded) under which this detector cannot tell the board from itself: the camera
  /// orientation of a detection may be S * R_target_cam_true. A checkerboard with an even number
  /// of inner corners along both axes looks the same turned by 180 degrees; a square grid also
  /// turned by 90. AprilGrids have none (every tag has an id). The hint resolves these only while
  /// the camera turns less than 90 degrees between hints; CalibrationPipeline checks each pose
  /// against the IMU's rotation angle.
  std::vector<Eigen::Matrix3d> symmetries() const;

 private:
  bool detectAprilGrid(const cv::Mat& mono8, TargetObservation* observation) const;

  struct Impl;
  TargetDescription target_;
  DetectorSettings settings_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace camera_imu_alignment
