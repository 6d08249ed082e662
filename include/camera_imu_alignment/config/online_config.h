// OnlineSettings from the same flat `key: value` map as the pipeline's settings
// (config/default.yaml documents every key): the nodelet and calibrate_bag --config read one file.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/config/online_settings.h"
#include "camera_imu_alignment/config/pipeline_settings.h"
#include "camera_imu_alignment/config/setting_keys.h"

namespace camera_imu_alignment {

/// The calibrator's keys (gates, change detection, capture), in documentation order.
const std::vector<SettingKey<OnlineSettings>>& onlineKeys();
const std::vector<std::string>& onlineConfigKeys();

/// The calibrator's settings: their ranges (onlineKeys), then the rules across them
/// (settings_checks.h).
std::optional<SettingProblem> findProblem(const OnlineSettings& settings);
/// Both settings: the pipeline's ranges, the calibrator's, then every rule across them (e.g.
/// min_poses <= window_poses). OnlineCalibrator refuses what this finds.
std::optional<SettingProblem> findProblem(const PipelineSettings& pipeline,
                                          const OnlineSettings& online);

/// Reads a YAML file of `key: value` pairs over both settings (absent keys keep their value):
/// each key is the calibrator's or else the pipeline's; keys in `ignored_keys` (the ROS wrapper's:
/// topics, frames, paths) are skipped. Throws InputError naming the file and key on an unknown
/// key (with the closest known key as a suggestion), a wrong type, a value out of range or an
/// unusable combination (SettingsError).
void loadCalibrationConfig(const std::string& path, PipelineSettings* pipeline,
                           OnlineSettings* online, const std::vector<std::string>& ignored_keys);
/// Same from a parsed map; `source` names it in messages. `handled(name, value)` may take a key
/// first (the ROS wrapper's own) and return true; `other_keys` (the wrapper's) are also offered
/// as "did you mean" for an unknown key.
void parseCalibrationConfig(
    const YAML::Node& root, const std::string& source, PipelineSettings* pipeline,
    OnlineSettings* online,
    const std::function<bool(const std::string&, const YAML::Node&)>& handled = {},
    const std::vector<std::string>& other_keys = {});

/// How calibrate_bag solves a recording faster than real time, with the estimates and verdicts of
/// solving each window on the caller's thread: on the worker with solves_in_order, motion solved
/// as its window doubles (motion_solves_double), the joint estimate on up to two cores
/// (JointSettings::solver_threads). The other settings (the user's config) are left as they are.
void solveAsRecording(PipelineSettings* pipeline, OnlineSettings* online);

}  // namespace camera_imu_alignment
