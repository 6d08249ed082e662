// The online calibrator (online/online_calibrator.h) without ROS, on simulated sample streams
// (camera orientations given, no images) of several IMU grades: broadcasts within 0.2 deg of the
// truth, finds a remount before anything was broadcast within 3 poses and then broadcasts the new
// mount from the poses after it alone, raises no false remount on unchanged recordings; reset,
// clock jumps, forced calibration, manual capture and the worker thread.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/simulation/trajectory.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"
#include "solve_worker.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;

sim::SimulationConfig configFor(sim::ImuGrade grade, std::uint64_t seed) {
  sim::SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(sim::applyScenario("nominal", &c));
  sim::applyImuGrade(grade, &c);
  return c;
}

/// `grade`'s recording whose mount turns by `turn_deg` about camera (0.6, -0.8, 0) between the
/// 7th and the 8th of `num_poses` poses.
sim::SimulationConfig remountedConfig(sim::ImuGrade grade, std::uint64_t seed, double turn_deg,
                                      int num_poses) {
  sim::SimulationConfig c = configFor(grade, seed);
  c.num_poses = num_poses;
  c.remount = true;
  c.remount_rotvec_cam = deg2rad(turn_deg) * Eigen::Vector3d(0.6, -0.8, 0.0);
  const std::vector<sim::StationaryPose> planned = sim::Trajectory(c).poses();
  c.remount_time_s = 0.5 * (planned[6].end_s + planned[7].start_s);
  return c;
}

/// Everything the calibrator said, in order.
struct Recorder {
  std::vector<StationaryPose> poses;
  std::vector<EstimateEvent> estimates;
  std::vector<BroadcastEstimate> broadcasts;
  std::vector<RemountEvent> remounts;
  std::vector<double> clock_jumps;
  /// Poses found when each remount was reported (how many poses it took).
  std::vector<int> poses_at_remount;
  /// For each broadcast: the newest pose's index then (-1 before any) and remounts reported so far.
  std::vector<int> newest_pose_at_broadcast, remounts_at_broadcast;
  OnlineCallbacks callbacks() {
    OnlineCallbacks cb;
    cb.on_pose = [this](const StationaryPose& p) { poses.push_back(p); };
    cb.on_estimate = [this](const EstimateEvent& e) { estimates.push_back(e); };
    cb.on_broadcast = [this](const BroadcastEstimate& b) {
      broadcasts.push_back(b);
      newest_pose_at_broadcast.push_back(poses.empty() ? -1 : poses.back().index);
      remounts_at_broadcast.push_back(static_cast<int>(remounts.size()));
    };
    cb.on_remount = [this](const RemountEvent& e) {
      remounts.push_back(e);
      poses_at_remount.push_back(static_cast<int>(poses.size()));
    };
    cb.on_clock_jump = [this](double jump_s, InputStream) { clock_jumps.push_back(jump_s); };
    return cb;
  }
};

struct Run {
  std::unique_ptr<sim::SimulationRun> simulated;
  Recorder recorder;
  std::unique_ptr<OnlineCalibrator> calibrator;
};

std::unique_ptr<Run> calibrate(const sim::SimulationConfig& c, OnlineSettings online = {},
                               bool finish = true,
                               ImuOrientationSource source = ImuOrientationSource::kJoint) {
  auto run = std::make_unique<Run>();
  run->simulated = std::make_unique<sim::SimulationRun>(c);
  PipelineSettings settings;
  settings.imu_orientation = source;
  settings.joint = test::jointSettingsFor(c);
  run->calibrator =
      std::make_unique<OnlineCalibrator>(parseTargetYaml(sim::targetYaml(c.target), "target"),
                                         settings, online, run->recorder.callbacks());
  test::feedSinkWithoutImages(*run->simulated, run->calibrator.get(), 0.03, false, 50 + c.seed);
  if (finish) {
    run->calibrator->finish();
    run->calibrator->waitForSolves();
  }
  return run;
}

OnlineSettings synchronous() {
  OnlineSettings s;
  s.threaded = false;
  return s;
}

