// Blocking calls (the panel's ROS service calls) run off the calling (Qt GUI) thread: start()
// returns at once, the call runs on its own thread, its answer is collected later with
// takeFinished() (the panel polls it from a timer on the GUI thread). Qt-free and ROS-free, so
// that it is unit-tested without a display or a ROS master (test_panel_text).
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "camera_imu_alignment/rviz/panel_text.h"

namespace camera_imu_alignment {

class BackgroundCalls {
 public:
  /// A blocking call; its answer as a panel row. An exception it throws becomes a kError row
  /// naming the call and the exception's text.
  using Call = std::function<PanelRow()>;

  struct Finished {
    std::string key;  ///< as given to start()
    PanelRow answer;
  };

  /// `wait_on_destruction`: how long the destructor waits for calls still running (e.g. rviz
  /// closing during a ~calibrate); after that they finish on their own and their answers are
  /// dropped. Nothing they use belongs to this object.
  explicit BackgroundCalls(
      std::chrono::milliseconds wait_on_destruction = std::chrono::milliseconds(2000));
  ~BackgroundCalls();
  BackgroundCalls(const BackgroundCalls&) = delete;
  BackgroundCalls& operator=(const BackgroundCalls&) = delete;

  /// Starts `call` on its own thread unless a call with the same `key` is still running (then
  /// returns false and does nothing: one ~calibrate at a time, not a queue of them).
  bool start(const std::string& key, Call call);

  /// A call with `key` is running.
  bool pending(const std::string& key) const;

  /// Seconds since the running call with `key` started; 0 when none runs.
  double pendingSeconds(const std::string& key) const;

  /// The answers of the calls that ended since the last take, in the order they ended.
  std::vector<Finished> takeFinished();

 private:
  struct Shared;
  std::shared_ptr<Shared> shared_;
  std::chrono::milliseconds wait_on_destruction_;
};

}  // namespace camera_imu_alignment
