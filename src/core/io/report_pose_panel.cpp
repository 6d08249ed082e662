// Panel (d) of the PNG report: the figures of every pose in recording order (report_figures.h).
#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <optional>
#include <sstream>

#include "report_draw.h"

namespace camera_imu_alignment {
namespace report_draw {
namespace {

/// Maps the i-th of `count` poses to the centre of its column in `plot`.
struct PoseAxis {
  cv::Rect plot;  ///< the columns' horizontal extent (its y and height unused)
  std::size_t count = 0;
  double step() const { return count ? static_cast<double>(plot.width) / count : plot.width; }
  int left(std::size_t i) const { return plot.x + static_cast<int>(std::lround(i * step())); }
  int centre(std::size_t i) const {
    return plot.x + static_cast<int>(std::lround((i + 0.5) * step()));
  }
};

/// Largest finite |value| of `values` (0 when none).
double largestAbs(const std::vector<double>& values) {
  double top = 0.0;
  for (double v : values) {
    if (std::isfinite(v)) top = std::max(top, std::abs(v));
  }
  return top;
}

std::string axisLabel(double value) {
  std::ostringstream label;
  label << std::setprecision(3) << value;
  return label.str();
}

/// One strip: its label on the left, the columns of poses outside the window shaded, the frame.
void stripFrame(cv::Mat& img, const cv::Rect& strip, const PoseAxis& axis,
                const std::vector<PoseFigure>& poses, const std::string& label) {
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (poses[i].in_window) continue;
    cv::rectangle(img, cv::Point(axis.left(i), strip.y),
                  cv::Point(axis.left(i + 1), strip.y + strip.height), kShade, cv::FILLED);
  }
  cv::rectangle(img, strip, kBlack, 1);
  putText(img, label, {strip.x, strip.y - 4}, 0.42, kBlack, strip.width - 385);
}

/// Scale marks 0 and `top` on the left edge of `strip` (values upwards from its bottom).
void barScale(cv::Mat& img, const cv::Rect& strip, double top) {
  putText(img, axisLabel(top), {strip.x - 30, strip.y + 10}, 0.35, kBlack);
  putText(img, "0", {strip.x - 12, strip.y + strip.height}, 0.35, kBlack);
}

/// Bars of `values` (>= 0, NaN: none) from the strip's bottom, on a round axis of at least
/// `min_top`; `reference` > 0 draws a dashed-looking line at that value (e.g. 1 sigma).
void drawBarStrip(cv::Mat& img, const cv::Rect& strip, const PoseAxis& axis,
                  const std::vector<PoseFigure>& poses, const std::vector<double>& values,
                  const std::string& label, const cv::Scalar& colour, double min_top,
                  double reference = 0.0) {
  stripFrame(img, strip, axis, poses, label);
  const double top = niceCeil(std::max({largestAbs(values), reference, min_top}));
  barScale(img, strip, top);
  const int bottom = strip.y + strip.height;
  auto y_of = [&](double v) {
    return bottom - static_cast<int>(std::lround(std::clamp(v / top, 0.0, 1.0) * strip.height));
  };
  if (reference > 0.0) {
    const int y = y_of(reference);
    for (int x = strip.x; x < strip.x + strip.width; x += 8) {
      cv::line(img, {x, y}, {std::min(x + 4, strip.x + strip.width), y}, kGrey, 1);
    }
  }
  const int gap = axis.step() > 4.0 ? std::max(1, static_cast<int>(axis.step() / 5)) : 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) continue;
    const int x0 = axis.left(i) + gap / 2, x1 = std::max(x0, axis.left(i + 1) - (gap + 1) / 2 - 1);
    cv::rectangle(img, cv::Point(x0, y_of(values[i])), cv::Point(x1, bottom - 1), colour,
                  cv::FILLED);
  }
}

