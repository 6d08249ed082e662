// The calibration report: roll/pitch/yaw against analytic rotations, the export blocks parsed back
// (Kalibr, OpenVINS, VINS, tf2) to 1e-8, the summary text (the truth, verdict and per-pose lines
// only added), and the PNG page for realistic, empty and NaN inputs. The figures per pose and to
// the truth themselves: test_report_figures.cpp.
#include "camera_imu_alignment/io/calibration_report.h"
#include "camera_imu_alignment/io/report_figures.h"
#include "camera_imu_alignment/solver/rotation_math.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "report_inputs.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

using test::axisAngle;
using test::countColour;
using test::countReddish;
using test::degenerateInput;
using test::randomRotation;
using test::realisticInput;

constexpr double kRoundTrip = 1e-8;  // exported numbers parsed back, absolute
constexpr double kDeg = test::kPiTest / 180.0;

/// R = Rz(yaw) Ry(pitch) Rx(roll), angles in degrees, built with Eigen's AngleAxis.
Eigen::Matrix3d fromRollPitchYawDeg(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw * kDeg, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch * kDeg, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll * kDeg, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// ---------------------------------------------------------------------------------------------
// Export blocks, parsed back
// ---------------------------------------------------------------------------------------------

/// The blank-line separated blocks of exportBlocks().
std::vector<std::string> splitBlocks(const std::string& text) {
  std::vector<std::string> blocks;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find("\n\n", begin);
    if (end == std::string::npos) end = text.size();
    blocks.push_back(text.substr(begin, end - begin + 1));
    begin = end + 2;
  }
  return blocks;
}

/// The block containing `key`; fails the test when there is not exactly one.
std::string blockWith(const std::vector<std::string>& blocks, const std::string& key) {
  std::string found;
  int count = 0;
  for (const std::string& b : blocks) {
    if (b.find(key) != std::string::npos) {
      found = b;
      ++count;
    }
  }
  EXPECT_EQ(count, 1) << key;
  return found;
}

/// A YAML list of 4 lists of 4 numbers -> its top-left 3x3 block; checks the last row / column.
Eigen::Matrix3d rotationOfTransform(const YAML::Node& T,
                                    const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
  EXPECT_TRUE(T.IsSequence());
  EXPECT_EQ(T.size(), 4u);
  Eigen::Matrix3d R = Eigen::Matrix3d::Constant(std::nan(""));
  if (!T.IsSequence() || T.size() != 4) return R;
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(T[i].size(), 4u);
    for (int k = 0; k < 4; ++k) {
      const double value = T[i][k].as<double>();
      if (i < 3 && k < 3) {
        R(i, k) = value;
      } else {
        const double expected = i == 3 ? (k == 3 ? 1.0 : 0.0) : t(i);
        EXPECT_NEAR(value, expected, 1e-9) << "row " << i << " col " << k;  // 9 digits
      }
    }
  }
  return R;
}

Eigen::Matrix3d parseVinsRotation(const std::string& block) {
  const YAML::Node node = YAML::Load(block)["extrinsicRotation"];
  EXPECT_EQ(node.Tag(), "tag:yaml.org,2002:opencv-matrix");
  EXPECT_EQ(node["rows"].as<int>(), 3);
  EXPECT_EQ(node["cols"].as<int>(), 3);
  EXPECT_EQ(node["dt"].as<std::string>(), "d");
  EXPECT_EQ(node["data"].size(), 9u);
  Eigen::Matrix3d R;
  for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = node["data"][i].as<double>();  // row-major
  return R;
}

struct TfLine {
  Eigen::Vector3d translation = Eigen::Vector3d::Constant(std::nan(""));
  Eigen::Quaterniond q{std::nan(""), 0, 0, 0};
  std::string parent, child;
};

