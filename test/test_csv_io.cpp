// CSV readers/writers and the result YAML: formats of doc/CONVENTIONS.md, errors naming file and
// line.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "camera_imu_alignment/io/csv_io.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

const std::string& tempDir() { return test::processTempDir(); }

std::string writeTemp(const std::string& name, const std::string& text) {
  return test::writeTempFile(name, text);
}

const Eigen::Vector3d kX = Eigen::Vector3d::UnitX(), kY = Eigen::Vector3d::UnitY(),
                      kZ = Eigen::Vector3d::UnitZ();

/// True when `msg` contains "path:<digit>".
bool namesALine(const std::string& msg, const std::string& path) {
  for (auto at = msg.find(path + ":"); at != std::string::npos; at = msg.find(path + ":", at + 1)) {
    const size_t next = at + path.size() + 1;
    if (next < msg.size() && std::isdigit(static_cast<unsigned char>(msg[next]))) return true;
  }
  return false;
}

/// Runs `read` (expected to throw InputError) and checks the message: it contains `path`, and
/// "path:line" when `line` > 0 (any "path:<number>" when line == 0; line unchecked when < 0), and
/// every string of `parts`.
template <typename Read>
void expectError(Read read, const std::string& path, int line,
                 const std::vector<std::string>& parts = {}) {
  try {
    read(path);
    ADD_FAILURE() << "no InputError for " << path;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << "'" << msg << "' does not name " << path;
    if (line > 0) {
      EXPECT_NE(msg.find(path + ":" + std::to_string(line)), std::string::npos)
          << "'" << msg << "' does not name line " << line;
    } else if (line == 0) {
      EXPECT_TRUE(namesALine(msg, path)) << "'" << msg << "' names no line of " << path;
    }
    for (const auto& part : parts)
      EXPECT_NE(msg.find(part), std::string::npos) << "'" << msg << "' lacks '" << part << "'";
  }
}

const auto readPairs = [](const std::string& p) { return readPairsCsv(p); };
const auto readPoses = [](const std::string& p) { return readPosesCsv(p); };

const std::string kPairsHeader = "qa_w,qa_x,qa_y,qa_z,qb_w,qb_x,qb_y,qb_z\n";
const std::string kPosesHeader = "stamp,cam_qw,cam_qx,cam_qy,cam_qz,imu_qw,imu_qx,imu_qy,imu_qz\n";

TEST(CsvIo, PairsColumnsInAnyOrderWithCrlfCommentsAndExtraColumns) {
  const double h = std::sqrt(0.5);
  std::ostringstream text;
  text.precision(17);
  text << "# a comment\r\n\r\n  \nnote,qb_x,qb_y,qb_z,qb_w,qa_w,extra,qa_x,qa_y,qa_z\r\n"
       << "first,0,0," << h << "," << h << ",1,99,0,0,0\r\n"
       << "# a comment between rows, then a blank line\r\n\r\n"
       << "second,0,0,0,-1,0,-5,1,0,0\r\n";
  const RotationPairs pairs = readPairsCsv(writeTemp("order.csv", text.str()));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_ROTATION_NEAR_DEG(pairs[0].A_cam, Eigen::Matrix3d::Identity(), 1e-12);
  EXPECT_ROTATION_NEAR_DEG(pairs[0].B_imu, test::axisAngle(kZ, test::kPiTest / 2), 1e-12);
  EXPECT_ROTATION_NEAR_DEG(pairs[1].B_imu, Eigen::Matrix3d::Identity(), 1e-12);  // q = -1
  EXPECT_ROTATION_NEAR_DEG(pairs[1].A_cam, test::axisAngle(kX, test::kPiTest), 1e-12);
  for (const auto& p : pairs) {
    EXPECT_EQ(p.pose_k, -1);  // independent pairs
    EXPECT_EQ(p.pose_t, -1);
  }
}