TEST(OnlineCalibrator, BroadcastsWithinATenthOfADegreeForEachGrade) {
  for (sim::ImuGrade grade :
       {sim::ImuGrade::kIdeal, sim::ImuGrade::kTactical, sim::ImuGrade::kConsumer}) {
    const auto run = calibrate(configFor(grade, 41), synchronous());
    const OnlineCalibrator& c = *run->calibrator;
    ASSERT_TRUE(c.broadcast().has_value()) << toString(grade) << ": " << c.stateMessage();
    EXPECT_EQ(c.state(), CalibrationState::kCalibrated) << c.stateMessage();
    EXPECT_LT(test::angleBetweenDeg(c.broadcast()->R_cam_imu,
                                    run->simulated->trajectory.R_cam_imu_final()),
              0.2)
        << toString(grade);
    EXPECT_EQ(c.snapshot().remounts, 0) << toString(grade);
    // What is broadcast carries its own quality: the poses and 1-sigma of that estimate.
    const BroadcastEstimate& b = run->recorder.broadcasts.back();
    ASSERT_TRUE(b.result.has_value());
    EXPECT_EQ(b.source, "estimated");
    EXPECT_GE(b.poses, 3);
    EXPECT_LE(b.poses, static_cast<int>(run->recorder.poses.size()));
    EXPECT_EQ(b.std_dev_deg, b.result->quality.std_dev_deg);
  }
}

TEST(OnlineCalibrator, RemountBeforeTheFirstBroadcastIsFoundWithinThreePoses) {
  // The mount turns after the seventh pose; min_poses is high enough that nothing is broadcast
  // before the seventh pose (the case: a residual gate then blocked every broadcast for
  // ever). Every grade: found within 3 poses, split at the right pose (before the fix, a noisy
  // unit's change was declared when one pose of the new mount was in, split one pose early, and
  // the restarted window held an old-mount pose), and from then on only the new mount's poses are
  // broadcast. Tactical and consumer units reach 0.2 deg from the 7 poses after the change; the
  // noisy grade (MPU-6050 class on a vibrating mount) cannot (0.2 deg at 3 sigma takes it about
  // 100 poses, BENCHMARKS.md "Online calibrator"): it gets 14 poses after the change and its
  // broadcast must lie within 3 of its reported 1-sigma of the new mount.
  int case_index = 0;
  for (sim::ImuGrade grade :
       {sim::ImuGrade::kTactical, sim::ImuGrade::kConsumer, sim::ImuGrade::kNoisy}) {
    for (double turn_deg : {2.0, 5.0}) {
      const bool noisy = grade == sim::ImuGrade::kNoisy;
      const sim::SimulationConfig c =
          remountedConfig(grade, 60 + case_index, turn_deg, noisy ? 21 : 14);
      OnlineSettings online = synchronous();
      online.min_poses = 7;
      const auto run = calibrate(c, online);
      ++case_index;
      const Recorder& r = run->recorder;
      const Eigen::Matrix3d truth_after = run->simulated->trajectory.R_cam_imu_final();
      const double t_remount = run->simulated->trajectory.remountTime();
      int first_after = -1;
      for (const StationaryPose& p : r.poses) {
        if (p.start_s > t_remount) {
          first_after = p.index;
          break;
        }
      }
      ASSERT_GE(first_after, 1);
      const std::string what =
          std::string(toString(grade)) + " " + std::to_string(turn_deg) + " deg";
      ASSERT_FALSE(r.remounts.empty()) << what << ": " << run->calibrator->stateMessage();
      // Found when the 2nd or 3rd pose of the new mount arrived.
      EXPECT_LE(r.poses_at_remount.front() - first_after, 3) << what;
      EXPECT_EQ(r.remounts.front().first_pose_index, first_after) << what;
      // The restarted window keeps no pose of the old mount (it may drop one of the new).
      EXPECT_GE(r.remounts.front().first_pose_kept, first_after) << what;
      EXPECT_LE(r.remounts.front().first_pose_kept, first_after + 1) << what;
      EXPECT_NEAR(r.remounts.front().change_deg, turn_deg, 0.3) << what;
      EXPECT_EQ(r.remounts.size(), 1u) << what << ": " << r.remounts.back().message;
      // After the change was found, only estimates from the new mount's poses are broadcast.
      int new_mount_broadcasts = 0;
      for (std::size_t i = 0; i < r.broadcasts.size(); ++i) {
        if (r.remounts_at_broadcast[i] == 0) continue;
        ++new_mount_broadcasts;
        EXPECT_LE(r.broadcasts[i].poses, r.newest_pose_at_broadcast[i] - first_after + 1)
            << what << ": broadcast " << i << " uses a pose of the old mount";
      }
      ASSERT_GT(new_mount_broadcasts, 0) << what << ": " << run->calibrator->stateMessage();
      const BroadcastEstimate& b = *run->calibrator->broadcast();
      if (!noisy) {
        EXPECT_LT(test::angleBetweenDeg(b.R_cam_imu, truth_after), 0.2) << what;
        continue;
      }
      // Per camera axis within 3 of its reported 1-sigma (left perturbation, camera axes).
      const Eigen::Vector3d error_deg =
          rad2deg(1.0) * logSO3(b.R_cam_imu * truth_after.transpose());
      for (int axis = 0; axis < 3; ++axis) {
        EXPECT_LE(std::abs(error_deg(axis)), 3.0 * b.std_dev_deg(axis))
            << what << " axis " << axis << ": error " << error_deg.transpose() << " deg, 1-sigma "
            << b.std_dev_deg.transpose() << " from " << b.poses << " poses";
      }
      std::printf(
          "%s: broadcast %.3f deg off the new mount, 1-sigma [%.3f %.3f %.3f] deg, %d poses\n",
          what.c_str(), test::angleBetweenDeg(b.R_cam_imu, truth_after), b.std_dev_deg(0),
          b.std_dev_deg(1), b.std_dev_deg(2), b.poses);
    }
  }
}

