// config/alignment.yaml documents every setting with its default: it must load, know every key,
// and equal the built-in defaults. Bad files are refused with the file and key named.
#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "camera_imu_alignment/csv_io.h"
#include "camera_imu_alignment/pipeline_config.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

std::string configPath() { return std::string(PACKAGE_SOURCE_DIR) + "/config/alignment.yaml"; }

/// Settings with every configurable value changed, to see that loading overwrites each of them.
PipelineSettings scrambled() {
  PipelineSettings s;
  s.stationary.window_s = 7;
  s.stationary.min_duration_s = 7;
  s.stationary.max_gyro_rad_s = 7;
  s.stationary.max_accel_std_m_s2 = 7;
  s.stationary.max_initial_gyro_bias_rad_s = 7;
  s.stationary.max_gyro_std_rad_s = 7;
  s.stationary.noise_factor = 7;
  s.stationary.max_gravity_error_m_s2 = 7;
  s.stationary.gravity_m_s2 = 7;
  s.stationary.max_gap_s = 7;
  s.max_gyro_span_s = 7;
  s.imu_orientation = ImuOrientationSource::kMagnetometer;
  s.accel_weight = 0.7;
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
  s.frame_margin_s = 7;
  s.max_camera_spread_deg = 7;
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
  EXPECT_EQ(s.stationary.max_gyro_rad_s, d.stationary.max_gyro_rad_s);
  EXPECT_EQ(s.stationary.max_accel_std_m_s2, d.stationary.max_accel_std_m_s2);
  EXPECT_EQ(s.stationary.max_initial_gyro_bias_rad_s, d.stationary.max_initial_gyro_bias_rad_s);
  EXPECT_EQ(s.stationary.max_gyro_std_rad_s, d.stationary.max_gyro_std_rad_s);
  EXPECT_EQ(s.stationary.noise_factor, d.stationary.noise_factor);
  EXPECT_EQ(s.stationary.max_gravity_error_m_s2, d.stationary.max_gravity_error_m_s2);
  EXPECT_EQ(s.stationary.gravity_m_s2, d.stationary.gravity_m_s2);
  EXPECT_EQ(s.stationary.max_gap_s, d.stationary.max_gap_s);
  EXPECT_EQ(s.max_gyro_span_s, d.max_gyro_span_s);
  EXPECT_EQ(s.imu_orientation, d.imu_orientation);
  EXPECT_EQ(s.accel_weight, d.accel_weight);
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
  EXPECT_EQ(s.frame_margin_s, d.frame_margin_s);
  EXPECT_EQ(s.max_camera_spread_deg, d.max_camera_spread_deg);
  EXPECT_EQ(s.frame_queue_s, d.frame_queue_s);
  EXPECT_EQ(s.window_poses, d.window_poses);
  EXPECT_EQ(s.min_poses_to_solve, d.min_poses_to_solve);
  EXPECT_EQ(s.solver.method, d.solver.method);
  EXPECT_EQ(s.solver.two_step.max_iterations, d.solver.two_step.max_iterations);
}

TEST(PipelineConfig, DocumentedDefaultsEqualTheBuiltInOnes) {
  PipelineSettings loaded = scrambled();
  ASSERT_NO_THROW(loadPipelineConfig(configPath(), &loaded));
  expectDefaults(loaded);
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
  EXPECT_EQ(documented.size(), pipelineConfigKeys().size());
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
  expectRefused("max_gyro_norm_rad_s: -1\n", "max_gyro_norm_rad_s");
  expectRefused("max_gyro_norm_rad_s: fast\n", "max_gyro_norm_rad_s");
  expectRefused("stationary_window: 1.0\n", "unknown key 'stationary_window'");
  expectRefused("solver_method: best\n", "solver_method");
  expectRefused("imu_orientation: compass\n", "imu_orientation");
  expectRefused("mag_hard_iron_t: [1, 2]\n", "mag_hard_iron_t");
  expectRefused("mag_soft_iron: [0, 0, 0, 0, 0, 0, 0, 0, 0]\n", "soft_iron");
  expectRefused("accel_weight: 1.5\n", "accel_weight");
  expectRefused("- a list\n", "map");
  expectRefused("frame_margin_s: .nan\n", "frame_margin_s");
}

TEST(PipelineConfig, RosOnlyKeysCanBeSkippedAndPartialFilesKeepTheRest) {
  PipelineSettings s;
  parsePipelineConfig("camera_frame: cam\nwindow_poses: 12\n", "params.yaml", &s, {"camera_frame"});
  EXPECT_EQ(s.window_poses, 12u);
  EXPECT_EQ(s.stationary.window_s, PipelineSettings().stationary.window_s);
}

}  // namespace
}  // namespace camera_imu_alignment
