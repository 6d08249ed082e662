// The settings tables (config/setting_keys.h) against config/default.yaml and their generated
// checks: every key in the file is in a table with the struct's default and every table key is
// in the file; every range is enforced with the key named; the checks across keys name both keys;
// an unknown key is answered with the closest known one; every bad setting is a SettingsError.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>

#include "camera_imu_alignment/config/online_config.h"
#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/config/settings_checks.h"
#include "camera_imu_alignment/config/settings_error.h"
#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/ros/wrapper_settings.h"
#include "camera_imu_alignment/vision/target_description.h"

namespace camera_imu_alignment {
namespace {

YAML::Node defaultFile() {
  return YAML::LoadFile(std::string(PACKAGE_SOURCE_DIR) + "/config/default.yaml");
}

/// Checks one table against the file: each of its keys is in the file, and the file's value read
/// into default settings leaves the default unchanged. Adds the table's names to `known`.
template <typename Settings>
void expectFileHoldsTheDefaults(const std::vector<SettingKey<Settings>>& table,
                                const YAML::Node& file, std::set<std::string>* known) {
  const Settings defaults;
  for (const SettingKey<Settings>& key : table) {
    EXPECT_TRUE(known->insert(key.name).second) << key.name << " is in two tables";
    const YAML::Node value = file[key.name];
    if (!value) {
      ADD_FAILURE() << key.name << " is not in config/default.yaml";
      continue;
    }
    Settings loaded = defaults;
    ASSERT_NO_THROW(readKey(key, "default.yaml", value, &loaded)) << key.name;
    EXPECT_EQ(key.text(loaded), key.text(defaults))
        << key.name << ": config/default.yaml says " << yamlText(value);
    // Every entry is complete and its default is within its own range.
    EXPECT_FALSE(key.allowed.empty()) << key.name;
    EXPECT_FALSE(key.description.empty()) << key.name;
    EXPECT_TRUE(key.in_range(defaults)) << key.name << " = " << key.text(defaults);
  }
}

TEST(SettingsTable, DefaultFileAndTablesAgreeInBothDirections) {
  const YAML::Node file = defaultFile();
  std::set<std::string> known;
  expectFileHoldsTheDefaults(pipelineKeys(), file, &known);
  expectFileHoldsTheDefaults(onlineKeys(), file, &known);
  expectFileHoldsTheDefaults(wrapperKeyTable(), file, &known);
  for (const auto& entry : file) {
    const std::string name = entry.first.as<std::string>();
    EXPECT_TRUE(known.count(name)) << name << " in config/default.yaml is in no table";
  }
}

TEST(SettingsTable, TheDefaultCheckSeesADefaultThatDiffers) {
  // The comparison above is not vacuous: a file value other than the default reads differently.
  const SettingKey<PipelineSettings>* key = findKey(pipelineKeys(), "gravity_m_s2");
  ASSERT_NE(key, nullptr);
  PipelineSettings loaded;
  readKey(*key, "test", YAML::Load("9.8100001"), &loaded);
  EXPECT_NE(key->text(loaded), key->text(PipelineSettings()));
  EXPECT_EQ(formatSettingNumber(0.1), "0.1");
  EXPECT_EQ(formatSettingNumber(1.5e-05), "1.5e-05");
}

/// The message for `text` (target_file set), or "" when it was accepted.
std::string refusal(const std::string& text) {
  WrapperSettings w;
  PipelineSettings p;
  try {
    parseSettings("target_file: t.yaml\n" + text, "params", &w, &p);
  } catch (const SettingsError& e) {
    return e.what();
  }
  return "";
}

template <typename Settings>
void expectEveryRangeEnforced(const std::vector<SettingKey<Settings>>& table) {
  for (const SettingKey<Settings>& key : table) {
    if (!key.range) continue;
    const SettingRange& r = *key.range;
    ASSERT_TRUE(std::isfinite(r.min)) << key.name;
    // Just below the range (the bound itself when it is open).
    const double below = r.min_open ? r.min : r.min - (key.integer ? 1.0 : 1e-3);
    const std::string value = formatSettingNumber(below);
    const std::string message = refusal(key.name + ": " + value + "\n");
    EXPECT_NE(message.find("params: " + key.name + " = "), std::string::npos)
        << key.name << ": " << value << " -> " << message;
    if (std::isfinite(r.max)) {
      const double above_max = r.max_open ? r.max : r.max + 1.0;
      const std::string high = refusal(key.name + ": " + formatSettingNumber(above_max) + "\n");
      EXPECT_NE(high.find("params: " + key.name + " = "), std::string::npos) << high;
    }
    if (!key.integer) {
      const std::string nan = refusal(key.name + ": .nan\n");
      EXPECT_NE(nan.find("params: " + key.name + " = nan: must be"), std::string::npos) << nan;
    }
  }
}

TEST(SettingsTable, EveryRangeIsEnforcedNamingTheKey) {
  expectEveryRangeEnforced(pipelineKeys());
  expectEveryRangeEnforced(onlineKeys());
  expectEveryRangeEnforced(wrapperKeyTable());
}

TEST(SettingsTable, AllowedTextIsGeneratedFromTheRange) {
  EXPECT_EQ(rangeText(above(0.0), false), "a finite number > 0");
  EXPECT_EQ(rangeText(atLeast(0.0), false), "a finite number >= 0");
  EXPECT_EQ(rangeText(between(0.0, 1.0), false), "a number within (0, 1)");
  EXPECT_EQ(rangeText(atLeast(2), true), "an integer >= 2");
  EXPECT_EQ(rangeText(within(2, 200), true), "an integer within [2, 200]");
  EXPECT_EQ(wordsText({"raw", "compressed"}), "'raw' or 'compressed'");
  EXPECT_EQ(wordsText({"a", "b", "c"}), "'a', 'b' or 'c'");
  EXPECT_EQ(findKey(pipelineKeys(), "imu_orientation")->allowed,
            "'joint', 'auto', 'magnetometer' or 'message'");
}

TEST(SettingsChecks, EachCheckAcrossKeysNamesBothKeys) {
  const std::pair<std::string, std::string> cases[] = {
      {"window_poses: 20\nmin_poses: 21", "min_poses = 21 > window_poses = 20"},
      {"window_poses: 20\nmin_poses_to_solve: 25", "min_poses_to_solve = 25 > window_poses = 20"},
      {"min_frames_per_pose: 5\nmax_frames_per_pose: 4",
       "min_frames_per_pose = 5 > max_frames_per_pose = 4"},
      {"min_frame_interval_s: 2\nmissed_frame_interval_s: 1.5",
       "min_frame_interval_s = 2 > missed_frame_interval_s = 1.5"},
      {"remount_min_poses_after: 5\nremount_max_poses_after: 4",
       "remount_min_poses_after = 5 > remount_max_poses_after = 4"},
      {"window_poses: 5\nmin_poses: 3\nremount_min_poses_before: 4",
       "remount_min_poses_before + remount_min_poses_after = 6 > window_poses = 5"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string message = refusal(text + "\n");
    EXPECT_NE(message.find("params: " + expected), std::string::npos) << text << " -> " << message;
    EXPECT_NE(message.find(" must be <= "), std::string::npos) << message;
  }
  // The remount test runs in the joint modes only: pair modes accept that window.
  EXPECT_EQ(refusal("imu_orientation: auto\nwindow_poses: 5\nmin_poses: 3\n"
                    "remount_min_poses_before: 4\n"),
            "");
  // Equal is allowed.
  EXPECT_EQ(refusal("window_poses: 20\nmin_poses: 20\nmin_poses_to_solve: 20\n"), "");
}

TEST(SettingsChecks, TheCalibratorRefusesAMinPosesItsWindowNeverHolds) {
  // min_poses > window_poses: nothing would ever be broadcast, and nothing said so before.
  const TargetDescription target = parseTargetYaml(
      "target_type: checkerboard\ntargetCols: 8\ntargetRows: 6\nrowSpacingMeters: 0.04\n"
      "colSpacingMeters: 0.04\n",
      "target");
  PipelineSettings pipeline;
  pipeline.window_poses = 10;
  OnlineSettings online;
  online.min_poses = 12;
  online.threaded = false;
  try {
    OnlineCalibrator calibrator(target, pipeline, online, {});
    ADD_FAILURE() << "accepted min_poses 12 with window_poses 10";
  } catch (const SettingsError& e) {
    EXPECT_EQ(e.key(), "min_poses");
    EXPECT_NE(std::string(e.what()).find("min_poses = 12 > window_poses = 10"), std::string::npos)
        << e.what();
  }
  online.min_poses = 10;
  EXPECT_NO_THROW({ OnlineCalibrator accepted(target, pipeline, online, {}); });
}

TEST(SettingsError, EveryBadSettingIsOneTypeNamingSourceAndKey) {
  try {
    PipelineSettings p;
    parsePipelineConfig("accel_weight: 1.5\n", "params.yaml", &p);
    ADD_FAILURE();
  } catch (const SettingsError& e) {
    EXPECT_EQ(e.source(), "params.yaml");
    EXPECT_EQ(e.key(), "accel_weight");
    EXPECT_EQ(std::string(e.what()),
              "params.yaml: accel_weight = 1.5: must be a number within (0, 1)");
  }
  // A struct handed to the library: the same type (and an std::invalid_argument, as before).
  const TargetDescription target = parseTargetYaml(
      "target_type: checkerboard\ntargetCols: 8\ntargetRows: 6\nrowSpacingMeters: 0.04\n"
      "colSpacingMeters: 0.04\n",
      "target");
  PipelineSettings bad;
  bad.frame_queue_s = -1.0;
  try {
    CalibrationPipeline pipeline(target, bad);
    ADD_FAILURE();
  } catch (const SettingsError& e) {
    EXPECT_EQ(e.key(), "frame_queue_s");
    EXPECT_EQ(std::string(e.what()), "frame_queue_s = -1: must be a finite number > 0");
  }
  EXPECT_THROW({ CalibrationPipeline refused(target, bad); }, std::invalid_argument);
  // A wrong type, an unknown key; no target_file is no error (the natural scene).
  WrapperSettings w;
  PipelineSettings p;
  EXPECT_THROW(parseSettings("target_file: t.yaml\nmin_poses: many\n", "params", &w, &p),
               SettingsError);
  EXPECT_THROW(parseSettings("target_file: t.yaml\nmin_pose: 3\n", "params", &w, &p),
               SettingsError);
  EXPECT_NO_THROW(parseSettings("camera_frame: c\n", "params", &w, &p));
  EXPECT_TRUE(w.target_file.empty());
}

TEST(SettingsTypo, AnUnknownKeyIsAnsweredWithTheClosestKnownKey) {
  const std::pair<std::string, std::string> cases[] = {
      {"stationary_window: 1.0",
       "unknown key 'stationary_window' (see config/default.yaml); "
       "did you mean 'stationary_window_s'?"},
      {"camera_frme: cam", "did you mean 'camera_frame'?"},           // the wrapper's table
      {"min_pose: 3", "did you mean 'min_poses'?"},                   // the calibrator's
      {"max_std_dev_dg: 0.5", "did you mean 'max_std_dev_deg'?"},     // a letter left out
      {"gravity_m_s: 9.8", "did you mean 'gravity_m_s2'?"},           // the pipeline's
      {"imu_orientaton: joint", "did you mean 'imu_orientation'?"}};  // a letter dropped
  for (const auto& [text, expected] : cases) {
    const std::string message = refusal(text + "\n");
    EXPECT_NE(message.find(expected), std::string::npos) << text << " -> " << message;
  }
  // Nothing close: no guess.
  const std::string far = refusal("colour: blue\n");
  EXPECT_NE(far.find("unknown key 'colour'"), std::string::npos) << far;
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
  // A config file for calibrate_bag: the same answer.
  PipelineSettings p;
  OnlineSettings o;
  try {
    parseCalibrationConfig(YAML::Load("window_pose: 10"), "my.yaml", &p, &o);
    ADD_FAILURE();
  } catch (const SettingsError& e) {
    EXPECT_NE(std::string(e.what()).find("my.yaml: unknown key 'window_pose' (see "
                                         "config/default.yaml); did you mean 'window_poses'?"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(closestKey("window_poses", {"window_poses"}), "window_poses");
  EXPECT_EQ(closestKey("ab", {"abc"}), "");  // 1 edit in 2 characters is no typo
}

}  // namespace
}  // namespace camera_imu_alignment
