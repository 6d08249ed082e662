// calibrate_bag's bag reading (bag_reader.h).
#include "bag_reader.h"

#include <geometry_msgs/PoseStamped.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <vector>

#include "camera_imu_alignment/ros/message_input.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

BagProgress::BagProgress(bool enabled, double start_s, double end_s)
    : enabled_(enabled), tty_(isatty(fileno(stderr))), start_(start_s), end_(end_s) {}

void BagProgress::update(double t, const OnlineCalibrator& calibrator, bool force) {
  if (!enabled_) return;
  const double span = end_ - start_;
  const int percent = span > 0.0 ? static_cast<int>(100.0 * (t - start_) / span) : 100;
  const int step = tty_ ? 1 : 10;
  if (!force && percent / step == last_ / step) return;
  last_ = percent;
  const CalibrationSnapshot snap = calibrator.snapshot(SnapshotContents::kWithHistory);
  std::ostringstream line;
  line << "[calibrate_bag] " << std::setw(3) << std::min(percent, 100) << "% of bag time, "
       << snap.rests.size() << " rests, " << snap.poses.size() << " poses";
  if (snap.inputs.motion_frames > 0) {
    line << ", " << snap.inputs.motion_frames << " camera orientations during motion";
  }
  if (snap.latest) {
    const AlignmentResult& result = snap.latest->result;
    line << ", R_cam_imu " << rollPitchYawText(result.R_cam_imu, 2) << " +- " << std::fixed
         << std::setprecision(2) << result.quality.std_dev_deg.maxCoeff();
  }
  if (tty_) {
    std::cerr << "\r\033[K" << line.str() << std::flush;
  } else {
    std::cerr << line.str() << "\n";
  }
}

void BagProgress::done() {
  if (enabled_ && tty_) std::cerr << "\n";
}

void BagRejectLog::operator()(RejectReason reason, InputStream stream, const std::string& detail) {
  const int n = ++shown_[reason];
  if (n <= 3) {
    std::cerr << "[calibrate_bag] " << topicOf(stream) << ": rejected (" << toString(reason)
              << "): " << detail << "\n";
  }
  if (n == 3) {
    std::cerr << "[calibrate_bag] (further '" << toString(reason)
              << "' rejections are counted, not shown)\n";
  }
}

std::string BagRejectLog::topicOf(InputStream stream) const {
  switch (stream) {
    case InputStream::kImu:
      return topics_.imu;
    case InputStream::kMagnetometer:
      return topics_.mag;
    case InputStream::kImage:
      return topics_.image;
    case InputStream::kCameraInfo:
      return topics_.camera_info;
    case InputStream::kCameraPose:
      if (!topics_.camera_pose.empty()) return topics_.camera_pose;
      break;
  }
  return toString(stream);
}

namespace {

/// The bag's static transforms (/tf_static, e.g. the magnetometer's frame in the IMU's).
void readStaticTransforms(const rosbag::Bag& bag, tf2::BufferCore* tf) {
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/tf_static", "tf_static"}));
  for (const rosbag::MessageInstance& m : view) {
    const auto msg = m.instantiate<tf2_msgs::TFMessage>();
    if (!msg) continue;
    for (geometry_msgs::TransformStamped t : msg->transforms) {
      t.header.frame_id = normalizeFrameId(t.header.frame_id);
      t.child_frame_id = normalizeFrameId(t.child_frame_id);
      tf->setTransform(t, "bag", true);  // a bad transform is refused by tf2 (logged)
    }
  }
}

}  // namespace

bool readBagWindow(const CliArgs& args, BagRunInfo* info) {
  if (!args.has("--start") && !args.has("--end")) return true;
  const double duration_s = info->end_s - info->start_s;
  double from_s = 0.0, to_s = duration_s;
  try {
    from_s = args.getDouble("--start", 0.0, 0.0, 1e9);
    to_s = args.getDouble("--end", duration_s, 0.0, 1e9);
  } catch (const UsageError& e) {
    std::cerr << "calibrate_bag: " << e.what() << "\n";
    return false;
  }
  if (from_s >= std::min(to_s, duration_s)) {
    std::cerr << "calibrate_bag: --start " << from_s << " s to --end " << to_s
              << " s holds nothing of the bag (" << duration_s << " s long)\n";
    return false;
  }
  info->windowed = true;
  const double begin_s = info->start_s;
  info->start_s = begin_s + from_s;
  info->end_s = begin_s + std::min(to_s, duration_s);
  std::cerr << "[calibrate_bag] reading " << from_s << " s to " << info->end_s - begin_s
            << " s of the bag (" << duration_s << " s)\n";
  return true;
}

std::string bagErrorMessage(const std::string& path, const std::exception& e) {
  const std::string what = e.what();
  const bool cut_short = dynamic_cast<const rosbag::BagUnindexedException*>(&e) != nullptr ||
                         what.find("Error reading from file") != std::string::npos ||
                         what.find("unindexed") != std::string::npos;
  if (!cut_short) return path + ": " + what;
  return path + ": cannot read the bag (" + what +
         "): it is truncated or was not closed (a recording cut short has no index at its end); "
         "rebuild the index with 'rosbag reindex " +
         path + "' (it keeps the original beside it) and run again";
}

void readBag(const rosbag::Bag& bag, const BagTopics& topics, OnlineCalibrator* calibrator,
             BagProgress* progress, BagRunInfo* info) {
  std::vector<std::string> names = {topics.imu};
  for (const auto& t : {topics.mag, topics.image, topics.camera_info, topics.camera_pose}) {
    if (!t.empty()) names.push_back(t);
  }
  rosbag::View view;
  if (info->windowed) {  // --start / --end
    view.addQuery(bag, rosbag::TopicQuery(names), ros::Time(info->start_s), ros::Time(info->end_s));
  } else {
    view.addQuery(bag, rosbag::TopicQuery(names));
  }
  // The nodelet's checks and conversions (MessageInput), so that both refuse the same messages.
  MessageInput input(calibrator, [](const std::string& notice) {
    std::cerr << "[calibrate_bag] note: " << notice << "\n";
  });
  tf2::BufferCore static_tf;
  readStaticTransforms(bag, &static_tf);
  input.setTransforms(&static_tf);
  for (const rosbag::MessageInstance& m : view) {
    const std::string& topic = m.getTopic();
    if (topic == topics.imu) {
      if (const auto msg = m.instantiate<sensor_msgs::Imu>()) input.addImu(*msg);
    } else if (topic == topics.mag) {
      if (const auto msg = m.instantiate<sensor_msgs::MagneticField>()) input.addMagnetic(*msg);
    } else if (topic == topics.camera_info) {
      ++info->info_messages;
      if (const auto msg = m.instantiate<sensor_msgs::CameraInfo>()) input.setCameraInfo(*msg);
    } else if (topic == topics.camera_pose) {
      ++info->camera_pose_messages;
      if (const auto msg = m.instantiate<geometry_msgs::PoseStamped>()) input.addCameraPose(*msg);
    } else if (topic == topics.image) {
      ++info->image_messages;
      if (topics.image_compressed) {
        if (const auto msg = m.instantiate<sensor_msgs::CompressedImage>()) input.addImage(*msg);
      } else if (const auto msg = m.instantiate<sensor_msgs::Image>()) {
        input.addImage(*msg);
      }
    }
    progress->update(m.getTime().toSec(), *calibrator);
  }
  info->imu_frame = input.imuFrame();
  info->camera_frame = input.cameraFrame();
  calibrator->finish();
  progress->update(info->end_s, *calibrator, true);
  progress->done();
}

}  // namespace camera_imu_alignment
