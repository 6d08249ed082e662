// Panel (f) of the PNG report: the continuous motion's counterpart of the per-pose panel, drawn
// from the figures the pipeline and the estimator computed (JointResult::motion); nothing is
// recomputed.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "camera_imu_alignment/io/joint_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "report_draw.h"
#include "report_text.h"

namespace camera_imu_alignment {
namespace report_draw {
namespace {

using report_text::fixed;

/// Half-width (s) of the time offset fit shown around the estimate.
constexpr double kOffsetWindowS = 0.025;

std::string numberLabel(double value) {
  std::ostringstream label;
  label << std::setprecision(3) << value;
  return label.str();
}

void dashedHorizontal(cv::Mat& img, int x0, int x1, int y, const cv::Scalar& colour) {
  for (int x = x0; x < x1; x += 8) cv::line(img, {x, y}, {std::min(x + 4, x1), y}, colour, 1);
}

void dashedVertical(cv::Mat& img, int x, int y0, int y1, const cv::Scalar& colour) {
  for (int y = y0; y < y1; y += 8) cv::line(img, {x, y}, {x, std::min(y + 4, y1)}, colour, 1);
}

/// (f1) The whitened residual of every motion node against time (s from the recording start).
void drawNodeResiduals(cv::Mat& img, const cv::Rect& plot, const MotionFigures& m, double start_s,
                       double end_s) {
  putText(img, "residual per motion node (sigma; dashed: 1) against time (s)",
          {plot.x - 45, plot.y - 8}, 0.42, kBlack, plot.width + 45);
  cv::rectangle(img, plot, kBlack, 1);
  const std::vector<double>& t = m.node_stamps_s;
  const std::vector<double>& r = m.node_residual_sigma;
  const std::size_t n = std::min(t.size(), r.size());
  if (n == 0) {
    putText(img, "no per-node residuals", plot.tl() + cv::Point(10, plot.height / 2), 0.45, kGrey);
    return;
  }
  double t0 = start_s, t1 = end_s;
  if (!(std::isfinite(t1 - t0) && t1 > t0)) {
    t0 = *std::min_element(t.begin(), t.begin() + n);
    t1 = std::max(t0 + 1.0, *std::max_element(t.begin(), t.begin() + n));
  }
  double top = 2.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isfinite(r[i])) top = std::max(top, r[i]);
  }
  top = niceCeil(top);
  const int bottom = plot.y + plot.height;
  auto x_of = [&](double time) {
    const double f = std::clamp((time - t0) / (t1 - t0), 0.0, 1.0);
    return plot.x + static_cast<int>(std::lround(f * plot.width));
  };
  auto y_of = [&](double v) {
    return bottom - static_cast<int>(std::lround(std::clamp(v / top, 0.0, 1.0) * plot.height));
  };
  dashedHorizontal(img, plot.x, plot.x + plot.width, y_of(1.0), kGrey);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(r[i]) || !std::isfinite(t[i])) continue;
    const int x = x_of(t[i]);
    cv::line(img, {x, bottom - 1}, {x, y_of(r[i])}, r[i] > 3.0 ? kRed : kOrange, 1);
  }
  putText(img, numberLabel(top), {plot.x - 30, plot.y + 10}, 0.35, kBlack);
  putText(img, "0", {plot.x - 12, bottom}, 0.35, kBlack);
  const double step = niceCeil((t1 - t0) / 8.0);
  for (int i = 0; i <= 20 && i * step <= (t1 - t0) * (1.0 + 1e-9); ++i) {
    const int x = x_of(t0 + i * step);
    cv::line(img, {x, bottom}, {x, bottom + 4}, kBlack, 1);
    putText(img, numberLabel(i * step), {x - 8, bottom + 17}, 0.35, kBlack);
  }
}

