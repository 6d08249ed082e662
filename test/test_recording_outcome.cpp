// calibrate_bag's decisions without a bag (offline/recording_outcome.h): the exit code and the
// closing lines for each kind of run, every output checked before the run, and the outputs written
// as the decision says (a forced FAILED estimate marked so in its YAML).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "camera_imu_alignment/io/exit_codes.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/offline/recording_outcome.h"
#include "report_inputs.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

std::string temp(const std::string& name) { return test::tempPath(name); }

bool has(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& line : lines) {
    if (line.find(text) != std::string::npos) return true;
  }
  return false;
}

std::string joined(const RecordingOutcome& o) {
  std::string text;
  for (const std::string& line : o.out_lines) text += "out: " + line + "\n";
  for (const std::string& line : o.err_lines) text += "err: " + line + "\n";
  return text;
}

/// A run that read images and camera info and solved an estimate that passed its gates.
RecordingFacts passedRun() {
  RecordingFacts f;
  f.bag_path = "rig.bag";
  f.image_topic = "/cam/image_raw";
  f.image_messages = 300;
  f.camera_info_topic = "/cam/camera_info";
  f.has_intrinsics = true;
  f.status = SolveStatus::kOk;
  f.message = "joint estimate: 8 poses";
  f.has_rests = true;
  f.verdict = CalibrationVerdict{true, "PASSED (the nodelet would broadcast it)"};
  f.outputs.output = "result.yaml";
  return f;
}

/// The same run with its estimate failing a quality gate.
RecordingFacts failedRun() {
  RecordingFacts f = passedRun();
  f.gate_why = "1-sigma 0.05 deg > max_std_dev_deg 0.0001";
  f.verdict = CalibrationVerdict{false, "FAILED: " + f.gate_why};
  return f;
}

CalibrationCheck checkOf(bool consistent) {
  CalibrationCheck c;
  c.consistent = consistent;
  c.text = consistent ? "the current calibration is 0.01 deg (0.3 sigma) ...: still right"
                      : "the current calibration is 1 deg (40 sigma) ...: NOT consistent";
  return c;
}

TEST(DecideRecordingOutcome, APassedEstimateIsWrittenUnderItsVerdict) {
  const RecordingOutcome o = decideRecordingOutcome(passedRun());
  EXPECT_EQ(o.exit_code, kExitOk);
  EXPECT_TRUE(o.summary);
  EXPECT_TRUE(o.write_result);
  EXPECT_TRUE(o.result_verdict.passed);
  EXPECT_FALSE(o.result_verdict.forced);
  EXPECT_EQ(o.result_verdict.text, "PASSED (the nodelet would broadcast it)");
  EXPECT_TRUE(o.err_lines.empty()) << joined(o);
}

TEST(DecideRecordingOutcome, NoCameraDataOrCameraInfoExitsTwoWithoutASummary) {
  RecordingFacts f = passedRun();
  f.image_messages = 0;
  RecordingOutcome o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitBadInput);
  EXPECT_FALSE(o.summary);
  EXPECT_FALSE(o.write_result);
  EXPECT_TRUE(has(o.err_lines, "rig.bag: no camera data")) << joined(o);

  f = passedRun();
  f.has_intrinsics = false;
  o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitBadInput);
  EXPECT_TRUE(has(o.err_lines, "no usable camera info (/cam/camera_info)")) << joined(o);

  f = passedRun();
  f.camera_poses = true;
  f.camera_pose_topic = "/camera_pose";
  f.windowed = true;
  o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitBadInput);
  EXPECT_TRUE(has(o.err_lines,
                  "no messages on /camera_pose (geometry_msgs/PoseStamped) between "
                  "--start and --end"))
      << joined(o);
  f.camera_pose_messages = 20;  // camera poses need no camera info
  EXPECT_EQ(decideRecordingOutcome(f).exit_code, kExitOk);
}

TEST(DecideRecordingOutcome, AWrongCameraModelIsBadInputEvenForced) {
  RecordingFacts f = failedRun();
  f.camera_model_problem = "the camera intrinsics in camera_info do not fit the images";
  f.force = true;
  const RecordingOutcome o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitBadInput);
  EXPECT_TRUE(o.summary);
  EXPECT_FALSE(o.write_result);
  EXPECT_TRUE(has(o.err_lines, "/cam/camera_info: the camera intrinsics")) << joined(o);
}

TEST(DecideRecordingOutcome, NoEstimateIsNotEnoughInformationOrABadTarget) {
  RecordingFacts f = passedRun();
  f.status = SolveStatus::kNotObservable;
  f.message = "not observable: rotate about camera x or y";
  f.verdict.reset();
  f.force = true;
  RecordingOutcome o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitNotEnoughInformation);
  EXPECT_FALSE(o.write_result);
  EXPECT_TRUE(has(o.err_lines, "rotate about camera x or y")) << joined(o);
  EXPECT_TRUE(has(o.err_lines, "--force: nothing written")) << joined(o);
  f.has_rests = false;
  f.motion_frames = 12;
  o = decideRecordingOutcome(f);
  EXPECT_TRUE(has(o.err_lines, "no stationary rests and 12 camera orientation(s)")) << joined(o);
  f.status = SolveStatus::kBadInput;
  f.target_path = "t.yaml";
  f.target_diagnosis = "the target (checkerboard 7 x 6) was found in none of the rests";
  o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitBadInput);
  EXPECT_TRUE(has(o.err_lines, "t.yaml: the target (checkerboard 7 x 6)")) << joined(o);
}

