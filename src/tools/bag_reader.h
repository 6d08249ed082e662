// Reading a rosbag into the core's OnlineCalibrator for calibrate_bag: every message of the
// selected topics through the nodelet's MessageInput (the same checks and conversions), the bag's
// static transforms, a progress line and a log of the first rejections of each kind, by topic.
#pragma once

#include <rosbag/bag.h>

#include <cstdint>
#include <exception>
#include <map>
#include <string>

#include "bag_topics.h"
#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/pipeline/input_rejections.h"
#include "cli_args.h"

namespace camera_imu_alignment {

/// Progress on stderr: a live line on a terminal, plain lines every 10% of bag time otherwise.
class BagProgress {
 public:
  /// start_s, end_s: the bag's first and last stamps (s).
  BagProgress(bool enabled, double start_s, double end_s);
  /// At bag time t (s): rests, poses and the latest estimate, when the percentage moved on.
  void update(double t, const OnlineCalibrator& calibrator, bool force = false);
  void done();

 private:
  bool enabled_, tty_;
  double start_, end_;
  int last_ = -100;
};

/// Prints the first few rejections of each reason, naming the bag topic, then only counts (the
/// summary at the end has them all). Plugs into OnlineCallbacks::on_reject.
class BagRejectLog {
 public:
  explicit BagRejectLog(const BagTopics& topics) : topics_(topics) {}
  void operator()(RejectReason reason, InputStream stream, const std::string& detail);

 private:
  std::string topicOf(InputStream stream) const;

  BagTopics topics_;
  std::map<RejectReason, int> shown_;
};

/// What the reading saw besides the samples.
struct BagRunInfo {
  std::string camera_frame, imu_frame;  ///< from the messages' headers ("" when none)
  std::uint64_t image_messages = 0, info_messages = 0, camera_pose_messages = 0;
  double start_s = 0.0, end_s = 0.0;  ///< the bag's time span (set by the caller)
  /// --start / --end: only the messages in [start_s, end_s] (bag time, s) are read, start_s and
  /// end_s narrowed to them.
  bool windowed = false;
};

/// Applies calibrate_bag's --start / --end (seconds from the bag's first message) to `info`
/// (start_s and end_s set to the bag's span). False after printing why on stderr (naming the
/// option and the bag's duration) when a value is not a number or the window is empty.
bool readBagWindow(const CliArgs& args, BagRunInfo* info);

/// The message for a bag that rosbag could not open or read to the end (`e`, rosbag's exception),
/// naming `path`. A bag cut short or never closed (rosbag's "Error reading from file", "Bag
/// unindexed": the index at the end of the file is missing) is said so, with the command that
/// rebuilds the index: `rosbag reindex <path>`.
std::string bagErrorMessage(const std::string& path, const std::exception& e);

/// Feeds every message of the selected topics to `calibrator` in bag order, then finish()es it.
/// Throws rosbag exceptions on a corrupt or truncated bag.
void readBag(const rosbag::Bag& bag, const BagTopics& topics, OnlineCalibrator* calibrator,
             BagProgress* progress, BagRunInfo* info);

}  // namespace camera_imu_alignment
