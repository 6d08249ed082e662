// The calibrator's setting keys (online_config.h).
#include "camera_imu_alignment/config/online_config.h"

#include <fstream>
#include <sstream>

#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/io/input_error.h"

namespace camera_imu_alignment {
namespace {

using Key = SettingKey<OnlineSettings>;

template <typename T, typename Access>
Key field(const std::string& name, Access access, const std::string& allowed) {
  return fieldKey<T, OnlineSettings>(name, access, allowed);
}

const char* const kPositive = "a finite number > 0";
const char* const kProbability = "a number within (0, 1)";

}  // namespace

const std::vector<Key>& onlineKeys() {
  static const std::vector<Key> table = {
      field<int>(
          "min_poses", [](OnlineSettings* s) { return &s->min_poses; }, "an integer >= 2"),
      field<double>(
          "max_std_dev_deg", [](OnlineSettings* s) { return &s->max_std_dev_deg; }, kPositive),
      field<double>(
          "consistency_level", [](OnlineSettings* s) { return &s->consistency_level; },
          kProbability),
      field<double>(
          "max_residual_deg", [](OnlineSettings* s) { return &s->max_residual_deg; }, kPositive),
      field<double>(
          "min_change_deg", [](OnlineSettings* s) { return &s->min_change_deg; },
          "a finite number >= 0"),
      field<bool>(
          "manual_capture", [](OnlineSettings* s) { return &s->manual_capture; }, "true or false"),
      field<double>(
          "remount_level", [](OnlineSettings* s) { return &s->remount.level; }, kProbability),
      field<int>(
          "remount_min_poses_after", [](OnlineSettings* s) { return &s->remount.min_poses_after; },
          "an integer >= 2"),
      field<int>(
          "remount_max_poses_after", [](OnlineSettings* s) { return &s->remount.max_poses_after; },
          "an integer >= remount_min_poses_after"),
      field<int>(
          "remount_min_poses_before",
          [](OnlineSettings* s) { return &s->remount.min_poses_before; }, "an integer >= 2"),
      field<int>(
          "remount_poses", [](OnlineSettings* s) { return &s->remount_poses; }, "an integer >= 1"),
      field<double>(
          "remount_residual_deg", [](OnlineSettings* s) { return &s->remount_residual_deg; },
          kPositive),
  };
  return table;
}

const std::vector<std::string>& onlineConfigKeys() {
  static const std::vector<std::string> names = keyNames(onlineKeys());
  return names;
}

void parseCalibrationConfig(
    const YAML::Node& root, const std::string& source, PipelineSettings* pipeline,
    OnlineSettings* online,
    const std::function<bool(const std::string&, const YAML::Node&)>& handled) {
  PipelineSettings updated_pipeline = *pipeline;
  OnlineSettings updated_online = *online;
  if (root.IsMap()) {
    for (const auto& entry : root) {
      const std::string name = entry.first.as<std::string>();
      if (handled && handled(name, entry.second)) continue;
      const Key* key = findKey(onlineKeys(), name);
      if (!key) {
        readPipelineKey(source, name, entry.second, &updated_pipeline);
        continue;
      }
      try {
        key->read(entry.second, &updated_online);
      } catch (const YAML::Exception&) {
        throw InputError(badValueMessage(source, name, yamlText(entry.second), key->allowed));
      }
    }
  }
  checkPipelineSettings(source, updated_pipeline);
  const std::string error = updated_online.validate();
  if (!error.empty()) throw InputError(source + ": " + error);
  *pipeline = updated_pipeline;
  *online = updated_online;
}

void loadCalibrationConfig(const std::string& path, PipelineSettings* pipeline,
                           OnlineSettings* online, const std::vector<std::string>& ignored_keys) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the configuration file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const YAML::Node root = parseSettingsYaml(buffer.str(), path);
  parseCalibrationConfig(
      root, path, pipeline, online, [&](const std::string& name, const YAML::Node&) {
        return std::find(ignored_keys.begin(), ignored_keys.end(), name) != ignored_keys.end();
      });
}

}  // namespace camera_imu_alignment
