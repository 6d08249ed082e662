#include "bag_topics.h"

#include <rosbag/view.h>

#include <algorithm>
#include <map>
#include <stdexcept>
#include <vector>

namespace camera_imu_alignment {
namespace {

const char* kImu = "sensor_msgs/Imu";
const char* kMag = "sensor_msgs/MagneticField";
const char* kImage = "sensor_msgs/Image";
const char* kCompressed = "sensor_msgs/CompressedImage";
const char* kInfo = "sensor_msgs/CameraInfo";
const char* kPose = "geometry_msgs/PoseStamped";

std::string normalise(std::string topic) {
  if (!topic.empty() && topic[0] != '/') topic = "/" + topic;
  return topic;
}

std::string list(const std::vector<std::string>& topics) {
  std::string out;
  for (const auto& t : topics) out += (out.empty() ? "" : ", ") + t;
  return out;
}

/// The bag's topics of `wanted_types`, for a message about a topic that is not one of them:
/// "the bag's sensor_msgs/Imu topics: /imu0, /imu1", or that it has none.
std::string topicsOfTypes(const std::map<std::string, std::string>& types,
                          const std::vector<std::string>& wanted_types) {
  std::vector<std::string> found;
  for (const auto& [topic, type] : types) {
    if (std::find(wanted_types.begin(), wanted_types.end(), type) != wanted_types.end()) {
      found.push_back(topic + (wanted_types.size() > 1 ? " (" + type + ")" : ""));
    }
  }
  std::string kinds;
  for (const auto& t : wanted_types) kinds += (kinds.empty() ? "" : " or ") + t;
  if (found.empty()) return "the bag has no " + kinds + " topic";
  return "the bag's " + kinds + " topics: " + list(found);
}

/// The topic of `type`: the requested one (checked) or the only one in the bag.
std::string pick(const std::map<std::string, std::string>& types, const std::string& requested,
                 const std::vector<std::string>& wanted_types, const char* what, bool required,
                 const char* option) {
  if (!requested.empty()) {
    // "imu" and "/imu" name the same topic; bags store whichever the recorder used.
    auto it = types.find(requested);
    for (auto c = types.begin(); it == types.end() && c != types.end(); ++c) {
      if (normalise(c->first) == normalise(requested)) it = c;
    }
    if (it == types.end()) {
      throw std::runtime_error(std::string(option) + " " + requested +
                               ": no such topic in the bag; " + topicsOfTypes(types, wanted_types));
    }
    for (const auto& t : wanted_types) {
      if (it->second == t) return it->first;
    }
    throw std::runtime_error(std::string(option) + " " + requested + ": topic has type " +
                             it->second + ", " + what + " needs " + list(wanted_types) + "; " +
                             topicsOfTypes(types, wanted_types));
  }
  std::vector<std::string> candidates;
  for (const auto& [topic, type] : types) {
    for (const auto& t : wanted_types) {
      if (type == t) candidates.push_back(topic);
    }
  }
  if (candidates.size() > 1) {
    throw std::runtime_error(std::string("several ") + what + " topics in the bag (" +
                             list(candidates) + "): choose one with " + option);
  }
  if (candidates.empty()) {
    if (required) {
      throw std::runtime_error(std::string("no ") + what + " topic (" + list(wanted_types) +
                               ") in the bag");
    }
    return "";
  }
  return candidates.front();
}

/// The camera_pose topic to use without --camera-pose-topic: a PoseStamped topic whose last name
/// is camera_pose ("/camera_pose", "/cam0/camera_pose"); "" when none, an error when several.
std::string defaultCameraPoseTopic(const std::map<std::string, std::string>& types) {
  std::vector<std::string> found;
  for (const auto& [topic, type] : types) {
    const std::string t = normalise(topic);
    if (type == kPose && t.size() >= 12 && t.compare(t.size() - 12, 12, "/camera_pose") == 0) {
      found.push_back(topic);
    }
  }
  if (found.size() > 1) {
    throw std::runtime_error("several camera pose topics in the bag (" + list(found) +
                             "): choose one with --camera-pose-topic");
  }
  return found.empty() ? "" : found.front();
}

/// Images and their camera info (requested or detected by type), into `topics`.
void selectImageTopics(std::map<std::string, std::string> types, const BagTopics& requested,
                       BagTopics* out) {
  BagTopics& topics = *out;
  // Images: a raw and a compressed topic of the same camera are common; prefer the raw one.
  if (requested.image.empty()) {
    topics.image = pick(types, "", {kImage}, "image", false, "--image-topic");
    if (topics.image.empty()) {
      topics.image = pick(types, "", {kCompressed}, "image", false, "--image-topic");
    }
  } else {
    topics.image =
        pick(types, requested.image, {kImage, kCompressed}, "image", true, "--image-topic");
  }
  topics.image_compressed = !topics.image.empty() && types[topics.image] == kCompressed;
  // Camera info: the one next to the image topic when there are several.
  if (requested.camera_info.empty() && !topics.image.empty()) {
    std::string base = topics.image;
    if (topics.image_compressed && base.size() > 11 &&
        base.compare(base.size() - 11, 11, "/compressed") == 0) {
      base.resize(base.size() - 11);
    }
    const std::string sibling = base.substr(0, base.find_last_of('/')) + "/camera_info";
    if (types.count(sibling) && types[sibling] == kInfo) {
      topics.camera_info = sibling;
      return;
    }
  }
  topics.camera_info =
      pick(types, requested.camera_info, {kInfo}, "camera info", false, "--camera-info-topic");
}

}  // namespace

BagTopics selectBagTopics(const rosbag::Bag& bag, const BagTopics& requested) {
  std::map<std::string, std::string> types;
  rosbag::View view(bag);
  for (const rosbag::ConnectionInfo* c : view.getConnections()) types[c->topic] = c->datatype;

  BagTopics topics;
  topics.imu = pick(types, requested.imu, {kImu}, "IMU", true, "--imu-topic");
  topics.mag = pick(types, requested.mag, {kMag}, "magnetometer", false, "--mag-topic");
  if (!requested.camera_pose.empty()) {  // camera poses chosen explicitly
    if (!requested.image.empty() || !requested.camera_info.empty()) {
      throw std::runtime_error(
          "--camera-pose-topic with --image-topic / --camera-info-topic: give one camera source, "
          "camera poses or images");
    }
    topics.camera_pose =
        pick(types, requested.camera_pose, {kPose}, "camera pose", true, "--camera-pose-topic");
    topics.camera_source_note = "camera source: camera poses on " + topics.camera_pose +
                                " (--camera-pose-topic; images, if any, are not read)";
    return topics;
  }
  const std::string pose_topic = defaultCameraPoseTopic(types);
  selectImageTopics(types, requested, &topics);
  if (topics.image.empty() && !pose_topic.empty()) {
    topics.camera_info.clear();
    topics.camera_pose = pose_topic;
    topics.camera_source_note =
        "camera source: camera poses on " + pose_topic + " (the bag has no image topic)";
  } else if (!topics.image.empty() && !pose_topic.empty()) {
    topics.camera_source_note =
        "camera source: images on " + topics.image + "; the bag also has camera poses on " +
        pose_topic + ", not read (--camera-pose-topic " + pose_topic + " uses them instead)";
  }
  return topics;
}

}  // namespace camera_imu_alignment