TEST(CsvIo, PosesColumnsInAnyOrderWithCrlfCommentsAndExtraColumns) {
  // Pose 0: camera 90 deg about y, IMU 90 deg about x; pose 1: camera identity, IMU 180 about z.
  const double h = std::sqrt(0.5);
  std::ostringstream text;
  text.precision(17);
  text << "# poses\r\nimu_qz,imu_qy,imu_qx,imu_qw,frame,cam_qz,cam_qy,cam_qx,cam_qw,stamp\r\n"
       << "0,0," << h << "," << h << ",17,0," << h << ",0," << h << ",12.25\r\n\r\n"
       << "1,0,0,0,18,0,0,0,-1,13.5\r\n";
  const auto poses = readPosesCsv(writeTemp("poses_order.csv", text.str()));
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].stamp_s, 12.25);
  EXPECT_EQ(poses[1].stamp_s, 13.5);
  EXPECT_ROTATION_NEAR_DEG(poses[0].R_target_cam, test::axisAngle(kY, test::kPiTest / 2), 1e-12);
  EXPECT_ROTATION_NEAR_DEG(poses[0].R_world_imu, test::axisAngle(kX, test::kPiTest / 2), 1e-12);
  EXPECT_ROTATION_NEAR_DEG(poses[1].R_target_cam, Eigen::Matrix3d::Identity(), 1e-12);
  EXPECT_ROTATION_NEAR_DEG(poses[1].R_world_imu, test::axisAngle(kZ, test::kPiTest), 1e-12);
}

