// One way to describe a settings struct's keys for the readers of config files and ROS parameters:
// a table of SettingKey (name -> how to read the YAML value into the struct). The pipeline's
// table (pipeline_config.cpp) and the ROS wrapper's (wrapper_settings.cpp) are both written with
// it, and one reader walks a flat `key: value` map over both tables (parseSettings). Every bad
// value is reported in one form, badValueMessage: "<source>: <key> = <value given>: must be
// <allowed>".
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace camera_imu_alignment {

template <typename Settings>
struct SettingKey {
  std::string name;
  /// Reads `node` into the settings; throws YAML::Exception (wrong type, bad value).
  std::function<void(const YAML::Node&, Settings*)> read;
  /// The values allowed, for messages: "a number > 0", "an integer within [2, 200]",
  /// "'optimal' or 'two_step'" (the same ranges the settings' own checks apply).
  std::string allowed;
};

/// A key read with YAML's conversion into the field `access(settings)` points to.
template <typename T, typename Settings, typename Access>
SettingKey<Settings> fieldKey(const std::string& name, Access access, const std::string& allowed) {
  return {name, [access](const YAML::Node& node, Settings* s) { *access(s) = node.as<T>(); },
          allowed};
}

/// A value as the user wrote it: a scalar's text, a list or map in YAML flow style.
inline std::string yamlText(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  if (node.IsNull()) return "(empty)";
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

/// The one form of every bad-value message: "<source>: <key> = <value>: must be <allowed>".
inline std::string badValueMessage(const std::string& source, const std::string& key,
                                   const std::string& value, const std::string& allowed) {
  return source + ": " + key + " = " + value + ": must be " + allowed;
}

/// The key named `name` in `table`, or nullptr.
template <typename Settings>
const SettingKey<Settings>* findKey(const std::vector<SettingKey<Settings>>& table,
                                    const std::string& name) {
  const auto it = std::find_if(table.begin(), table.end(),
                               [&](const SettingKey<Settings>& k) { return k.name == name; });
  return it == table.end() ? nullptr : &*it;
}

/// The names of a table, in its order.
template <typename Settings>
std::vector<std::string> keyNames(const std::vector<SettingKey<Settings>>& table) {
  std::vector<std::string> names;
  for (const auto& key : table) names.push_back(key.name);
  return names;
}

}  // namespace camera_imu_alignment