TEST(OnlineCalibrator, ATacticalUnitsTurnIsFoundAlthoughTheMixedWindowDropsItsMatrices) {
  // On these two recordings of a tactical unit (0.1 % scale, 0.05 deg axes: tens of sigma in its
  // data) the window holding both mounts made the model selection hold T_g and T_a at identity;
  // the two-mount fits inherited that, fitted no pose set well, and a 5 deg turn was never found.
  // The change test now fits both models with the matrices estimated there.
  for (std::uint64_t seed : {65u, 71u}) {
    const sim::SimulationConfig c = remountedConfig(sim::ImuGrade::kTactical, seed, 5.0, 14);
    OnlineSettings online = synchronous();
    online.min_poses = 7;
    const auto run = calibrate(c, online);
    const Recorder& r = run->recorder;
    ASSERT_EQ(r.remounts.size(), 1u) << "seed " << seed << ": " << run->calibrator->stateMessage();
    EXPECT_EQ(r.remounts.front().first_pose_index, 7) << "seed " << seed;
    EXPECT_LE(r.poses_at_remount.front() - 7, 3) << "seed " << seed;
    ASSERT_TRUE(run->calibrator->broadcast().has_value()) << "seed " << seed;
    EXPECT_LT(test::angleBetweenDeg(run->calibrator->broadcast()->R_cam_imu,
                                    run->simulated->trajectory.R_cam_imu_final()),
              0.2)
        << "seed " << seed;
  }
}

/// Forwards samples to `inner`, with the camera orientations of the frames from `from_s` on seen
/// through a mount turned by `turn` (camera axes): R_target_cam' = R_target_cam turn^T.
class TurnTheCameraFrom : public SampleSink {
 public:
  TurnTheCameraFrom(SampleSink* inner, double from_s, const Eigen::Matrix3d& turn)
      : inner_(inner), from_s_(from_s), turn_(turn) {}
  void addImu(const ImuSample& s) override { inner_->addImu(s); }
  void addMagnetic(const MagneticSample& s) override { inner_->addMagnetic(s); }
  bool setCameraIntrinsics(const CameraIntrinsics& i) override {
    return inner_->setCameraIntrinsics(i);
  }
  void addFrame(const CameraFrame& frame) override {
    CameraFrame out = frame;
    if (out.R_target_cam && out.stamp_s >= from_s_) {
      out.R_target_cam = Eigen::Matrix3d(*out.R_target_cam * turn_.transpose());
    }
    inner_->addFrame(out);
  }
  void rejectInput(RejectReason r, InputStream s, const std::string& d) override {
    inner_->rejectInput(r, s, d);
  }
  ImuOrientationSource imuOrientationSource() const override {
    return inner_->imuOrientationSource();
  }