TEST(CsvIo, NormalisesNearlyUnitQuaternionsAndTreatsQAndMinusQAlike) {
  // (0.5, 0.5, 0.5, 0.5) is 120 deg about (1, 1, 1); scaled by 1.001 it must read as the same.
  const Eigen::Matrix3d R120 = test::axisAngle(Eigen::Vector3d(1, 1, 1), 2 * test::kPiTest / 3);
  const std::string path = writeTemp("norm.csv", kPairsHeader +
                                                     "1.001,0,0,0,0.5005,0.5005,0.5005,0.5005\n"
                                                     "-1.001,0,0,0,-0.5,-0.5,-0.5,-0.5\n"
                                                     "0.999,0,0,0,0.4995,0.4995,0.4995,0.4995\n");
  const RotationPairs pairs = readPairsCsv(path);
  ASSERT_EQ(pairs.size(), 3u);
  for (const auto& p : pairs) {
    EXPECT_TRUE(isRotationMatrix(p.A_cam, 1e-14));
    EXPECT_TRUE(isRotationMatrix(p.B_imu, 1e-14));
    EXPECT_LT((p.A_cam - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_LT((p.B_imu - R120).norm(), 1e-14);
  }
  // The documented tolerance: accepted just inside, rejected just outside.
  const double inside = 1.0 + 0.5 * kQuaternionNormTolerance;
  const double outside = 1.0 + 2.0 * kQuaternionNormTolerance;
  EXPECT_NO_THROW(readPairsCsv(
      writeTemp("inside.csv", kPairsHeader + std::to_string(inside) + ",0,0,0,1,0,0,0\n")));
  expectError(
      readPairs,
      writeTemp("outside.csv", kPairsHeader + "1,0,0,0," + std::to_string(outside) + ",0,0,0\n"), 2,
      {"norm"});
}

TEST(CsvIo, PairsInputErrorsNameFileAndLine) {
  expectError(readPairs, "/nonexistent_dir/pairs.csv", -1);
  expectError(readPairs, writeTemp("empty.csv", ""), -1, {"empty"});  // 0 bytes: no line
  expectError(readPairs,
              writeTemp("bad_header.csv", "qa_w,qa_x,qa_y,qb_w,qb_x,qb_y,qb_z\n1,0,0,1,0,0,0\n"), 1,
              {"qa_z"});
  // Line numbers count every physical line, comments and blank lines included.
  const std::string lead = "# truth ...\n\n" + kPairsHeader + "1,0,0,0,1,0,0,0\n";  // rows at 4..
  expectError(readPairs, writeTemp("text.csv", lead + "1,0,zero,0,1,0,0,0\n"), 5, {"qa_y", "zero"});
  expectError(readPairs, writeTemp("half.csv", lead + "1,0,0,0,1,0.5x,0,0\n"), 5, {"qb_x"});
  expectError(readPairs, writeTemp("nan.csv", lead + "\n1,0,0,0,nan,0,0,0\n"), 6, {"qb_w"});
  expectError(readPairs, writeTemp("inf.csv", lead + "1,0,0,0,1,inf,0,0\n"), 5, {"qb_x"});
  expectError(readPairs, writeTemp("minf.csv", lead + "1,-inf,0,0,1,0,0,0\n"), 5, {"qa_x"});
  expectError(readPairs, writeTemp("huge.csv", lead + "1,0,0,0,1,1e999,0,0\n"), 5, {"qb_x"});
  expectError(readPairs, writeTemp("short.csv", lead + "1,0,0,0,1,0,0\n"), 5, {"qb_z"});
  expectError(readPairs, writeTemp("very_short.csv", lead + "1,0\n"), 5, {"missing"});
  expectError(readPairs, writeTemp("empty_cell.csv", lead + "1,0,,0,1,0,0,0\n"), 5, {"qa_y"});
  expectError(readPairs, writeTemp("big.csv", lead + "1.5,0,0,0,1,0,0,0\n"), 5, {"norm"});
  expectError(readPairs, writeTemp("zero.csv", lead + "1,0,0,0,0,0,0,0\n"), 5, {"norm"});
  expectError(readPairs,
              writeTemp("crlf_bad.csv",
                        "qa_w,qa_x,qa_y,qa_z,qb_w,qb_x,qb_y,qb_z\r\n"
                        "1,0,0,0,1,0,0,0\r\n1,0,0,0,2,0,0,0\r\n"),
              3, {"norm"});
  // A poses file given as pairs: the missing columns are named.
  expectError(readPairs, writeTemp("poses_as_pairs.csv", kPosesHeader + "0,1,0,0,0,1,0,0,0\n"), 1,
              {"qa_w"});
}

TEST(CsvIo, FilesWithoutDataRowsNameTheLine) {
  // csv_io.h: "Every problem is reported as an InputError naming the file and the line". A file
  // with lines but no data row has a line to name (the header, or the last line read).
  expectError(readPairs, writeTemp("comments_only.csv", "# nothing\n\n# here\n"), 0);
  expectError(readPairs, writeTemp("header_only.csv", kPairsHeader), 0, {"no data rows"});
  expectError(readPairs, writeTemp("header_blank.csv", kPairsHeader + "\n# c\n\n"), 0);
  expectError(readPoses, writeTemp("poses_header_only.csv", kPosesHeader), 0);
}

TEST(CsvIo, TinyFiniteValuesAreNotErrors) {
  // 1e-320 is finite (subnormal); strtod flags its underflow with ERANGE, which is no input error.
  const std::string path =
      writeTemp("tiny.csv", kPairsHeader + "1,1e-320,0,0,1,0,-2.5e-310,0\n1,1e-300,0,0,1,0,0,0\n");
  RotationPairs pairs;
  try {
    pairs = readPairsCsv(path);
  } catch (const InputError& e) {
    FAIL() << e.what();
  }
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_ROTATION_NEAR_DEG(pairs[0].A_cam, Eigen::Matrix3d::Identity(), 1e-12);
}

TEST(CsvIo, PosesInputErrorsNameFileAndLine) {
  expectError(readPoses, "/nonexistent_dir/poses.csv", -1);
  expectError(readPoses, writeTemp("poses_empty.csv", ""), -1);
  expectError(readPoses, writeTemp("poses_no_stamp.csv", kPairsHeader + "1,0,0,0,1,0,0,0\n"), 1,
              {"stamp"});
  const std::string lead = "# c\n" + kPosesHeader + "0,1,0,0,0,1,0,0,0\n";  // rows at 3..
  expectError(readPoses, writeTemp("poses_stamp.csv", lead + "t1,1,0,0,0,1,0,0,0\n"), 4, {"stamp"});
  expectError(readPoses, writeTemp("poses_nan.csv", lead + "nan,1,0,0,0,1,0,0,0\n"), 4, {"stamp"});
  expectError(readPoses, writeTemp("poses_norm.csv", lead + "1,1,0,0,0,0.5,0,0,0\n"), 4, {"norm"});
  expectError(readPoses, writeTemp("poses_short.csv", lead + "1,1,0,0,0,1,0,0\n"), 4, {"imu_qz"});
}

TEST(CsvIo, PairsAndPosesRoundTrip) {
  std::mt19937_64 rng(51);
  RotationPairs pairs(20);
  std::vector<PoseOrientation> poses(12);
  for (auto& p : pairs) {
    p.A_cam = test::randomRotation(rng);
    p.B_imu = test::randomRotation(rng);
  }
  pairs[0].A_cam = test::axisAngle(kZ, test::kPiTest);  // w = 0 exactly
  pairs[1].B_imu = Eigen::Matrix3d::Identity();
  for (size_t k = 0; k < poses.size(); ++k) {
    poses[k].stamp_s = 1.7e9 + 0.1 * k;  // Unix-time stamps keep sub-millisecond digits
    poses[k].R_target_cam = test::randomRotation(rng);
    poses[k].R_world_imu = test::randomRotation(rng);
  }
  const std::string pairs_path = tempDir() + "roundtrip_pairs.csv";
  const std::string poses_path = tempDir() + "roundtrip_poses.csv";
  writePairsCsv(pairs_path, pairs);
  writePosesCsv(poses_path, poses);
  const RotationPairs pairs_back = readPairsCsv(pairs_path);
  const auto poses_back = readPosesCsv(poses_path);
  ASSERT_EQ(pairs_back.size(), pairs.size());
  ASSERT_EQ(poses_back.size(), poses.size());
  for (size_t j = 0; j < pairs.size(); ++j) {
    EXPECT_LT((pairs_back[j].A_cam - pairs[j].A_cam).norm(), 1e-14);
    EXPECT_LT((pairs_back[j].B_imu - pairs[j].B_imu).norm(), 1e-14);
  }
  for (size_t k = 0; k < poses.size(); ++k) {
    EXPECT_EQ(poses_back[k].stamp_s, poses[k].stamp_s);
    EXPECT_LT((poses_back[k].R_target_cam - poses[k].R_target_cam).norm(), 1e-14);
    EXPECT_LT((poses_back[k].R_world_imu - poses[k].R_world_imu).norm(), 1e-14);
  }
  EXPECT_THROW(writePairsCsv("/nonexistent_dir/p.csv", pairs), InputError);
  EXPECT_THROW(writePosesCsv("/nonexistent_dir/p.csv", poses), InputError);
}

// ------------------------------------------------------------------------------------------------
// Result YAML
// ------------------------------------------------------------------------------------------------

/// A result with known values (no solver involved), as in doc/CONVENTIONS.md's example.
AlignmentResult knownResult(const Eigen::Matrix3d& R) {
  AlignmentResult r;
  r.status = SolveStatus::kOk;
  r.R_cam_imu = R;
  r.iterations = 9;
  r.quality.observable = true;
  r.quality.num_pairs = 66;
  r.quality.num_inliers = 64;
  r.quality.residual_rms_deg = 0.21;
  r.quality.std_dev_deg = Eigen::Vector3d(0.03, 0.04, 0.05);
  return r;
}

TEST(ResultYaml, HasEveryKeyOfTheConventions) {
  const Eigen::Matrix3d X = test::axisAngle(kZ, test::kPiTest / 2);  // 90 deg about z
  ResultMetadata meta;
  meta.camera_frame = "cam: #0 \"left\" \\ [x]";  // YAML syntax in names must survive
  meta.imu_frame = "- imu, {a}";
  meta.num_poses = 12;
  const YAML::Node y = YAML::Load(resultToYaml(knownResult(X), meta));
  EXPECT_EQ(y["camera_frame"].as<std::string>(), meta.camera_frame);
  EXPECT_EQ(y["imu_frame"].as<std::string>(), meta.imu_frame);
  const auto q = y["R_cam_imu"]["quaternion_xyzw"].as<std::vector<double>>();
  ASSERT_EQ(q.size(), 4u);  // x, y, z, w: [0, 0, 0.7071, 0.7071]
  EXPECT_NEAR(q[0], 0.0, 1e-9);
  EXPECT_NEAR(q[1], 0.0, 1e-9);
  EXPECT_NEAR(q[2], std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(q[3], std::sqrt(0.5), 1e-9);
  const auto m = y["R_cam_imu"]["matrix"].as<std::vector<std::vector<double>>>();
  const auto T = y["T_cam_imu"].as<std::vector<std::vector<double>>>();
  ASSERT_EQ(m.size(), 3u);
  ASSERT_EQ(T.size(), 4u);
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(m[i].size(), 3u);
    ASSERT_EQ(T[i].size(), 4u);
    EXPECT_EQ(T[i][3], 0.0);  // no joint estimate: the translation is not measured, zero
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(m[i][k], X(i, k), 1e-9);
      EXPECT_NEAR(T[i][k], X(i, k), 1e-9);
    }
  }
  EXPECT_EQ(T[3], (std::vector<double>{0, 0, 0, 1}));
  const YAML::Node quality = y["quality"];
  ASSERT_TRUE(quality.IsMap());
  EXPECT_TRUE(quality["observable"].as<bool>());
  EXPECT_EQ(quality["num_poses"].as<int>(), 12);
  EXPECT_EQ(quality["num_pairs"].as<int>(), 66);
  EXPECT_EQ(quality["num_inliers"].as<int>(), 64);
  EXPECT_NEAR(quality["residual_rms_deg"].as<double>(), 0.21, 1e-9);
  EXPECT_EQ(quality["std_dev_deg"].as<std::vector<double>>(),
            (std::vector<double>{0.03, 0.04, 0.05}));
  EXPECT_EQ(quality["iterations"].as<int>(), 9);
  EXPECT_FALSE(y["translation"]["measured"].as<bool>());
  EXPECT_NE(y["translation"]["source"].as<std::string>().find("keep your measured translation"),
            std::string::npos);
  // Measured by the motion: T_cam_imu's translation, its 1-sigma.
  AlignmentResult with_lever_arm = knownResult(X);
  JointResult joint;
  joint.ok = true;
  joint.motion_nodes = 500;
  joint.lever_arm_in_model = joint.lever_arm_measured = true;
  joint.p_cam_imu_m = Eigen::Vector3d(-0.0449, -0.0206, -0.0086);
  joint.p_cam_imu_sigma_m = Eigen::Vector3d(0.002, 0.003, 0.004);
  with_lever_arm.joint = joint;
  const YAML::Node measured = YAML::Load(resultToYaml(with_lever_arm, meta));
  const auto Tm = measured["T_cam_imu"].as<std::vector<std::vector<double>>>();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(Tm[i][3], joint.p_cam_imu_m(i), 1e-9);
  EXPECT_TRUE(measured["translation"]["measured"].as<bool>());
  EXPECT_EQ(measured["translation"]["sigma_m"].as<std::vector<double>>(),
            (std::vector<double>{0.002, 0.003, 0.004}));
  AlignmentResult unobservable = knownResult(X);
  unobservable.quality.observable = false;
  EXPECT_FALSE(YAML::Load(resultToYaml(unobservable, meta))["quality"]["observable"].as<bool>());
}

TEST(ResultYaml, QuaternionAndMatricesDescribeTheSameRotation) {
  std::mt19937_64 rng(54);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix3d X = test::randomRotation(rng);
    const YAML::Node y = YAML::Load(resultToYaml(knownResult(X), ResultMetadata{}));
    const auto q = y["R_cam_imu"]["quaternion_xyzw"].as<std::vector<double>>();
    ASSERT_EQ(q.size(), 4u);
    EXPECT_NEAR(std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]), 1.0, 1e-11);
    EXPECT_ROTATION_NEAR_DEG(Eigen::Quaterniond(q[3], q[0], q[1], q[2]).toRotationMatrix(), X,
                             1e-9);
    const auto m = y["R_cam_imu"]["matrix"].as<std::vector<std::vector<double>>>();
    const auto T = y["T_cam_imu"].as<std::vector<std::vector<double>>>();
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(m[i][k], X(i, k), 1e-8);
        EXPECT_NEAR(T[i][k], X(i, k), 1e-8);
      }
    }
  }
}

