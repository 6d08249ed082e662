#include "camera_imu_alignment/config/pipeline_config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "camera_imu_alignment/io/input_error.h"

namespace camera_imu_alignment {
namespace {

using Key = SettingKey<PipelineSettings>;

template <typename T, typename Access>
Key number(const std::string& name, Access access, const std::string& allowed) {
  return fieldKey<T, PipelineSettings>(name, access, allowed);
}

// The ranges PipelineSettings::validate() applies, as told in messages.
const char* const kPositive = "a finite number > 0";
const char* const kNonNegative = "a finite number >= 0";

const std::vector<Key>& keys() {
  static const std::vector<Key> table = {
      // Stationary detection (IMU).
      number<double>(
          "stationary_window_s", [](auto* s) { return &s->stationary.window_s; }, kPositive),
      number<double>(
          "min_stationary_duration_s", [](auto* s) { return &s->stationary.min_duration_s; },
          kPositive),
      number<double>(
          "max_gyro_std_rad_s", [](auto* s) { return &s->stationary.max_gyro_std_rad_s; },
          kPositive),
      number<double>(
          "max_accel_std_m_s2", [](auto* s) { return &s->stationary.max_accel_std_m_s2; },
          kPositive),
      number<double>(
          "stationary_noise_factor", [](auto* s) { return &s->stationary.noise_factor; },
          kNonNegative),
      number<double>(
          "max_gyro_change_rad_s", [](auto* s) { return &s->stationary.max_gyro_change_rad_s; },
          kPositive),
      number<double>(
          "max_gravity_turn_rate_rad_s",
          [](auto* s) { return &s->stationary.max_gravity_turn_rate_rad_s; }, kPositive),
      number<double>(
          "stationary_change_noise_factor",
          [](auto* s) { return &s->stationary.change_noise_factor; }, kNonNegative),
      number<double>(
          "max_gyro_bias_rad_s", [](auto* s) { return &s->stationary.max_gyro_bias_rad_s; },
          kPositive),
      number<double>(
          "max_rate_about_gravity_rad_s",
          [](auto* s) { return &s->stationary.max_rate_about_gravity_rad_s; }, kPositive),
      number<double>(
          "max_gravity_error_m_s2", [](auto* s) { return &s->stationary.max_gravity_error_m_s2; },
          kPositive),
      number<double>(
          "gravity_m_s2", [](auto* s) { return &s->stationary.gravity_m_s2; }, kPositive),
      number<double>(
          "max_imu_gap_s", [](auto* s) { return &s->stationary.max_gap_s; }, kPositive),
      number<double>(
          "max_gyro_span_s", [](auto* s) { return &s->max_gyro_span_s; }, kPositive),
      // IMU orientation.
      {"imu_orientation",
       [](const YAML::Node& node, PipelineSettings* s) {
         if (!parseImuOrientationSource(node.as<std::string>(), &s->imu_orientation)) {
           throw YAML::Exception(node.Mark(), "unknown source");
         }
       },
       "'joint', 'auto', 'magnetometer' or 'message'"},
      number<double>(
          "accel_weight", [](auto* s) { return &s->accel_weight; }, "a number within (0, 1)"),
      {"imu_matrices",
       [](const YAML::Node& node, PipelineSettings* s) {
         if (!parseImuMatrixModel(node.as<std::string>(), &s->joint.imu_matrices)) {
           throw YAML::Exception(node.Mark(), "unknown model");
         }
       },
       "'select', 'estimate' or 'identity'"},
      // Joint estimate: 1-sigma of the priors on the IMU's errors.
      number<double>(
          "imu_prior_gyro_scale", [](auto* s) { return &s->joint.priors.gyro_scale; }, kPositive),
      number<double>(
          "imu_prior_gyro_cross_axis", [](auto* s) { return &s->joint.priors.gyro_cross_axis; },
          kPositive),
      number<double>(
          "imu_prior_gyro_bias_walk_rad_s_sqrt_s",
          [](auto* s) { return &s->joint.priors.gyro_bias_walk_rad_s_sqrt_s; }, kPositive),
      number<double>(
          "imu_prior_accel_scale", [](auto* s) { return &s->joint.priors.accel_scale; }, kPositive),
      number<double>(
          "imu_prior_accel_cross_axis", [](auto* s) { return &s->joint.priors.accel_cross_axis; },
          kPositive),
      number<double>(
          "imu_prior_accel_bias_m_s2", [](auto* s) { return &s->joint.priors.accel_bias_m_s2; },
          kPositive),
      number<double>(
          "imu_prior_accel_bias_walk_m_s2_sqrt_s",
          [](auto* s) { return &s->joint.priors.accel_bias_walk_m_s2_sqrt_s; }, kPositive),
      number<double>(
          "imu_prior_soft_iron_scale", [](auto* s) { return &s->joint.priors.soft_iron_scale; },
          kPositive),
      number<double>(
          "imu_prior_soft_iron_cross", [](auto* s) { return &s->joint.priors.soft_iron_cross; },
          kPositive),
      number<double>(
          "imu_prior_hard_iron_t", [](auto* s) { return &s->joint.priors.hard_iron_t; }, kPositive),
      // Magnetometer.
      number<double>(
          "mag_scale", [](auto* s) { return &s->magnetometer.scale; }, kPositive),
      {"mag_hard_iron_t",
       [](const YAML::Node& node, PipelineSettings* s) {
         const auto v = node.as<std::vector<double>>();
         if (v.size() != 3) throw YAML::Exception(node.Mark(), "needs 3 numbers (T)");
         s->magnetometer.hard_iron_t = Eigen::Vector3d(v[0], v[1], v[2]);
       },
       "a list of 3 finite numbers (tesla)"},
      {"mag_soft_iron",
       [](const YAML::Node& node, PipelineSettings* s) {
         const auto v = node.as<std::vector<double>>();
         if (v.size() != 9) throw YAML::Exception(node.Mark(), "needs 9 numbers (row-major 3x3)");
         for (int i = 0; i < 9; ++i) s->magnetometer.soft_iron(i / 3, i % 3) = v[i];
       },
       "a list of 9 finite numbers, an invertible row-major 3x3 matrix"},
      number<double>(
          "mag_max_norm_change", [](auto* s) { return &s->disturbance.max_norm_change; },
          kPositive),
      number<double>(
          "mag_max_dip_change_deg", [](auto* s) { return &s->disturbance.max_dip_change_deg; },
          kPositive),
      number<double>(
          "mag_max_scatter_deg", [](auto* s) { return &s->disturbance.max_within_segment_std_deg; },
          kPositive),
      // Camera.
      number<int>(
          "min_target_points", [](auto* s) { return &s->detector.min_points; }, "an integer >= 4"),
      number<double>(
          "max_reprojection_rms_px", [](auto* s) { return &s->pose.max_reprojection_rms_px; },
          kPositive),
      number<double>(
          "min_ambiguity_ratio", [](auto* s) { return &s->pose.min_ambiguity_ratio; }, kPositive),
      number<int>(
          "min_frames_per_pose", [](auto* s) { return &s->min_frames_per_pose; },
          "an integer within [1, max_frames_per_pose]"),
      number<int>(
          "max_frames_per_pose", [](auto* s) { return &s->max_frames_per_pose; },
          "an integer >= min_frames_per_pose"),
      number<double>(
          "min_frame_interval_s", [](auto* s) { return &s->min_frame_interval_s; }, kNonNegative),
      number<double>(
          "missed_frame_interval_s", [](auto* s) { return &s->missed_frame_interval_s; },
          "a finite number >= min_frame_interval_s"),
      number<double>(
          "frame_margin_s", [](auto* s) { return &s->frame_margin_s; }, kNonNegative),
      number<double>(
          "max_camera_spread_deg", [](auto* s) { return &s->max_camera_spread_deg; }, kPositive),
      number<double>(
          "frame_queue_s", [](auto* s) { return &s->frame_queue_s; }, kPositive),
      // Window and solver.
      number<std::size_t>(
          "window_poses", [](auto* s) { return &s->window_poses; }, "an integer within [2, 200]"),
      number<int>(
          "min_poses_to_solve", [](auto* s) { return &s->min_poses_to_solve; },
          "an integer within [2, window_poses]"),
      {"solver_method",
       [](const YAML::Node& node, PipelineSettings* s) {
         if (!parseSolverMethod(node.as<std::string>(), &s->solver.method)) {
           throw YAML::Exception(node.Mark(), "unknown method");
         }
       },
       "'optimal' or 'two_step'"},
      number<int>(
          "two_step_max_iterations", [](auto* s) { return &s->solver.two_step.max_iterations; },
          "an integer >= 1"),
  };
  return table;
}

}  // namespace

const std::vector<SettingKey<PipelineSettings>>& pipelineKeys() { return keys(); }

const std::vector<std::string>& pipelineConfigKeys() {
  static const std::vector<std::string> names = keyNames(keys());
  return names;
}

void readPipelineKey(const std::string& source, const std::string& name, const YAML::Node& value,
                     PipelineSettings* settings) {
  const Key* key = findKey(keys(), name);
  if (!key) throw InputError(source + ": unknown key '" + name + "' (see config/default.yaml)");
  try {
    key->read(value, settings);
  } catch (const YAML::Exception&) {
    throw InputError(badValueMessage(source, name, yamlText(value), key->allowed));
  }
}

void checkPipelineSettings(const std::string& source, const PipelineSettings& settings) {
  if (settings.solver.two_step.max_iterations < 1) {
    throw InputError(badValueMessage(source, "two_step_max_iterations",
                                     std::to_string(settings.solver.two_step.max_iterations),
                                     "an integer >= 1"));
  }
  const std::string error = settings.validate();
  if (!error.empty()) throw InputError(source + ": " + error);
}

YAML::Node parseSettingsYaml(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": not valid YAML: " + e.what());
  }
  if (!root.IsNull() && !root.IsMap()) {
    throw InputError(source + ": expected a map of 'key: value' settings");
  }
  return root;
}

void parsePipelineConfig(const std::string& text, const std::string& source,
                         PipelineSettings* settings, const std::vector<std::string>& ignored_keys) {
  const YAML::Node root = parseSettingsYaml(text, source);
  if (root.IsNull()) return;
  PipelineSettings updated = *settings;
  for (const auto& entry : root) {
    const std::string name = entry.first.as<std::string>();
    if (std::find(ignored_keys.begin(), ignored_keys.end(), name) != ignored_keys.end()) continue;
    readPipelineKey(source, name, entry.second, &updated);
  }
  checkPipelineSettings(source, updated);
  *settings = updated;
}

void loadPipelineConfig(const std::string& path, PipelineSettings* settings,
                        const std::vector<std::string>& ignored_keys) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the configuration file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  parsePipelineConfig(buffer.str(), path, settings, ignored_keys);
}

}  // namespace camera_imu_alignment
