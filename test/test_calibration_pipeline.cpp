// CalibrationPipeline end to end on simulated runs (ground truth from the simulator): stationary
// poses found where the rig rested, camera and IMU orientations at each pose, R_cam_imu within
// 0.1 deg with an honest 1-sigma, and the rules of calibration_pipeline.h (gyro chain, pose groups,
// time offsets, magnetometer hygiene, bad input counted and dropped).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;

sim::SimulationConfig scenario(const std::string& name, std::uint64_t seed) {
  sim::SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(sim::applyScenario(name, &c)) << name;
  return c;
}

/// Index of the true hold that contains [start, end], or -1.
int trueHold(const sim::Trajectory& trajectory, double start_s, double end_s) {
  const auto& holds = trajectory.poses();
  for (std::size_t i = 0; i < holds.size(); ++i) {
    if (start_s >= holds[i].start_s - 1e-9 && end_s <= holds[i].end_s + 1e-9) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

/// Checks the estimate from the final window: error below `max_error_deg` and within 3 sigma on
/// every axis.
void expectAccurate(const AlignmentResult& result, const Eigen::Matrix3d& R_cam_imu_true,
                    double max_error_deg) {
  ASSERT_EQ(result.status, SolveStatus::kOk) << result.message;
  const Eigen::Vector3d error = test::leftError(result.R_cam_imu, R_cam_imu_true);
  EXPECT_LT(rad2deg(error.norm()), max_error_deg);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LT(std::abs(rad2deg(error(axis))), 3.0 * result.quality.std_dev_deg(axis) + 1e-3)
        << "axis " << axis << ": 1-sigma " << result.quality.std_dev_deg.transpose();
  }
}

void expectAccurate(const CalibrationPipeline& pipeline, const Eigen::Matrix3d& R_cam_imu_true,
                    double max_error_deg) {
  expectAccurate(test::solveFinalWindow(pipeline), R_cam_imu_true, max_error_deg);
}

TEST(CalibrationPipeline, NominalRunFindsEveryPoseAndTheMounting) {
  // Through the online calibrator (the product's path), solving on this thread.
  const auto r = test::runCalibrator(scenario("nominal", 3));
  const CalibrationSnapshot snap = r.calibrator->snapshot(SnapshotContents::kWithHistory);
  const auto& trajectory = r.run->trajectory;
  const auto& poses = snap.poses;
  EXPECT_EQ(poses.size(), trajectory.poses().size()) << snap.rejections.summary();
  const Eigen::Matrix3d R_world_target = trajectory.R_world_target();
  std::vector<int> holds;
  for (const auto& pose : poses) {
    const int hold = trueHold(trajectory, pose.start_s, pose.end_s);
    ASSERT_GE(hold, 0) << "pose " << pose.index << " [" << pose.start_s << ", " << pose.end_s
                       << "] is not inside a true rest";
    holds.push_back(hold);
    // Camera orientation at the pose: PnP averaged over the frames.
    const Eigen::Matrix3d R_target_cam_true =
        R_world_target.transpose() * trajectory.poses()[hold].R_world_cam;
    EXPECT_LT(test::angleBetweenDeg(pose.R_target_cam, R_target_cam_true), 0.05) << pose.index;
    EXPECT_GE(pose.num_frames, 2);
    EXPECT_EQ(pose.group, 0);
  }
  // IMU relative rotations between poses (gyro chain) against the truth.
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const Eigen::Matrix3d B = poses[k - 1].R_world_imu.transpose() * poses[k].R_world_imu;
    const double t0 = 0.5 * (poses[k - 1].start_s + poses[k - 1].end_s);
    const double t1 = 0.5 * (poses[k].start_s + poses[k].end_s);
    const Eigen::Matrix3d B_true =
        trajectory.at(t0).R_world_imu().transpose() * trajectory.at(t1).R_world_imu();
    // Angle random walk 1.87e-4 rad/s/sqrt(Hz) over ~4 s between rests plus the rest-mean bias
    // error: ~0.04 deg RMS (3 axes); 0.1 deg is about 2.5 sigma.
    EXPECT_LT(test::angleBetweenDeg(B, B_true), 0.1) << "poses " << k - 1 << ", " << k;
    EXPECT_EQ(poses[k].imu_source, PoseImuSource::kGyro);
    ASSERT_TRUE(poses[k].gyro_mag_difference_deg.has_value());
    EXPECT_LT(*poses[k].gyro_mag_difference_deg, 2.0);
  }
  ASSERT_TRUE(snap.latest);
  EXPECT_EQ(snap.latest->window_poses, poses.size());  // the final window's estimate
  expectAccurate(snap.latest->result, r.R_cam_imu_true(), 0.1);
  // Detection ran only at rest, on a bounded number of frames per rest.
  EXPECT_LE(snap.inputs.frames_detected,
            snap.rests.size() * PipelineSettings{}.max_frames_per_pose);
  EXPECT_LT(snap.inputs.frames_detected, snap.inputs.frames / 2);
  EXPECT_EQ(snap.rejections.total(), 0u) << snap.rejections.summary();
  // An estimate after every pose from the third on (min_poses_to_solve), and one after every 100
  // motion frames without a solve (the motion between the rests: motion nodes); no remount.
  EXPECT_GE(r.estimates->size(), poses.size() - 2);
  EXPECT_LE(r.estimates->size(), poses.size() - 2 + snap.inputs.frames / 100);
  EXPECT_EQ(snap.remounts, 0);
}

