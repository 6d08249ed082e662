// SolveWorker and runSolveJob (solve_worker.h).
#include "solve_worker.h"

#include <algorithm>
#include <utility>

namespace camera_imu_alignment {

SolveOutput runSolveJob(SolveJob job, const PipelineSettings& pipeline,
                        const OnlineSettings& online) {
  SolveOutput out;
  out.inputs = job.inputs;
  MountTestBasis basis;
  out.result = solveWindow(job.window, pipeline, &basis);
  if (job.test_mount_change && out.result.joint && out.result.joint->ok && basis.as_measured.ok) {
    // A split whose first pose was never a candidate of a test (its windows were skipped) is
    // one: the splits with fewer than min_poses_after poses after them in the last tested window
    // were only pending, so the reach is the untested poses plus min_poses_after - 1.
    MountChangeSettings remount = online.remount;
    remount.max_poses_after =
        std::max(remount.max_poses_after, job.poses_not_yet_tested + remount.min_poses_after - 1);
    const JointSettings joint = jointSettingsOf(pipeline);
    MountChangeTest test = testMountChange(job.window.joint, basis.as_measured, joint, remount);
    // With natural-scene links fitted again, a change must show on them too (MountTestBasis).
    if ((test.detected || test.pending) && !basis.refitted_problem.camera_links.empty() &&
        basis.refitted.ok) {
      const MountChangeTest again =
          testMountChange(basis.refitted_problem, basis.refitted, joint, remount);
      if (!again.detected && !again.pending) {
        test.detected = test.pending = false;
        test.message = "no mount change: the natural-scene rotations as measured show one (" +
                       test.message +
                       "), but not once fitted again with the rotation held near the estimate "
                       "(a moved object in view; " +
                       again.message + ")";
      }
    }
    out.mount_test = std::move(test);
  }
  out.window = std::move(job.window);
  return out;
}

SolveWorker::SolveWorker(PipelineSettings pipeline, OnlineSettings online)
    : pipeline_(std::move(pipeline)), online_(std::move(online)), thread_([this] { run(); }) {}

SolveWorker::~SolveWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    waiting_.reset();
  }
  wake_.notify_all();
  thread_.join();
}

void SolveWorker::submit(SolveJob job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    waiting_ = std::move(job);
  }
  wake_.notify_all();
}

std::deque<SolveOutput> SolveWorker::takeFinished() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::deque<SolveOutput> out;
  out.swap(finished_);
  return out;
}

void SolveWorker::waitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return stop_ || (!waiting_ && !running_); });
}

void SolveWorker::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stop_ || waiting_.has_value(); });
    if (stop_) break;
    SolveJob job = std::move(*waiting_);
    waiting_.reset();
    running_ = true;
    lock.unlock();
    SolveOutput output = runSolveJob(std::move(job), pipeline_, online_);
    lock.lock();
    running_ = false;
    finished_.push_back(std::move(output));
    idle_.notify_all();
  }
  running_ = false;
  idle_.notify_all();
}

}  // namespace camera_imu_alignment