/// The mount offset about camera x, y, z as three coloured lines on a symmetric axis.
void drawMountStrip(cv::Mat& img, const cv::Rect& strip, const PoseAxis& axis,
                    const std::vector<PoseFigure>& poses) {
  stripFrame(img, strip, axis, poses,
             "mount (deg): the rotation from the estimate each pose implies; a mount that "
             "moved is a step");
  std::vector<double> all;
  for (const PoseFigure& f : poses) {
    for (int a = 0; a < 3; ++a) all.push_back(f.mount_offset_deg(a));
  }
  const double top = niceCeil(std::max(largestAbs(all), 0.01));
  const int mid = strip.y + strip.height / 2;
  cv::line(img, {strip.x, mid}, {strip.x + strip.width, mid}, kLightGrey, 1);
  putText(img, "+" + axisLabel(top), {strip.x - 38, strip.y + 10}, 0.35, kBlack);
  putText(img, "0", {strip.x - 12, mid + 4}, 0.35, kBlack);
  putText(img, "-" + axisLabel(top), {strip.x - 38, strip.y + strip.height}, 0.35, kBlack);
  auto y_of = [&](double v) {
    const double f = std::clamp(v / top, -1.0, 1.0);
    return mid - static_cast<int>(std::lround(f * (strip.height / 2 - 3)));
  };
  const cv::Scalar colours[3] = {kRed, kGreen, kBlue};
  const char* names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    std::optional<cv::Point> previous;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const double v = poses[i].mount_offset_deg(a);
      if (!std::isfinite(v)) {
        previous.reset();
        continue;
      }
      const cv::Point p(axis.centre(i), y_of(v));
      if (previous) cv::line(img, *previous, p, colours[a], 1, cv::LINE_AA);
      cv::circle(img, p, 3, colours[a], cv::FILLED, cv::LINE_AA);
      previous = p;
    }
    putText(img, std::string("about camera ") + names[a],
            {strip.x + strip.width - 375 + 125 * a, strip.y - 4}, 0.42, colours[a]);
  }
}

/// Pose indices under the last strip (every n-th when they would overlap).
void drawPoseLabels(cv::Mat& img, const PoseAxis& axis, const std::vector<PoseFigure>& poses,
                    int y) {
  const int every = std::max(1, static_cast<int>(std::ceil(30.0 / std::max(axis.step(), 1.0))));
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i % every != 0) continue;
    const std::string label = std::to_string(poses[i].index);
    putText(img, label, {axis.centre(i) - textWidth(label, 0.38) / 2, y}, 0.38, kBlack);
  }
}

std::vector<double> series(const std::vector<PoseFigure>& poses,
                           const std::function<double(const PoseFigure&)>& get) {
  std::vector<double> values;
  values.reserve(poses.size());
  for (const PoseFigure& f : poses) values.push_back(get(f));
  return values;
}

}  // namespace

void drawPosePanel(cv::Mat& img, const cv::Rect& panel, const ReportFigures& figures) {
  panelFrame(img, panel,
             "(d) per pose, in recording order (pose index below; shaded: not in the estimate's "
             "window)");
  const std::vector<PoseFigure>& poses = figures.poses;
  const cv::Rect plot(panel.x + 50, panel.y + 50, panel.width - 65, panel.height - 76);
  if (poses.empty()) {
    putText(img, "no poses", plot.tl() + cv::Point(10, 40), 0.6, kGrey);
    return;
  }
  const PoseAxis axis{plot, poses.size()};
  const int gap = 20, mount_h = plot.height * 2 / 5;
  const int bar_h = (plot.height - mount_h - 3 * gap) / 3;
  cv::Rect strip(plot.x, plot.y, plot.width, mount_h);
  drawMountStrip(img, strip, axis, poses);
  strip = cv::Rect(plot.x, strip.y + strip.height + gap, plot.width, bar_h);
  drawBarStrip(img, strip, axis, poses,
               series(poses, [](const PoseFigure& f) { return f.pair_residual_rms_deg; }),
               "RMS residual of the pose's pairs at the estimate (deg)", kBlue, 0.01);
  strip.y += bar_h + gap;
  drawBarStrip(img, strip, axis, poses,
               series(poses, [](const PoseFigure& f) { return f.joint_residual_sigma; }),
               "joint estimate: whitened residual (sigma; dashed: 1)", kOrange, 1.0, 1.0);
  strip.y += bar_h + gap;
  drawBarStrip(img, strip, axis, poses,
               series(poses, [](const PoseFigure& f) { return f.reprojection_rms_px; }),
               "reprojection error, RMS (px)", kGreen, 0.1);
  drawPoseLabels(img, axis, poses, strip.y + strip.height + 16);
}

}  // namespace report_draw
}  // namespace camera_imu_alignment