std::unique_ptr<CalibrationPipeline> runWithoutImages(const sim::SimulationRun& run,
                                                      const PipelineSettings& settings,
                                                      bool imu_orientation) {
  return test::feedWithoutImages(run, settings, 0.02, imu_orientation);
}

std::unique_ptr<sim::SimulationRun> runOf(const std::string& name, std::uint64_t seed) {
  sim::SimulationConfig c = scenario(name, seed);
  c.camera_rate_hz = 1.0;  // nothing is rendered here; frame times are chosen by the test
  return std::make_unique<sim::SimulationRun>(c);
}

TEST(CalibrationPipeline, GivenCameraOrientationsNeedNoImages) {
  const auto simulated = runOf("nominal", 19);
  const sim::SimulationRun& run = *simulated;
  const auto pipeline = runWithoutImages(run, PipelineSettings(), false);
  EXPECT_EQ(pipeline->poses().size(), run.trajectory.poses().size());
  EXPECT_EQ(pipeline->rejections().total(), 0u) << pipeline->rejections().summary();
  const AlignmentResult result = test::solveFinalWindow(*pipeline);
  ASSERT_EQ(result.status, SolveStatus::kOk) << result.message;
  EXPECT_LT(rad2deg(test::leftError(result.R_cam_imu, run.trajectory.R_cam_imu_final()).norm()),
            0.1);
  // Not a rotation: refused and counted, never used.
  CameraFrame broken;
  broken.stamp_s = run.imu.back().t + 1.0;
  broken.R_target_cam = 2.0 * Eigen::Matrix3d::Identity();
  pipeline->addFrame(broken);
  EXPECT_EQ(pipeline->rejections().total(), 1u);
}

TEST(CalibrationPipeline, ImuOwnOrientationIsUsedWhenAsked) {
  const auto simulated = runOf("no_magnetometer", 23);
  const sim::SimulationRun& run = *simulated;
  PipelineSettings settings;
  settings.imu_orientation = ImuOrientationSource::kMessage;
  const auto pipeline = runWithoutImages(run, settings, true);
  ASSERT_EQ(pipeline->poses().size(), run.trajectory.poses().size());
  for (const auto& pose : pipeline->poses()) {
    EXPECT_EQ(pose.imu_source, PoseImuSource::kMessage);
    EXPECT_EQ(pose.group, 0);
    const double t = 0.5 * (pose.start_s + pose.end_s);
    EXPECT_LT(test::angleBetweenDeg(pose.R_world_imu, run.trajectory.at(t).R_world_imu()), 0.05);
  }
  const AlignmentResult result = test::solveFinalWindow(*pipeline);
  ASSERT_EQ(result.status, SolveStatus::kOk) << result.message;
  EXPECT_LT(rad2deg(test::leftError(result.R_cam_imu, run.trajectory.R_cam_imu_final()).norm()),
            0.1);
  // Without orientations in the samples, the rule falls back to the gyro chain.
  const auto fallback = runWithoutImages(run, settings, false);
  ASSERT_GE(fallback->poses().size(), 2u);
  EXPECT_EQ(fallback->poses()[1].imu_source, PoseImuSource::kGyro);
}