TEST(ResultYaml, WriteThenReadRoundTrips) {
  std::mt19937_64 rng(53);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d X = test::randomRotation(rng);
    ResultMetadata meta;
    meta.camera_frame = "cam" + std::to_string(trial);
    meta.imu_frame = "imu_link";
    const std::string path = tempDir() + "result.yaml";
    writeResultYaml(path, knownResult(X), meta);  // overwrites the previous trial's file
    const StoredCalibration back = readResultYaml(path);
    EXPECT_ROTATION_NEAR_DEG(back.R_cam_imu, X, 1e-9);
    EXPECT_EQ(back.camera_frame, meta.camera_frame);
    EXPECT_EQ(back.imu_frame, "imu_link");
  }
  // Only the matrix (9 digits): read through it.
  const Eigen::Matrix3d X = test::randomRotation(rng);
  std::ostringstream text;
  text.precision(17);
  text << "R_cam_imu:\n  matrix: [";
  for (int i = 0; i < 3; ++i)
    text << (i ? ", " : "") << "[" << X(i, 0) << ", " << X(i, 1) << ", " << X(i, 2) << "]";
  text << "]\n";
  EXPECT_ROTATION_NEAR_DEG(readResultYaml(writeTemp("matrix_only.yaml", text.str())).R_cam_imu, X,
                           1e-9);
}

