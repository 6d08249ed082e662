// config/default.yaml documents every setting with its default: it must load, know every key,
// and equal the built-in defaults. Bad files are refused with the file and key named.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/config/online_config.h"
#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/config/settings_checks.h"
#include "camera_imu_alignment/config/settings_error.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/ros/wrapper_settings.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

std::string configPath() { return std::string(PACKAGE_SOURCE_DIR) + "/config/default.yaml"; }

/// Settings with every configurable value changed, to see that loading overwrites each of them.
PipelineSettings scrambled() {
  PipelineSettings s;
  s.stationary.window_s = 7;
  s.stationary.min_duration_s = 7;
  s.stationary.max_accel_std_m_s2 = 7;
  s.stationary.max_gyro_std_rad_s = 7;
  s.stationary.noise_factor = 7;
  s.stationary.max_gyro_change_rad_s = 7;
  s.stationary.max_gravity_turn_rate_rad_s = 7;
  s.stationary.change_noise_factor = 7;
  s.stationary.max_gyro_bias_rad_s = 7;
  s.stationary.max_rate_about_gravity_rad_s = 7;
  s.stationary.max_gravity_error_m_s2 = 7;
  s.stationary.gravity_m_s2 = 7;
  s.stationary.max_gap_s = 7;
  s.max_gyro_span_s = 7;
  s.imu_orientation = ImuOrientationSource::kMagnetometer;
  s.accel_weight = 0.7;
  s.joint.imu_matrices = ImuMatrixModel::kIdentity;
  s.joint.priors.gyro_scale = 7;
  s.joint.priors.gyro_cross_axis = 7;
  s.joint.priors.gyro_bias_walk_rad_s_sqrt_s = 7;
  s.joint.priors.accel_scale = 7;
  s.joint.priors.accel_cross_axis = 7;
  s.joint.priors.accel_bias_m_s2 = 7;
  s.joint.priors.accel_bias_walk_m_s2_sqrt_s = 7;
  s.joint.priors.soft_iron_scale = 7;
  s.joint.priors.soft_iron_cross = 7;
  s.joint.priors.hard_iron_t = 7;
  s.magnetometer.scale = 7;
  s.magnetometer.hard_iron_t = Eigen::Vector3d::Constant(7);
  s.magnetometer.soft_iron = 7 * Eigen::Matrix3d::Identity();
  s.disturbance.max_norm_change = 7;
  s.disturbance.max_dip_change_deg = 7;
  s.disturbance.max_within_segment_std_deg = 7;
  s.detector.min_points = 7;
  s.pose.max_reprojection_rms_px = 7;
  s.pose.min_ambiguity_ratio = 7;
  s.min_frames_per_pose = 7;
  s.max_frames_per_pose = 77;
  s.min_frame_interval_s = 7;
  s.missed_frame_interval_s = 17;
  s.frame_margin_s = 7;
  s.max_camera_spread_deg = 7;
  useSceneProfile(SceneProfile::kFast, &s.scene_features, &s.scene_rotation);
  s.frame_queue_s = 7;
  s.window_poses = 77;
  s.min_poses_to_solve = 7;
  s.solver.method = SolverMethod::kTwoStep;
  s.solver.two_step.max_iterations = 7;
  return s;
}

