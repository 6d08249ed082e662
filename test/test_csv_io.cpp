// CSV readers/writers and the result YAML: formats of CONVENTIONS.md, errors naming file and line.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>

#include "camera_imu_alignment/csv_io.h"
#include "camera_imu_alignment/result_yaml.h"
#include "camera_imu_alignment/rotation_math.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "cia_" + name;
  std::ofstream(path) << text;
  return path;
}

/// Expects readPairsCsv to throw an InputError whose message contains all of `parts`.
void expectPairsError(const std::string& path, const std::vector<std::string>& parts) {
  try {
    readPairsCsv(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const auto& part : parts)
      EXPECT_NE(msg.find(part), std::string::npos) << msg << " lacks " << part;
  }
}

const char* kHeader = "qa_w,qa_x,qa_y,qa_z,qb_w,qb_x,qb_y,qb_z\n";

TEST(CsvIo, ReadsColumnsByNameInAnyOrder) {
  const std::string path =
      writeTemp("order.csv",
                "# a comment\n\nnote,qb_x,qb_y,qb_z,qb_w,qa_w,qa_x,qa_y,qa_z\r\n"
                "first,0,0,0.70710678,0.70710678,1,0,0,0\r\n"
                "second,0,0,0,-1,0,1,0,0\r\n");
  const RotationPairs pairs = readPairsCsv(path);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_LT((pairs[0].A_cam - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT((pairs[0].B_imu - test::axisAngle(Eigen::Vector3d::UnitZ(), test::kPiTest / 2)).norm(),
            1e-7);
  EXPECT_LT((pairs[1].B_imu - Eigen::Matrix3d::Identity()).norm(),
            1e-12);  // q = -1 is the identity
  EXPECT_LT((pairs[1].A_cam - test::axisAngle(Eigen::Vector3d::UnitX(), test::kPiTest)).norm(),
            1e-12);
  EXPECT_EQ(pairs[0].pose_k, -1);
}

TEST(CsvIo, NormalisesNearlyUnitQuaternionsAndTreatsQAndMinusQAlike) {
  const std::string path = writeTemp("norm.csv", std::string(kHeader) +
                                                     "1.001,0,0,0,0.5,0.5,0.5,0.5\n"
                                                     "-1.001,0,0,0,-0.5,-0.5,-0.5,-0.5\n");
  const RotationPairs pairs = readPairsCsv(path);
  EXPECT_TRUE(isRotationMatrix(pairs[0].A_cam, 1e-12));
  EXPECT_LT((pairs[0].A_cam - pairs[1].A_cam).norm(), 1e-12);
  EXPECT_LT((pairs[0].B_imu - pairs[1].B_imu).norm(), 1e-12);
}

TEST(CsvIo, BadInputNamesFileAndLine) {
  expectPairsError("/nonexistent/pairs.csv", {"/nonexistent/pairs.csv", "cannot open"});
  expectPairsError(writeTemp("empty.csv", ""), {"empty.csv", "empty"});
  expectPairsError(writeTemp("header_only.csv", kHeader), {"header_only.csv", "no data rows"});
  expectPairsError(
      writeTemp("bad_header.csv", "qa_w,qa_x,qa_y,qb_w,qb_x,qb_y,qb_z\n1,0,0,1,0,0,0\n"),
      {"bad_header.csv:1", "qa_z"});
  expectPairsError(
      writeTemp("text.csv", std::string(kHeader) + "1,0,0,0,1,0,0,0\n1,0,zero,0,1,0,0,0\n"),
      {"text.csv:3", "qa_y", "not a number"});
  expectPairsError(writeTemp("nan.csv", std::string(kHeader) + "1,0,0,0,nan,0,0,0\n"),
                   {"nan.csv:2", "not finite"});
  expectPairsError(writeTemp("inf.csv", std::string(kHeader) + "1,0,0,0,1,inf,0,0\n"),
                   {"inf.csv:2", "not finite"});
  expectPairsError(writeTemp("short.csv", std::string(kHeader) + "1,0,0,0,1,0\n"),
                   {"short.csv:2", "missing value"});
  expectPairsError(writeTemp("big.csv", std::string(kHeader) + "1.5,0,0,0,1,0,0,0\n"),
                   {"big.csv:2", "norm"});
  expectPairsError(writeTemp("zero.csv", std::string(kHeader) + "1,0,0,0,0,0,0,0\n"),
                   {"zero.csv:2", "norm"});
}

TEST(CsvIo, PairsAndPosesRoundTrip) {
  std::mt19937_64 rng(51);
  RotationPairs pairs(5);
  std::vector<PoseOrientation> poses(4);
  for (auto& p : pairs) {
    p.A_cam = test::randomRotation(rng);
    p.B_imu = test::randomRotation(rng);
  }
  for (size_t k = 0; k < poses.size(); ++k) {
    poses[k].stamp_s = 1.5 * k;
    poses[k].R_target_cam = test::randomRotation(rng);
    poses[k].R_world_imu = test::randomRotation(rng);
  }
  const std::string pairs_path = ::testing::TempDir() + "cia_roundtrip_pairs.csv";
  const std::string poses_path = ::testing::TempDir() + "cia_roundtrip_poses.csv";
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
}

AlignmentResult solvedExample(const Eigen::Matrix3d& X) {
  std::mt19937_64 rng(52);
  RotationPairs pairs;
  for (int j = 0; j < 10; ++j) pairs.push_back(test::exactPair(X, test::randomRotation(rng)));
  return solveAlignment(pairs);
}

TEST(ResultYaml, HasEveryKeyOfTheConventionsInTheRightOrder) {
  const Eigen::Matrix3d X = test::axisAngle(Eigen::Vector3d::UnitZ(), test::kPiTest / 2);
  const AlignmentResult r = solvedExample(X);
  ResultMetadata meta;
  meta.camera_frame = "cam0_optical";
  meta.imu_frame = "imu0";
  meta.num_poses = 0;
  const YAML::Node y = YAML::Load(resultToYaml(r, meta));
  EXPECT_EQ(y["camera_frame"].as<std::string>(), "cam0_optical");
  EXPECT_EQ(y["imu_frame"].as<std::string>(), "imu0");
  const auto q = y["R_cam_imu"]["quaternion_xyzw"].as<std::vector<double>>();
  ASSERT_EQ(q.size(), 4u);  // x, y, z, w: 90 deg about z
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
    EXPECT_EQ(T[i][3], 0.0);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(m[i][k], X(i, k), 1e-8);
      EXPECT_EQ(T[i][k], m[i][k]);
    }
  }
  EXPECT_EQ(T[3], (std::vector<double>{0, 0, 0, 1}));
  const YAML::Node quality = y["quality"];
  EXPECT_TRUE(quality["observable"].as<bool>());
  EXPECT_EQ(quality["num_poses"].as<int>(), 0);
  EXPECT_EQ(quality["num_pairs"].as<int>(), 10);
  EXPECT_EQ(quality["num_inliers"].as<int>(), 10);
  EXPECT_GE(quality["residual_rms_deg"].as<double>(), 0.0);
  EXPECT_EQ(quality["std_dev_deg"].as<std::vector<double>>().size(), 3u);
  EXPECT_GE(quality["iterations"].as<int>(), 1);
  const auto inverse = y["R_imu_cam"]["matrix"].as<std::vector<std::vector<double>>>();
  EXPECT_NEAR(inverse[0][1], X(1, 0), 1e-8);
}