TEST(ResultYaml, FailedWritesThrowAndLeaveNoTrace) {
  const AlignmentResult r = knownResult(Eigen::Matrix3d::Identity());
  expectError([&](const std::string& p) { writeResultYaml(p, r, ResultMetadata{}); },
              "/nonexistent_dir/x.yaml", -1);
  // The target is a directory: the write fails; the directory stays and no temporary file is left.
  const std::string dir_target = tempDir() + "a_directory";
  std::filesystem::create_directory(dir_target);  // may exist from a repeated run
  ASSERT_TRUE(std::filesystem::is_directory(dir_target));
  const auto entries = [] {
    return std::distance(std::filesystem::directory_iterator(tempDir()),
                         std::filesystem::directory_iterator());
  };
  const auto entries_before = entries();
  expectError([&](const std::string& p) { writeResultYaml(p, r, ResultMetadata{}); }, dir_target,
              -1);
  EXPECT_TRUE(std::filesystem::is_directory(dir_target));
  EXPECT_EQ(entries(), entries_before);
}

TEST(ResultYaml, ReadOnlyDirectoryKeepsThePreviousFile) {
  // A directory the writer may read but not write, reachable by everyone (not under the 0700
  // per-process temp dir, so that the unprivileged child gets as far as the write).
  char pattern[] = "/tmp/cia_read_only_XXXXXX";
  ASSERT_NE(mkdtemp(pattern), nullptr);
  const std::string dir = std::string(pattern) + "/";
  const std::string path = dir + "result.yaml";
  const Eigen::Matrix3d before = test::axisAngle(kX, 0.3);
  writeResultYaml(path, knownResult(before), ResultMetadata{});
  ASSERT_EQ(chmod(path.c_str(), 0644), 0);
  ASSERT_EQ(chmod(dir.c_str(), 0555), 0);
  const bool refused = test::asUnprivilegedUser([&] {
    try {
      writeResultYaml(path, knownResult(Eigen::Matrix3d::Identity()), ResultMetadata{});
    } catch (const InputError& e) {
      const std::string what = e.what();
      return what.find("Permission denied") != std::string::npos &&
             what.find("previous file is unchanged") != std::string::npos;
    }
    return false;
  });
  chmod(dir.c_str(), 0755);
  EXPECT_TRUE(refused) << "the write into a read-only directory did not fail with a clear error";
  EXPECT_ROTATION_NEAR_DEG(readResultYaml(path).R_cam_imu, before, 1e-9);
  std::filesystem::remove_all(dir);
}

