#include "camera_imu_alignment/pipeline/pipeline_config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>

#include "camera_imu_alignment/io/input_error.h"

namespace camera_imu_alignment {
namespace {

/// One configuration key: how to read it into the settings.
struct Key {
  std::string name;
  std::function<void(const YAML::Node&, PipelineSettings*)> read;
};

template <typename T>
Key number(const std::string& name, std::function<T*(PipelineSettings*)> field) {
  return {name, [field](const YAML::Node& node, PipelineSettings* s) { *field(s) = node.as<T>(); }};
}

const std::vector<Key>& keys() {
  static const std::vector<Key> table = {
      // Stationary detection (IMU).
      number<double>("stationary_window_s", [](auto* s) { return &s->stationary.window_s; }),
      number<double>("min_stationary_duration_s",
                     [](auto* s) { return &s->stationary.min_duration_s; }),
      number<double>("max_gyro_std_rad_s",
                     [](auto* s) { return &s->stationary.max_gyro_std_rad_s; }),
      number<double>("max_accel_std_m_s2",
                     [](auto* s) { return &s->stationary.max_accel_std_m_s2; }),
      number<double>("stationary_noise_factor",
                     [](auto* s) { return &s->stationary.noise_factor; }),
      number<double>("max_gyro_change_rad_s",
                     [](auto* s) { return &s->stationary.max_gyro_change_rad_s; }),
      number<double>("max_gravity_turn_rate_rad_s",
                     [](auto* s) { return &s->stationary.max_gravity_turn_rate_rad_s; }),
      number<double>("stationary_change_noise_factor",
                     [](auto* s) { return &s->stationary.change_noise_factor; }),
      number<double>("max_gyro_bias_rad_s",
                     [](auto* s) { return &s->stationary.max_gyro_bias_rad_s; }),
      number<double>("max_rate_about_gravity_rad_s",
                     [](auto* s) { return &s->stationary.max_rate_about_gravity_rad_s; }),
      number<double>("max_gravity_error_m_s2",
                     [](auto* s) { return &s->stationary.max_gravity_error_m_s2; }),
      number<double>("gravity_m_s2", [](auto* s) { return &s->stationary.gravity_m_s2; }),
      number<double>("max_imu_gap_s", [](auto* s) { return &s->stationary.max_gap_s; }),
      number<double>("max_gyro_span_s", [](auto* s) { return &s->max_gyro_span_s; }),
      // IMU orientation.
      {"imu_orientation",
       [](const YAML::Node& node, PipelineSettings* s) {
         if (!parseImuOrientationSource(node.as<std::string>(), &s->imu_orientation)) {
           throw YAML::Exception(node.Mark(), "must be 'auto', 'magnetometer' or 'message'");
         }
       }},
      number<double>("accel_weight", [](auto* s) { return &s->accel_weight; }),
      // Magnetometer.
      number<double>("mag_scale", [](auto* s) { return &s->magnetometer.scale; }),
      {"mag_hard_iron_t",
       [](const YAML::Node& node, PipelineSettings* s) {
         const auto v = node.as<std::vector<double>>();
         if (v.size() != 3) throw YAML::Exception(node.Mark(), "needs 3 numbers (T)");
         s->magnetometer.hard_iron_t = Eigen::Vector3d(v[0], v[1], v[2]);
       }},
      {"mag_soft_iron",
       [](const YAML::Node& node, PipelineSettings* s) {
         const auto v = node.as<std::vector<double>>();
         if (v.size() != 9) throw YAML::Exception(node.Mark(), "needs 9 numbers (row-major 3x3)");
         for (int i = 0; i < 9; ++i) s->magnetometer.soft_iron(i / 3, i % 3) = v[i];
       }},
      number<double>("mag_max_norm_change",
                     [](auto* s) { return &s->disturbance.max_norm_change; }),
      number<double>("mag_max_dip_change_deg",
                     [](auto* s) { return &s->disturbance.max_dip_change_deg; }),
      number<double>("mag_max_scatter_deg",
                     [](auto* s) { return &s->disturbance.max_within_segment_std_deg; }),
      // Camera.
      number<int>("min_target_points", [](auto* s) { return &s->detector.min_points; }),
      number<double>("max_reprojection_rms_px",
                     [](auto* s) { return &s->pose.max_reprojection_rms_px; }),
      number<double>("min_ambiguity_ratio", [](auto* s) { return &s->pose.min_ambiguity_ratio; }),
      number<int>("min_frames_per_pose", [](auto* s) { return &s->min_frames_per_pose; }),
      number<int>("max_frames_per_pose", [](auto* s) { return &s->max_frames_per_pose; }),
      number<double>("min_frame_interval_s", [](auto* s) { return &s->min_frame_interval_s; }),
      number<double>("missed_frame_interval_s",
                     [](auto* s) { return &s->missed_frame_interval_s; }),
      number<double>("frame_margin_s", [](auto* s) { return &s->frame_margin_s; }),
      number<double>("max_camera_spread_deg", [](auto* s) { return &s->max_camera_spread_deg; }),
      number<double>("frame_queue_s", [](auto* s) { return &s->frame_queue_s; }),
      // Window and solver.
      number<std::size_t>("window_poses", [](auto* s) { return &s->window_poses; }),
      number<int>("min_poses_to_solve", [](auto* s) { return &s->min_poses_to_solve; }),
      {"solver_method",
       [](const YAML::Node& node, PipelineSettings* s) {
         if (!parseSolverMethod(node.as<std::string>(), &s->solver.method)) {
           throw YAML::Exception(node.Mark(), "must be 'optimal' or 'two_step'");
         }
       }},
      number<int>("two_step_max_iterations",
                  [](auto* s) { return &s->solver.two_step.max_iterations; }),
  };
  return table;
}

}  // namespace

const std::vector<std::string>& pipelineConfigKeys() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& key : keys()) n.push_back(key.name);
    return n;
  }();
  return names;
}

void parsePipelineConfig(const std::string& text, const std::string& source,
                         PipelineSettings* settings, const std::vector<std::string>& ignored_keys) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": not valid YAML: " + e.what());
  }
  if (root.IsNull()) return;
  if (!root.IsMap()) throw InputError(source + ": expected a map of 'key: value' settings");
  PipelineSettings updated = *settings;
  for (const auto& entry : root) {
    const std::string name = entry.first.as<std::string>();
    if (std::find(ignored_keys.begin(), ignored_keys.end(), name) != ignored_keys.end()) continue;
    const auto it =
        std::find_if(keys().begin(), keys().end(), [&](const Key& k) { return k.name == name; });
    if (it == keys().end()) {
      throw InputError(source + ": unknown key '" + name + "' (see config/default.yaml)");
    }
    try {
      it->read(entry.second, &updated);
    } catch (const YAML::Exception& e) {
      throw InputError(source + ": key '" + name + "': " + e.msg);
    }
  }
  if (updated.solver.two_step.max_iterations < 1) {
    throw InputError(source + ": key 'two_step_max_iterations' must be >= 1");
  }
  const std::string error = updated.validate();
  if (!error.empty()) throw InputError(source + ": " + error);
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