 private:
  SampleSink* inner_;
  double from_s_;
  Eigen::Matrix3d turn_;
};

TEST(OnlineCalibrator, ANewestPoseThatLooksLikeARemountIsNotBroadcast) {
  // The last pose of a noisy unit seen through a mount turned by 1 deg: the change test finds a
  // significant change before it but cannot declare it with one pose after (a remount or a bad
  // pose). Whenever it is pending, the estimate is held back until the next pose decides, and the
  // broadcast estimate stays the one before; in some recordings the chi-square and 1-sigma gates
  // alone would have broadcast it over both mounts (in others the chi-square test refuses it).
  int pending = 0, gates_alone_would_broadcast = 0;
  for (std::uint64_t seed : {91, 92, 93, 94, 95, 102}) {
    const sim::SimulationConfig c = configFor(sim::ImuGrade::kNoisy, seed);
    const sim::SimulationRun simulated(c);
    Recorder recorder;
    PipelineSettings settings;
    settings.joint = test::jointSettingsFor(c);
    OnlineCalibrator calibrator(parseTargetYaml(sim::targetYaml(c.target), "target"), settings,
                                synchronous(), recorder.callbacks());
    TurnTheCameraFrom turned(&calibrator, simulated.trajectory.poses().back().start_s - 1.0,
                             expSO3(deg2rad(1.0) * Eigen::Vector3d(0.6, -0.8, 0.0)));
    test::feedSinkWithoutImages(simulated, &turned, 0.03, false, 50 + c.seed);
    calibrator.finish();
    calibrator.waitForSolves();
    const std::string what = "seed " + std::to_string(seed);
    ASSERT_TRUE(calibrator.lastEstimate().has_value()) << what;
    const EstimateEvent& last = *calibrator.lastEstimate();
    ASSERT_TRUE(last.mount_test.has_value()) << what;
    EXPECT_EQ(calibrator.snapshot().remounts, 0) << what;
    if (!last.mount_test->pending) continue;
    ++pending;
    EXPECT_EQ(last.mount_test->first_pose_kept, static_cast<int>(last.window_poses) - 1) << what;
    // Held back, and what is broadcast (if anything yet) does not use the turned pose.
    EXPECT_EQ(last.gate.decision, GateDecision::kReject) << what;
    if (calibrator.broadcast()) {
      EXPECT_LT(calibrator.broadcast()->poses, static_cast<int>(last.window_poses)) << what;
    }
    if (judgeEstimate(last.result, last.window_poses, calibrator.settings(), calibrator.broadcast(),
                      false)
            .decision == GateDecision::kBroadcast) {
      ++gates_alone_would_broadcast;  // then the hold is the reason
      EXPECT_NE(last.gate.why.find("waiting for the next pose"), std::string::npos)
          << what << ": " << last.gate.why;
    }
  }
  std::printf("pending in %d of 6 recordings, the gates alone would have broadcast %d\n", pending,
              gates_alone_would_broadcast);
  EXPECT_GE(pending, 4);
  EXPECT_GE(gates_alone_would_broadcast, 1);
}

TEST(OnlineCalibrator, PairModesKeepTheResidualRemountTest) {
  // imu_orientation auto (the gyro chain's pairs, no joint estimate): remount_poses poses in a row
  // off the broadcast estimate by more than remount_residual_deg restart the window from them.
  sim::SimulationConfig c;
  c.seed = 43;
  ASSERT_TRUE(sim::applyScenario("remount", &c));  // 16 poses, 10 deg about camera y halfway
  const auto run = calibrate(c, synchronous(), true, ImuOrientationSource::kAuto);
  const Recorder& r = run->recorder;
  ASSERT_EQ(r.remounts.size(), 1u) << run->calibrator->stateMessage();
  EXPECT_NE(r.remounts[0].message.find("remount_residual_deg"), std::string::npos);
  ASSERT_TRUE(run->calibrator->broadcast().has_value());
  EXPECT_LT(test::angleBetweenDeg(run->calibrator->broadcast()->R_cam_imu,
                                  run->simulated->trajectory.R_cam_imu_final()),
            0.3);
}

