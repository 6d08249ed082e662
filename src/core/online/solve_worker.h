// The online calibrator's solves, away from the thread that feeds samples: a job is a snapshot of
// the window; the newest job waiting replaces an older one (only the latest window matters).
// Private to the pipeline; not installed.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>

#include "camera_imu_alignment/online/online_types.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/solve/window_solver.h"

namespace camera_imu_alignment {

/// What the calibrator had taken in when a window was taken: a later window taken with the same
/// mark holds the same data (OnlineCalibrator::calibrateNow then reuses its solve).
struct InputMark {
  std::uint64_t generation = 0;  ///< bumped by reset, remount, clock jump
  std::uint64_t imu = 0, magnetic = 0, frames = 0, finishes = 0;
  bool operator==(const InputMark& o) const {
    return generation == o.generation && imu == o.imu && magnetic == o.magnetic &&
           frames == o.frames && finishes == o.finishes;
  }
};

struct SolveJob {
  InputMark inputs;  ///< when the window was taken (its generation: reset, remount, jump)
  WindowSnapshot window;
  bool test_mount_change = false;
  /// The window's newest poses that no earlier change-point test had among its poses (the
  /// worker skipped their windows while it was busy): the test's candidate splits reach back
  /// to them as well as to the newest remount_max_poses_after.
  int poses_not_yet_tested = 0;
};

struct SolveOutput {
  InputMark inputs;       ///< the job's
  WindowSnapshot window;  ///< the job's (pose indices of the estimate)
  AlignmentResult result;
  std::optional<MountChangeTest> mount_test;
  std::vector<SceneRefit> scene_refits;  ///< for CalibrationPipeline::rememberSceneRefits
};

/// The window solve (solve/window_solver.h) with, for joint estimates, the change-point test.
SolveOutput runSolveJob(SolveJob job, const PipelineSettings& pipeline,
                        const OnlineSettings& online);

class SolveWorker {
 public:
  SolveWorker(PipelineSettings pipeline, OnlineSettings online);
  ~SolveWorker();  ///< finishes the running job, drops the waiting one, joins
  /// Queues `job` in place of any job still waiting.
  void submit(SolveJob job);
  /// Finished outputs, oldest first (moved out).
  std::deque<SolveOutput> takeFinished();
  /// Blocks until nothing is waiting or running.
  void waitIdle();

 private:
  void run();
  const PipelineSettings pipeline_;
  const OnlineSettings online_;
  std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::optional<SolveJob> waiting_;
  bool running_ = false, stop_ = false;
  std::deque<SolveOutput> finished_;
  std::thread thread_;
};

}  // namespace camera_imu_alignment