TfLine parseTfLine(const std::string& block) {
  static const std::regex kLine(
      R"(rosrun tf2_ros static_transform_publisher (\S+) (\S+) (\S+) (\S+) (\S+) (\S+) (\S+) (\S+) (\S+)\n)");
  std::smatch m;
  TfLine tf;
  EXPECT_TRUE(std::regex_search(block, m, kLine)) << block;
  if (m.empty()) return tf;
  tf.translation = Eigen::Vector3d(std::stod(m[1]), std::stod(m[2]), std::stod(m[3]));
  tf.q = Eigen::Quaterniond(std::stod(m[7]), std::stod(m[4]), std::stod(m[5]), std::stod(m[6]));
  tf.parent = m[8];
  tf.child = m[9];
  return tf;
}

void expectMatrixNear(const Eigen::Matrix3d& actual, const Eigen::Matrix3d& expected,
                      const std::string& what) {
  EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), kRoundTrip) << what << "\nactual\n"
                                                                   << actual << "\nexpected\n"
                                                                   << expected;
}

// ---------------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------------

TEST(RollPitchYaw, MatchesAnalyticRotations) {
  const double values[][3] = {{0, 0, 0},       {10, 0, 0},      {0, 20, 0},     {0, 0, 30},
                              {-15, 25, -160}, {170, -80, 5},   {-179, 45, 90}, {33.3, -12.5, -90},
                              {-90, 89, 179},  {120, -60, -120}};
  for (const auto& v : values) {
    const Eigen::Vector3d rpy = rollPitchYawDeg(fromRollPitchYawDeg(v[0], v[1], v[2]));
    EXPECT_NEAR(rpy(0), v[0], 1e-9) << v[0] << " " << v[1] << " " << v[2];
    EXPECT_NEAR(rpy(1), v[1], 1e-9) << v[0] << " " << v[1] << " " << v[2];
    EXPECT_NEAR(rpy(2), v[2], 1e-9) << v[0] << " " << v[1] << " " << v[2];
  }
}

TEST(RollPitchYaw, RebuildsRandomRotationsAndGimbalLock) {
  std::mt19937_64 rng(11);
  std::vector<Eigen::Matrix3d> rotations = {fromRollPitchYawDeg(30, 90, 40),
                                            fromRollPitchYawDeg(-20, -90, 10)};
  for (int i = 0; i < 50; ++i) rotations.push_back(randomRotation(rng));
  for (const Eigen::Matrix3d& R : rotations) {
    const Eigen::Vector3d rpy = rollPitchYawDeg(R);
    EXPECT_LE(std::abs(rpy(1)), 90.0);
    EXPECT_ROTATION_NEAR_DEG(fromRollPitchYawDeg(rpy(0), rpy(1), rpy(2)), R, 1e-6);
  }
}

TEST(ExportBlocks, EveryBlockRoundTripsToTheRotation) {
  std::mt19937_64 rng(12);
  std::vector<Eigen::Matrix3d> rotations = {
      Eigen::Matrix3d::Identity(), axisAngle(Eigen::Vector3d(1, -2, 0.5), test::kPiTest),
      axisAngle(Eigen::Vector3d(0, 0, 1), 1e-7), fromRollPitchYawDeg(-90, 0, -90)};
  for (int i = 0; i < 20; ++i) rotations.push_back(randomRotation(rng));
  for (const Eigen::Matrix3d& R_cam_imu : rotations) {
    const std::string text = exportBlocks(R_cam_imu, "cam_optical", "imu_link");
    const std::vector<std::string> blocks = splitBlocks(text);
    ASSERT_EQ(blocks.size(), 4u) << text;
    for (const std::string& b : blocks) EXPECT_EQ(b.rfind("# ", 0), 0u) << "comment first:\n" << b;

    const YAML::Node kalibr = YAML::Load(blockWith(blocks, "Kalibr"));
    expectMatrixNear(rotationOfTransform(kalibr["cam0"]["T_cam_imu"]), R_cam_imu, "Kalibr");

    const YAML::Node openvins = YAML::Load(blockWith(blocks, "OpenVINS"));
    expectMatrixNear(rotationOfTransform(openvins["cam0"]["T_imu_cam"]), R_cam_imu.transpose(),
                     "OpenVINS");

    expectMatrixNear(parseVinsRotation(blockWith(blocks, "VINS-Mono")), R_cam_imu.transpose(),
                     "VINS extrinsicRotation");

    const TfLine tf = parseTfLine(blockWith(blocks, "static_transform_publisher"));
    EXPECT_EQ(tf.translation, Eigen::Vector3d::Zero());
    EXPECT_NEAR(tf.q.norm(), 1.0, kRoundTrip);
    // Sign-agnostic: q and -q give the same matrix.
    expectMatrixNear(tf.q.normalized().toRotationMatrix(), R_cam_imu, "tf quaternion");
    EXPECT_EQ(tf.parent, "cam_optical");
    EXPECT_EQ(tf.child, "imu_link");
  }
}

