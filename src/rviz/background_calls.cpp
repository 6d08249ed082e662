// BackgroundCalls: each call on a detached thread; the state the threads touch is shared (see
// background_calls.h), so a call may outlive the object that started it.
#include "camera_imu_alignment/rviz/background_calls.h"

#include <condition_variable>
#include <exception>
#include <map>
#include <mutex>
#include <thread>

namespace camera_imu_alignment {

struct BackgroundCalls::Shared {
  mutable std::mutex mutex;
  std::condition_variable all_done;
  std::map<std::string, std::chrono::steady_clock::time_point> running;  ///< key -> start
  std::vector<Finished> finished;
  bool owner_alive = true;  ///< false: answers are dropped
};

BackgroundCalls::BackgroundCalls(std::chrono::milliseconds wait_on_destruction)
    : shared_(std::make_shared<Shared>()), wait_on_destruction_(wait_on_destruction) {}

BackgroundCalls::~BackgroundCalls() {
  std::unique_lock<std::mutex> lock(shared_->mutex);
  shared_->all_done.wait_for(lock, wait_on_destruction_,
                             [this] { return shared_->running.empty(); });
  shared_->owner_alive = false;
  shared_->finished.clear();
}

bool BackgroundCalls::start(const std::string& key, Call call) {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (!shared_->running.emplace(key, std::chrono::steady_clock::now()).second) return false;
  }
  std::thread([shared = shared_, key, call = std::move(call)]() {
    PanelRow answer;
    try {
      answer = call();
    } catch (const std::exception& e) {
      answer = {key, std::string("the call failed: ") + e.what(), RowLevel::kError, ""};
    } catch (...) {
      answer = {key, "the call failed with an unknown exception", RowLevel::kError, ""};
    }
    std::lock_guard<std::mutex> lock(shared->mutex);
    shared->running.erase(key);
    if (shared->owner_alive) shared->finished.push_back({key, answer});
    shared->all_done.notify_all();
  }).detach();
  return true;
}

bool BackgroundCalls::pending(const std::string& key) const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  return shared_->running.count(key) > 0;
}

double BackgroundCalls::pendingSeconds(const std::string& key) const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  const auto it = shared_->running.find(key);
  if (it == shared_->running.end()) return 0.0;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second).count();
}

std::vector<BackgroundCalls::Finished> BackgroundCalls::takeFinished() {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  std::vector<Finished> out;
  out.swap(shared_->finished);
  return out;
}

}  // namespace camera_imu_alignment
