// A mount change during continuous motion (issue 25: "remount detection works on motion too"):
// the waving scenario (60 s, no rests, consumer unit, 15 ms camera offset, camera orientations at
// 20 Hz as camera_pose gives them) with R_cam_imu turned by 3 deg about a camera axis over 1 s at
// 30 s, fed to the online calibrator as calibrate_bag feeds it (solveAsRecording). Against the
// simulated truth: the change is declared once, located within 1 s of where it happened, and the
// estimate after it (from the motion after the change alone) is within 3 of its 1-sigma of the new
// mount; the same recordings without a change declare none.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "camera_imu_alignment/config/online_config.h"
#include "camera_imu_alignment/estimation/mount_change.h"
#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"
#include "test_helpers.h"
#include "waving_sessions.h"

namespace camera_imu_alignment {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kRemountAtS = 30.0;  // since the start of the simulation

struct Outcome {
  std::vector<RemountEvent> remounts;
  CalibrateOutcome final;
};

Outcome calibrate(const simulation::SimulationConfig& c, const simulation::SimulationRun& run) {
  Outcome out;
  OnlineCallbacks callbacks;
  callbacks.on_remount = [&](const RemountEvent& e) { out.remounts.push_back(e); };
  OnlineSettings online;
  PipelineSettings settings;
  settings.joint = test::jointSettingsFor(c);
  solveAsRecording(&settings, &online);
  OnlineCalibrator calibrator(test::simulatedTarget(c), settings, online, callbacks);
  test::feedOrientations(run, &calibrator);
  calibrator.finish();
  out.final = calibrator.calibrateNow(false);
  return out;
}

TEST(MotionRemount, AChangeDuringTheMotionIsFoundAndTheNewMountCalibrated) {
  const Eigen::Vector3d axes[] = {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX()};
  for (int i = 0; i < 2; ++i) {
    simulation::SimulationConfig c =
        test::wavingConfig(simulation::ImuGrade::kConsumer, static_cast<std::uint64_t>(31 + i));
    c.remount = true;
    c.remount_time_s = kRemountAtS;
    c.remount_rotvec_cam = 3.0 * kDeg * axes[i];
    const simulation::SimulationRun run(c);
    const Outcome o = calibrate(c, run);
    for (const RemountEvent& e : o.remounts) std::printf("  remount: %s\n", e.message.c_str());
    ASSERT_EQ(o.remounts.size(), 1u) << "seed " << c.seed;
    EXPECT_NEAR(o.remounts[0].change_deg, 3.0, 1.0);
    // Where: the message names the camera-clock stamp; the truth's is the run's start + 30 s.
    const double truth_stamp_s = run.imu.front().t + kRemountAtS;
    const std::string& text = o.remounts[0].message;
    const std::size_t at = text.find("motion at ");
    ASSERT_NE(at, std::string::npos) << text;
    EXPECT_NEAR(std::stod(text.substr(at + 10)), truth_stamp_s, 1.0) << text;
    // The verdict names the change by its time, not by a pose (there are none).
    EXPECT_NEAR(o.remounts[0].change_stamp_s, truth_stamp_s, 1.0);
    ASSERT_TRUE(o.final.verdict.has_value());
    EXPECT_FALSE(o.final.verdict->passed);
    EXPECT_NE(o.final.verdict->text.find("during the motion at"), std::string::npos)
        << o.final.verdict->text;
    EXPECT_EQ(o.final.verdict->text.find("pose"), std::string::npos) << o.final.verdict->text;
    ASSERT_TRUE(o.final.result.joint && o.final.result.joint->ok) << o.final.result.message;
    const double error_deg =
        test::angleBetweenDeg(o.final.result.R_cam_imu, run.trajectory.R_cam_imu_final());
    const double sigma_deg = o.final.result.quality.std_dev_deg.norm();
    std::printf("  new mount: %.3f deg from the truth, 1-sigma norm %.3f deg\n", error_deg,
                sigma_deg);
    EXPECT_LT(error_deg, 3.0 * sigma_deg);
  }
}

TEST(MotionRemount, AnUnchangedMountIsNeverDeclaredChanged) {
  for (std::uint64_t seed : {31, 32, 33}) {
    const simulation::SimulationConfig c =
        test::wavingConfig(simulation::ImuGrade::kConsumer, seed);
    const simulation::SimulationRun run(c);
    const Outcome o = calibrate(c, run);
    EXPECT_TRUE(o.remounts.empty()) << "seed " << seed << ": " << o.remounts.front().message;
  }
}

}  // namespace
}  // namespace camera_imu_alignment
