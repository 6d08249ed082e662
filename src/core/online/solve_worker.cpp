// SolveWorker and runSolveJob (solve_worker.h).
#include "solve_worker.h"

#include <algorithm>
#include <utility>

namespace camera_imu_alignment {

SolveOutput runSolveJob(SolveJob job, const PipelineSettings& pipeline,
                        const OnlineSettings& online) {
  WindowSolveRequest request;
  request.test_mount_change = job.test_mount_change;
  request.remount = online.remount;
  request.poses_not_yet_tested = job.poses_not_yet_tested;
  WindowSolveOutput solved = WindowSolver(pipeline).solve(job.window, request);
  SolveOutput out;
  out.inputs = job.inputs;
  out.result = std::move(solved.result);
  out.mount_test = std::move(solved.mount_test);
  out.scene_refits = std::move(solved.scene_refits);
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
