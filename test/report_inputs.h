// Report inputs for the report tests (test_calibration_report, test_report_figures): a realistic
// recording built from known orientations and a degenerate one, and pixel counts of the page.
#pragma once

#include <Eigen/Geometry>
#include <limits>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "camera_imu_alignment/io/calibration_summary.h"
#include "camera_imu_alignment/solver/alignment_solver.h"
#include "camera_imu_alignment/solver/pose_window.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace test {

/// A recording of `num_poses` rests 10 s apart: camera and IMU orientations consistent with
/// R_cam_imu (plus small noise), all pairs formed from them and solved; one rest rejected.
inline ReportInput realisticInput(std::mt19937_64& rng, const Eigen::Matrix3d& R_cam_imu,
                                  int num_poses, double noise_rad) {
  ReportInput in;
  in.start_s = 1000.0;
  in.end_s = 1000.0 + 10.0 * (num_poses + 2);
  in.source = "/data/rig.bag";
  std::vector<PoseOrientation> orientations;
  const Eigen::Matrix3d R_target_world = randomRotation(rng);  // unknown in practice; cancels
  for (int k = 0; k < num_poses; ++k) {
    const Eigen::Matrix3d R_world_imu = randomRotation(rng);
    PoseOrientation o;
    o.stamp_s = in.start_s + 5.0 + 10.0 * k;
    o.R_world_imu = R_world_imu * test::rotationFromVector(test::gaussianVector(rng, noise_rad));
    o.R_target_cam = R_target_world * R_world_imu * R_cam_imu.transpose() *
                     test::rotationFromVector(test::gaussianVector(rng, noise_rad));
    orientations.push_back(o);
    StationaryPose pose;
    pose.index = k;
    pose.start_s = o.stamp_s - 2.0;
    pose.end_s = o.stamp_s + 2.0;
    pose.R_target_cam = o.R_target_cam;
    pose.R_world_imu = o.R_world_imu;
    pose.num_frames = 3 + k;
    pose.reprojection_rms_px = 0.1 + 0.07 * k;  // distinct per pose
    in.poses.push_back(pose);
    StationarySegment segment;
    segment.start_s = pose.start_s - 0.5;
    segment.end_s = pose.end_s + 0.5;
    in.segments.push_back(segment);
  }
  RejectedPose rejected;
  rejected.start_s = in.start_s + 5.0 + 10.0 * num_poses - 3.0;
  rejected.end_s = rejected.start_s + 6.0;
  rejected.reason = "target seen in 1 frame (2 needed)";
  in.rejected.push_back(rejected);
  in.segments.push_back({});
  in.segments.back().start_s = rejected.start_s;
  in.segments.back().end_s = rejected.end_s;
  in.rejections.add(RejectReason::kTargetNotFound, 7);
  in.rejections.add(RejectReason::kStampBackwards);
  in.pairs = makeAllPairs(orientations);
  in.result = solveAlignment(in.pairs);
  return in;
}

/// Everything empty or NaN, start_s == end_s.
inline ReportInput degenerateInput() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ReportInput in;
  in.start_s = in.end_s = 42.0;
  SolutionQuality& q = in.result.quality;
  q.residual_rms_deg = nan;
  q.observability = nan;
  q.weakest_excitation_deg = nan;
  q.std_dev_deg = Eigen::Vector3d::Constant(nan);
  q.weak_axis_cam = Eigen::Vector3d::Constant(nan);
  q.excite_axis_cam = Eigen::Vector3d::Constant(nan);
  q.covariance_rad2 = Eigen::Matrix3d::Constant(nan);
  PairDiagnostics p;
  p.residual_deg = nan;
  q.pairs = {p, p};
  q.num_pairs = 2;
  in.pairs = {RotationPair{}, RotationPair{}};  // zero rotations: no axis
  in.pairs[1].A_cam = Eigen::Matrix3d::Constant(nan);
  in.segments.push_back({});
  in.segments.back().start_s = nan;
  in.segments.push_back({});
  in.segments.back().start_s = -std::numeric_limits<double>::infinity();
  in.segments.back().end_s = std::numeric_limits<double>::infinity();
  in.rejected.push_back({nan, 42.0, ""});
  StationaryPose reversed;
  reversed.start_s = 50.0;
  reversed.end_s = 10.0;
  in.poses.push_back(reversed);
  return in;
}

/// Count of pixels equal to `bgr`.
inline int countColour(const cv::Mat& img, const cv::Vec3b& bgr) {
  int n = 0;
  for (int r = 0; r < img.rows; ++r) {
    for (int c = 0; c < img.cols; ++c) n += img.at<cv::Vec3b>(r, c) == bgr;
  }
  return n;
}

/// Pixels of a red hue (anti-aliased red text included).
inline int countReddish(const cv::Mat& img) {
  int n = 0;
  for (int r = 0; r < img.rows; ++r) {
    for (int c = 0; c < img.cols; ++c) {
      const cv::Vec3b& p = img.at<cv::Vec3b>(r, c);
      n += p[2] > 150 && p[1] < 120 && p[0] < 120;
    }
  }
  return n;
}

}  // namespace test
}  // namespace camera_imu_alignment
