// A remount in the field (issue 26, item 6): the simulator's robot stopping in the textured room
// (room_robot, consumer IMU, no board) with the camera's mount turned by 2 deg during the drive
// between two stops, fed to the online calibrator as calibrate_bag feeds it (no target: the
// camera's rotation between rests from the natural scene; solving on the caller's thread). The
// remount must be declared within 3 stops of the new mount, at the stop where it happened, and the
// final estimate must lie within 3 of its 1-sigma of the new mount; the same recordings without a
// remount must give no remount verdict. Everything against the simulator's truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/simulation/imu_grades.h"
#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;

/// room_robot with a consumer IMU; with `remount_deg_cam` (a rotation vector in degrees, camera
/// axes) the mount turns by it in the middle of the drive between the 6th and the 7th of 12 stops
/// (the simulator's default remount time).
sim::SimulationConfig roomRobot(std::uint64_t seed,
                                const std::optional<Eigen::Vector3d>& remount_deg_cam,
                                const std::string& scenario = "room_robot",
                                double camera_rate_hz = 10.0) {
  sim::SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(sim::applyScenario(scenario, &c));
  sim::applyImuGrade(sim::ImuGrade::kConsumer, &c);
  c.camera_rate_hz = camera_rate_hz;  // each rest is rendered once (the harness caches it)
  if (remount_deg_cam) {
    c.remount = true;
    c.remount_rotvec_cam = deg2rad(1.0) * *remount_deg_cam;
  }
  return c;
}

/// What the calibrator said, in order.
struct Recorder {
  std::vector<StationaryPose> poses;
  std::vector<EstimateEvent> estimates;
  std::vector<RemountEvent> remounts;
  std::vector<int> poses_at_remount;  ///< poses found when each remount was reported
  OnlineCallbacks callbacks() {
    OnlineCallbacks cb;
    cb.on_pose = [this](const StationaryPose& p) { poses.push_back(p); };
    cb.on_estimate = [this](const EstimateEvent& e) { estimates.push_back(e); };
    cb.on_remount = [this](const RemountEvent& e) {
      remounts.push_back(e);
      poses_at_remount.push_back(static_cast<int>(poses.size()));
    };
    return cb;
  }
};

struct RoomRun {
  std::unique_ptr<sim::SimulationRun> simulated;
  Recorder recorder;
  std::unique_ptr<OnlineCalibrator> calibrator;
  CalibrateOutcome outcome;  ///< calibrateNow at the end, as calibrate_bag's verdict
};

/// calibrate_bag's path: default settings, no target, unthreaded, calibrateNow(false) at the end.
std::unique_ptr<RoomRun> calibrate(const sim::SimulationConfig& c) {
  auto run = std::make_unique<RoomRun>();
  run->simulated = std::make_unique<sim::SimulationRun>(c);
  OnlineSettings online;
  online.threaded = false;
  run->calibrator = std::make_unique<OnlineCalibrator>(TargetDescription{}, PipelineSettings{},
                                                       online, run->recorder.callbacks());
  test::feedRenderedRun(*run->simulated, run->calibrator.get());
  run->calibrator->finish();
  run->outcome = run->calibrator->calibrateNow(false);
  return run;
}

/// The mount-change test's line after each pose (what the calibrator decided, for the log).
void printMountTests(const Recorder& r) {
  for (const EstimateEvent& e : r.estimates) {
    std::printf("  %zu poses in the window: %s\n", e.window_poses,
                e.mount_test ? e.mount_test->message.c_str() : "(no mount test)");
  }
}

/// CIA_SCENE_REMOUNT_SEEDS=N: seeds 100 .. 100 + N - 1, each with both remounts and without one
/// (the figures in BENCHMARKS.md); unset: the seeds below.
int seedCount() {
  const char* text = std::getenv("CIA_SCENE_REMOUNT_SEEDS");
  return text ? std::max(0, std::atoi(text)) : 0;
}

// 2 deg about the camera's y (pointing down, near the robot's vertical: the axis it turns about
// most, so the turns tell least about it) and about the camera's x (the camera's pitch on the
// robot).
const Eigen::Vector3d kAboutY(0.0, 2.0, 0.0), kAboutX(2.0, 0.0, 0.0);