TEST(CsvIo, PoseGroupsSurviveTheFileAndAreNeverPaired) {
  // calibrate_bag --export-poses: poses of two gyro chains (groups) must not be paired by
  // solve_rotation either. A single group keeps the plain header.
  std::mt19937_64 rng(5);
  std::vector<PoseOrientation> poses(4);
  for (int i = 0; i < 4; ++i) {
    poses[i].stamp_s = i;
    poses[i].R_target_cam = test::randomRotation(rng);
    poses[i].R_world_imu = test::randomRotation(rng);
    poses[i].group = i / 2;
  }
  const std::string two = tempDir() + "two_groups.csv", one = tempDir() + "one_group.csv";
  writePosesCsv(two, poses);
  const std::vector<PoseOrientation> read = readPosesCsv(two);
  ASSERT_EQ(read.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(read[i].group, i / 2);
  EXPECT_EQ(makeAllPairs(read).size(), 2u);  // (0, 1) and (2, 3), not 6
  for (auto& p : poses) p.group = 3;
  writePosesCsv(one, poses);
  std::ifstream in(one);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "stamp,cam_qw,cam_qx,cam_qy,cam_qz,imu_qw,imu_qx,imu_qy,imu_qz");
  EXPECT_EQ(makeAllPairs(readPosesCsv(one)).size(), 6u);
  std::ofstream(tempDir() + "bad_group.csv")
      << "stamp,cam_qw,cam_qx,cam_qy,cam_qz,imu_qw,imu_qx,imu_qy,imu_qz,group\n"
      << "0,1,0,0,0,1,0,0,0,1.5\n";
  EXPECT_THROW(readPosesCsv(tempDir() + "bad_group.csv"), InputError);
}