TEST(CalibrationPipeline, CameraTimeOffsetsOfTensOfMillisecondsChangeNothing) {
  for (double offset : {-0.05, 0.03}) {
    sim::SimulationConfig c = scenario("nominal", 5);
    c.camera_time_offset_s = offset;
    const auto r = test::runPipeline(c);
    EXPECT_EQ(r.pipeline->poses().size(), r.run->trajectory.poses().size()) << offset;
    expectAccurate(*r.pipeline, r.R_cam_imu_true(), 0.1);
  }
}

TEST(CalibrationPipeline, WithoutMagnetometerTheGyroCarriesTheHeading) {
  // The pairs' IMU orientation (the joint estimate's start; the joint estimate itself across the
  // IMU grades: test_joint_pipeline).
  PipelineSettings settings;
  settings.imu_orientation = ImuOrientationSource::kAuto;
  const auto r = test::runPipeline(scenario("no_magnetometer", 7), settings);
  const auto& poses = r.pipeline->poses();
  ASSERT_GE(poses.size(), 10u);
  EXPECT_EQ(poses.front().imu_source, PoseImuSource::kAccelOnly);
  for (std::size_t k = 1; k < poses.size(); ++k) {
    EXPECT_EQ(poses[k].imu_source, PoseImuSource::kGyro);
    EXPECT_EQ(poses[k].group, 0);
    EXPECT_FALSE(poses[k].magnetometer_usable);
  }
  expectAccurate(*r.pipeline, r.R_cam_imu_true(), 0.1);
}

TEST(CalibrationPipeline, DisturbedFieldIsFlaggedAndNeverUsed) {
  for (ImuOrientationSource source :
       {ImuOrientationSource::kAuto, ImuOrientationSource::kMagnetometer}) {
    PipelineSettings settings;
    settings.imu_orientation = source;
    const sim::SimulationConfig c = scenario("magnetic_disturbance", 11);
    const auto r = test::runPipeline(c, settings);
    const auto& trajectory = r.run->trajectory;
    int flagged = 0;
    for (const auto& pose : r.pipeline->poses()) {
      const int hold = trueHold(trajectory, pose.start_s, pose.end_s);
      const bool disturbed =
          std::find(c.mag_disturbance_poses.begin(), c.mag_disturbance_poses.end(), hold) !=
          c.mag_disturbance_poses.end();
      if (disturbed) {
        EXPECT_FALSE(pose.magnetometer_usable) << "hold " << hold;
        EXPECT_NE(pose.imu_source, PoseImuSource::kAccelMag);
        ++flagged;
      } else if (source == ImuOrientationSource::kMagnetometer && pose.index > 0) {
        EXPECT_TRUE(pose.magnetometer_usable) << "hold " << hold << ": " << pose.magnetometer_note;
      }
    }
    EXPECT_EQ(flagged, static_cast<int>(c.mag_disturbance_poses.size()));
    // The paper's accelerometer + magnetometer attitude carries the accelerometer bias (about
    // 0.3 deg of tilt per pose here): it cannot reach the gyro's accuracy.
    expectAccurate(*r.pipeline, r.R_cam_imu_true(),
                   source == ImuOrientationSource::kAuto ? 0.1 : 0.6);
  }
}

TEST(CalibrationPipeline, SingleAxisMotionIsNotObservableAboutTheOpticalAxis) {
  const auto r = test::runPipeline(scenario("degenerate", 13));
  ASSERT_GE(r.pipeline->poses().size(), 3u);
  const AlignmentResult result = test::solveFinalWindow(*r.pipeline);
  EXPECT_EQ(result.status, SolveStatus::kNotObservable) << result.message;
  EXPECT_GT(std::abs(result.quality.weak_axis_cam.z()), 0.9) << result.quality.weak_axis_cam;
  EXPECT_NE(result.quality.observability_message.find("camera x or y"), std::string::npos)
      << result.quality.observability_message;
}