/// (f2) The coarse fit's RMS angle difference against candidate offsets around the estimate, the
/// coarse minimum (grey, dashed), the joint estimate (red) and its 1-sigma (shaded).
void drawOffsetFit(cv::Mat& img, const cv::Rect& plot, const MotionFigures& m,
                   const JointResult& joint) {
  putText(img, "time offset fit: angle difference (deg)", {plot.x - 45, plot.y - 8}, 0.42, kBlack,
          plot.width + 60);
  cv::rectangle(img, plot, kBlack, 1);
  const std::vector<double>& c = m.timeshift_candidates_s;
  const std::vector<double>& v = m.timeshift_rms_difference_rad;
  const std::size_t n = std::min(c.size(), v.size());
  if (n < 2) {
    putText(img, "no fit", plot.tl() + cv::Point(10, plot.height / 2), 0.45, kGrey);
    return;
  }
  const double centre =
      joint.timeshift_estimated ? joint.timeshift_cam_imu_s : m.coarse_timeshift_s;
  const double lo = std::max(c.front(), centre - kOffsetWindowS);
  const double hi = std::max(lo + 1e-3, std::min(c.back(), centre + kOffsetWindowS));
  double v_min = HUGE_VAL, v_max = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (c[i] < lo || c[i] > hi || !std::isfinite(v[i])) continue;
    v_min = std::min(v_min, rad2deg(v[i]));
    v_max = std::max(v_max, rad2deg(v[i]));
  }
  if (!(v_max > v_min)) v_max = v_min + 1e-3;
  const int bottom = plot.y + plot.height;
  auto x_of = [&](double s) {
    const double f = std::clamp((s - lo) / (hi - lo), 0.0, 1.0);
    return plot.x + static_cast<int>(std::lround(f * plot.width));
  };
  auto y_of = [&](double deg) {
    const double f = std::clamp((deg - v_min) / (v_max - v_min), 0.0, 1.0);
    return bottom - 4 - static_cast<int>(std::lround(f * (plot.height - 8)));
  };
  if (joint.timeshift_estimated) {
    const double sigma = std::isfinite(joint.timeshift_sigma_s) ? joint.timeshift_sigma_s : 0.0;
    const int x0 = x_of(joint.timeshift_cam_imu_s - sigma),
              x1 = x_of(joint.timeshift_cam_imu_s + sigma);
    cv::rectangle(img, cv::Point(std::min(x0, x1 - 1), plot.y + 1), cv::Point(x1, bottom - 1),
                  cv::Scalar(200, 200, 255), cv::FILLED);
    const int x = x_of(joint.timeshift_cam_imu_s);
    cv::line(img, {x, plot.y + 1}, {x, bottom - 1}, kRed, 1);
  }
  dashedVertical(img, x_of(m.coarse_timeshift_s), plot.y + 1, bottom - 1, kGrey);
  cv::Point previous(-1, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (c[i] < lo || c[i] > hi || !std::isfinite(v[i])) continue;
    const cv::Point p(x_of(c[i]), y_of(rad2deg(v[i])));
    if (previous.x >= 0) cv::line(img, previous, p, kBlue, 1, cv::LINE_AA);
    cv::circle(img, p, 2, kBlue, cv::FILLED, cv::LINE_AA);
    previous = p;
  }
  putText(img, fixed(v_max, 3), {plot.x - 44, plot.y + 10}, 0.35, kBlack);
  putText(img, fixed(v_min, 3), {plot.x - 44, bottom}, 0.35, kBlack);
  putText(img, fixed(1e3 * lo, 0) + " ms", {plot.x - 6, bottom + 17}, 0.35, kBlack);
  putText(img, fixed(1e3 * hi, 0) + " ms", {plot.x + plot.width - 30, bottom + 17}, 0.35, kBlack);
  putText(img, "offset", {plot.x + plot.width / 2 - 20, bottom + 17}, 0.35, kBlack);
}