TEST(ResultYaml, FullDiskKeepsThePreviousFile) {
  // The temporary file is a link to /dev/full: every write fails with ENOSPC, also for root.
  const std::string path = tempDir() + "disk_full.yaml";
  const Eigen::Matrix3d before = test::axisAngle(kX, 0.3);
  writeResultYaml(path, knownResult(before), ResultMetadata{});
  std::filesystem::remove(path + ".tmp");
  std::filesystem::create_symlink("/dev/full", path + ".tmp");
  try {
    writeResultYaml(path, knownResult(Eigen::Matrix3d::Identity()), ResultMetadata{});
    ADD_FAILURE() << "writing to a full disk did not fail";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
  }
  EXPECT_ROTATION_NEAR_DEG(readResultYaml(path).R_cam_imu, before, 1e-9);
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(path + ".tmp")));
}

TEST(ResultYaml, TheVerdictBlockIsWrittenReadAndAFailedOneIsNoted) {
  const Eigen::Matrix3d X = test::axisAngle(kX, 0.2);
  ResultMetadata meta;
  const std::string plain = tempDir() + "no_verdict.yaml";
  writeResultYaml(plain, knownResult(X), meta);  // solve_rotation: no gates, no block
  EXPECT_FALSE(readResultYaml(plain).verdict);
  EXPECT_EQ(failedVerdictNote(readResultYaml(plain), plain), "");
  meta.verdict = ResultVerdict{false, "FAILED: joint estimate inconsistent \"chi2\"", true};
  const std::string forced = tempDir() + "forced.yaml";
  writeResultYaml(forced, knownResult(X), meta);
  const StoredCalibration stored = readResultYaml(forced);
  ASSERT_TRUE(stored.verdict);
  EXPECT_FALSE(stored.verdict->passed);
  EXPECT_TRUE(stored.verdict->forced);
  EXPECT_EQ(stored.verdict->text, "FAILED: joint estimate inconsistent \"chi2\"");
  EXPECT_ROTATION_NEAR_DEG(stored.R_cam_imu, X, 1e-9);  // the rotation reads as before
  EXPECT_EQ(failedVerdictNote(stored, forced),
            forced +
                " holds an estimate that FAILED its quality gates, written on request "
                "(force): joint estimate inconsistent \"chi2\"");
  // A block without its verdict is an error naming the key, not a silent pass.
  const std::string text = "R_cam_imu:\n  quaternion_xyzw: [0, 0, 0, 1]\nverdict: FAILED\n";
  try {
    readResultYaml(writeTemp("bad_verdict.yaml", text));
    ADD_FAILURE() << "a verdict without passed was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("verdict needs the key passed"), std::string::npos)
        << e.what();
  }
}

