// The one-page PNG report of a calibration run (the text summary: calibration_summary.h).
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "camera_imu_alignment/io/calibration_summary.h"

namespace camera_imu_alignment {

/// Size of the page (px).
inline constexpr int kReportWidthPx = 1200, kReportHeightPx = 1640;

/// One-page report (CV_8UC3, kReportWidthPx x kReportHeightPx): (a) per-pair residuals (inliers /
/// outliers), (b) the coverage of rotation axes in the camera frame (which axes were excited),
/// (c) the stationary segments over time (poses used, rejected rests with reasons), (d) per pose
/// in recording order the mount it implies (a remount shows as a step), its pairs' residual, the
/// joint estimate's residual and the reprojection error (report_figures.h), and (e) the estimate
/// with its 1-sigma, the error to the truth when given, the joint estimate's consistency and the
/// data it used (rests, motion, both), observability, status and the verdict when given; (f) with
/// motion nodes, their counterpart of (d) (JointResult::motion): each node's whitened residual
/// against time, the time offset's fit against candidate offsets with the estimate and its
/// 1-sigma, and the rotation the motion carried about each camera axis.
cv::Mat renderReport(const ReportInput& input);

/// renderReport encoded in the format of the path's extension (PNG without one) and written
/// atomically (io/atomic_file.h); false with `error` set when writing fails.
bool writeReportPng(const std::string& path, const ReportInput& input, std::string* error);

}  // namespace camera_imu_alignment
