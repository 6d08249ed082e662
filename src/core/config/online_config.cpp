// The calibrator's setting keys (online_config.h): one table, one entry per key; its ranges are
// findProblem's.
#include "camera_imu_alignment/config/online_config.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <thread>

#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/config/settings_checks.h"

namespace camera_imu_alignment {
namespace {

using Key = SettingKey<OnlineSettings>;

template <typename T, typename Access>
Key number(const std::string& name, Access access, SettingRange range, const std::string& unit,
           const std::string& description) {
  return numberKey<T, OnlineSettings>(name, access, range, unit, description);
}

}  // namespace

const std::vector<Key>& onlineKeys() {
  const SettingRange positive = above(0.0);
  const SettingRange probability = between(0.0, 1.0);
  static const std::vector<Key> table = {
      number<int>("min_poses", CIA_MEMBER(min_poses), atLeast(2), "",
                  "gate: stationary poses in the window before broadcasting"),
      number<double>("min_motion_s", CIA_MEMBER(min_motion_s), atLeast(0.0), "s",
                     "gate without min_poses poses: motion in the window before broadcasting"),
      number<double>("min_motion_rotation_deg", CIA_MEMBER(min_motion_rotation_deg), atLeast(0.0),
                     "deg", "gate with min_motion_s: rotation about each camera axis needed"),
      number<double>("max_std_dev_deg", CIA_MEMBER(max_std_dev_deg), positive, "deg",
                     "gate: largest 1-sigma about a camera axis of a broadcast estimate"),
      number<double>("consistency_level", CIA_MEMBER(consistency_level), probability, "",
                     "gate (joint estimate): its chi-square p-value must be >= this"),
      number<double>("max_residual_deg", CIA_MEMBER(max_residual_deg), positive, "deg",
                     "gate (imu_orientation auto or message): RMS pair residual"),
      number<double>("min_change_deg", CIA_MEMBER(min_change_deg), atLeast(0.0), "deg",
                     "re-broadcast only when the estimate moved more than this"),
      boolKey<OnlineSettings>("manual_capture", CIA_MEMBER(manual_capture),
                              "true: a rest becomes a pose only after ~capture_pose"),
      number<double>("remount_level", CIA_MEMBER(remount.level), probability, "",
                     "remount test: false-alarm probability per test"),
      number<int>("remount_min_poses_after", CIA_MEMBER(remount.min_poses_after), atLeast(2), "",
                  "remount test: poses of the new mount needed"),
      number<int>("remount_max_poses_after", CIA_MEMBER(remount.max_poses_after), atLeast(2), "",
                  "remount test: the newest this many poses are candidate first poses"),
      number<int>("remount_min_poses_before", CIA_MEMBER(remount.min_poses_before), atLeast(2), "",
                  "remount test: poses of the old mount needed"),
      number<int>("remount_poses", CIA_MEMBER(remount_poses), atLeast(1), "",
                  "pair modes: consecutive disagreeing poses that restart the window"),
      number<double>("remount_residual_deg", CIA_MEMBER(remount_residual_deg), positive, "deg",
                     "pair modes: RMS disagreement of a pose with the broadcast estimate"),
  };
  return table;
}

const std::vector<std::string>& onlineConfigKeys() {
  static const std::vector<std::string> names = keyNames(onlineKeys());
  return names;
}

std::optional<SettingProblem> findProblem(const OnlineSettings& settings) {
  if (auto problem = checkRanges(onlineKeys(), settings)) return problem;
  return checkAcrossKeys(nullptr, &settings);
}

std::optional<SettingProblem> findProblem(const PipelineSettings& pipeline,
                                          const OnlineSettings& online) {
  if (auto problem = checkRanges(pipelineKeys(), pipeline)) return problem;
  if (auto problem = checkRanges(onlineKeys(), online)) return problem;
  return checkAcrossKeys(&pipeline, &online);
}

void parseCalibrationConfig(
    const YAML::Node& root, const std::string& source, PipelineSettings* pipeline,
    OnlineSettings* online,
    const std::function<bool(const std::string&, const YAML::Node&)>& handled,
    const std::vector<std::string>& other_keys) {
  PipelineSettings updated_pipeline = *pipeline;
  OnlineSettings updated_online = *online;
  if (root.IsMap()) {
    for (const auto& entry : root) {
      const std::string name = entry.first.as<std::string>();
      if (handled && handled(name, entry.second)) continue;
      if (const Key* key = findKey(onlineKeys(), name)) {
        readKey(*key, source, entry.second, &updated_online);
      } else if (findKey(pipelineKeys(), name)) {
        readPipelineKey(source, name, entry.second, &updated_pipeline);
      } else {
        std::vector<std::string> known = pipelineConfigKeys();
        known.insert(known.end(), onlineConfigKeys().begin(), onlineConfigKeys().end());
        known.insert(known.end(), other_keys.begin(), other_keys.end());
        throw SettingsError(source, name, unknownKeyMessage(name, known));
      }
    }
  }
  throwIfProblem(source, findProblem(updated_pipeline, updated_online));
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
      root, path, pipeline, online,
      [&](const std::string& name, const YAML::Node&) {
        return std::find(ignored_keys.begin(), ignored_keys.end(), name) != ignored_keys.end();
      },
      ignored_keys);
}

void solveAsRecording(PipelineSettings* pipeline, OnlineSettings* online) {
  online->threaded = true;
  online->solves_in_order = true;
  online->motion_solves_double = true;
  pipeline->joint.solver_threads =
      static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 2u));
}

}  // namespace camera_imu_alignment