// Where the motion measured T_cam_imu's translation, every block carries it in its own convention
// (Kalibr t_cam_imu, OpenVINS and VINS t_imu_cam = -R_cam_imu^T t_cam_imu, tf the IMU's position
// in the camera frame) and says its 1-sigma; where not, 0 and the reason.
TEST(ExportBlocks, AMeasuredTranslationInEveryConventionAndAnUnmeasuredOneSaysWhy) {
  std::mt19937_64 rng(21);
  const Eigen::Matrix3d R_cam_imu = randomRotation(rng);
  ExportTranslation t;
  t.measured = true;
  t.p_cam_imu_m = Eigen::Vector3d(-0.0449, -0.0206, -0.0086);
  t.sigma_m = Eigen::Vector3d(0.002, 0.003, 0.004);
  const std::vector<std::string> blocks =
      splitBlocks(exportBlocks(R_cam_imu, "cam", "imu", std::nullopt, t));
  ASSERT_EQ(blocks.size(), 4u);
  const Eigen::Vector3d t_imu_cam = -(R_cam_imu.transpose() * t.p_cam_imu_m);
  const YAML::Node kalibr = YAML::Load(blockWith(blocks, "Kalibr"));
  expectMatrixNear(rotationOfTransform(kalibr["cam0"]["T_cam_imu"], t.p_cam_imu_m), R_cam_imu,
                   "Kalibr");
  const YAML::Node openvins = YAML::Load(blockWith(blocks, "OpenVINS"));
  expectMatrixNear(rotationOfTransform(openvins["cam0"]["T_imu_cam"], t_imu_cam),
                   R_cam_imu.transpose(), "OpenVINS");
  const YAML::Node vins = YAML::Load(blockWith(blocks, "VINS-Mono"))["extrinsicTranslation"];
  ASSERT_TRUE(vins.IsMap());
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(vins["data"][i].as<double>(), t_imu_cam(i), 1e-9);
  const TfLine tf = parseTfLine(blockWith(blocks, "static_transform_publisher"));
  EXPECT_LT((tf.translation - t.p_cam_imu_m).norm(), 1e-9) << tf.translation.transpose();
  for (const std::string& b : blocks) {
    EXPECT_NE(b.find("translation measured during motion, 1-sigma"), std::string::npos) << b;
  }
  // Not measured: zeros, no extrinsicTranslation, and the reason in every block.
  ExportTranslation none;
  none.not_measured_reason = "not measured: rests only";
  const std::vector<std::string> plain =
      splitBlocks(exportBlocks(R_cam_imu, "cam", "imu", std::nullopt, none));
  EXPECT_FALSE(YAML::Load(blockWith(plain, "VINS-Mono"))["extrinsicTranslation"]);
  EXPECT_EQ(parseTfLine(blockWith(plain, "static_transform_publisher")).translation,
            Eigen::Vector3d::Zero());
  for (const std::string& b : plain) {
    EXPECT_NE(b.find("not measured: rests only (0 here)"), std::string::npos) << b;
  }
}