TEST(SceneRemount, TwoDegreesAreFoundWithinThreeStopsAndTheNewMountEstimated) {
  struct Case {
    std::uint64_t seed;
    Eigen::Vector3d remount_deg_cam;
  };
  std::vector<Case> cases = {{3, kAboutY}, {4, kAboutX}};
  if (seedCount() > 0) {
    cases.clear();
    for (int i = 0; i < seedCount(); ++i) {
      for (const Eigen::Vector3d& v : {kAboutY, kAboutX}) cases.push_back({100u + i, v});
    }
  }
  std::vector<int> found_at(5, 0);  // cases found at the k-th stop of the new mount (4: later)
  int within_3_sigma = 0;
  double sum_sq_deg = 0.0, worst_change_error_deg = 0.0;
  for (const Case& k : cases) {
    const auto run = calibrate(roomRobot(k.seed, k.remount_deg_cam));
    const Recorder& r = run->recorder;
    const sim::Trajectory& truth = run->simulated->trajectory;
    char what_text[96];
    std::snprintf(what_text, sizeof(what_text), "seed %llu, remount [%.0f %.0f %.0f] deg",
                  static_cast<unsigned long long>(k.seed), k.remount_deg_cam.x(),
                  k.remount_deg_cam.y(), k.remount_deg_cam.z());
    const std::string what = what_text;
    std::printf("%s:\n", what.c_str());
    printMountTests(r);
    ASSERT_EQ(r.poses.size(), truth.poses().size()) << what << ": every stop a pose";
    int first_after = -1;
    for (const StationaryPose& p : r.poses) {
      if (p.start_s > truth.remountTime()) {
        first_after = p.index;
        break;
      }
    }
    ASSERT_GE(first_after, 2) << what;
    if (r.remounts.empty()) {
      ++found_at[4];
      ADD_FAILURE() << what << ": no remount found; " << run->calibrator->stateMessage();
      continue;
    }
    const RemountEvent& found = r.remounts.front();
    const int stops_of_new_mount = r.poses_at_remount.front() - first_after;
    ++found_at[std::min(4, std::max(0, stops_of_new_mount))];
    worst_change_error_deg =
        std::max(worst_change_error_deg, std::abs(found.change_deg - k.remount_deg_cam.norm()));
    std::printf("%s: found at stop %d of the new mount; %s\n", what.c_str(), stops_of_new_mount,
                found.message.c_str());
    EXPECT_LE(stops_of_new_mount, 3) << what;
    EXPECT_EQ(found.first_pose_index, first_after) << what;
    EXPECT_GE(found.first_pose_kept, first_after) << what << ": an old-mount pose kept";
    EXPECT_EQ(r.remounts.size(), 1u) << what << ": " << r.remounts.back().message;
    // The estimate at the end (the poses after the remount): within 3 of its 1-sigma per camera
    // axis of the new mount (left perturbation, camera axes).
    const AlignmentResult& result = run->outcome.result;
    if (result.status != SolveStatus::kOk) {  // the other seeds still run (a Monte Carlo)
      ADD_FAILURE() << what << ": final estimate: " << result.message;
      continue;
    }
    const Eigen::Matrix3d truth_after = truth.R_cam_imu_final();
    const Eigen::Vector3d error_deg =
        rad2deg(1.0) * logSO3(result.R_cam_imu * truth_after.transpose());
    const Eigen::Vector3d& sigma_deg = result.quality.std_dev_deg;
    sum_sq_deg += error_deg.squaredNorm();
    std::printf(
        "%s: final estimate over %zu poses %.3f deg off the new mount, error [%.3f %.3f "
        "%.3f], 1-sigma [%.3f %.3f %.3f] deg\n",
        what.c_str(), run->outcome.window_poses, error_deg.norm(), error_deg(0), error_deg(1),
        error_deg(2), sigma_deg(0), sigma_deg(1), sigma_deg(2));
    bool within = true;
    for (int axis = 0; axis < 3; ++axis) {
      within = within && std::abs(error_deg(axis)) <= 3.0 * sigma_deg(axis);
      EXPECT_LE(std::abs(error_deg(axis)), 3.0 * sigma_deg(axis)) << what << " axis " << axis;
    }
    within_3_sigma += within;
  }
  const int found = static_cast<int>(cases.size()) - found_at[4];
  std::printf(
      "%zu remounts of 2 deg: found at stop 1/2/3/later-or-never of the new mount: "
      "%d/%d/%d/%d; change size within %.2f deg of 2; final estimates RMS %.3f deg, %d "
      "within 3 sigma per axis\n",
      cases.size(), found_at[1], found_at[2], found_at[3], found_at[4], worst_change_error_deg,
      found > 0 ? std::sqrt(sum_sq_deg / found) : 0.0, within_3_sigma);
}

TEST(SceneRemount, NoRemountVerdictWithoutARemount) {
  struct Case {
    std::string scenario;
    std::uint64_t seed;
    double camera_rate_hz;
    bool moving_objects = false;
  };
  // Hand-held seed 100 at 3 Hz: a 0.3 deg false remount (p 4e-15) while the links were compared
  // at their stated noise (mount_change.cpp), and 0.19 deg (p 7e-13) when compared on the links
  // fitted again with the rotation held alone. Hand-held seed 104 with moving objects: 1.5 deg
  // (p 3e-32) on the links as measured alone (solve_worker.cpp: both must show a change).
  std::vector<Case> cases = {{"room_robot", 3, 10.0},
                             {"room_robot", 4, 10.0},
                             {"room_robot", 5, 10.0},
                             {"room_handheld", 100, 3.0},
                             {"room_handheld", 104, 3.0, true}};
  if (seedCount() > 0) {
    cases.clear();
    for (const char* scenario : {"room_robot", "room_handheld"}) {
      for (int i = 0; i < seedCount(); ++i) cases.push_back({scenario, 100u + i, 10.0});
    }
  }
  int false_remounts = 0;
  for (const Case& k : cases) {
    sim::SimulationConfig config = roomRobot(k.seed, std::nullopt, k.scenario, k.camera_rate_hz);
    config.moving_objects = k.moving_objects;
    const auto run = calibrate(config);
    const Recorder& r = run->recorder;
    const std::string what = k.scenario + " seed " + std::to_string(k.seed) +
                             (k.moving_objects ? " with moving objects" : "");
    std::printf("%s, no remount:\n", what.c_str());
    printMountTests(r);
    false_remounts += static_cast<int>(r.remounts.size());
    EXPECT_TRUE(r.remounts.empty())
        << what << ": " << (r.remounts.empty() ? "" : r.remounts.front().message);
    ASSERT_TRUE(run->outcome.verdict.has_value()) << what;
    EXPECT_EQ(run->outcome.verdict->text.find("mount change"), std::string::npos)
        << what << ": " << run->outcome.verdict->text;
  }
  std::printf("%zu unchanged recordings: %d remount verdicts\n", cases.size(), false_remounts);
}

}  // namespace
}  // namespace camera_imu_alignment