TEST(ResultYaml, WritesAtomicallyAndReadsBack) {
  std::mt19937_64 rng(53);
  const Eigen::Matrix3d X = test::randomRotation(rng);
  const std::string path = ::testing::TempDir() + "cia_result.yaml";
  writeResultYaml(path, solvedExample(X), ResultMetadata{});
  const StoredCalibration back = readResultYaml(path);
  EXPECT_LT(test::angleBetweenDeg(back.R_cam_imu, X), 1e-9);
  EXPECT_EQ(back.camera_frame, "camera_optical_frame");
  EXPECT_THROW(writeResultYaml("/nonexistent_dir/result.yaml", solvedExample(X), ResultMetadata{}),
               InputError);
  // A failed write leaves no temporary file and the previous file intact.
  EXPECT_FALSE(std::ifstream(path + ".tmp").good());
  EXPECT_LT(test::angleBetweenDeg(readResultYaml(path).R_cam_imu, X), 1e-9);
}

TEST(ResultYaml, ReaderErrorsNameTheFile) {
  const auto expectError = [](const std::string& path, const std::string& part) {
    try {
      readResultYaml(path);
      ADD_FAILURE() << "no error for " << path;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  expectError("/nonexistent/result.yaml", "/nonexistent/result.yaml");
  expectError(writeTemp("invalid.yaml", "R_cam_imu: [unclosed\n"), "invalid.yaml");
  expectError(writeTemp("nokey.yaml", "camera_frame: c\n"), "no R_cam_imu");
  expectError(writeTemp("badq.yaml", "R_cam_imu:\n  quaternion_xyzw: [0, 0, 0, 2]\n"),
              "unit quaternion");
  expectError(writeTemp("badm.yaml", "R_cam_imu:\n  matrix: [[1, 0, 0], [0, 1, 0], [0, 0, 2]]\n"),
              "rotation");
}

}  // namespace
}  // namespace camera_imu_alignment
