// solve_rotation end to end: the real binary, its exit codes (0 ok, 2 bad input, 3 not observable),
// messages naming the file/line/axis, and results against known truths.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <random>

#include "camera_imu_alignment/csv_io.h"
#include "camera_imu_alignment/result_yaml.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// Runs a command under `timeout` (a hang fails the test instead of blocking it).
RunResult run(const std::string& args) {
  const std::string dir = ::testing::TempDir();
  const std::string out_path = dir + "cia_cli_stdout.txt", err_path = dir + "cia_cli_stderr.txt";
  const std::string cmd = "timeout 60 " + args + " >" + out_path + " 2>" + err_path;
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream out(out_path), err(err_path);
  r.out.assign(std::istreambuf_iterator<char>(out), {});
  r.err.assign(std::istreambuf_iterator<char>(err), {});
  return r;
}

const std::string kSolve = SOLVE_ROTATION_EXE;
const std::string kGenerate = GENERATE_EXAMPLE_EXE;
const std::string kData = TEST_DATA_DIR;

std::string temp(const std::string& name) { return ::testing::TempDir() + "cia_cli_" + name; }

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = temp(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

Eigen::Matrix3d resultRotation(const std::string& yaml_text) {
  const auto q = YAML::Load(yaml_text)["R_cam_imu"]["quaternion_xyzw"].as<std::vector<double>>();
  return Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
}

TEST(SolveRotationCli, HelpExitsZero) {
  const RunResult r = run(kSolve + " --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--pairs"), std::string::npos);
}