/// CIA_FALSE_REMOUNT_SEEDS=N: N unchanged recordings per grade in
/// NoFalseRemountOnUnchangedRecordings (20: the target, none found in the 80; about 110 s);
/// unset: 8, to keep the test command short.
int unchangedSeedCount() {
  const char* text = std::getenv("CIA_FALSE_REMOUNT_SEEDS");
  const int n = text ? std::atoi(text) : 0;
  return n > 0 ? n : 8;
}

TEST(OnlineCalibrator, NoFalseRemountOnUnchangedRecordings) {
  // The target: none in 20 unchanged recordings per grade, with the change test run after
  // every pose of each (12 poses: about 10 tests per recording).
  int remounts = 0;
  const int seeds = unchangedSeedCount();
  for (sim::ImuGrade grade : {sim::ImuGrade::kIdeal, sim::ImuGrade::kTactical,
                              sim::ImuGrade::kConsumer, sim::ImuGrade::kNoisy}) {
    for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(seeds); ++seed) {
      const auto run = calibrate(configFor(grade, 80 + seed), synchronous());
      remounts += run->calibrator->snapshot().remounts;
      EXPECT_EQ(run->calibrator->snapshot().remounts, 0)
          << toString(grade) << " seed " << seed << ": " << run->calibrator->stateMessage();
    }
  }
  std::printf("false remounts in %d unchanged recordings (%d per grade): %d\n", 4 * seeds, seeds,
              remounts);
}

TEST(OnlineCalibrator, ResetForgetsTheWindowAndKeepsTheBroadcast) {
  const auto run = calibrate(configFor(sim::ImuGrade::kConsumer, 43), synchronous());
  OnlineCalibrator& c = *run->calibrator;
  ASSERT_TRUE(c.broadcast().has_value());
  const Eigen::Matrix3d broadcast = c.broadcast()->R_cam_imu;
  c.reset();
  EXPECT_EQ(c.snapshot().window.size(), 0u);
  EXPECT_EQ(c.snapshot().poses_total, 0u);
  EXPECT_FALSE(c.lastEstimate().has_value());
  EXPECT_EQ(c.state(), CalibrationState::kCollecting);
  EXPECT_NE(c.stateMessage().find("reset"), std::string::npos);
  ASSERT_TRUE(c.broadcast().has_value());
  EXPECT_TRUE(c.broadcast()->R_cam_imu.isApprox(broadcast));
  EXPECT_EQ(c.snapshot().remounts, 0);
}

TEST(OnlineCalibrator, AClockJumpBackClearsTheWindowAndKeepsTheBroadcast) {
  const auto run = calibrate(configFor(sim::ImuGrade::kIdeal, 44), synchronous());
  OnlineCalibrator& c = *run->calibrator;
  ASSERT_TRUE(c.broadcast().has_value());
  ASSERT_GT(c.snapshot().window.size(), 0u);
  c.addImu({1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81)});  // a bag loop
  ASSERT_EQ(run->recorder.clock_jumps.size(), 1u);
  EXPECT_GT(run->recorder.clock_jumps[0], 10.0);
  EXPECT_EQ(c.snapshot().window.size(), 0u);
  EXPECT_TRUE(c.broadcast().has_value());
}

TEST(OnlineCalibrator, CalibrateNowSaysWhyNotAndForceBroadcasts) {
  OnlineSettings online = synchronous();
  online.max_std_dev_deg = 1e-4;  // no estimate can pass
  const auto run = calibrate(configFor(sim::ImuGrade::kIdeal, 45), online);
  OnlineCalibrator& c = *run->calibrator;
  EXPECT_FALSE(c.broadcast().has_value());
  const CalibrateOutcome refused = c.calibrateNow(false);
  EXPECT_EQ(refused.result.status, SolveStatus::kOk);
  EXPECT_FALSE(refused.broadcast);
  EXPECT_NE(refused.not_broadcast_reason.find("max_std_dev_deg"), std::string::npos)
      << refused.not_broadcast_reason;
  const CalibrateOutcome forced = c.calibrateNow(true);
  EXPECT_TRUE(forced.broadcast);
  ASSERT_TRUE(c.broadcast().has_value());
  EXPECT_TRUE(c.broadcast()->R_cam_imu.isApprox(forced.result.R_cam_imu));
  EXPECT_NE(c.stateMessage().find("force"), std::string::npos);
  // The broadcast (and what the nodelet saves from it) says which gate it failed.
  EXPECT_NE(c.broadcast()->forced_although.find("max_std_dev_deg"), std::string::npos)
      << c.broadcast()->forced_although;
}