TEST(CalibrationPipeline, ImuGapWithoutMagnetometerStartsANewGroup) {
  // Drop one second of IMU data in the middle of the motion after the 6th hold: the rotation over
  // the gap is unknown, so poses after it cannot be paired with poses before it.
  sim::SimulationConfig c = scenario("no_magnetometer", 17);
  sim::SimulationRun probe(c);
  const auto& holds = probe.trajectory.poses();
  const double gap_begin = holds[5].end_s + 0.3, gap_end = gap_begin + 1.0;
  PipelineSettings settings;
  test::PipelineRun r;
  r.run = std::make_unique<sim::SimulationRun>(c);
  r.run->imu.erase(std::remove_if(r.run->imu.begin(), r.run->imu.end(),
                                  [&](const sim::InertialSample& s) {
                                    return s.t > gap_begin && s.t < gap_end;
                                  }),
                   r.run->imu.end());
  r = test::feedPipeline(std::move(r.run), settings);
  const auto& poses = r.pipeline->poses();
  ASSERT_GE(poses.size(), 10u);
  int groups = 0;
  for (const auto& pose : poses) groups = std::max(groups, pose.group + 1);
  EXPECT_EQ(groups, 2);
  for (const auto& pose : poses) {
    EXPECT_EQ(pose.group, pose.start_s > gap_end ? 1 : 0) << pose.index;
  }
  expectAccurate(*r.pipeline, r.R_cam_imu_true(), 0.1);
}

TEST(CalibrationPipeline, BadSamplesAreCountedAndDropped) {
  sim::SimulationConfig c = scenario("nominal", 19);
  c.num_poses = 6;
  test::Injection injection;
  injection.nan_imu_every = 997;
  injection.duplicate_imu_every = 1499;
  injection.backwards_imu_every = 2003;
  injection.nan_mag_every = 53;
  injection.gauss_mag_every = 301;
  injection.empty_frame_every = 17;
  const auto r = test::runPipeline(c, {}, injection);
  const RejectionCounts& counts = r.pipeline->rejections();
  EXPECT_EQ(counts.count(RejectReason::kNonFinite), r.injected.nan_imu + r.injected.nan_mag);
  EXPECT_EQ(counts.count(RejectReason::kDuplicateStamp), r.injected.duplicate_imu);
  EXPECT_EQ(counts.count(RejectReason::kStampBackwards), r.injected.backwards_imu);
  EXPECT_EQ(counts.count(RejectReason::kMagneticUnits), r.injected.gauss_mag);
  EXPECT_EQ(counts.count(RejectReason::kBadImage), r.injected.empty_frames);
  EXPECT_GT(r.injected.nan_imu * r.injected.duplicate_imu * r.injected.backwards_imu, 0u);
  EXPECT_EQ(r.pipeline->poses().size(), 6u);
  expectAccurate(*r.pipeline, r.R_cam_imu_true(), 0.1);
}

TEST(CalibrationPipeline, ATargetPartlyOrNotInViewIsCountedAndGivesNoPose) {
  for (const double covered : {0.5, 1.0}) {
    sim::SimulationConfig c = scenario("nominal", 23);
    c.num_poses = 2;
    test::Injection injection;
    injection.cover_fraction = covered;
    PipelineSettings settings;
    settings.min_frame_interval_s = 0.15;
    settings.missed_frame_interval_s = 1.0;
    const auto r = test::runCalibrator(c, settings, injection);
    const CalibrationSnapshot snap = r.calibrator->snapshot(SnapshotContents::kWithHistory);
    EXPECT_EQ(snap.poses_total, 0u) << covered;
    // After 3 misses in a row at a rest, one attempt per missed_frame_interval_s (a miss costs
    // up to 15x a hit); at min_frame_interval_s a 4 s rest would cost about 25 attempts.
    ASSERT_EQ(snap.rests.size(), 2u) << covered;
    double most_attempts = 0.0;
    for (const StationarySegment& rest : snap.rests) {
      most_attempts += 3 + 1.0 + rest.duration() / 1.0;  // 3: kMissesBeforeBackoff
    }
    EXPECT_GE(snap.inputs.frames_detected, 2u * 3u) << covered;
    EXPECT_LE(snap.inputs.frames_detected, most_attempts) << covered;
    // Every detection attempt at rest failed and was counted; none was taken for a pose.
    EXPECT_EQ(snap.rejections.count(RejectReason::kTargetNotFound), snap.inputs.frames_detected)
        << covered;
    ASSERT_FALSE(snap.rejected_poses.empty()) << covered;
    EXPECT_NE(snap.rejected_poses[0].reason.find("target seen in 0"), std::string::npos)
        << snap.rejected_poses[0].reason;
    EXPECT_TRUE(r.estimates->empty()) << covered;
  }
}

}  // namespace
}  // namespace camera_imu_alignment

