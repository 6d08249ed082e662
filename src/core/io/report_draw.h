// Drawing helpers of the PNG report (calibration_report.cpp) and its per-pose panel
// (report_pose_panel.cpp) and motion panel (report_motion_panel.cpp): OpenCV primitives, BGR
// colours, pixel coordinates. Private to the io room; not installed.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "camera_imu_alignment/io/report_figures.h"

namespace camera_imu_alignment {
namespace report_draw {

const cv::Scalar kBlack(0, 0, 0), kGrey(150, 150, 150), kLightGrey(225, 225, 225);
const cv::Scalar kShade(242, 242, 242);  ///< background of poses outside the window
const cv::Scalar kBlue(200, 110, 30), kGreen(40, 160, 40), kRed(30, 30, 220), kOrange(0, 140, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

int textWidth(const std::string& text, double scale);

/// `text` shortened with "..." so that it fits in `max_width` px.
std::string fitText(std::string text, int max_width, double scale);

/// `text` broken at spaces into at most `max_lines` lines of at most `max_width` px (the last one
/// shortened with "...").
std::vector<std::string> wrapText(const std::string& text, int max_width, double scale,
                                  int max_lines);

void putText(cv::Mat& img, const std::string& text, cv::Point origin, double scale,
             const cv::Scalar& colour, int max_width = 10000);

/// A grey frame around `panel` with `title` in its top-left corner.
void panelFrame(cv::Mat& img, const cv::Rect& panel, const std::string& title);

/// Smallest 1, 2 or 5 times a power of ten >= value (value > 0).
double niceCeil(double value);

/// Panel (d): the per-pose figures in recording order, one column per pose, in strips sharing the
/// pose axis: the mount offset about camera x, y, z (deg), the RMS residual of each pose's pairs
/// (deg), the joint estimate's whitened residual (sigma) and the reprojection error (px).
void drawPosePanel(cv::Mat& img, const cv::Rect& panel, const ReportFigures& figures);

/// Panel (f): the continuous motion (JointResult::motion): each motion node's whitened residual
/// against time, the time offset's coarse fit around the estimate with the joint estimate and its
/// 1-sigma, the rotation the motion carried about each camera axis, and which data were used. A
/// grey note when the estimate used no motion nodes.
void drawMotionPanel(cv::Mat& img, const cv::Rect& panel, const ReportInput& input);

}  // namespace report_draw
}  // namespace camera_imu_alignment