TEST(FormatSummary, ShowsStatusNumbersRejectionsAndEndsWithTheBlocks) {
  std::mt19937_64 rng(13);
  const Eigen::Matrix3d R_cam_imu = randomRotation(rng);
  const ReportInput in = realisticInput(rng, R_cam_imu, 8, 0.002);
  ASSERT_EQ(in.result.status, SolveStatus::kOk) << in.result.message;
  EXPECT_ROTATION_NEAR_DEG(in.result.R_cam_imu, R_cam_imu, 1.0);

  const std::string text = formatSummary(in);
  const std::string blocks = exportBlocks(in.result.R_cam_imu, in.camera_frame, in.imu_frame,
                                          std::nullopt, exportTranslationOf(in.result));
  ASSERT_GE(text.size(), blocks.size());
  EXPECT_EQ(text.substr(text.size() - blocks.size()), blocks);
  EXPECT_NE(text.find("status: ok"), std::string::npos) << text;
  EXPECT_NE(text.find(in.source), std::string::npos);
  EXPECT_EQ(text.find("WARNING"), std::string::npos);

  std::ostringstream rpy;
  const Eigen::Vector3d angles = rollPitchYawDeg(in.result.R_cam_imu);
  rpy << std::fixed << std::setprecision(4) << "[" << angles(0) << ", " << angles(1) << ", "
      << angles(2) << "]";
  EXPECT_NE(text.find(rpy.str()), std::string::npos) << rpy.str() << "\n" << text;
  std::ostringstream rms;
  rms << std::fixed << std::setprecision(4) << in.result.quality.residual_rms_deg;
  EXPECT_NE(text.find("residual RMS (deg): " + rms.str()), std::string::npos) << text;
  EXPECT_NE(text.find("poses used: 8"), std::string::npos) << text;
  EXPECT_NE(text.find("target seen in 1 frame (2 needed)"), std::string::npos) << text;
  EXPECT_NE(text.find("target_not_found: 7"), std::string::npos) << text;
  EXPECT_NE(text.find("stamp_backwards: 1"), std::string::npos) << text;
}

TEST(FormatSummary, NotObservableNamesTheAxisAndWarnsAboveTheBlocks) {
  std::mt19937_64 rng(14);
  const Eigen::Matrix3d R_cam_imu = randomRotation(rng);
  ReportInput in;
  const Eigen::Vector3d axis_imu = R_cam_imu.transpose() * Eigen::Vector3d::UnitY();
  for (double angle : {0.4, 0.9, 1.5, -0.7}) {
    in.pairs.push_back(test::exactPair(R_cam_imu, axisAngle(axis_imu, angle)));
  }
  in.result = solveAlignment(in.pairs);
  ASSERT_EQ(in.result.status, SolveStatus::kNotObservable);
  const std::string text = formatSummary(in);
  EXPECT_NE(text.find("status: not observable"), std::string::npos) << text;
  EXPECT_NE(text.find("observable: NO"), std::string::npos) << text;
  EXPECT_NE(text.find("constrain the rotation about camera y"), std::string::npos) << text;
  EXPECT_LT(text.find("WARNING"), text.find("# Kalibr"));
}

TEST(FormatSummary, NanFieldsPrintNa) {
  const std::string text = formatSummary(degenerateInput());
  EXPECT_NE(text.find("n/a"), std::string::npos) << text;
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;
  EXPECT_NE(text.find("status: bad input"), std::string::npos) << text;
}

/// A recording whose poses were read but gave no estimate (status bad input: nothing solved; its
/// R_cam_imu is a placeholder), with that placeholder set to `placeholder`.
ReportInput noEstimate(const Eigen::Matrix3d& placeholder) {
  std::mt19937_64 rng(31);
  ReportInput in = realisticInput(rng, randomRotation(rng), 2, 0.002);
  in.pairs.clear();
  in.result = AlignmentResult{};
  in.result.message = "no rotation pairs: 1 pose in the window";
  in.result.R_cam_imu = placeholder;
  in.truth = KnownTruth{randomRotation(rng), "truth.yaml"};
  return in;
}

TEST(FormatSummary, NoEstimatePrintsNoRotationAndNoBlocks) {
  // Before: the placeholder identity was printed as R_cam_imu, with blocks to paste and a
  // static_transform_publisher line, for a recording that gave nothing.
  const ReportInput in = noEstimate(Eigen::Matrix3d::Identity());
  ASSERT_FALSE(hasEstimate(in.result));
  const std::string text = formatSummary(in);
  EXPECT_NE(text.find("\nR_cam_imu: no estimate\n"), std::string::npos) << text;
  for (const char* absent :
       {"quaternion xyzw", "roll, pitch, yaw", "T_cam_imu", "T_imu_cam", "extrinsicRotation",
        "static_transform_publisher", "1-sigma about", "observable:", "mount [0.000"}) {
    EXPECT_EQ(text.find(absent), std::string::npos) << absent << "\n" << text;
  }
  EXPECT_NE(text.find("truth (truth.yaml): error n/a deg"), std::string::npos) << text;
  EXPECT_NE(text.find("poses used: 2"), std::string::npos) << text;
  EXPECT_NE(text.find("# no estimate: no blocks for other tools"), std::string::npos) << text;
  // Whatever the placeholder, the text is the same: nothing in it comes from a rotation.
  EXPECT_EQ(formatSummary(noEstimate(axisAngle(Eigen::Vector3d::UnitZ(), 0.7))), text);
}