/// (f3) The rotation the motion carried about each camera axis (deg), bars.
void drawExcitation(cv::Mat& img, const cv::Rect& plot, const MotionFigures& m) {
  putText(img, "rotation per camera axis (deg)", {plot.x - 30, plot.y - 8}, 0.42, kBlack,
          plot.width + 30);
  cv::rectangle(img, plot, kBlack, 1);
  const Eigen::Vector3d deg = rad2deg(1.0) * m.excitation_rad;
  const double top = niceCeil(std::max(deg.allFinite() ? deg.maxCoeff() : 0.0, 1.0));
  const cv::Scalar colours[3] = {kRed, kGreen, kBlue};
  const char* names[3] = {"x", "y", "z"};
  const int bottom = plot.y + plot.height;
  const int width = plot.width / 3;
  for (int a = 0; a < 3; ++a) {
    const int x0 = plot.x + a * width + width / 4, x1 = plot.x + (a + 1) * width - width / 4;
    const double value = std::isfinite(deg(a)) ? deg(a) : 0.0;
    const int y = bottom - static_cast<int>(std::lround(std::min(1.0, value / top) * plot.height));
    cv::rectangle(img, cv::Point(x0, y), cv::Point(x1, bottom - 1), colours[a], cv::FILLED);
    putText(img, fixed(deg(a), 0), {x0, std::max(plot.y + 12, y - 4)}, 0.38, kBlack);
    putText(img, names[a], {(x0 + x1) / 2 - 4, bottom + 17}, 0.45, colours[a]);
  }
  putText(img, fixed(top, 0), {plot.x - 36, plot.y + 10}, 0.35, kBlack);
}

}  // namespace

void drawMotionPanel(cv::Mat& img, const cv::Rect& panel, const ReportInput& in) {
  panelFrame(img, panel, "(f) continuous motion: the motion nodes' counterpart of (d)");
  const std::optional<JointResult>& joint = in.result.joint;
  if (!joint || !joint->ok || joint->motion_nodes == 0) {
    const std::string why = !joint       ? "no joint estimate: no motion nodes used"
                            : !joint->ok ? "the joint estimate failed: no motion figures"
                                         : "no motion nodes: the estimate used rests only";
    putText(img, why, panel.tl() + cv::Point(20, panel.height / 2), 0.55, kGrey);
    return;
  }
  const MotionFigures& m = joint->motion;
  const int top = panel.y + 62, height = panel.height - 130;
  drawNodeResiduals(img, cv::Rect(panel.x + 50, top, 500, height), m, in.start_s, in.end_s);
  drawOffsetFit(img, cv::Rect(panel.x + 630, top, 290, height), m, *joint);
  drawExcitation(img, cv::Rect(panel.x + 990, top, 180, height), m);
  const int text_y = top + height + 40;
  const std::string line =
      "data used: " + std::string(dataUsed(*joint)) + " (" + std::to_string(joint->rests_used) +
      " rest(s), " + std::to_string(joint->motion_nodes) + " motion nodes over " +
      fixed(m.excitation_duration_s, 1) + " s); rotation about camera x, y, z " +
      report_text::fixedList(rad2deg(1.0) * m.excitation_rad, 0) + " deg" +
      (joint->noise.learned[static_cast<size_t>(NoiseKind::kCameraMotion)]
           ? "; camera noise " + fixed(joint->noise.sigmaFactor(NoiseKind::kCameraMotion), 2) +
                 "x stated, gyro " + fixed(joint->noise.sigmaFactor(NoiseKind::kGyroWhite), 2) + "x"
           : "") +
      (m.frames_dropped > 0 ? "; " + std::to_string(m.frames_dropped) +
                                  " frame(s) dropped: reprojection far beyond the recording's"
                            : "");
  putText(img, line, {panel.x + 10, text_y}, 0.45, kBlack, panel.width - 20);
  const std::string offset = joint->timeshift_estimated
                                 ? "timeshift_cam_imu_s (t_imu = t_cam + timeshift): " +
                                       fixed(1e3 * joint->timeshift_cam_imu_s, 3) + " ms +- " +
                                       fixed(1e3 * joint->timeshift_sigma_s, 3) +
                                       " ms (red, 1-sigma shaded); coarse " +
                                       fixed(1e3 * m.coarse_timeshift_s, 2) + " ms (dashed)"
                                 : "time offset not estimated";
  putText(img, offset, {panel.x + 10, text_y + 22}, 0.45, kBlack, panel.width - 20);
}

}  // namespace report_draw
}  // namespace camera_imu_alignment
