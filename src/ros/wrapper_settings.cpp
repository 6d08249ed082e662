#include "camera_imu_alignment/ros/wrapper_settings.h"

#include <XmlRpcValue.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "camera_imu_alignment/config/online_config.h"
#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/io/input_error.h"

namespace camera_imu_alignment {
namespace {

using Key = SettingKey<WrapperSettings>;

template <typename T>
Key field(const std::string& name, T WrapperSettings::*member, const std::string& allowed) {
  return fieldKey<T, WrapperSettings>(
      name, [member](WrapperSettings* s) { return &(s->*member); }, allowed);
}

// The ranges check() applies, as told in messages.
const char* const kPath = "a file path (text)";
const char* const kFrame = "a tf frame name (text), or empty";
const char* const kBool = "true or false";
const char* const kPositive = "a finite number > 0";

const std::vector<Key>& keys() {
  static const std::vector<Key> table = {
      field("target_file", &WrapperSettings::target_file, kPath),
      field("camera_frame", &WrapperSettings::camera_frame, kFrame),
      field("imu_frame", &WrapperSettings::imu_frame, kFrame),
      field("publish_inverse", &WrapperSettings::publish_inverse, kBool),
      field("output_file", &WrapperSettings::output_file, "a file path (text), or empty"),
      field("load_on_start", &WrapperSettings::load_on_start, kBool),
      field("status_period_s", &WrapperSettings::status_period_s, kPositive),
      {"image_transport",
       [](const YAML::Node& node, WrapperSettings* s) {
         const std::string transport = node.as<std::string>();
         if (transport != "raw" && transport != "compressed") {
           throw YAML::Exception(node.Mark(), "unknown transport");
         }
         s->image_transport = transport;
       },
       "'raw' or 'compressed'"},
  };
  return table;
}

/// "<key> = <value>: must be <allowed>" for check(), with the table's words.
template <typename T>
std::string bad(const std::string& name, const T& value) {
  std::ostringstream text;
  text << value;
  return name + " = " + text.str() + ": must be " + findKey(keys(), name)->allowed;
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
      throw InputError("parameter '" + name +
                       "': unsupported type (a number, bool, string or list)");
  }
}

std::string check(const WrapperSettings& s) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (s.target_file.empty()) return "target_file is required (a Kalibr target YAML)";
  if (!positive(s.status_period_s)) return bad("status_period_s", s.status_period_s);
  return "";
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
  if (!fs::is_regular_file(target_abs, error)) {
    const bool relative = fs::path(target).is_relative();
    throw InputError("target_file '" + settings->target_file + "': no such file: tried " +
                     target_abs.string() +
                     (relative ? "; " + where + ": give an absolute path" : ""));
  }
  settings->target_file = target_abs.string();
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
        try {
          key->read(value, &updated);
        } catch (const YAML::Exception&) {
          throw InputError(badValueMessage(source, name, yamlText(value), key->allowed));
        }
        return true;
      });
  const std::string error = check(updated);
  if (!error.empty()) throw InputError(source + ": " + error);
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