namespace camera_imu_alignment {
namespace {

/// A long run (more poses than the history keeps) at 100 Hz with given camera orientations:
/// every buffer stays within its cap, totals and indices keep counting, and the estimate is still
/// the true mounting. This is what lets the nodelet run for days.
TEST(CalibrationPipeline, MemoryStaysBoundedOverALongRun) {
  const Eigen::Matrix3d R_cam_imu = expSO3(Eigen::Vector3d(0.3, -0.5, 1.6));
  const Eigen::Matrix3d R_target_world = expSO3(Eigen::Vector3d(3.0, 0.2, 0.1));
  // The pipeline alone, solved once at the end: a joint solve after each of the 1150 poses took a
  // minute and is not what this test is about (the window it solves is bounded like every other
  // buffer).
  PipelineSettings settings;
  CalibrationPipeline pipeline(
      parseTargetYaml("target_type: 'checkerboard'\ntargetCols: 8\ntargetRows: 6\n"
                      "rowSpacingMeters: 0.04\ncolSpacingMeters: 0.04\n",
                      "test target"),
      settings);
  const std::size_t kPoses = CalibrationPipeline::kHistoryLimit + 150;
  const double dt = 0.01;
  const Eigen::Vector3d up(0.0, 0.0, 9.81);
  const Eigen::Vector3d axes[] = {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0),
                                  Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 1, 0).normalized()};
  Eigen::Matrix3d R_world_imu = Eigen::Matrix3d::Identity();
  double t = 1.0;
  PipelineBufferSizes largest;
  auto grow = [](std::size_t* biggest, std::size_t now) { *biggest = std::max(*biggest, now); };
  for (std::size_t pose = 0; pose < kPoses; ++pose) {
    for (int i = 0; i < 330; ++i, t += dt) {  // 3.3 s at rest, camera at 10 Hz
      pipeline.addImu({t, Eigen::Vector3d::Zero(), R_world_imu.transpose() * up});
      if (i % 10 == 5) {
        CameraFrame frame;
        frame.stamp_s = t;
        frame.R_target_cam = R_target_world * R_world_imu * R_cam_imu.transpose();
        pipeline.addFrame(frame);
      }
    }
    // 0.5 s turning by 0.4 rad about one of four axes (alternating sign: the rig stays near level).
    const Eigen::Vector3d omega = axes[pose % 4] * (pose % 8 < 4 ? 0.8 : -0.8);
    for (int i = 0; i < 50; ++i, t += dt) {
      pipeline.addImu({t, omega, R_world_imu.transpose() * up});
      R_world_imu = R_world_imu * Eigen::AngleAxisd(omega.norm() * dt, omega.normalized()).matrix();
    }
    const PipelineBufferSizes now = pipeline.bufferSizes();
    grow(&largest.imu, now.imu);
    grow(&largest.frame_queue, now.frame_queue);
    grow(&largest.detections, now.detections);
    grow(&largest.poses, now.poses);
    grow(&largest.rests, now.rests);
    grow(&largest.rejected_rests, now.rejected_rests);
    grow(&largest.window, now.window);
  }
  pipeline.finish();
  EXPECT_EQ(pipeline.posesTotal(), kPoses) << pipeline.rejections().summary();
  EXPECT_EQ(pipeline.restsTotal(), kPoses);
  EXPECT_EQ(largest.poses, CalibrationPipeline::kHistoryLimit);
  EXPECT_EQ(largest.rests, CalibrationPipeline::kHistoryLimit);
  EXPECT_EQ(pipeline.poses().size(), CalibrationPipeline::kHistoryLimit);
  EXPECT_EQ(pipeline.poses().back().index, static_cast<int>(kPoses) - 1);
  EXPECT_EQ(largest.window, settings.window_poses);
  EXPECT_LE(largest.imu, static_cast<std::size_t>(settings.max_gyro_span_s / dt) + 1);
  EXPECT_LE(largest.frame_queue, static_cast<std::size_t>(settings.frame_queue_s / 0.1) + 1);
  EXPECT_LE(largest.detections, static_cast<std::size_t>(settings.max_frames_per_pose));
  const AlignmentResult result = test::solveFinalWindow(pipeline);
  ASSERT_TRUE(result.joint && result.joint->ok) << result.message;
  EXPECT_EQ(result.joint->intrinsics.accel_bias_per_pose_m_s2.size(), settings.window_poses);
  EXPECT_LT(rad2deg(rotationAngle(result.R_cam_imu.transpose() * R_cam_imu)), 1e-3);
}

}  // namespace
}  // namespace camera_imu_alignment