TEST(DecideRecordingOutcome, AFailedEstimateIsWrittenOnlyWhenForcedAndMarkedFailed) {
  RecordingFacts f = failedRun();
  RecordingOutcome o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitQualityGate);
  EXPECT_FALSE(o.write_result);
  EXPECT_TRUE(has(o.err_lines,
                  "fails the quality gates (see 'verdict:'); not written to "
                  "--output / --imu-yaml"))
      << joined(o);
  f.force = true;
  f.outputs.imu_yaml = "imu.yaml";
  o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitQualityGate);  // forced, still a failure
  EXPECT_TRUE(o.write_result);
  EXPECT_FALSE(o.result_verdict.passed);
  EXPECT_TRUE(o.result_verdict.forced);
  EXPECT_EQ(o.result_verdict.text, "FAILED: " + f.gate_why);
  EXPECT_TRUE(has(o.err_lines, "written to --output / --imu-yaml marked FAILED (--force)"))
      << joined(o);
  f.outputs = {};  // forced, but nowhere to write
  o = decideRecordingOutcome(f);
  EXPECT_FALSE(o.write_result);
  EXPECT_TRUE(has(o.err_lines, "not written")) << joined(o);
  // A remount fails the verdict however much data there was.
  f = failedRun();
  f.remounted = true;
  f.enough_data = false;
  EXPECT_EQ(decideRecordingOutcome(f).exit_code, kExitQualityGate);
}

TEST(DecideRecordingOutcome, TooLittleDataIsNotEnoughInformation) {
  RecordingFacts f = failedRun();
  f.enough_data = false;
  f.gate_why = "2 poses in the window, min_poses is 4";
  f.verdict = CalibrationVerdict{false, "FAILED: " + f.gate_why};
  RecordingOutcome o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitNotEnoughInformation);
  EXPECT_TRUE(has(o.err_lines,
                  "not enough information (see 'verdict:'): 2 poses in the window, "
                  "min_poses is 4; nothing written"))
      << joined(o);
  f.force = true;
  o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitNotEnoughInformation);
  EXPECT_TRUE(o.write_result);
  EXPECT_TRUE(o.result_verdict.forced);
}

TEST(DecideRecordingOutcome, CheckIsJudgedOnlyByAnEstimateThatPassedItsGates) {
  RecordingFacts f = passedRun();
  f.check_path = "current.yaml";
  f.check = checkOf(true);
  RecordingOutcome o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitOk);
  EXPECT_FALSE(o.write_result);  // a check writes no result
  EXPECT_TRUE(has(o.out_lines, "check: current.yaml: the current calibration is")) << joined(o);
  EXPECT_TRUE(has(o.out_lines, "still right")) << joined(o);
  f.check = checkOf(false);
  o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitQualityGate);
  EXPECT_TRUE(has(o.out_lines, "NOT consistent")) << joined(o);

  // The bag's estimate failed its gates: it cannot vouch for the current calibration, however
  // close the two are (before: "still right", exit 0).
  f = failedRun();
  f.check_path = "current.yaml";
  f.check = checkOf(true);
  o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitQualityGate);
  EXPECT_FALSE(o.write_result);
  EXPECT_FALSE(has(o.out_lines, "still right")) << joined(o);
  EXPECT_TRUE(has(o.out_lines, "check: current.yaml: the new estimate FAILED its quality gates"))
      << joined(o);
  f.enough_data = false;
  o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitNotEnoughInformation);
  EXPECT_TRUE(has(o.out_lines, "not enough information in the bag to check it")) << joined(o);
  f = passedRun();
  f.check_path = "current.yaml";
  f.joint_message = "none was run";
  o = decideRecordingOutcome(f);
  EXPECT_EQ(o.exit_code, kExitNotEnoughInformation);
  EXPECT_TRUE(has(o.err_lines, "--check needs the joint estimate")) << joined(o);
}

TEST(CheckOutputPaths, EveryProblemIsNamedWithItsOption) {
  RecordingOutputPaths paths;
  EXPECT_TRUE(checkOutputPaths(paths).empty());
  paths = {temp("r.yaml"), temp("imu.yaml"), temp("report.png"), temp("poses.csv")};
  EXPECT_TRUE(checkOutputPaths(paths).empty());
  std::ofstream(temp("plain_file")) << "x";
  paths.output = temp("missing_folder/r.yaml");
  paths.report = temp("plain_file/report.png");
  const std::vector<std::string> problems = checkOutputPaths(paths);
  ASSERT_EQ(problems.size(), 2u);  // each one, not only the first
  EXPECT_EQ(problems[0].rfind("--output " + paths.output + ": ", 0), 0u) << problems[0];
  EXPECT_EQ(problems[1].rfind("--report " + paths.report + ": ", 0), 0u) << problems[1];
  // Two options naming one file; the bag as an output.
  paths = {temp("same.yaml"), temp("./same.yaml"), "", temp("rig.bag")};
  std::ofstream(temp("rig.bag")) << "bag";
  const std::vector<std::string> clash = checkOutputPaths(paths, {temp("rig.bag")});
  ASSERT_EQ(clash.size(), 2u);
  EXPECT_NE(clash[0].find("--imu-yaml"), std::string::npos) << clash[0];
  EXPECT_NE(clash[0].find("the same file as --output"), std::string::npos) << clash[0];
  EXPECT_NE(clash[1].find("--export-poses"), std::string::npos) << clash[1];
  EXPECT_NE(clash[1].find("it would be overwritten"), std::string::npos) << clash[1];
}

