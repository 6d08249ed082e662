// The one-page PNG report of a calibration run (the text summary: calibration_summary.h).
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "camera_imu_alignment/io/calibration_summary.h"

namespace camera_imu_alignment {

/// One-page report (CV_8UC3, about 1200x900): per-pair residuals (inliers / outliers), the
/// coverage of rotation axes in the camera frame (which axes were excited), the stationary
/// segments over time (poses used, rejected rests with reasons), and the estimate with its
/// 1-sigma, observability and status.
cv::Mat renderReport(const ReportInput& input);

/// renderReport + cv::imwrite; false with `error` set when writing fails.
bool writeReportPng(const std::string& path, const ReportInput& input, std::string* error);

}  // namespace camera_imu_alignment
