// Atomic writes (io/atomic_file.h) and the writers that go through them: the contents arrive
// whole, a failed write (missing folder, read-only folder, full disk) throws naming the file and
// leaves the previous file and no temporary one; whyNotWritable says the same before any write.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/io/atomic_file.h"
#include "camera_imu_alignment/io/calibration_report.h"
#include "camera_imu_alignment/io/csv_io.h"
#include "report_inputs.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

std::string temp(const std::string& name) { return test::tempPath(name); }

/// `path + ".tmp"` made a link to /dev/full: every write to it fails with ENOSPC, also for root.
void fillTheDisk(const std::string& path) {
  std::filesystem::remove(path + ".tmp");
  std::filesystem::create_symlink("/dev/full", path + ".tmp");
}

bool noTemporaryLeft(const std::string& path) {
  return !std::filesystem::exists(std::filesystem::symlink_status(path + ".tmp"));
}

TEST(AtomicFile, WritesAndReplacesTheWholeContents) {
  const std::string path = temp("atomic.txt");
  writeFileAtomically(path, "first\n");
  EXPECT_EQ(test::readFile(path), "first\n");
  const std::string binary("a\0b\nc", 5);
  writeFileAtomically(path, binary);
  EXPECT_EQ(test::readFile(path), binary);
  writeFileAtomically(path, "");
  EXPECT_EQ(test::readFile(path), "");
  EXPECT_TRUE(noTemporaryLeft(path));
}

TEST(AtomicFile, AFailedWriteThrowsNamingTheFileAndKeepsThePreviousOne) {
  const std::string missing = temp("no_such_folder/x.txt");
  try {
    writeFileAtomically(missing, "x");
    ADD_FAILURE() << "a write into a missing folder did not fail";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(missing + ":", 0), 0u) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
  const std::string path = temp("full.txt");
  writeFileAtomically(path, "before\n");
  fillTheDisk(path);
  try {
    writeFileAtomically(path, "after\n");
    ADD_FAILURE() << "writing to a full disk did not fail";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("No space left"), std::string::npos) << what;
    EXPECT_NE(what.find("the previous file is unchanged"), std::string::npos) << what;
  }
  EXPECT_EQ(test::readFile(path), "before\n");
  EXPECT_TRUE(noTemporaryLeft(path));
}

TEST(AtomicFile, WhyNotWritableNamesEachProblemBeforeAnyWrite) {
  EXPECT_EQ(whyNotWritable(temp("fine.yaml")), "");
  EXPECT_FALSE(std::filesystem::exists(temp("fine.yaml")));  // the probe left nothing
  EXPECT_TRUE(noTemporaryLeft(temp("fine.yaml")));
  const std::string missing = temp("no_such_folder/out.yaml");
  EXPECT_NE(whyNotWritable(missing).find(missing + ": the folder "), std::string::npos)
      << whyNotWritable(missing);
  EXPECT_NE(whyNotWritable(missing).find("does not exist"), std::string::npos);
  std::ofstream(temp("a_file")) << "x";
  const std::string under_file = temp("a_file/out.yaml");
  EXPECT_NE(whyNotWritable(under_file).find("is not a folder"), std::string::npos)
      << whyNotWritable(under_file);
  std::filesystem::create_directories(temp("a_folder"));
  EXPECT_NE(whyNotWritable(temp("a_folder")).find("is a folder, not a file"), std::string::npos);
  EXPECT_FALSE(whyNotWritable("").empty());
  // A read-only folder, as a user whom its permissions bind (root's are not).
  const std::string read_only = test::readOnlyFolder();
  const bool refused = test::asUnprivilegedUser([&] {
    const std::string why = whyNotWritable(read_only + "out.yaml");
    return why.find("cannot create a file in") != std::string::npos &&
           why.find("Permission denied") != std::string::npos;
  });
  chmod(read_only.c_str(), 0755);
  std::filesystem::remove_all(read_only);
  EXPECT_TRUE(refused) << "a read-only folder was not said to be one";
}

TEST(AtomicFile, CsvWritersAreAtomic) {
  // Before: written in place with std::ofstream, a failed write truncated the previous file.
  const std::string poses_path = temp("poses.csv"), pairs_path = temp("pairs.csv");
  std::vector<PoseOrientation> poses(2);
  poses[1].stamp_s = 1.0;
  writePosesCsv(poses_path, poses);
  writePairsCsv(pairs_path, RotationPairs(2));
  const std::string poses_before = test::readFile(poses_path);
  const std::string pairs_before = test::readFile(pairs_path);
  fillTheDisk(poses_path);
  fillTheDisk(pairs_path);
  poses.resize(5);
  EXPECT_THROW(writePosesCsv(poses_path, poses), InputError);
  EXPECT_THROW(writePairsCsv(pairs_path, RotationPairs(5)), InputError);
  EXPECT_EQ(test::readFile(poses_path), poses_before);
  EXPECT_EQ(test::readFile(pairs_path), pairs_before);
  EXPECT_TRUE(noTemporaryLeft(poses_path));
  EXPECT_TRUE(noTemporaryLeft(pairs_path));
  EXPECT_EQ(readPosesCsv(poses_path).size(), 2u);
}

TEST(AtomicFile, TheReportIsWrittenAtomically) {
  std::mt19937_64 rng(61);
  const ReportInput in = test::realisticInput(rng, test::randomRotation(rng), 5, 0.001);
  const std::string path = temp("atomic_report.png");
  std::string error;
  ASSERT_TRUE(writeReportPng(path, in, &error)) << error;
  const std::string before = test::readFile(path);
  fillTheDisk(path);
  EXPECT_FALSE(writeReportPng(path, in, &error));
  EXPECT_NE(error.find("No space left"), std::string::npos) << error;
  EXPECT_EQ(test::readFile(path), before);
  EXPECT_TRUE(noTemporaryLeft(path));
}

}  // namespace
}  // namespace camera_imu_alignment