TEST(CheckOutputPaths, AReadOnlyFolderIsNamed) {
  const std::string folder = test::readOnlyFolder();
  const bool named = test::asUnprivilegedUser([&] {
    RecordingOutputPaths paths;
    paths.output = folder + "r.yaml";
    paths.imu_yaml = folder + "imu.yaml";
    const std::vector<std::string> problems = checkOutputPaths(paths);
    return problems.size() == 2u && problems[0].rfind("--output " + paths.output, 0) == 0 &&
           problems[0].find("Permission denied") != std::string::npos &&
           problems[1].rfind("--imu-yaml " + paths.imu_yaml, 0) == 0;
  });
  chmod(folder.c_str(), 0755);
  std::filesystem::remove_all(folder);
  EXPECT_TRUE(named);
}

TEST(WriteRecordingOutputs, AForcedEstimateCarriesItsFailedVerdict) {
  std::mt19937_64 rng(62);
  const ReportInput report = test::realisticInput(rng, test::randomRotation(rng), 6, 0.001);
  ASSERT_EQ(report.result.status, SolveStatus::kOk);
  RecordingOutputPaths paths;
  paths.output = temp("forced.yaml");
  paths.report = temp("forced.png");
  RecordingProducts products;
  products.report = &report;
  products.meta.num_poses = 6;
  RecordingOutcome outcome = decideRecordingOutcome([] {
    RecordingFacts f = failedRun();
    f.force = true;
    return f;
  }());
  ASSERT_TRUE(outcome.write_result);
  EXPECT_TRUE(writeRecordingOutputs(paths, outcome, products).empty());
  const YAML::Node yaml = YAML::LoadFile(paths.output);
  EXPECT_FALSE(yaml["verdict"]["passed"].as<bool>());
  EXPECT_TRUE(yaml["verdict"]["forced"].as<bool>());
  EXPECT_EQ(yaml["verdict"]["text"].as<std::string>(),
            "FAILED: 1-sigma 0.05 deg > max_std_dev_deg 0.0001");
  // Read back, it is known for what it is, and every reader can say so.
  const StoredCalibration stored = readResultYaml(paths.output);
  ASSERT_TRUE(stored.verdict);
  EXPECT_FALSE(stored.verdict->passed);
  const std::string note = failedVerdictNote(stored, paths.output);
  EXPECT_NE(note.find(paths.output + " holds an estimate that FAILED its quality gates, written "
                                     "on request (force): 1-sigma 0.05 deg"),
            std::string::npos)
      << note;
  EXPECT_TRUE(std::filesystem::exists(paths.report));

  // No summary (no camera data): no report; not to be written: no result.
  std::filesystem::remove(paths.output);
  std::filesystem::remove(paths.report);
  outcome.summary = false;
  outcome.write_result = false;
  EXPECT_TRUE(writeRecordingOutputs(paths, outcome, products).empty());
  EXPECT_FALSE(std::filesystem::exists(paths.output));
  EXPECT_FALSE(std::filesystem::exists(paths.report));
}

TEST(WriteRecordingOutputs, APassedEstimateIsMarkedPassedAndFailuresAreNamed) {
  std::mt19937_64 rng(63);
  const ReportInput report = test::realisticInput(rng, test::randomRotation(rng), 6, 0.001);
  RecordingOutputPaths paths;
  paths.output = temp("passed.yaml");
  paths.imu_yaml = temp("passed_imu.yaml");  // a pair solve has no joint estimate to write
  paths.export_poses = temp("missing_folder/poses.csv");
  RecordingProducts products;
  products.report = &report;
  const RecordingOutcome outcome = decideRecordingOutcome(passedRun());
  const std::vector<std::string> errors = writeRecordingOutputs(paths, outcome, products);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].rfind("--export-poses " + paths.export_poses, 0), 0u) << errors[0];
  EXPECT_EQ(errors[1].rfind("--imu-yaml " + paths.imu_yaml + ": no joint estimate", 0), 0u)
      << errors[1];
  const StoredCalibration stored = readResultYaml(paths.output);
  ASSERT_TRUE(stored.verdict);
  EXPECT_TRUE(stored.verdict->passed);
  EXPECT_EQ(failedVerdictNote(stored, paths.output), "");
  EXPECT_FALSE(std::filesystem::exists(paths.imu_yaml));
}

}  // namespace
}  // namespace camera_imu_alignment
