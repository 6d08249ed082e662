// The rviz panel's service calls off the GUI thread (src/rviz/background_calls.cpp), without Qt
// or ROS: start() returns while the call blocks, one call per service at a time, an exception
// becomes an error answer, and a call may end after its owner is gone (rviz closed meanwhile).
#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <memory>
#include <stdexcept>
#include <thread>

#include "camera_imu_alignment/rviz/background_calls.h"

namespace camera_imu_alignment {
namespace {

/// Polls takeFinished() until something arrives or `timeout` passes.
std::vector<BackgroundCalls::Finished> waitForAnswers(BackgroundCalls& calls,
                                                      std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    std::vector<BackgroundCalls::Finished> finished = calls.takeFinished();
    if (!finished.empty()) return finished;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return {};
}

TEST(BackgroundCalls, StartReturnsAtOnceWhileTheCallBlocks) {
  BackgroundCalls calls;
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  const auto before = std::chrono::steady_clock::now();
  ASSERT_TRUE(calls.start("calibrate", [released]() {
    // A service that takes its time (bounded: a start() that ran the call itself would fail the
    // timing check below instead of hanging).
    released.wait_for(std::chrono::seconds(10));
    return PanelRow{"calibrate", "broadcast", RowLevel::kGood, ""};
  }));
  EXPECT_LT(std::chrono::steady_clock::now() - before, std::chrono::milliseconds(500));
  EXPECT_TRUE(calls.pending("calibrate"));
  EXPECT_FALSE(calls.pending("save"));
  // One call per service at a time; other services are independent.
  EXPECT_FALSE(calls.start("calibrate", [] { return PanelRow{}; }));
  EXPECT_TRUE(calls.start("save", [] { return PanelRow{"save", "done", RowLevel::kGood, ""}; }));
  std::vector<BackgroundCalls::Finished> finished =
      waitForAnswers(calls, std::chrono::milliseconds(5000));
  ASSERT_EQ(finished.size(), 1u);
  EXPECT_EQ(finished[0].key, "save");
  EXPECT_TRUE(calls.takeFinished().empty());
  EXPECT_TRUE(calls.pending("calibrate"));
  release.set_value();
  finished = waitForAnswers(calls, std::chrono::milliseconds(5000));
  ASSERT_EQ(finished.size(), 1u);
  EXPECT_EQ(finished[0].key, "calibrate");
  EXPECT_EQ(finished[0].answer.value, "broadcast");
  EXPECT_FALSE(calls.pending("calibrate"));
  EXPECT_DOUBLE_EQ(calls.pendingSeconds("calibrate"), 0.0);
}

TEST(BackgroundCalls, AnExceptionBecomesAnErrorAnswer) {
  BackgroundCalls calls;
  ASSERT_TRUE(
      calls.start("reset", []() -> PanelRow { throw std::runtime_error("connection refused"); }));
  const std::vector<BackgroundCalls::Finished> finished =
      waitForAnswers(calls, std::chrono::milliseconds(5000));
  ASSERT_EQ(finished.size(), 1u);
  EXPECT_EQ(finished[0].answer.level, RowLevel::kError);
  EXPECT_EQ(finished[0].answer.value, "the call failed: connection refused");
}

TEST(BackgroundCalls, ACallMayOutliveItsOwner) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  auto ended = std::make_shared<std::promise<void>>();
  std::future<void> call_ended = ended->get_future();
  auto calls = std::make_unique<BackgroundCalls>(std::chrono::milliseconds(20));
  ASSERT_TRUE(calls->start("calibrate", [released, ended]() {
    released.wait_for(std::chrono::seconds(10));
    ended->set_value();
    return PanelRow{"calibrate", "late", RowLevel::kGood, ""};
  }));
  const auto before = std::chrono::steady_clock::now();
  calls.reset();  // rviz closes during a call: the destructor waits 20 ms, not for the call
  EXPECT_LT(std::chrono::steady_clock::now() - before, std::chrono::milliseconds(1000));
  release.set_value();  // the call ends after its owner is gone: no crash, the answer dropped
  EXPECT_EQ(call_ended.wait_for(std::chrono::seconds(5)), std::future_status::ready);
}

}  // namespace
}  // namespace camera_imu_alignment