TEST(RenderReport, NoEstimateDrawsNoRotation) {
  // The page of a run without an estimate does not depend on the placeholder rotation (before, it
  // drew the placeholder's quaternion and angles, and the per-pose mounts against it).
  const cv::Mat identity = renderReport(noEstimate(Eigen::Matrix3d::Identity()));
  const cv::Mat turned = renderReport(noEstimate(axisAngle(Eigen::Vector3d::UnitZ(), 0.7)));
  EXPECT_EQ(cv::norm(identity, turned, cv::NORM_INF), 0.0);
  ReportInput solved = noEstimate(axisAngle(Eigen::Vector3d::UnitZ(), 0.7));
  solved.result.status = SolveStatus::kNotObservable;  // a best guess is shown, as such
  EXPECT_GT(cv::norm(renderReport(solved), turned, cv::NORM_INF), 0.0);
}

TEST(RenderReport, RealisticInputDrawsAPageWithOutliersInRed) {
  std::mt19937_64 rng(15);
  const Eigen::Matrix3d R_cam_imu = randomRotation(rng);
  ReportInput in = realisticInput(rng, R_cam_imu, 10, 0.002);
  in.pairs.push_back(test::exactPair(randomRotation(rng), randomRotation(rng)));  // gross outlier
  in.result = solveAlignment(in.pairs);
  ASSERT_EQ(in.result.status, SolveStatus::kOk) << in.result.message;
  ASSERT_EQ(in.result.quality.pairs.size(), in.pairs.size());
  ASSERT_FALSE(in.result.quality.pairs.back().inlier);

  const cv::Mat img = renderReport(in);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.type(), CV_8UC3);
  EXPECT_EQ(img.cols, 1200);
  EXPECT_EQ(img.rows, kReportHeightPx);
  EXPECT_GT(countColour(img, {30, 30, 220}), 50);    // outlier bar, rejected rest
  EXPECT_GT(countColour(img, {40, 160, 40}), 200);   // accepted poses
  EXPECT_GT(countColour(img, {200, 110, 30}), 200);  // inlier bars, axis points
}

TEST(RenderReport, EmptyAndNanInputsDrawWithoutCrashing) {
  std::vector<ReportInput> inputs(1);
  inputs.push_back(degenerateInput());
  for (const ReportInput& in : inputs) {
    const cv::Mat img = renderReport(in);
    ASSERT_FALSE(img.empty());
    EXPECT_EQ(img.type(), CV_8UC3);
    EXPECT_EQ(img.cols, kReportWidthPx);
    EXPECT_EQ(img.rows, kReportHeightPx);
  }
}

TEST(RenderReport, NonFiniteOrHugeRecordingSpansDrawWithoutCrashing) {
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& [start, end] : std::vector<std::pair<double, double>>{
           {-inf, inf}, {1e300, -1e300}, {1e308, 1e308}, {0.0, 1e-300}, {-1e308, 1e308}}) {
    ReportInput in = degenerateInput();
    in.start_s = start;
    in.end_s = end;
    const cv::Mat img = renderReport(in);
    EXPECT_EQ(img.type(), CV_8UC3) << start << " " << end;
    EXPECT_FALSE(formatSummary(in).empty());
  }
}