TEST(ResultYaml, CorruptSavedFileIsSetAsideAndTheNodeStartsFresh) {
  std::string warning;
  EXPECT_FALSE(loadSavedCalibration(tempDir() + "never_saved.yaml", &warning));
  EXPECT_TRUE(warning.empty());
  const std::string good = tempDir() + "saved_good.yaml";
  const Eigen::Matrix3d X = test::axisAngle(kX, 0.4);
  writeResultYaml(good, knownResult(X), ResultMetadata{});
  const auto loaded = loadSavedCalibration(good, &warning);
  ASSERT_TRUE(loaded) << warning;
  EXPECT_ROTATION_NEAR_DEG(loaded->R_cam_imu, X, 1e-9);
  const std::string corrupt =
      writeTemp("saved_corrupt.yaml", "R_cam_imu:\n  quaternion_xyzw: [0, 0");
  std::filesystem::remove(corrupt + ".bad");
  EXPECT_FALSE(loadSavedCalibration(corrupt, &warning));
  EXPECT_NE(warning.find("saved_corrupt.yaml"), std::string::npos) << warning;
  EXPECT_NE(warning.find(".bad"), std::string::npos) << warning;
  EXPECT_FALSE(std::filesystem::exists(corrupt));
  EXPECT_TRUE(std::filesystem::exists(corrupt + ".bad"));
  EXPECT_FALSE(loadSavedCalibration(corrupt, &warning));  // next start: nothing left to read
  EXPECT_TRUE(warning.empty());
}

TEST(ResultYaml, ReaderErrorsNameTheFileAndTheProblem) {
  const auto read = [](const std::string& p) { return readResultYaml(p); };
  expectError(read, "/nonexistent_dir/result.yaml", -1);
  expectError(read, writeTemp("invalid.yaml", "camera_frame: c\nR_cam_imu: [unclosed\n"), 0);
  expectError(read, writeTemp("tabs.yaml", "R_cam_imu:\n\tquaternion_xyzw: [0, 0, 0, 1]\n"), 0);
  expectError(read, writeTemp("nokey.yaml", "camera_frame: c\n"), -1, {"R_cam_imu"});
  expectError(read, writeTemp("empty.yaml", ""), -1, {"R_cam_imu"});
  expectError(read, writeTemp("scalar.yaml", "just text\n"), -1);
  expectError(read, writeTemp("scalar_rot.yaml", "R_cam_imu: 5\n"), -1);
  expectError(read, writeTemp("neither.yaml", "R_cam_imu:\n  angle: 1\n"), -1, {"R_cam_imu"});
  expectError(read, writeTemp("badq.yaml", "R_cam_imu:\n  quaternion_xyzw: [0, 0, 0, 2]\n"), -1,
              {"quaternion_xyzw", "unit"});
  expectError(read, writeTemp("zeroq.yaml", "R_cam_imu:\n  quaternion_xyzw: [0, 0, 0, 0]\n"), -1,
              {"quaternion_xyzw"});
  expectError(read, writeTemp("nanq.yaml", "R_cam_imu:\n  quaternion_xyzw: [.nan, 0, 0, 1]\n"), -1,
              {"quaternion_xyzw"});
  expectError(read, writeTemp("shortq.yaml", "R_cam_imu:\n  quaternion_xyzw: [0, 0, 1]\n"), -1,
              {"quaternion_xyzw"});
  expectError(read, writeTemp("textq.yaml", "R_cam_imu:\n  quaternion_xyzw: [a, b, c, d]\n"), -1);
  expectError(read,
              writeTemp("badm.yaml", "R_cam_imu:\n  matrix: [[1, 0, 0], [0, 1, 0], [0, 0, 2]]\n"),
              -1, {"matrix"});
  expectError(read,
              writeTemp("refl.yaml", "R_cam_imu:\n  matrix: [[1, 0, 0], [0, 1, 0], [0, 0, -1]]\n"),
              -1, {"matrix"});
  // A hand edit of one of the two forms (the quaternion turned 90 deg about z, the matrix kept):
  // refused, naming both keys and the angle.
  expectError(read,
              writeTemp("disagree.yaml",
                        "R_cam_imu:\n  quaternion_xyzw: [0, 0, 0.70710678, 0.70710678]\n"
                        "  matrix: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n"),
              -1, {"quaternion_xyzw", "matrix", "deg apart"});
  // Agreeing to the matrix's 4 typed decimals (0.005 deg): read.
  EXPECT_NO_THROW(readResultYaml(
      writeTemp("agree.yaml",
                "R_cam_imu:\n  quaternion_xyzw: [0, 0, 0.70710678, 0.70710678]\n"
                "  matrix: [[0.0000, -1.0000, 0], [1.0000, 0.0000, 0], [0, 0, 1]]\n")));
}

}  // namespace
}  // namespace camera_imu_alignment
