#include "camera_imu_alignment/ros/wrapper_settings.h"

#include <XmlRpcValue.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/config/online_config.h"
#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/config/settings_checks.h"

namespace camera_imu_alignment {
namespace {

using Key = SettingKey<WrapperSettings>;

const std::vector<Key>& keys() {
  const char* const frame = "a tf frame name (text), or empty";
  static const std::vector<Key> table = {
      textKey<WrapperSettings>(
          "target_file", CIA_MEMBER(target_file), "a file path (text)",
          "Kalibr target YAML; empty: no board, the camera's rotation from the natural scene"),
      textKey<WrapperSettings>("camera_frame", CIA_MEMBER(camera_frame), frame,
                               "tf frame of the camera; empty: the image header's frame_id"),
      textKey<WrapperSettings>("imu_frame", CIA_MEMBER(imu_frame), frame,
                               "tf frame of the IMU; empty: the Imu header's frame_id"),
      boolKey<WrapperSettings>("publish_inverse", CIA_MEMBER(publish_inverse),
                               "false: camera -> imu (parent camera); true: imu -> camera"),
      textKey<WrapperSettings>("output_file", CIA_MEMBER(output_file),
                               "a file path (text), or empty",
                               "each accepted calibration is written here; empty: not saved"),
      boolKey<WrapperSettings>("load_on_start", CIA_MEMBER(load_on_start),
                               "broadcast output_file's calibration at start if it exists"),
      numberKey<double, WrapperSettings>("status_period_s", CIA_MEMBER(status_period_s), above(0.0),
                                         "s",
                                         "~status and /diagnostics are also published this often"),
      wordKey<WrapperSettings>("image_transport", CIA_MEMBER(image_transport),
                               {"raw", "compressed"}, "image_transport's parameter"),
  };
  return table;
}

/// XmlRpc parameter value -> YAML node (scalars and lists; maps are not settings).
YAML::Node toYaml(XmlRpc::XmlRpcValue& value, const std::string& name) {
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return YAML::Node(static_cast<bool>(value));
    case XmlRpc::XmlRpcValue::TypeInt:
      return YAML::Node(static_cast<int>(value));
    case XmlRpc::XmlRpcValue::TypeDouble:
      return YAML::Node(static_cast<double>(value));
    case XmlRpc::XmlRpcValue::TypeString:
      return YAML::Node(static_cast<std::string>(value));
    case XmlRpc::XmlRpcValue::TypeArray: {
      YAML::Node list(YAML::NodeType::Sequence);
      for (int i = 0; i < value.size(); ++i) list.push_back(toYaml(value[i], name));
      return list;
    }
    default:
      throw SettingsError(
          "", name, "parameter '" + name + "': unsupported type (a number, bool, string or list)");
  }
}

/// The wrapper's ranges (an empty target_file: the natural scene, no board).
void check(const std::string& source, const WrapperSettings& s) {
  throwIfProblem(source, checkRanges(keys(), s));
}

}  // namespace

std::string expandHome(const std::string& path) {
  if (path.empty() || path[0] != '~' || (path.size() > 1 && path[1] != '/')) return path;
  const char* home = std::getenv("HOME");
  return home ? std::string(home) + path.substr(1) : path;
}

std::vector<std::string> resolvePaths(WrapperSettings* settings) {
  namespace fs = std::filesystem;
  std::vector<std::string> notices;
  const std::string where =
      "a relative path resolves from the node's working directory (ROS_HOME under roslaunch, "
      "~/.ros by default), not from where roslaunch was typed";
  const std::string target = expandHome(settings->target_file);
  std::error_code error;
  const fs::path target_abs = fs::absolute(target, error);
  if (!settings->target_file.empty()) {  // empty: no board, the natural scene
    if (!fs::is_regular_file(target_abs, error)) {
      const bool relative = fs::path(target).is_relative();
      throw SettingsError("", "target_file",
                          "target_file '" + settings->target_file + "': no such file: tried " +
                              target_abs.string() +
                              (relative ? "; " + where + ": give an absolute path" : ""));
    }
    settings->target_file = target_abs.string();
  }
  if (!settings->output_file.empty()) {
    const std::string output = expandHome(settings->output_file);
    const std::string output_abs = fs::absolute(output, error).string();
    if (fs::path(output).is_relative()) {
      notices.push_back("output_file '" + settings->output_file + "' is a relative path: " + where +
                        "; the calibration is written to " + output_abs);
    }
    settings->output_file = output_abs;
  }
  return notices;
}

const std::vector<SettingKey<WrapperSettings>>& wrapperKeyTable() { return keys(); }

const std::vector<std::string>& wrapperKeys() {
  static const std::vector<std::string> names = keyNames(keys());
  return names;
}

void parseSettings(const YAML::Node& root, const std::string& source, WrapperSettings* wrapper,
                   PipelineSettings* pipeline) {
  // One pass over the map and the three tables: a key is the wrapper's, else the calibrator's,
  // else the pipeline's (whose reader names an unknown key).
  WrapperSettings updated = *wrapper;
  PipelineSettings updated_pipeline = *pipeline;
  parseCalibrationConfig(
      root, source, &updated_pipeline, &updated.online,
      [&](const std::string& name, const YAML::Node& value) {
        const Key* key = findKey(keys(), name);
        if (!key) return false;
        readKey(*key, source, value, &updated);
        return true;
      },
      wrapperKeys());
  check(source, updated);
  *wrapper = updated;
  *pipeline = updated_pipeline;
}

void parseSettings(const std::string& yaml_text, const std::string& source,
                   WrapperSettings* wrapper, PipelineSettings* pipeline) {
  parseSettings(parseSettingsYaml(yaml_text, source), source, wrapper, pipeline);
}

void readSettings(const ros::NodeHandle& private_nh, WrapperSettings* wrapper,
                  PipelineSettings* pipeline) {
  const std::string ns = private_nh.getNamespace() + "/";
  std::vector<std::string> names;
  private_nh.getParamNames(names);
  YAML::Node root(YAML::NodeType::Map);
  for (const std::string& full : names) {
    if (full.compare(0, ns.size(), ns) != 0) continue;
    const std::string name = full.substr(ns.size());
    if (name.empty() || name.find('/') != std::string::npos) continue;  // nested: not a setting
    XmlRpc::XmlRpcValue value;
    if (!private_nh.getParam(name, value)) continue;
    root[name] = toYaml(value, name);
  }
  parseSettings(root, "parameters of " + private_nh.getNamespace(), wrapper, pipeline);
}

}  // namespace camera_imu_alignment
