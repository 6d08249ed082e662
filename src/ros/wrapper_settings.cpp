#include "camera_imu_alignment/ros/wrapper_settings.h"

#include <XmlRpcValue.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "camera_imu_alignment/io/input_error.h"
#include "camera_imu_alignment/pipeline/pipeline_config.h"

namespace camera_imu_alignment {
namespace {

using Key = SettingKey<WrapperSettings>;

template <typename T>
Key field(const std::string& name, T WrapperSettings::*member) {
  return fieldKey<T, WrapperSettings>(name, [member](WrapperSettings* s) { return &(s->*member); });
}

const std::vector<Key>& keys() {
  static const std::vector<Key> table = {
      field("target_file", &WrapperSettings::target_file),
      field("camera_frame", &WrapperSettings::camera_frame),
      field("imu_frame", &WrapperSettings::imu_frame),
      field("publish_inverse", &WrapperSettings::publish_inverse),
      field("output_file", &WrapperSettings::output_file),
      field("load_on_start", &WrapperSettings::load_on_start),
      field("min_poses", &WrapperSettings::min_poses),
      field("max_residual_deg", &WrapperSettings::max_residual_deg),
      field("max_std_dev_deg", &WrapperSettings::max_std_dev_deg),
      field("min_change_deg", &WrapperSettings::min_change_deg),
      field("manual_capture", &WrapperSettings::manual_capture),
      field("remount_poses", &WrapperSettings::remount_poses),
      field("remount_residual_deg", &WrapperSettings::remount_residual_deg),
      field("status_period_s", &WrapperSettings::status_period_s),
      field("image_transport", &WrapperSettings::image_transport),
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
      throw InputError("parameter '" + name +
                       "': unsupported type (a number, bool, string or list)");
  }
}

std::string check(const WrapperSettings& s) {
  std::ostringstream out;
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (s.target_file.empty()) {
    out << "target_file is required (a Kalibr target YAML)";
  } else if (s.min_poses < 2) {
    out << "min_poses = " << s.min_poses << ": must be >= 2";
  } else if (!positive(s.max_residual_deg)) {
    out << "max_residual_deg = " << s.max_residual_deg << ": must be > 0";
  } else if (!positive(s.max_std_dev_deg)) {
    out << "max_std_dev_deg = " << s.max_std_dev_deg << ": must be > 0";
  } else if (!(std::isfinite(s.min_change_deg) && s.min_change_deg >= 0.0)) {
    out << "min_change_deg = " << s.min_change_deg << ": must be >= 0";
  } else if (s.remount_poses < 1) {
    out << "remount_poses = " << s.remount_poses << ": must be >= 1";
  } else if (!positive(s.remount_residual_deg)) {
    out << "remount_residual_deg = " << s.remount_residual_deg << ": must be > 0";
  } else if (!positive(s.status_period_s)) {
    out << "status_period_s = " << s.status_period_s << ": must be > 0";
  }
  return out.str();
}

}  // namespace

const std::vector<std::string>& wrapperKeys() {
  static const std::vector<std::string> names = keyNames(keys());
  return names;
}

void parseSettings(const YAML::Node& root, const std::string& source, WrapperSettings* wrapper,
                   PipelineSettings* pipeline) {
  // One pass over the map and the two tables: a key is the wrapper's or else the pipeline's
  // (whose reader names an unknown key).
  WrapperSettings updated = *wrapper;
  PipelineSettings updated_pipeline = *pipeline;
  if (root.IsMap()) {
    for (const auto& entry : root) {
      const std::string name = entry.first.as<std::string>();
      const Key* key = findKey(keys(), name);
      if (!key) {
        readPipelineKey(source, name, entry.second, &updated_pipeline);
        continue;
      }
      try {
        key->read(entry.second, &updated);
      } catch (const YAML::Exception& e) {
        throw InputError(source + ": parameter '" + name + "': " + e.msg);
      }
    }
  }
  checkPipelineSettings(source, updated_pipeline);
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