void expectDefaults(const PipelineSettings& s) {
  const PipelineSettings d;
  EXPECT_EQ(s.stationary.window_s, d.stationary.window_s);
  EXPECT_EQ(s.stationary.min_duration_s, d.stationary.min_duration_s);
  EXPECT_EQ(s.stationary.max_accel_std_m_s2, d.stationary.max_accel_std_m_s2);
  EXPECT_EQ(s.stationary.max_gyro_std_rad_s, d.stationary.max_gyro_std_rad_s);
  EXPECT_EQ(s.stationary.noise_factor, d.stationary.noise_factor);
  EXPECT_EQ(s.stationary.max_gyro_change_rad_s, d.stationary.max_gyro_change_rad_s);
  EXPECT_EQ(s.stationary.max_gravity_turn_rate_rad_s, d.stationary.max_gravity_turn_rate_rad_s);
  EXPECT_EQ(s.stationary.change_noise_factor, d.stationary.change_noise_factor);
  EXPECT_EQ(s.stationary.max_gyro_bias_rad_s, d.stationary.max_gyro_bias_rad_s);
  EXPECT_EQ(s.stationary.max_rate_about_gravity_rad_s, d.stationary.max_rate_about_gravity_rad_s);
  EXPECT_EQ(s.stationary.max_gravity_error_m_s2, d.stationary.max_gravity_error_m_s2);
  EXPECT_EQ(s.stationary.gravity_m_s2, d.stationary.gravity_m_s2);
  EXPECT_EQ(s.stationary.max_gap_s, d.stationary.max_gap_s);
  EXPECT_EQ(s.max_gyro_span_s, d.max_gyro_span_s);
  EXPECT_EQ(s.imu_orientation, d.imu_orientation);
  EXPECT_EQ(s.accel_weight, d.accel_weight);
  EXPECT_EQ(s.joint.imu_matrices, d.joint.imu_matrices);
  EXPECT_EQ(s.joint.priors.gyro_scale, d.joint.priors.gyro_scale);
  EXPECT_EQ(s.joint.priors.gyro_cross_axis, d.joint.priors.gyro_cross_axis);
  EXPECT_EQ(s.joint.priors.gyro_bias_walk_rad_s_sqrt_s, d.joint.priors.gyro_bias_walk_rad_s_sqrt_s);
  EXPECT_EQ(s.joint.priors.accel_scale, d.joint.priors.accel_scale);
  EXPECT_EQ(s.joint.priors.accel_cross_axis, d.joint.priors.accel_cross_axis);
  EXPECT_EQ(s.joint.priors.accel_bias_m_s2, d.joint.priors.accel_bias_m_s2);
  EXPECT_EQ(s.joint.priors.accel_bias_walk_m_s2_sqrt_s, d.joint.priors.accel_bias_walk_m_s2_sqrt_s);
  EXPECT_EQ(s.joint.priors.soft_iron_scale, d.joint.priors.soft_iron_scale);
  EXPECT_EQ(s.joint.priors.soft_iron_cross, d.joint.priors.soft_iron_cross);
  EXPECT_EQ(s.joint.priors.hard_iron_t, d.joint.priors.hard_iron_t);
  EXPECT_EQ(s.magnetometer.scale, d.magnetometer.scale);
  EXPECT_EQ(s.magnetometer.hard_iron_t, d.magnetometer.hard_iron_t);
  EXPECT_EQ(s.magnetometer.soft_iron, d.magnetometer.soft_iron);
  EXPECT_EQ(s.disturbance.max_norm_change, d.disturbance.max_norm_change);
  EXPECT_EQ(s.disturbance.max_dip_change_deg, d.disturbance.max_dip_change_deg);
  EXPECT_EQ(s.disturbance.max_within_segment_std_deg, d.disturbance.max_within_segment_std_deg);
  EXPECT_EQ(s.detector.min_points, d.detector.min_points);
  EXPECT_EQ(s.pose.max_reprojection_rms_px, d.pose.max_reprojection_rms_px);
  EXPECT_EQ(s.pose.min_ambiguity_ratio, d.pose.min_ambiguity_ratio);
  EXPECT_EQ(s.min_frames_per_pose, d.min_frames_per_pose);
  EXPECT_EQ(s.max_frames_per_pose, d.max_frames_per_pose);
  EXPECT_EQ(s.min_frame_interval_s, d.min_frame_interval_s);
  EXPECT_EQ(s.missed_frame_interval_s, d.missed_frame_interval_s);
  EXPECT_EQ(s.frame_margin_s, d.frame_margin_s);
  EXPECT_EQ(s.max_camera_spread_deg, d.max_camera_spread_deg);
  EXPECT_EQ(s.scene_features.image_scale, d.scene_features.image_scale);
  EXPECT_EQ(s.scene_features.max_features, d.scene_features.max_features);
  EXPECT_EQ(s.scene_rotation.refine_matches, d.scene_rotation.refine_matches);
  EXPECT_EQ(s.frame_queue_s, d.frame_queue_s);
  EXPECT_EQ(s.window_poses, d.window_poses);
  EXPECT_EQ(s.min_poses_to_solve, d.min_poses_to_solve);
  EXPECT_EQ(s.solver.method, d.solver.method);
  EXPECT_EQ(s.solver.two_step.max_iterations, d.solver.two_step.max_iterations);
}