TEST(WriteReportPng, WritesAReadablePngAndReportsUnwritablePaths) {
  std::mt19937_64 rng(16);
  const ReportInput in = realisticInput(rng, randomRotation(rng), 6, 0.001);
  const std::string path = test::processTempDir() + "report.png";
  std::string error;
  ASSERT_TRUE(writeReportPng(path, in, &error)) << error;
  const cv::Mat read = cv::imread(path);
  ASSERT_FALSE(read.empty());
  const cv::Mat expected = renderReport(in);
  EXPECT_EQ(read.size(), expected.size());
  EXPECT_EQ(read.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(read, expected, cv::NORM_INF), 0.0);  // PNG is lossless

  error.clear();
  EXPECT_FALSE(writeReportPng("/nonexistent_dir/x.png", in, &error));
  EXPECT_FALSE(error.empty());
  EXPECT_NE(error.find("/nonexistent_dir"), std::string::npos) << error;
  error.clear();
  EXPECT_FALSE(writeReportPng(test::processTempDir() + "report.unknown_extension", in, &error));
  EXPECT_FALSE(error.empty());
}

/// The lines of `text`.
std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(FormatSummary, TruthVerdictAndPosesOnlyAddLines) {
  std::mt19937_64 rng(26);
  const Eigen::Matrix3d R_cam_imu = randomRotation(rng);
  ReportInput plain = realisticInput(rng, R_cam_imu, 6, 0.002);
  plain.poses.clear();  // the summary as it was: no per-pose lines
  ReportInput full = realisticInput(rng, R_cam_imu, 6, 0.002);
  full.result = plain.result;
  full.pairs = plain.pairs;
  full.truth = KnownTruth{R_cam_imu, "truth.yaml"};
  full.verdict = ReportVerdict{false, "FAILED: remount at pose 6"};
  const std::vector<std::string> before = linesOf(formatSummary(plain));
  const std::vector<std::string> after = linesOf(formatSummary(full));
  // Every line of the plain summary is in the full one, in the same order.
  std::size_t j = 0;
  for (const std::string& line : before) {
    if (line.rfind("poses used:", 0) == 0) continue;  // counts differ (no poses in `plain`)
    while (j < after.size() && after[j] != line) ++j;
    ASSERT_LT(j, after.size()) << "missing or reordered: '" << line << "'";
  }
  const std::string text = formatSummary(full);
  EXPECT_NE(text.find("\nverdict: FAILED: remount at pose 6\n"), std::string::npos) << text;
  EXPECT_LT(text.find("status: ok"), text.find("verdict:"));
  EXPECT_NE(text.find("\ntruth (truth.yaml): error "), std::string::npos) << text;
  EXPECT_EQ(after.size(), before.size() + 2 + 2 + 6);  // verdict, truth, per-pose header, poses
}

TEST(RenderReport, VerdictAndTruthAreDrawnAndNanTruthPrintsNa) {
  std::mt19937_64 rng(27);
  const Eigen::Matrix3d R_cam_imu = randomRotation(rng);
  ReportInput in = realisticInput(rng, R_cam_imu, 6, 0.002);
  const cv::Mat plain = renderReport(in);
  in.verdict = ReportVerdict{false, "FAILED: remount at pose 3"};
  const cv::Mat failed = renderReport(in);
  EXPECT_GT(countReddish(failed), countReddish(plain) + 50);
  in.verdict.reset();
  in.truth = KnownTruth{R_cam_imu, "truth.yaml"};
  EXPECT_GT(cv::norm(renderReport(in), plain, cv::NORM_L1), 0.0);

  ReportInput broken = degenerateInput();
  broken.truth = KnownTruth{Eigen::Matrix3d::Constant(std::nan("")), "nan.yaml"};
  const ReportFigures figures = reportFigures(broken);
  ASSERT_TRUE(figures.truth_error);
  EXPECT_TRUE(std::isnan(figures.truth_error->angle_deg));
  const std::string text = formatSummary(broken);
  EXPECT_NE(text.find("truth (nan.yaml): error n/a deg"), std::string::npos) << text;
  EXPECT_EQ(text.find("nan "), std::string::npos) << text;
  const cv::Mat img = renderReport(broken);
  EXPECT_EQ(img.cols, kReportWidthPx);
  EXPECT_EQ(img.rows, kReportHeightPx);
}

}  // namespace
}  // namespace camera_imu_alignment
