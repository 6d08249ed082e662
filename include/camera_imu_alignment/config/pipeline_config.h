// PipelineSettings from a flat YAML map whose keys are the node's private parameter names
// (config/default.yaml documents every key with its default and unit). calibrate_bag --config
// and the nodelet read the same keys, so one file configures both.
#pragma once

#include <string>
#include <vector>

#include "camera_imu_alignment/config/pipeline_settings.h"
#include "camera_imu_alignment/config/setting_keys.h"

namespace camera_imu_alignment {

/// The pipeline's keys, in documentation order.
const std::vector<SettingKey<PipelineSettings>>& pipelineKeys();
/// Their names.
const std::vector<std::string>& pipelineConfigKeys();

/// Reads one key's value into `settings`; throws SettingsError naming `source` and the key on an
/// unknown key (with the closest pipeline key as a suggestion) or a value of the wrong type.
void readPipelineKey(const std::string& source, const std::string& name, const YAML::Node& value,
                     PipelineSettings* settings);
/// Throws SettingsError naming `source` and the key when a value is out of its range or the
/// settings are unusable together (settings_checks.h).
void checkPipelineSettings(const std::string& source, const PipelineSettings& settings);
/// YAML text -> a map node (or null for an empty text); throws InputError naming `source`.
YAML::Node parseSettingsYaml(const std::string& text, const std::string& source);

/// Reads a YAML file of `key: value` pairs over `settings` (absent keys keep their value).
/// Throws SettingsError naming the file and key on an unknown key, a wrong type, a value out of
/// range or an unusable combination (PipelineSettings::validate). Keys not read by the pipeline
/// but used by the ROS wrapper (topics, frames, paths) are listed in `ignored_keys` and skipped.
void loadPipelineConfig(const std::string& path, PipelineSettings* settings,
                        const std::vector<std::string>& ignored_keys = {});
/// Same from YAML text; `source` names it in messages.
void parsePipelineConfig(const std::string& text, const std::string& source,
                         PipelineSettings* settings,
                         const std::vector<std::string>& ignored_keys = {});

}  // namespace camera_imu_alignment