TEST(PipelineConfig, DocumentedDefaultsEqualTheBuiltInOnes) {
  PipelineSettings loaded = scrambled();
  OnlineSettings online;
  online.min_poses = 7, online.max_residual_deg = 7, online.max_std_dev_deg = 7;
  online.consistency_level = 0.7, online.min_change_deg = 7;
  online.remount.level = 0.7, online.remount.max_poses_after = 7;
  online.remount_poses = 7, online.remount_residual_deg = 7, online.manual_capture = true;
  ASSERT_NO_THROW(loadCalibrationConfig(configPath(), &loaded, &online, wrapperKeys()));
  expectDefaults(loaded);
  const OnlineSettings online_defaults;
  EXPECT_EQ(online.min_poses, online_defaults.min_poses);
  EXPECT_EQ(online.max_residual_deg, online_defaults.max_residual_deg);
  EXPECT_EQ(online.max_std_dev_deg, online_defaults.max_std_dev_deg);
  EXPECT_EQ(online.consistency_level, online_defaults.consistency_level);
  EXPECT_EQ(online.min_change_deg, online_defaults.min_change_deg);
  EXPECT_EQ(online.remount.level, online_defaults.remount.level);
  EXPECT_EQ(online.remount.max_poses_after, online_defaults.remount.max_poses_after);
  EXPECT_EQ(online.remount.min_poses_after, online_defaults.remount.min_poses_after);
  EXPECT_EQ(online.remount.min_poses_before, online_defaults.remount.min_poses_before);
  EXPECT_EQ(online.remount_poses, online_defaults.remount_poses);
  EXPECT_EQ(online.remount_residual_deg, online_defaults.remount_residual_deg);
  EXPECT_EQ(online.manual_capture, online_defaults.manual_capture);
  // The wrapper's section too (target_file empty: the natural scene).
  std::ifstream in(configPath());
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  WrapperSettings w;
  w.status_period_s = 7;
  w.publish_inverse = true, w.load_on_start = false;
  PipelineSettings p;
  ASSERT_NO_THROW(parseSettings(text, "default.yaml", &w, &p));  // target_file: "", no board
  EXPECT_TRUE(w.target_file.empty());
  ASSERT_NO_THROW(parseSettings(text + "target_file: t.yaml\n", "default.yaml", &w, &p));
  const WrapperSettings d;
  EXPECT_EQ(w.status_period_s, d.status_period_s);
  EXPECT_EQ(w.publish_inverse, d.publish_inverse);
  EXPECT_EQ(w.load_on_start, d.load_on_start);
  EXPECT_EQ(w.camera_frame, d.camera_frame);
  EXPECT_EQ(w.output_file, d.output_file);
  EXPECT_EQ(w.image_transport, d.image_transport);
}

TEST(PipelineConfig, EveryKnownKeyIsDocumented) {
  std::ifstream in(configPath());
  std::set<std::string> documented;
  for (std::string line; std::getline(in, line);) {
    const auto colon = line.find(':');
    if (line.empty() || line[0] == '#' || line[0] == ' ' || colon == std::string::npos) continue;
    documented.insert(line.substr(0, colon));
  }
  for (const auto& key : pipelineConfigKeys()) EXPECT_TRUE(documented.count(key)) << key;
  for (const auto& key : wrapperKeys()) EXPECT_TRUE(documented.count(key)) << key;
  for (const auto& key : onlineConfigKeys()) EXPECT_TRUE(documented.count(key)) << key;
  EXPECT_EQ(documented.size(),
            pipelineConfigKeys().size() + wrapperKeys().size() + onlineConfigKeys().size());
}

void expectRefused(const std::string& text, const std::string& expected_in_message) {
  PipelineSettings s;
  try {
    parsePipelineConfig(text, "params.yaml", &s);
    ADD_FAILURE() << "accepted: " << text;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("params.yaml"), std::string::npos) << message;
    EXPECT_NE(message.find(expected_in_message), std::string::npos) << message;
  }
  expectDefaults(s);  // nothing half-applied
}

TEST(PipelineConfig, BadFilesAreRefusedNamingTheKey) {
  expectRefused("stationary_window_s: 0.5\nwindow_poses: 1\n", "window_poses");
  expectRefused("max_rate_about_gravity_rad_s: -1\n", "max_rate_about_gravity_rad_s");
  expectRefused("max_rate_about_gravity_rad_s: fast\n", "max_rate_about_gravity_rad_s");
  expectRefused("stationary_window: 1.0\n", "unknown key 'stationary_window'");
  expectRefused("solver_method: best\n", "solver_method");
  expectRefused("imu_orientation: compass\n", "imu_orientation");
  expectRefused("imu_matrices: guess\n", "'select', 'estimate' or 'identity'");
  expectRefused("mag_hard_iron_t: [1, 2]\n", "mag_hard_iron_t");
  expectRefused("mag_soft_iron: [0, 0, 0, 0, 0, 0, 0, 0, 0]\n", "soft_iron");
  expectRefused("accel_weight: 1.5\n", "accel_weight");
  expectRefused("- a list\n", "map");
  expectRefused("frame_margin_s: .nan\n", "frame_margin_s");
  expectRefused("scene_profile: quick\n", "scene_profile = quick: must be 'full' or 'fast'");
}