TEST(OnlineCalibrator, ManualCaptureWantsFramesOnlyWhileArmed) {
  OnlineSettings online = synchronous();
  online.manual_capture = true;
  const auto run = calibrate(configFor(sim::ImuGrade::kIdeal, 46), online, false);
  OnlineCalibrator& c = *run->calibrator;
  EXPECT_FALSE(c.wantsFrames());
  c.armCapture();
  EXPECT_TRUE(c.wantsFrames());
}

TEST(OnlineCalibrator, AChangeInWindowsTheBusyWorkerSkippedIsStillTested) {
  // The worker solves only the newest window; while it is busy (the nodelet's rostest replaying a
  // consumer unit's remount at 3x: 10-12 s per solve of a mixed window) several poses arrive
  // unsolved. A split among them must still be a candidate, although it lies beyond the newest
  // remount_max_poses_after poses: here 5 poses of the new mount (the 8th to 12th) arrive at once.
  const sim::SimulationConfig c = remountedConfig(sim::ImuGrade::kConsumer, 62, 3.0, 12);
  const sim::SimulationRun run(c);
  PipelineSettings settings;
  settings.imu_orientation = ImuOrientationSource::kJoint;
  settings.joint = test::jointSettingsFor(c);
  settings.motion_window_s = 0.0;  // the rests alone: a mixed window's motion costs seconds
  const auto pipeline = test::feedWithoutImages(run, settings, 0.03, false, 112);
  SolveJob job;
  job.window = pipeline->snapshot();
  job.test_mount_change = true;
  ASSERT_EQ(job.window.pose_indices.size(), 12u);
  OnlineSettings online;
  ASSERT_EQ(online.remount.max_poses_after, 4);
  // Every window up to the 7th pose was tested: the change before the 8th is out of reach.
  job.poses_not_yet_tested = 5;
  const SolveOutput reached = runSolveJob(job, settings, online);
  ASSERT_TRUE(reached.mount_test.has_value());
  EXPECT_TRUE(reached.mount_test->detected) << reached.mount_test->message;
  EXPECT_EQ(reached.mount_test->first_pose_after, 7) << reached.mount_test->message;
  EXPECT_NEAR(reached.mount_test->change_deg, 3.0, 0.3);
  // The same window as if its predecessors had all been tested: the split before the 8th pose is
  // no candidate (only the newest 4 are), so the change cannot be placed there.
  job.poses_not_yet_tested = 1;
  const SolveOutput newest_only = runSolveJob(job, settings, online);
  ASSERT_TRUE(newest_only.mount_test.has_value());
  EXPECT_FALSE(newest_only.mount_test->detected && newest_only.mount_test->first_pose_after == 7)
      << newest_only.mount_test->message;
}

TEST(OnlineCalibrator, TheWorkerThreadGivesTheSameFinalEstimate) {
  const sim::SimulationConfig config = configFor(sim::ImuGrade::kConsumer, 47);
  const auto inline_run = calibrate(config, synchronous());
  OnlineSettings threaded;
  threaded.threaded = true;
  const auto threaded_run = calibrate(config, threaded);
  ASSERT_TRUE(inline_run->calibrator->lastEstimate().has_value());
  ASSERT_TRUE(threaded_run->calibrator->lastEstimate().has_value());
  EXPECT_LT(test::angleBetweenDeg(inline_run->calibrator->lastEstimate()->result.R_cam_imu,
                                  threaded_run->calibrator->lastEstimate()->result.R_cam_imu),
            1e-9);
  EXPECT_TRUE(threaded_run->calibrator->broadcast().has_value());
}

TEST(OnlineCalibrator, SettingsValidatedByKey) {
  OnlineSettings s;
  s.consistency_level = 0.0;
  const TargetDescription target = parseTargetYaml(
      "target_type: checkerboard\ntargetCols: 8\ntargetRows: 6\nrowSpacingMeters: 0.04\n"
      "colSpacingMeters: 0.04\n",
      "target");
  try {
    OnlineCalibrator c(target, PipelineSettings{}, s, {});
    ADD_FAILURE() << "accepted consistency_level 0";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("consistency_level"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace camera_imu_alignment
