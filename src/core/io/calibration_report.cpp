// The one-page PNG report of a calibration run, drawn with OpenCV primitives only.
#include "camera_imu_alignment/io/calibration_report.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <vector>

#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/io/atomic_file.h"
#include "camera_imu_alignment/io/joint_yaml.h"
#include "camera_imu_alignment/io/report_figures.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "report_draw.h"
#include "report_text.h"

namespace camera_imu_alignment {
namespace {

using report_draw::drawMotionPanel;
using report_draw::drawPosePanel;
using report_draw::kBlack;
using report_draw::kBlue;
using report_draw::kFont;
using report_draw::kGreen;
using report_draw::kGrey;
using report_draw::kLightGrey;
using report_draw::kOrange;
using report_draw::kRed;
using report_draw::niceCeil;
using report_draw::panelFrame;
using report_draw::putText;
using report_draw::textWidth;
using report_draw::wrapText;
using report_text::canonicalQuaternion;
using report_text::exact;
using report_text::fixed;
using report_text::fixedList;
using report_text::hasAxisAdvice;

// --- (a) Residual bars

/// Top of the residual axis (deg): a round number above the largest inlier residual (all pairs
/// when none is an inlier), so that one gross outlier does not flatten the inlier bars.
double residualAxisTopDeg(const SolutionQuality& q) {
  double max_inlier = 0.0, max_all = 0.0;
  for (const PairDiagnostics& p : q.pairs) {
    if (!std::isfinite(p.residual_deg)) continue;
    max_all = std::max(max_all, std::abs(p.residual_deg));
    if (p.inlier) max_inlier = std::max(max_inlier, std::abs(p.residual_deg));
  }
  const double top = max_inlier > 0.0 ? max_inlier : max_all;
  return niceCeil(std::max(top, 0.01));  // noise-free data: bars at 0 on a 0.01 deg axis
}

void drawResidualScale(cv::Mat& img, const cv::Rect& panel, const cv::Rect& plot, double top_deg) {
  for (int i = 0; i <= 4; ++i) {  // y-axis scale, 0 .. top_deg
    const int y = plot.y + plot.height - i * plot.height / 4;
    cv::line(img, {plot.x, y}, {plot.x + plot.width, y}, kLightGrey, 1);
    std::ostringstream label;
    label << std::setprecision(3) << top_deg * i / 4.0;
    putText(img, label.str(), {panel.x + 6, y + 4}, 0.4, kBlack);
  }
  putText(img, "deg", {panel.x + 6, plot.y - 16}, 0.4, kBlack);
}

/// One bar per pair; residuals above the axis are clipped and marked with their value.
void drawResiduals(cv::Mat& img, const cv::Rect& panel, const SolutionQuality& q) {
  panelFrame(img, panel, "(a) residual per pair (deg): inliers blue, outliers red");
  const cv::Rect plot(panel.x + 60, panel.y + 50, panel.width - 80, panel.height - 90);
  if (q.pairs.empty()) {
    putText(img, "no pairs", plot.tl() + cv::Point(10, plot.height / 2), 0.6, kGrey);
    return;
  }
  const double top_deg = residualAxisTopDeg(q);
  drawResidualScale(img, panel, plot, top_deg);
  const double step = static_cast<double>(plot.width) / q.pairs.size();
  const int bottom = plot.y + plot.height;
  for (std::size_t j = 0; j < q.pairs.size(); ++j) {
    const PairDiagnostics& p = q.pairs[j];
    const int x0 = plot.x + static_cast<int>(j * step);
    const int x1 = std::max(x0, plot.x + static_cast<int>((j + 1) * step) - (step > 3 ? 1 : 0));
    if (!std::isfinite(p.residual_deg)) {
      putText(img, "?", {x0, bottom - 4}, 0.4, kOrange);
      continue;
    }
    const double frac = std::min(1.0, std::abs(p.residual_deg) / top_deg);
    const int y = bottom - static_cast<int>(std::lround(frac * plot.height));
    const cv::Scalar& colour = p.inlier ? kBlue : kRed;
    cv::rectangle(img, cv::Point(x0, y), cv::Point(x1, bottom), colour, cv::FILLED);
    if (std::abs(p.residual_deg) > top_deg) {  // clipped: print the value above the plot
      putText(img, fixed(p.residual_deg, 1), {std::min(x0, plot.x + plot.width - 30), plot.y - 4},
              0.35, colour);
    }
  }
  cv::rectangle(img, plot, kBlack, 1);
  putText(img,
          "pair index 0.." + std::to_string(q.pairs.size() - 1) +
              "   RMS over inliers: " + fixed(q.residual_rms_deg, 3) + " deg",
          {plot.x, bottom + 22}, 0.45, kBlack, plot.width);
}

// --- (b) Rotation-axis coverage in the camera frame

/// One orthographic view of the axis hemisphere whose pole is camera axis `pole` (0, 1, 2):
/// horizontal = camera axis `u`, vertical = camera axis `v` (drawn upwards).
struct HemisphereView {
  cv::Point centre;
  int radius;
  int pole, u, v;
  cv::Point project(const Eigen::Vector3d& axis_cam) const {
    const Eigen::Vector3d a = axis_cam(pole) < 0.0 ? Eigen::Vector3d(-axis_cam) : axis_cam;
    return centre + cv::Point(static_cast<int>(std::lround(radius * a(u))),
                              -static_cast<int>(std::lround(radius * a(v))));
  }
};

void drawViewFrame(cv::Mat& img, const HemisphereView& view) {
  static const char* kNames[] = {"x", "y", "z"};
  cv::circle(img, view.centre, view.radius, kGrey, 1, cv::LINE_AA);
  cv::line(img, view.centre - cv::Point(view.radius, 0), view.centre + cv::Point(view.radius, 0),
           kLightGrey, 1);
  cv::line(img, view.centre - cv::Point(0, view.radius), view.centre + cv::Point(0, view.radius),
           kLightGrey, 1);
  putText(img, kNames[view.u], view.centre + cv::Point(view.radius + 4, 5), 0.5, kBlack);
  putText(img, kNames[view.v], view.centre + cv::Point(-4, -view.radius - 6), 0.5, kBlack);
  putText(img, std::string("looking along camera ") + kNames[view.pole],
          view.centre + cv::Point(-view.radius, view.radius + 22), 0.45, kBlack);
}

/// RMS rotation angle (deg) about each camera axis over the pairs (axis components weighted).
Eigen::Vector3d excitationPerAxisDeg(const RotationPairs& pairs) {
  Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
  for (const RotationPair& p : pairs) {
    const Eigen::Vector3d v = logSO3(p.A_cam);  // axis * angle (rad), camera frame
    if (v.allFinite()) sum_sq += v.cwiseAbs2();
  }
  if (pairs.empty()) return Eigen::Vector3d::Zero();
  return (sum_sq / static_cast<double>(pairs.size())).cwiseSqrt() * (180.0 / kPi);
}

void drawAxisCoverage(cv::Mat& img, const cv::Rect& panel, const ReportInput& in) {
  panelFrame(img, panel, "(b) rotation axes of the camera pairs A_j (camera frame)");
  const SolutionQuality& q = in.result.quality;
  const int radius = std::min(panel.width / 4 - 30, panel.height / 2 - 80);
  const int cy = panel.y + 50 + radius;
  const HemisphereView views[] = {{{panel.x + panel.width / 4, cy}, radius, 2, 0, 1},
                                  {{panel.x + 3 * panel.width / 4, cy}, radius, 0, 1, 2}};
  for (const HemisphereView& view : views) drawViewFrame(img, view);
  for (std::size_t j = 0; j < in.pairs.size(); ++j) {
    const Eigen::Vector3d v = logSO3(in.pairs[j].A_cam);
    if (!v.allFinite() || v.norm() < 1e-9) continue;  // no axis for a zero rotation
    const bool outlier = j < q.pairs.size() && !q.pairs[j].inlier;
    for (const HemisphereView& view : views) {
      cv::circle(img, view.project(v.normalized()), 3, outlier ? kRed : kBlue, cv::FILLED,
                 cv::LINE_AA);
    }
  }
  if (hasAxisAdvice(in.result)) {
    for (const HemisphereView& view : views) {
      cv::drawMarker(img, view.project(q.weak_axis_cam.normalized()), kOrange, cv::MARKER_CROSS, 14,
                     2);
    }
  }
  const Eigen::Vector3d rms = excitationPerAxisDeg(in.pairs);
  int y = cy + radius + 50;
  putText(img,
          "RMS rotation about camera x, y, z (deg): " + fixedList(rms, 1) + "   (" +
              std::to_string(in.pairs.size()) + " pairs)",
          {panel.x + 10, y}, 0.45, kBlack, panel.width - 20);
  y += 20;
  if (q.observable) {
    putText(img, "all axes excited", {panel.x + 10, y}, 0.45, kGreen, panel.width - 20);
  } else if (!hasAxisAdvice(in.result)) {
    putText(img, "observability not evaluated", {panel.x + 10, y}, 0.45, kRed, panel.width - 20);
  } else {
    putText(img,
            "axis " + axisName(q.weak_axis_cam) + " not excited (orange +): rotate about camera " +
                axisName(q.excite_axis_cam),
            {panel.x + 10, y}, 0.45, kRed, panel.width - 20);
  }
}

// --- (c) Timeline of rests, poses and rejected rests

/// Maps recording time (s) to a pixel column of `plot`, clamped to it.
struct TimeAxis {
  double t0 = 0.0, t1 = 1.0;
  cv::Rect plot;
  int x(double t) const {
    if (!std::isfinite(t)) return plot.x;
    const double f = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
    return plot.x + static_cast<int>(std::lround(f * plot.width));
  }
};

/// The time span to show: [start_s, end_s], else the extent of what is drawn, else [0, 1].
TimeAxis makeTimeAxis(const ReportInput& in, const cv::Rect& plot) {
  TimeAxis axis;
  axis.plot = plot;
  auto usable = [](double a, double b) { return std::isfinite(b - a) && b > a; };
  double lo = in.start_s, hi = in.end_s;
  if (!usable(lo, hi)) {
    lo = HUGE_VAL;
    hi = -HUGE_VAL;
    auto extend = [&](double a, double b) {
      if (std::isfinite(a)) lo = std::min(lo, a);
      if (std::isfinite(b)) hi = std::max(hi, b);
    };
    for (const auto& s : in.segments) extend(s.start_s, s.end_s);
    for (const auto& p : in.poses) extend(p.start_s, p.end_s);
    for (const auto& r : in.rejected) extend(r.start_s, r.end_s);
    if (!usable(lo, hi)) {
      lo = std::isfinite(in.start_s) ? in.start_s : (std::isfinite(lo) ? lo : 0.0);
      hi = lo + 1.0;
    }
    if (!usable(lo, hi)) {  // lo so large that lo + 1 == lo
      lo = 0.0;
      hi = 1.0;
    }
  }
  axis.t0 = lo;
  axis.t1 = hi;
  return axis;
}

void drawTimeTicks(cv::Mat& img, const TimeAxis& axis) {
  const double span = axis.t1 - axis.t0;
  const double step = niceCeil(span / 10.0);
  const int y = axis.plot.y + axis.plot.height;
  cv::line(img, {axis.plot.x, y}, {axis.plot.x + axis.plot.width, y}, kBlack, 1);
  if (!(std::isfinite(step) && step > 0.0)) return;
  for (int i = 0; i <= 20 && i * step <= span * (1.0 + 1e-9); ++i) {
    const double dt = i * step;
    const int x = axis.x(axis.t0 + dt);
    cv::line(img, {x, y}, {x, y + 5}, kBlack, 1);
    std::ostringstream label;
    label << std::setprecision(4) << dt;
    putText(img, label.str(), {x - 8, y + 20}, 0.4, kBlack);
  }
}

void drawInterval(cv::Mat& img, const TimeAxis& axis, double a, double b, int y, int h,
                  const cv::Scalar& colour, const std::string& label) {
  const int x0 = axis.x(a), x1 = std::max(axis.x(b), x0 + 1);
  cv::rectangle(img, cv::Point(x0, y), cv::Point(x1, y + h), colour, cv::FILLED);
  if (!label.empty() && textWidth(label, 0.4) + 4 <= x1 - x0) {
    putText(img, label, {x0 + 2, y + h - 5}, 0.4, cv::Scalar(255, 255, 255));
  }
}

/// Short tag of rejected rest i in the timeline ("r1", ...), listed with its reason in panel (e).
std::string rejectedTag(std::size_t i) { return "r" + std::to_string(i + 1); }

void drawTimeline(cv::Mat& img, const cv::Rect& panel, const ReportInput& in) {
  panelFrame(img, panel,
             "(c) timeline (s from start): IMU rests grey, poses used green, rejected rests red");
  const cv::Rect plot(panel.x + 110, panel.y + 32, panel.width - 130, panel.height - 64);
  const TimeAxis axis = makeTimeAxis(in, plot);
  const int row_h = (plot.height - 8) / 3;
  const char* rows[] = {"IMU rests", "poses", "rejected"};
  for (int r = 0; r < 3; ++r) {
    putText(img, rows[r], {panel.x + 8, plot.y + r * row_h + row_h - 6}, 0.45, kBlack);
  }
  for (const StationarySegment& s : in.segments) {
    drawInterval(img, axis, s.start_s, s.end_s, plot.y, row_h - 4, kGrey, "");
  }
  for (const StationaryPose& p : in.poses) {
    drawInterval(img, axis, p.start_s, p.end_s, plot.y + row_h, row_h - 4, kGreen,
                 std::to_string(p.index));
  }
  for (std::size_t i = 0; i < in.rejected.size(); ++i) {
    const RejectedPose& r = in.rejected[i];
    const int box_px = axis.x(r.end_s) - axis.x(r.start_s);
    const std::string label = textWidth(r.reason, 0.4) + 4 <= box_px ? r.reason : rejectedTag(i);
    drawInterval(img, axis, r.start_s, r.end_s, plot.y + 2 * row_h, row_h - 4, kRed, label);
  }
  if (in.segments.empty() && in.poses.empty() && in.rejected.empty()) {
    putText(img, "no stationary segments", {plot.x + 10, plot.y + row_h - 6}, 0.45, kGrey);
  }
  drawTimeTicks(img, axis);
}

// --- (e) Estimate and quality as text ((d), per pose: report_pose_panel.cpp)

cv::Scalar statusColour(SolveStatus status) {
  if (status == SolveStatus::kOk) return kGreen;
  return status == SolveStatus::kNotObservable ? kOrange : kRed;
}

/// The joint estimate's consistency, or why there is none.
void jointLine(const AlignmentResult& r, std::string* text, cv::Scalar* colour) {
  if (!r.joint) {
    *text = "joint estimate: not run (estimate from the pairs alone)";
    *colour = kBlack;
  } else if (!r.joint->ok) {
    *text = "joint estimate: FAILED (" + r.joint->message + "); the pair estimate is shown";
    *colour = kRed;
  } else {
    *text = "joint estimate: " + jointConsistencyText(*r.joint) +
            "; data used: " + dataUsed(*r.joint) + " (" + std::to_string(r.joint->rests_used) +
            " rest(s), " + std::to_string(r.joint->motion_nodes) + " motion nodes)";
    *colour = r.joint->consistent() ? kGreen : kRed;
  }
}

void drawEstimateText(cv::Mat& img, const cv::Rect& panel, const ReportInput& in,
                      const ReportFigures& figures) {
  panelFrame(img, panel, "(e) estimate");
  const AlignmentResult& r = in.result;
  const SolutionQuality& q = r.quality;
  const Eigen::Quaterniond quat = canonicalQuaternion(r.R_cam_imu);
  const int width = panel.width - 20;
  int y = panel.y + 44;
  auto line = [&](const std::string& text, const cv::Scalar& colour) {
    putText(img, text, {panel.x + 10, y}, 0.5, colour, width);
    y += 22;
  };
  line("status: " + std::string(toString(r.status)), statusColour(r.status));
  if (in.verdict) {
    for (const std::string& text : wrapText("verdict: " + in.verdict->text, width, 0.5, 2)) {
      line(text, in.verdict->passed ? kGreen : kRed);
    }
  }
  for (const std::string& text : wrapText(r.message, width, 0.5, 2)) line(text, kBlack);
  if (!hasEstimate(r)) {  // nothing solved: no rotation is drawn (its placeholder is no answer)
    line("R_cam_imu: no estimate", kRed);
  } else {
    line("q_cam_imu (x, y, z, w): [" + fixed(quat.x(), 6) + ", " + fixed(quat.y(), 6) + ", " +
             fixed(quat.z(), 6) + ", " + fixed(quat.w(), 6) + "]   (p_cam = R_cam_imu * p_imu, " +
             in.camera_frame + " <- " + in.imu_frame + ")",
         kBlack);
    line("roll, pitch, yaw (deg, R = Rz Ry Rx): " + fixedList(rollPitchYawDeg(r.R_cam_imu), 3),
         kBlack);
    line("1-sigma about camera x, y, z (deg): " + fixedList(q.std_dev_deg, 4), kBlack);
  }
  if (figures.truth_error) {
    const double worst = figures.truth_error->largestErrorInSigmas();
    const cv::Scalar colour = std::isfinite(worst) && worst <= 3.0 ? kBlack : kRed;
    for (const std::string& text : wrapText(truthErrorText(*figures.truth_error), width, 0.5, 2)) {
      line(text, colour);
    }
  }
  std::string joint_text;
  cv::Scalar joint_colour;
  jointLine(r, &joint_text, &joint_colour);
  line(joint_text, joint_colour);
  line("residual RMS: " + fixed(q.residual_rms_deg, 4) + " deg   inliers: " +
           std::to_string(q.num_inliers) + " / " + std::to_string(q.num_pairs) + " pairs",
       kBlack);
  const std::string advice =
      hasAxisAdvice(r) ? " - rotate the rig about camera " + axisName(q.excite_axis_cam) : "";
  line("observable: " + std::string(q.observable ? "yes" : "NO") + "  (observability " +
           fixed(q.observability, 3) + ", weakest excitation " +
           fixed(q.weakest_excitation_deg, 2) + " deg)" + advice,
       q.observable ? kBlack : kRed);
  line("poses used: " + std::to_string(in.poses.size()) + "   rests rejected: " +
           std::to_string(in.rejected.size()) + "   inputs rejected: " + in.rejections.summary(),
       kBlack);
  std::string rests;
  for (std::size_t i = 0; i < in.rejected.size(); ++i) {
    const RejectedPose& rej = in.rejected[i];
    rests += (i == 0 ? "rejected rests: " : "; ") + rejectedTag(i) + " " +
             fixed(rej.start_s - in.start_s, 1) + "-" + fixed(rej.end_s - in.start_s, 1) +
             " s: " + (rej.reason.empty() ? "(no reason given)" : rej.reason);
  }
  if (!rests.empty()) line(rests, kRed);
}

}  // namespace

cv::Mat renderReport(const ReportInput& input) {
  const ReportFigures figures = reportFigures(input);
  cv::Mat img(kReportHeightPx, kReportWidthPx, CV_8UC3, cv::Scalar(255, 255, 255));
  const std::string title =
      "camera-IMU rotation report" + (input.source.empty() ? std::string() : ": " + input.source);
  putText(img, title, {10, 26}, 0.7, kBlack, kReportWidthPx - 20);
  drawResiduals(img, cv::Rect(5, 40, 590, 370), input.result.quality);
  drawAxisCoverage(img, cv::Rect(605, 40, 590, 370), input);
  drawTimeline(img, cv::Rect(5, 418, 1190, 160), input);
  drawPosePanel(img, cv::Rect(5, 586, 1190, 400), figures);
  drawEstimateText(img, cv::Rect(5, 994, 1190, 341), input, figures);
  drawMotionPanel(img, cv::Rect(5, 1343, 1190, 292), input);
  return img;
}

bool writeReportPng(const std::string& path, const ReportInput& input, std::string* error) {
  auto fail = [&](const std::string& why) {
    if (error) *error = "cannot write report '" + path + "': " + why;
    return false;
  };
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec)) {
    return fail("directory '" + parent.string() + "' does not exist");
  }
  // Encoded in memory (the format from the extension, as cv::imwrite), then written atomically.
  std::string extension = std::filesystem::path(path).extension().string();
  if (extension.empty()) extension = ".png";
  std::vector<unsigned char> encoded;
  try {
    if (!cv::imencode(extension, renderReport(input), encoded)) {
      return fail("cv::imencode failed for '" + extension + "'");
    }
  } catch (const cv::Exception& e) {
    return fail(e.what());
  }
  try {
    writeFileAtomically(path, std::string(encoded.begin(), encoded.end()));
  } catch (const InputError& e) {
    return fail(e.what());
  }
  return true;
}

}  // namespace camera_imu_alignment
