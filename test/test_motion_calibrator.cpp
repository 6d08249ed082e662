// Recordings without rests through the one data path (OnlineCalibrator -> CalibrationPipeline ->
// joint estimate): camera orientations during continuous motion and the raw gyro, with a camera
// time offset, against the simulated truth of motion_problem_simulation.h.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "camera_imu_alignment/config/online_config.h"
#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/solve/window_solver.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "motion_problem_simulation.h"
#include "pipeline_simulation.h"
#include "waving_sessions.h"

namespace camera_imu_alignment {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// Feeds the simulation's gyro (the accelerometer: gravity along the IMU's z, unused while
/// moving) and its camera orientations (as camera_pose messages) in stamp order.
void feed(const test::MotionSimulation& sim, OnlineCalibrator* calibrator) {
  const GyroStream& gyro = sim.problem.motion_gyro;
  const auto& frames = sim.problem.motion_frames;
  size_t f = 0;
  for (size_t i = 0; i < gyro.stamps_s.size(); ++i) {
    while (f < frames.size() && frames[f].stamp_s <= gyro.stamps_s[i]) {
      CameraFrame frame;
      frame.stamp_s = frames[f].stamp_s;
      frame.R_target_cam = frames[f].R_target_cam;
      calibrator->addFrame(frame);
      ++f;
    }
    ImuSample sample;
    sample.stamp_s = gyro.stamps_s[i];
    sample.gyro_rad_s = gyro.gyro_rad_s[i];
    sample.accel_m_s2 = Eigen::Vector3d(0.0, 0.0, 9.81);
    calibrator->addImu(sample);
  }
  calibrator->finish();
}

TEST(MotionCalibrator, CalibratesARecordingWithoutRestsAndFindsTheTimeOffset) {
  test::MotionSimulationOptions options;  // consumer gyro, 15 ms offset, 60 s
  options.gyro_scale = 0.0;               // an ideal gyro: see test_joint_motion for the gauge
  options.gyro_cross_axis = 0.0;
  for (uint64_t seed : {21, 22}) {
    const test::MotionSimulation sim = test::simulateMotionProblem(options, seed);
    std::vector<EstimateEvent> estimates;
    OnlineCallbacks callbacks;
    callbacks.on_estimate = [&](const EstimateEvent& e) { estimates.push_back(e); };
    OnlineSettings online;
    online.threaded = false;
    OnlineCalibrator calibrator(test::simulatedTarget(simulation::SimulationConfig{}),
                                PipelineSettings{}, online, callbacks);
    feed(sim, &calibrator);
    const CalibrateOutcome outcome = calibrator.calibrateNow(false);
    ASSERT_TRUE(outcome.result.joint.has_value()) << outcome.result.message;
    const JointResult& joint = *outcome.result.joint;
    ASSERT_TRUE(joint.ok) << joint.message;
    const double error_deg = geodesicDistance(outcome.result.R_cam_imu, sim.R_cam_imu) / kDeg;
    std::printf(
        "seed %llu: error %.4f deg, 1-sigma %.4f deg, timeshift %.3f ms (+- %.3f), %d "
        "nodes, %zu solves on the way; %s\n",
        static_cast<unsigned long long>(seed), error_deg, joint.std_dev_deg.norm(),
        1e3 * joint.timeshift_cam_imu_s, 1e3 * joint.timeshift_sigma_s, joint.motion_nodes,
        estimates.size(), outcome.result.message.c_str());
    EXPECT_LT(error_deg, 0.05);
    EXPECT_LT(error_deg, 3.0 * joint.std_dev_deg.norm());
    EXPECT_NEAR(joint.timeshift_cam_imu_s, 0.015, 5e-4);
    // Broadcast (the final solve may be kept back as within min_change_deg of it) and passed.
    const CalibrationSnapshot snapshot = calibrator.snapshot(SnapshotContents::kState);
    EXPECT_TRUE(snapshot.broadcast.has_value());
    ASSERT_TRUE(outcome.verdict.has_value());
    EXPECT_TRUE(outcome.verdict->passed) << outcome.verdict->text;
    // The online calibrator solved while the motion came in (every 100 motion frames).
    EXPECT_GE(estimates.size(), 5u);
  }
}

TEST(MotionCalibrator, ABagsMotionIsSolvedAsTheWindowDoublesWithTheSameFinalEstimate) {
  // calibrate_bag's cadence (motion_solves_double): a solve when the window has doubled since the
  // last, and one at finish() for the motion after it; the nodelet's: every 100 frames. The final
  // window is the same, so is its estimate; calibrateNow after finish() with nothing new is that
  // solve itself (the same solve time), not another.
  test::MotionSimulationOptions options;
  options.gyro_scale = 0.0;
  options.gyro_cross_axis = 0.0;
  const test::MotionSimulation sim = test::simulateMotionProblem(options, 24);
  const size_t frames = sim.problem.motion_frames.size();
  ASSERT_GE(frames, 1000u);
  std::vector<CalibrateOutcome> outcomes;
  std::vector<size_t> solves;
  for (bool doubling : {false, true}) {
    std::vector<EstimateEvent> estimates;
    OnlineCallbacks callbacks;
    callbacks.on_estimate = [&](const EstimateEvent& e) { estimates.push_back(e); };
    OnlineSettings online;
    online.threaded = false;
    online.motion_solves_double = doubling;
    OnlineCalibrator calibrator(test::simulatedTarget(simulation::SimulationConfig{}),
                                PipelineSettings{}, online, callbacks);
    feed(sim, &calibrator);
    ASSERT_FALSE(estimates.empty());
    const JointResult last = *estimates.back().result.joint;
    solves.push_back(estimates.size());
    outcomes.push_back(calibrator.calibrateNow(false));
    ASSERT_TRUE(outcomes.back().result.joint && outcomes.back().result.joint->ok);
    EXPECT_EQ(outcomes.back().result.joint->solve_time_s, last.solve_time_s) << "re-solved";
  }
  // 100 frames per solve, and the motion after the last at finish().
  EXPECT_EQ(solves[0], (frames + 99) / 100);
  // Windows of 100, 200, 400, 800 frames, then all of them at finish().
  size_t doublings = 1;
  for (size_t window = 100; 2 * window < frames; window *= 2) ++doublings;
  EXPECT_EQ(solves[1], doublings + 1);
  EXPECT_LT(geodesicDistance(outcomes[0].result.R_cam_imu, outcomes[1].result.R_cam_imu), 1e-9);
}

TEST(MotionCalibrator, SolvingAsARecordingGivesTheCallersThreadsEstimates) {
  // solveAsRecording (calibrate_bag): each solve on the worker while the input goes on, applied
  // when the next is asked for. The same windows are solved as on the caller's thread, so the
  // same estimates come out in the same order, whatever the threads' timing.
  test::MotionSimulationOptions options;
  const test::MotionSimulation sim = test::simulateMotionProblem(options, 25);
  std::vector<std::vector<EstimateEvent>> runs;
  for (bool as_recording : {false, true}) {
    runs.emplace_back();
    OnlineCallbacks callbacks;
    callbacks.on_estimate = [&](const EstimateEvent& e) { runs.back().push_back(e); };
    OnlineSettings online;
    PipelineSettings settings;
    solveAsRecording(&settings, &online);
    if (!as_recording) {
      online.threaded = false;
      online.solves_in_order = false;
    }
    OnlineCalibrator calibrator(test::simulatedTarget(simulation::SimulationConfig{}), settings,
                                online, callbacks);
    feed(sim, &calibrator);
    calibrator.calibrateNow(false);
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  ASSERT_GE(runs[0].size(), 4u);
  for (size_t k = 0; k < runs[0].size(); ++k) {
    EXPECT_EQ(runs[0][k].window_poses, runs[1][k].window_poses);
    EXPECT_EQ(runs[0][k].gate.decision, runs[1][k].gate.decision) << "solve " << k;
    // Ceres on two threads sums the cost in another order: equal to rounding.
    EXPECT_LT(geodesicDistance(runs[0][k].result.R_cam_imu, runs[1][k].result.R_cam_imu), 1e-9)
        << "solve " << k;
  }
}

TEST(MotionCalibrator, AnOffsetBeyondTheSearchRangeIsNamedWithTheRange) {
  test::MotionSimulationOptions options;
  options.timeshift_cam_imu_s = 0.3;
  const test::MotionSimulation sim = test::simulateMotionProblem(options, 23);
  OnlineSettings online;
  online.threaded = false;
  OnlineCalibrator calibrator(test::simulatedTarget(simulation::SimulationConfig{}),
                              PipelineSettings{}, online, {});
  feed(sim, &calibrator);
  const CalibrateOutcome outcome = calibrator.calibrateNow(false);
  EXPECT_FALSE(outcome.broadcast);
  EXPECT_NE(outcome.result.message.find("beyond the search range of +-0.100 s"), std::string::npos)
      << outcome.result.message;
}

// A 20 Hz camera's frames are 0.05 s apart only up to rounding (0.0499999... s): every one is kept
// with the default motion_frame_interval_s of 0.05 (before: 788 of 1201, two of every three) and
// every other one, 0.1 s apart, is a motion node (motion_node_spacing_s 0.1; before: 455 of 601).
TEST(MotionCalibrator, KeepsEveryFrameOfACameraAtTheFrameInterval) {
  const simulation::SimulationRun run(
      test::wavingConfig(simulation::ImuGrade::kIdeal, 3, 0.015, 20.0));
  ASSERT_EQ(run.camera_orientations.size(), 1201u);  // t = 0, 0.05, ..., 60
  CalibrationPipeline pipeline(test::simulatedTarget(run.config), PipelineSettings{});
  test::feedOrientations(run, &pipeline);
  pipeline.finish();
  const WindowSnapshot window = pipeline.snapshot();
  EXPECT_GE(window.joint.motion_frames.size(), 1195u);
  const AlignmentResult result = solveWindow(window, pipeline.settings());
  ASSERT_TRUE(result.joint && result.joint->ok) << result.message;
  EXPECT_GE(result.joint->motion_nodes, 590);
  EXPECT_LE(result.joint->motion_nodes, 601);
}

}  // namespace
}  // namespace camera_imu_alignment