TEST(PipelineConfig, TheSceneProfileSetsItsFeatureSettingsAndReadsBackAsItsName) {
  PipelineSettings s;
  EXPECT_EQ(findKey(pipelineKeys(), "scene_profile")->text(s), "full");
  parsePipelineConfig("scene_profile: fast\n", "params", &s);
  EXPECT_EQ(s.scene_features.image_scale, 0.5);
  EXPECT_EQ(s.scene_features.max_features, 1000);
  EXPECT_TRUE(s.scene_rotation.refine_matches);
  EXPECT_EQ(findKey(pipelineKeys(), "scene_profile")->text(s), "fast");
  // Back to full: every setting the fast profile changed returns to its default.
  parsePipelineConfig("scene_profile: full\n", "params", &s);
  const PipelineSettings d;
  EXPECT_EQ(s.scene_features.image_scale, d.scene_features.image_scale);
  EXPECT_EQ(s.scene_features.max_features, d.scene_features.max_features);
  EXPECT_EQ(s.scene_rotation.refine_matches, d.scene_rotation.refine_matches);
  // Set in code to neither: said so.
  s.scene_features.image_scale = 0.75;
  EXPECT_EQ(findKey(pipelineKeys(), "scene_profile")->text(s), "custom");
}

TEST(WrapperSettings, BadParametersAreRefusedNamingThem) {
  auto refused = [](const std::string& text, const std::string& expected) {
    WrapperSettings w;
    PipelineSettings p;
    try {
      parseSettings("target_file: t.yaml\n" + text, "params", &w, &p);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("min_poses: 1\n", "min_poses");
  refused("max_std_dev_deg: 0\n", "max_std_dev_deg");
  refused("remount_residual_deg: -2\n", "remount_residual_deg");
  refused("consistency_level: 1.5\n", "consistency_level");
  refused("remount_level: 0\n", "remount_level");
  refused("remount_min_poses_after: 1\n", "remount_min_poses_after");
  refused("remount_max_poses_after: 1\n", "remount_max_poses_after");
  refused("publish_inverse: maybe\n", "publish_inverse");
  refused("window_poses: 1\n", "window_poses");
  refused("camera_frme: cam\n", "unknown key 'camera_frme'");
}

/// The message for `text` (target_file set), or "" when it was accepted.
std::string refusal(const std::string& text) {
  WrapperSettings w;
  PipelineSettings p;
  try {
    parseSettings("target_file: t.yaml\n" + text, "params", &w, &p);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Settings, EveryBadValueNamesTheKeyTheAllowedValuesAndTheValueGiven) {
  // A value of the wrong kind for every key of the three tables: one form, "key = value: must be
  // ...".
  std::vector<std::string> keys = pipelineConfigKeys();
  keys.insert(keys.end(), wrapperKeys().begin(), wrapperKeys().end());
  keys.insert(keys.end(), onlineConfigKeys().begin(), onlineConfigKeys().end());
  for (const std::string& key : keys) {
    const std::string message = refusal(key + ": {a: 1}\n");
    EXPECT_NE(message.find("params: " + key + " = {a: 1}: must be "), std::string::npos) << message;
    EXPECT_EQ(message.find("bad conversion"), std::string::npos) << message;
  }
  // Out of range or the wrong type: the same form with the allowed range, for the cases.
  const std::pair<std::string, std::string> cases[] = {
      {"window_poses: -1", "window_poses = -1: must be an integer within [2, 200]"},
      {"window_poses: 0", "window_poses = 0: must be within [2, 200]"},
      {"window_poses: 2.5", "window_poses = 2.5: must be an integer within [2, 200]"},
      {"max_rate_about_gravity_rad_s: fast",
       "max_rate_about_gravity_rad_s = fast: must be a finite number > 0"},
      {"min_poses: -3", "min_poses = -3: must be an integer >= 2"},
      {"min_poses: lots", "min_poses = lots: must be an integer >= 2"},
      {"publish_inverse: maybe", "publish_inverse = maybe: must be true or false"},
      {"image_transport: theora", "image_transport = theora: must be 'raw' or 'compressed'"},
      {"solver_method: best", "solver_method = best: must be 'optimal' or 'two_step'"},
      {"mag_hard_iron_t: [1, 2]", "mag_hard_iron_t = [1, 2]: must be a list of 3 finite numbers"},
      {"two_step_max_iterations: 0", "two_step_max_iterations = 0: must be an integer >= 1"},
      {"max_std_dev_deg: 0", "max_std_dev_deg = 0: must be a finite number > 0"},
      {"consistency_level: 2", "consistency_level = 2: must be a number within (0, 1)"},
      {"remount_min_poses_after: 1", "remount_min_poses_after = 1: must be an integer >= 2"}};
  for (const auto& [text, expected] : cases) {
    const std::string message = refusal(text + "\n");
    EXPECT_NE(message.find(expected), std::string::npos) << text << " -> " << message;
  }
}

TEST(WrapperSettings, TheOutputFileDefaultsToAFileUnderDotRosAndPathsResolveVisibly) {
  namespace fs = std::filesystem;
  const std::string home = std::getenv("HOME") ? std::getenv("HOME") : "";
  ASSERT_FALSE(home.empty());
  const std::string target = test::processTempDir() + "board.yaml";
  std::ofstream(target) << "target_type: checkerboard\n";
  // The default (the documented one, as the launch file passes it) works out of the box.
  WrapperSettings settings;
  settings.target_file = target;
  ASSERT_NO_THROW(resolvePaths(&settings));
  EXPECT_EQ(settings.output_file, home + "/.ros/camera_imu_alignment.yaml");
  EXPECT_EQ(settings.target_file, target);
  // A relative target that is not there: the rule and the absolute path tried.
  settings.target_file = "no_such_board.yaml";
  try {
    resolvePaths(&settings);
    ADD_FAILURE() << "accepted a missing target";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("target_file 'no_such_board.yaml'"), std::string::npos) << message;
    EXPECT_NE(message.find("tried " + (fs::current_path() / "no_such_board.yaml").string()),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("~/.ros"), std::string::npos) << message;
  }
  // A relative output file is said where it goes.
  settings.target_file = target;
  settings.output_file = "result.yaml";
  const std::vector<std::string> notices = resolvePaths(&settings);
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_NE(notices[0].find((fs::current_path() / "result.yaml").string()), std::string::npos)
      << notices[0];
  EXPECT_EQ(expandHome("~"), home);
  EXPECT_EQ(expandHome("~user/x"), "~user/x");  // another user's home: left alone
}

TEST(PipelineConfig, RosOnlyKeysCanBeSkippedAndPartialFilesKeepTheRest) {
  PipelineSettings s;
  parsePipelineConfig("camera_frame: cam\nwindow_poses: 12\n", "params.yaml", &s, {"camera_frame"});
  EXPECT_EQ(s.window_poses, 12u);
  EXPECT_EQ(s.stationary.window_s, PipelineSettings().stationary.window_s);
}

TEST(Settings, AStructInCodeIsCheckedByTheSameTablesAndRulesAsAFile) {
  // One check for settings handed to the library: findProblem, with the key the file would name.
  EXPECT_FALSE(findProblem(OnlineSettings{}).has_value());
  EXPECT_FALSE(findProblem(PipelineSettings{}).has_value());
  OnlineSettings online;
  online.remount.min_poses_after = 1;
  ASSERT_TRUE(findProblem(online).has_value());
  EXPECT_EQ(findProblem(online)->key, "remount_min_poses_after");
  online = OnlineSettings{};
  online.remount.level = 0.0;
  ASSERT_TRUE(findProblem(online).has_value());
  EXPECT_EQ(findProblem(online)->key, "remount_level");
  online = OnlineSettings{};
  online.remount.min_poses_after = 5;
  online.remount.max_poses_after = 4;
  ASSERT_TRUE(findProblem(online).has_value());
  EXPECT_NE(findProblem(online)->message.find("remount_max_poses_after"), std::string::npos);
  PipelineSettings pipeline;
  pipeline.min_poses_to_solve = 40;
  ASSERT_TRUE(findProblem(pipeline).has_value());
  EXPECT_NE(findProblem(pipeline)->message.find("window_poses"), std::string::npos);
  EXPECT_THROW(CalibrationPipeline(TargetDescription{}, pipeline), SettingsError);
}

}  // namespace
}  // namespace camera_imu_alignment
