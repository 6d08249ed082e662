// The report's motion figures (JointResult::motion, drawn in panel (f)) against independent truth:
// the excitation per camera axis on constructed frames (exactly 0 about an axis never turned, the
// total variation of the angle about the others) and on a simulated waving recording (the integral
// of the simulator's own body rate); the time offset's fit, whose minimum is at the simulated
// offset and which rises on either side; the motion nodes' residuals (one per node, in time, about
// 1 sigma on consistent data); the summary and the page name the data used and draw the panel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/time_offset.h"
#include "camera_imu_alignment/io/calibration_report.h"
#include "camera_imu_alignment/io/calibration_summary.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"
#include "test_helpers.h"
#include "waving_sessions.h"

namespace camera_imu_alignment {
namespace {

constexpr double kTimeshiftS = 0.015;

// ---------------------------------------------------------------------------------------------
// Excitation on constructed frames
// ---------------------------------------------------------------------------------------------

/// 20 Hz frames: 10 s of a sinusoid of amplitude 20 deg at 0.5 Hz about camera x, then 10 s of
/// one of 30 deg about camera y (R = Rx(a(t)), then Ry(b(t)); both are I at t = 10 s).
std::vector<MotionFrame> xThenYFrames() {
  std::vector<MotionFrame> frames;
  const double w = 2.0 * test::kPiTest * 0.5;
  for (int k = 0; k <= 400; ++k) {
    const double t = 0.05 * k;
    MotionFrame f;
    f.stamp_s = t;
    f.R_target_cam =
        t <= 10.0
            ? test::axisAngle(Eigen::Vector3d::UnitX(), deg2rad(20.0) * std::sin(w * t))
            : test::axisAngle(Eigen::Vector3d::UnitY(), deg2rad(30.0) * std::sin(w * (t - 10)));
    frames.push_back(f);
  }
  return frames;
}

TEST(ReportMotion, ExcitationIsTheTotalTurnAboutEachAxisAndZeroAboutAnAxisNeverTurned) {
  const MotionExcitation e = motionExcitation(xThenYFrames());
  // Total variation of a sin over 5 whole periods: 20 a (the turning points fall on the 0.1 s
  // intervals' ends, so the sum of |increments| is exact).
  EXPECT_NEAR(rad2deg(e.about_cam_rad.x()), 20.0 * 20.0, 1e-6);
  EXPECT_NEAR(rad2deg(e.about_cam_rad.y()), 20.0 * 30.0, 1e-6);
  EXPECT_LT(rad2deg(e.about_cam_rad.z()), 1e-9);
  EXPECT_NEAR(e.duration_s, 20.0, 1e-6);
  // A gap longer than max_interval_s (the target out of view) is not counted.
  std::vector<MotionFrame> gap = xThenYFrames();
  gap.erase(gap.begin() + 100, gap.begin() + 110);  // 5.0 to 5.45 s missing
  // Intervals 0-4.9 s and 5.5-20 s; 4.9 to 5.5 s (through 4.95 s, 0.05 s on) is too long.
  EXPECT_NEAR(motionExcitation(gap).duration_s, 20.0 - 0.6, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// A simulated waving recording through the pipeline, as calibrate_bag runs it
// ---------------------------------------------------------------------------------------------

struct WavingReport {
  std::unique_ptr<simulation::SimulationRun> run;
  ReportInput report;
};

/// The frames captured in [from_s, to_s) are off the truth by +-0.5 deg about camera x,
/// alternating (1 deg between consecutive frames; e.g. a poor PnP fit).
constexpr double kBadFromS = 30.0, kBadToS = 32.0;

WavingReport wavingReport(std::uint64_t seed, bool corrupt = false) {
  WavingReport out;
  out.run = std::make_unique<simulation::SimulationRun>(
      test::wavingConfig(simulation::ImuGrade::kConsumer, seed, kTimeshiftS));
  int k = 0;
  for (simulation::CameraOrientation& o : out.run->camera_orientations) {
    if (!corrupt || o.capture_s < kBadFromS || o.capture_s >= kBadToS) continue;
    const double angle = deg2rad(0.5) * (k++ % 2 == 0 ? 1.0 : -1.0);
    o.R_target_cam = o.R_target_cam * test::axisAngle(Eigen::Vector3d::UnitX(), angle);
  }
  CalibrationPipeline pipeline(test::simulatedTarget(out.run->config), PipelineSettings{});
  test::feedOrientations(*out.run, &pipeline);
  pipeline.finish();
  ReportInput& in = out.report;
  in.result = test::solveFinalWindow(pipeline);
  in.poses = pipeline.poses();
  in.segments = pipeline.segments();
  in.pairs = pipeline.windowPairs();
  in.window_poses = pipeline.windowSize();
  in.start_s = 0.0;
  in.end_s = out.run->trajectory.duration();
  in.source = "waving seed " + std::to_string(seed);
  in.truth = KnownTruth{out.run->trajectory.R_cam_imu_final(), "simulated truth"};
  return out;
}

/// Integral of |omega_cam| per camera axis over [t0, t1] from the simulator's trajectory (rad).
Eigen::Vector3d trueExcitation(const simulation::Trajectory& trajectory, double t0, double t1) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const double dt = 1e-3;
  for (double t = t0 + 0.5 * dt; t < t1; t += dt) sum += dt * trajectory.at(t).omega_cam.cwiseAbs();
  return sum;
}

TEST(ReportMotion, WavingRecordingCarriesTheOffsetFitTheExcitationAndTheNodeResiduals) {
  const WavingReport w = wavingReport(7);
  const AlignmentResult& result = w.report.result;
  ASSERT_TRUE(result.joint && result.joint->ok) << result.message;
  const JointResult& joint = *result.joint;
  const MotionFigures& m = joint.motion;
  ASSERT_GT(joint.motion_nodes, 500);
  EXPECT_EQ(joint.rests_used, 0);

  // The time offset's fit: its lowest candidate is the simulated offset within 1 ms, as is the
  // interpolated minimum; away from it on either side the camera and the gyro disagree more and
  // more (1 ms candidates: 5, 10, 20, 40 ms off).
  const std::vector<double>& curve = m.timeshift_rms_difference_rad;
  ASSERT_EQ(m.timeshift_candidates_s.size(), curve.size());
  ASSERT_GT(curve.size(), 100u);
  const std::size_t best = std::min_element(curve.begin(), curve.end()) - curve.begin();
  EXPECT_NEAR(m.timeshift_candidates_s[best], kTimeshiftS, 1e-3);
  EXPECT_NEAR(m.coarse_timeshift_s, kTimeshiftS, 1e-3);
  ASSERT_GT(best, 40u);
  ASSERT_LT(best + 40, curve.size());
  EXPECT_NEAR(m.timeshift_candidates_s[best + 10] - m.timeshift_candidates_s[best], 0.010, 1e-9);
  std::size_t previous = 0;
  for (std::size_t off : {5, 10, 20, 40}) {
    EXPECT_GT(curve[best - off], curve[best - previous]) << off << " ms early";
    EXPECT_GT(curve[best + off], curve[best + previous]) << off << " ms late";
    previous = off;
  }
  std::cout << "[report_motion] RMS angle difference (deg) at the minimum " << rad2deg(curve[best])
            << ", 10 ms off " << rad2deg(curve[best - 10]) << " / " << rad2deg(curve[best + 10])
            << ", 40 ms off " << rad2deg(curve[best - 40]) << " / " << rad2deg(curve[best + 40])
            << "\n";
  // The joint estimate it started is within its 1-sigma-scaled bound of the truth too.
  ASSERT_TRUE(joint.timeshift_estimated);
  EXPECT_NEAR(joint.timeshift_cam_imu_s, kTimeshiftS,
              std::max(3.0 * joint.timeshift_sigma_s, 3e-4));

  // The excitation per camera axis against the simulator's body rate over the frames' span: the
  // frames' noise adds a little to every axis, reversals within 0.1 s take a little away.
  const auto& frames = w.run->camera_orientations;
  const Eigen::Vector3d truth_deg =
      rad2deg(1.0) *
      trueExcitation(w.run->trajectory, frames.front().capture_s, frames.back().capture_s);
  const Eigen::Vector3d figure_deg = rad2deg(1.0) * m.excitation_rad;
  for (int a = 0; a < 3; ++a) {
    EXPECT_GT(truth_deg(a), 200.0) << "axis " << a;  // the waving turns about every axis
    EXPECT_NEAR(figure_deg(a), truth_deg(a), 0.05 * truth_deg(a))
        << "axis " << a << ": figure " << figure_deg.transpose() << ", truth "
        << truth_deg.transpose();
  }
  EXPECT_NEAR(m.excitation_duration_s, frames.back().stamp_s - frames.front().stamp_s, 0.5);

  // One residual per node, in time order, within the recording; below 1 sigma (the camera_pose
  // noise assumed, 0.05 deg, is above the simulated 0.02 deg).
  ASSERT_EQ(m.node_stamps_s.size(), static_cast<std::size_t>(joint.motion_nodes));
  ASSERT_EQ(m.node_residual_sigma.size(), m.node_stamps_s.size());
  EXPECT_TRUE(std::is_sorted(m.node_stamps_s.begin(), m.node_stamps_s.end()));
  EXPECT_GE(m.node_stamps_s.front(), frames.front().stamp_s - 1e-9);
  EXPECT_LE(m.node_stamps_s.back(), frames.back().stamp_s + 1e-9);
  std::vector<double> sorted = m.node_residual_sigma;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_GT(sorted[sorted.size() / 2], 0.05);
  EXPECT_LT(sorted[sorted.size() / 2], 1.0);
}

TEST(ReportMotion, NodeResidualsPointAtTheStretchWhereTheCameraDisagreesWithTheGyro) {
  const WavingReport w = wavingReport(7, true);
  ASSERT_TRUE(w.report.result.joint && w.report.result.joint->ok) << w.report.result.message;
  const MotionFigures& m = w.report.result.joint->motion;
  ASSERT_EQ(m.node_stamps_s.size(), m.node_residual_sigma.size());
  // Stamps are the camera clock: capture time - timeshift.
  const double from = kBadFromS - kTimeshiftS, to = kBadToS - kTimeshiftS;
  std::vector<double> inside, outside;
  std::vector<std::pair<double, double>> by_residual;  // (residual, stamp)
  for (std::size_t i = 0; i < m.node_stamps_s.size(); ++i) {
    const double t = m.node_stamps_s[i], r = m.node_residual_sigma[i];
    (t >= from && t < to ? inside : outside).push_back(r);
    by_residual.emplace_back(r, t);
  }
  ASSERT_GE(inside.size(), 15u);
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  // The nodes take every other frame (0.1 s at 20 Hz): they see the stretch's frames offset by
  // the same 0.5 deg, a step that the gyro sees at the stretch's edges and within it as the
  // learned noise spreads it.
  EXPECT_GT(median(inside), 2.0 * median(outside))
      << "inside " << median(inside) << ", outside " << median(outside);
  std::sort(by_residual.rbegin(), by_residual.rend());
  for (std::size_t i = 0; i < 4; ++i) {
    const double t = by_residual[i].second;
    EXPECT_GE(t, from - 0.11) << i;
    EXPECT_LT(t, to + 0.11) << i;
    EXPECT_GT(by_residual[i].first, 5.0 * median(outside)) << i;
  }
}

// ---------------------------------------------------------------------------------------------
// The summary and the page
// ---------------------------------------------------------------------------------------------

/// Pixels of `colour` (BGR) in `area` of `img`.
int countColourIn(const cv::Mat& img, const cv::Rect& area, const cv::Vec3b& colour) {
  int count = 0;
  for (int y = area.y; y < area.y + area.height; ++y) {
    for (int x = area.x; x < area.x + area.width; ++x) count += img.at<cv::Vec3b>(y, x) == colour;
  }
  return count;
}

TEST(ReportMotion, SummaryAndPageNameTheDataUsedAndDrawTheMotionPanel) {
  const WavingReport w = wavingReport(8);
  ASSERT_TRUE(w.report.result.joint && w.report.result.joint->ok) << w.report.result.message;
  const std::string text = formatSummary(w.report);
  EXPECT_NE(text.find("data used: motion (0 rest(s), " +
                      std::to_string(w.report.result.joint->motion_nodes) + " motion node(s))"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("motion: rotation about camera x, y, z (deg): ["), std::string::npos) << text;

  const cv::Mat page = renderReport(w.report);
  ASSERT_EQ(page.rows, kReportHeightPx);
  const cv::Rect motion_panel(5, 1343, 1190, 292);
  const cv::Vec3b orange(0, 140, 255), red(30, 30, 220), blue(200, 110, 30), green(40, 160, 40);
  // (f1) a residual line per node, (f2) the estimate's line, (f3) the three bars.
  EXPECT_GT(countColourIn(page, {55, 1400, 500, 160}, orange) +
                countColourIn(page, {55, 1400, 500, 160}, red),
            200);
  EXPECT_GT(countColourIn(page, {635, 1400, 290, 160}, red), 20);
  EXPECT_GT(countColourIn(page, {635, 1400, 290, 160}, blue), 20);
  EXPECT_GT(countColourIn(page, {995, 1400, 180, 160}, green), 200);

  // A recording of rests alone: the panel says so and draws nothing of the motion.
  ReportInput rests_only = w.report;
  rests_only.result.joint->motion_nodes = 0;
  rests_only.result.joint->rests_used = 8;
  const cv::Mat plain = renderReport(rests_only);
  EXPECT_EQ(countColourIn(plain, motion_panel, orange), 0);
  EXPECT_EQ(countColourIn(plain, motion_panel, green), 0);
  EXPECT_NE(formatSummary(rests_only).find("data used: rests (8 rest(s), 0 motion node(s))"),
            std::string::npos);
}

}  // namespace
}  // namespace camera_imu_alignment