TEST(SolveRotationCli, GoldenPairsFileIsSolvedExactly) {
  // test/data/pairs_golden.csv: noise-free pairs of a known mounting (in its first comment line).
  const Eigen::Matrix3d truth = Eigen::Quaterniond(0.4849133775367413, 0.49991250255205361,
                                                   -0.50991191922892842, 0.5049122108904911)
                                    .toRotationMatrix();
  const RunResult r = run(kSolve + " --pairs " + kData + "/pairs_golden.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(test::angleBetweenDeg(resultRotation(r.out), truth), 1e-6);
  EXPECT_EQ(YAML::Load(r.out)["solver"]["method"].as<std::string>(), "optimal");
  // This mounting is 120 deg from the identity: the paper's two-step, started there, settles on a
  // wrong fixed point. The tool must say so (exit 3), not hand it out as a result.
  const RunResult two_step =
      run(kSolve + " --pairs " + kData + "/pairs_golden.csv --method two_step");
  EXPECT_EQ(two_step.exit_code, 3) << two_step.err;
  EXPECT_NE(two_step.err.find("does not fit"), std::string::npos) << two_step.err;
  EXPECT_EQ(YAML::Load(two_step.out)["solver"]["method"].as<std::string>(), "two_step");
}

TEST(SolveRotationCli, TwoStepMethodSolvesAModerateMounting) {
  std::mt19937_64 rng(63);
  const Eigen::Matrix3d X = test::axisAngle(test::randomUnitVector(rng), 0.6);
  RotationPairs pairs;
  for (int j = 0; j < 20; ++j) pairs.push_back(test::exactPair(X, test::randomRotation(rng)));
  const std::string path = temp("moderate.csv");
  writePairsCsv(path, pairs);
  const RunResult r = run(kSolve + " --pairs " + path + " --method two_step");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(test::angleBetweenDeg(resultRotation(r.out), X), 1e-6);
  EXPECT_EQ(YAML::Load(r.out)["solver"]["method"].as<std::string>(), "two_step");
}

TEST(SolveRotationCli, GeneratedExampleWithinItsOneSigma) {
  const std::string poses = temp("poses.csv"), truth_path = temp("truth.yaml"),
                    output = temp("out.yaml");
  ASSERT_EQ(
      run(kGenerate + " --seed 3 --poses-out " + poses + " --truth-out " + truth_path).exit_code,
      0);
  const RunResult r =
      run(kSolve + " --poses " + poses + " --truth " + truth_path + " --output " + output);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << "--output must keep stdout free";
  EXPECT_NE(r.err.find("error to the truth"), std::string::npos);
  const YAML::Node y = YAML::LoadFile(output);
  const Eigen::Matrix3d truth = readResultYaml(truth_path).R_cam_imu;
  const Eigen::Matrix3d estimate = readResultYaml(output).R_cam_imu;
  const auto sigma = y["quality"]["std_dev_deg"].as<std::vector<double>>();
  const double sigma_norm =
      std::sqrt(sigma[0] * sigma[0] + sigma[1] * sigma[1] + sigma[2] * sigma[2]);
  const double error = test::angleBetweenDeg(estimate, truth);
  EXPECT_LT(error, 3.0 * sigma_norm);
  EXPECT_LT(error, 1.0);
  EXPECT_EQ(y["quality"]["num_poses"].as<int>(), 12);
  EXPECT_EQ(y["quality"]["num_pairs"].as<int>(), 66);
}

TEST(SolveRotationCli, PairsFileFromPosesGivesTheSameAnswer) {
  const std::string poses = temp("poses2.csv"), pairs = temp("pairs2.csv"),
                    truth_path = temp("truth2.yaml");
  ASSERT_EQ(run(kGenerate + " --seed 5 --poses-out " + poses + " --pairs-out " + pairs +
                " --truth-out " + truth_path)
                .exit_code,
            0);
  const RunResult from_pairs = run(kSolve + " --pairs " + pairs);
  const RunResult from_poses = run(kSolve + " --poses " + poses);
  ASSERT_EQ(from_pairs.exit_code, 0) << from_pairs.err;
  ASSERT_EQ(from_poses.exit_code, 0) << from_poses.err;
  // Same pairs, same estimate; only the covariance model differs (independent vs shared poses).
  EXPECT_LT(test::angleBetweenDeg(resultRotation(from_pairs.out), resultRotation(from_poses.out)),
            1e-6);
}

void expectBadInput(const std::string& args, const std::vector<std::string>& parts) {
  const RunResult r = run(kSolve + " " + args);
  EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
  for (const auto& part : parts)
    EXPECT_NE(r.err.find(part), std::string::npos) << args << ": " << r.err;
}

TEST(SolveRotationCli, BadInputExitsTwoNamingFileAndLine) {
  const std::string header = "qa_w,qa_x,qa_y,qa_z,qb_w,qb_x,qb_y,qb_z\n";
  expectBadInput("--pairs /nonexistent/pairs.csv", {"/nonexistent/pairs.csv"});
  expectBadInput("--pairs " + writeFile("hdr.csv", "a,b,c\n1,2,3\n"), {"hdr.csv:1", "header"});
  expectBadInput("--pairs " + writeFile("nan.csv", header + "1,0,0,0,1,0,0,0\nnan,0,0,0,1,0,0,0\n"),
                 {"nan.csv:3"});
  expectBadInput("--pairs " + writeFile("rows.csv", header), {"rows.csv", "no data rows"});
  expectBadInput("--pairs " + writeFile("unit.csv", header + "2,0,0,0,1,0,0,0\n"),
                 {"unit.csv:2", "norm"});
  expectBadInput("--poses " + writeFile("poses_hdr.csv", header + "1,0,0,0,1,0,0,0\n"),
                 {"poses_hdr.csv:1", "stamp"});
  expectBadInput("--bogus", {"unknown argument"});
  expectBadInput("", {"exactly one"});
  expectBadInput("--pairs a.csv --poses b.csv", {"exactly one"});
  expectBadInput("--pairs " + kData + "/pairs_golden.csv --method bogus", {"--method"});
  expectBadInput("--pairs " + kData + "/pairs_golden.csv --max-iterations 0", {"--max-iterations"});
  expectBadInput("--pairs " + kData + "/pairs_golden.csv --max-iterations abc",
                 {"--max-iterations"});
  expectBadInput("--pairs " + kData + "/pairs_golden.csv --max-iterations", {"needs a value"});
  expectBadInput("--pairs " + kData + "/pairs_golden.csv --truth /nonexistent/t.yaml",
                 {"/nonexistent/t.yaml"});
}

TEST(SolveRotationCli, GarbageFilesNeverCrash) {
  std::mt19937_64 rng(61);
  for (int trial = 0; trial < 20; ++trial) {
    std::string bytes(1 + rng() % 4000, '\0');
    for (auto& c : bytes) c = static_cast<char>(rng() % 256);
    if (trial % 2) bytes = "qa_w,qa_x,qa_y,qa_z,qb_w,qb_x,qb_y,qb_z\n" + bytes;
    const RunResult r = run(kSolve + " --pairs " + writeFile("garbage.csv", bytes));
    EXPECT_TRUE(r.exit_code == 2 || r.exit_code == 3) << "exit " << r.exit_code << ": " << r.err;
  }
}

TEST(SolveRotationCli, SingleAxisMotionExitsThreeNamingTheAxis) {
  // All camera rotations about camera z (the IMU axis R^T z): not observable about camera z.
  std::mt19937_64 rng(62);
  const Eigen::Matrix3d X = test::randomRotation(rng);
  RotationPairs pairs;
  for (int j = 0; j < 10; ++j) {
    pairs.push_back(test::exactPair(
        X, test::axisAngle(X.transpose() * Eigen::Vector3d::UnitZ(), 0.2 + 0.25 * j)));
  }
  const std::string path = temp("single_axis.csv");
  writePairsCsv(path, pairs);
  const RunResult r = run(kSolve + " --pairs " + path);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("not observable"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("camera z"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("camera x or y"), std::string::npos) << r.err;
  EXPECT_FALSE(YAML::Load(r.out)["quality"]["observable"].as<bool>());
}

TEST(SolveRotationCli, TooLittleDataExitsThree) {
  const RunResult one_pose =
      run(kSolve + " --poses " +
          writeFile("one_pose.csv",
                    "stamp,cam_qw,cam_qx,cam_qy,cam_qz,imu_qw,imu_qx,imu_qy,imu_qz\n"
                    "0,1,0,0,0,1,0,0,0\n"));
  EXPECT_EQ(one_pose.exit_code, 3) << one_pose.err;
  EXPECT_NE(one_pose.err.find("single pose"), std::string::npos) << one_pose.err;
  const RunResult one_pair = run(kSolve + " --pairs " +
                                 writeFile("one_pair.csv",
                                           "qa_w,qa_x,qa_y,qa_z,qb_w,qb_x,qb_y,qb_z\n"
                                           "0.9,0.43588989,0,0,0.9,0,0.43588989,0\n"));
  EXPECT_EQ(one_pair.exit_code, 3) << one_pair.err;
  EXPECT_NE(one_pair.err.find("rotate the rig about"), std::string::npos) << one_pair.err;
}

}  // namespace
}  // namespace camera_imu_alignment
