// The pipeline's keys (pipeline_config.h): one table, one entry per key. Its ranges are
// findProblem's; config/default.yaml holds the same keys with the struct's
// defaults (test_pipeline_config checks both directions).
#include "camera_imu_alignment/config/pipeline_config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "camera_imu_alignment/config/settings_checks.h"

namespace camera_imu_alignment {
namespace {

using Key = SettingKey<PipelineSettings>;

template <typename T, typename Access>
Key number(const std::string& name, Access access, SettingRange range, const std::string& unit,
           const std::string& description) {
  return numberKey<T, PipelineSettings>(name, access, range, unit, description);
}

/// A list of `N` finite numbers in YAML flow style, written into `set`; `valid` judges the whole.
template <int N, typename Get, typename Set, typename Valid>
Key numberList(const std::string& name, Get get, Set set, Valid valid, const std::string& allowed,
               const std::string& unit, const std::string& description) {
  return {name,
          unit,
          description,
          allowed,
          [set](const YAML::Node& node, PipelineSettings* s) {
            const auto v = node.as<std::vector<double>>();
            if (v.size() != N) throw YAML::Exception(node.Mark(), "wrong length");
            set(v, s);
          },
          allowed,
          valid,
          [get](const PipelineSettings& s) {
            std::string text = "[";
            const std::vector<double> v = get(s);
            for (std::size_t i = 0; i < v.size(); ++i) {
              text += (i ? ", " : "") + formatSettingNumber(v[i]);
            }
            return text + "]";
          },
          std::nullopt,
          false};
}

/// scene_profile: sets the natural scene's feature settings that make up a profile; reads back
/// as the profile the settings are ("custom" when set in code to neither).
Key sceneProfileKey() {
  const std::string allowed = wordsText({"full", "fast"});
  return {"scene_profile",
          "",
          "without a target: full (SIFT on the full image) or fast (the image halved, each match "
          "refined: about 50 ms per rest, 30 per pair; for a scene that holds still: less accurate "
          "with objects moving in view)",
          allowed,
          [](const YAML::Node& node, PipelineSettings* s) {
            SceneProfile profile = SceneProfile::kFull;
            if (!parseSceneProfile(node.as<std::string>(), &profile)) {
              throw YAML::Exception(node.Mark(), "unknown word");
            }
            useSceneProfile(profile, &s->scene_features, &s->scene_rotation);
          },
          "",
          [](const PipelineSettings&) { return true; },
          [](const PipelineSettings& s) {
            return std::string(toString(sceneProfileOf(s.scene_features, s.scene_rotation)));
          },
          std::nullopt,
          false};
}

const std::vector<Key>& keys() {
  const SettingRange positive = above(0.0);
  const SettingRange non_negative = atLeast(0.0);
  static const std::vector<Key> table = {
      // Stationary detection (IMU).
      number<double>("stationary_window_s", CIA_MEMBER(stationary.window_s), positive, "s",
                     "sliding window over which rest is judged"),
      number<double>("min_stationary_duration_s", CIA_MEMBER(stationary.min_duration_s), positive,
                     "s", "shortest rest that becomes a pose (after trimming)"),
      number<double>("max_gyro_std_rad_s", CIA_MEMBER(stationary.max_gyro_std_rad_s), positive,
                     "rad/s", "gyro scatter about the window mean at rest (floor)"),
      number<double>("max_accel_std_m_s2", CIA_MEMBER(stationary.max_accel_std_m_s2), positive,
                     "m/s^2", "std of |accel| over the window at rest (floor)"),
      number<double>("stationary_noise_factor", CIA_MEMBER(stationary.noise_factor), non_negative,
                     "", "the scatter limits rise to this x the measured sensor noise"),
      number<double>("max_gyro_change_rad_s", CIA_MEMBER(stationary.max_gyro_change_rad_s),
                     positive, "rad/s", "change of the mean gyro within a rest (floor)"),
      number<double>("max_gravity_turn_rate_rad_s",
                     CIA_MEMBER(stationary.max_gravity_turn_rate_rad_s), positive, "rad/s",
                     "turn rate of the mean accel direction within a rest (floor)"),
      number<double>("stationary_change_noise_factor", CIA_MEMBER(stationary.change_noise_factor),
                     non_negative, "", "the change limits rise to this x their noise"),
      number<double>("max_gyro_bias_rad_s", CIA_MEMBER(stationary.max_gyro_bias_rad_s), positive,
                     "rad/s", "|window mean gyro| at any rest: the largest gyro bias"),
      number<double>("max_rate_about_gravity_rad_s",
                     CIA_MEMBER(stationary.max_rate_about_gravity_rad_s), positive, "rad/s",
                     "rotation about gravity at rest, which the accelerometer cannot see"),
      number<double>("max_gravity_error_m_s2", CIA_MEMBER(stationary.max_gravity_error_m_s2),
                     positive, "m/s^2", "| |mean accel| - gravity | at rest"),
      number<double>("gravity_m_s2", CIA_MEMBER(stationary.gravity_m_s2), positive, "m/s^2",
                     "local gravity: the stationary detector and the joint estimate's model"),
      number<double>("max_imu_gap_s", CIA_MEMBER(stationary.max_gap_s), positive, "s",
                     "a longer gap between IMU samples ends a rest and the gyro chain"),
      number<double>("max_gyro_span_s", CIA_MEMBER(max_gyro_span_s), positive, "s",
                     "longer motion between two rests breaks the gyro chain"),
      number<double>("motion_window_s", CIA_MEMBER(motion_window_s), non_negative, "s",
                     "camera frames and gyro during motion kept for the joint estimate; 0: rests "
                     "only"),
      number<double>("motion_frame_interval_s", CIA_MEMBER(motion_frame_interval_s), non_negative,
                     "s", "frames during motion closer than this to the last one used are skipped"),
      number<double>("max_timeshift_s", CIA_MEMBER(max_timeshift_s), positive, "s",
                     "the camera-IMU time offset is searched within +- this"),
      // How R_cam_imu is estimated.
      wordKey<PipelineSettings>(
          "imu_orientation", CIA_MEMBER(imu_orientation),
          {"joint", "auto", "magnetometer", "message"}, parseImuOrientationSource,
          [](ImuOrientationSource v) { return toString(v); },
          "where the IMU's orientation at each pose comes from"),
      number<double>("accel_weight", CIA_MEMBER(accel_weight), between(0.0, 1.0), "",
                     "q-method weight of gravity against magnetic north"),
      wordKey<PipelineSettings>(
          "imu_matrices", CIA_MEMBER(joint.imu_matrices), {"select", "estimate", "identity"},
          parseImuMatrixModel, [](ImuMatrixModel v) { return toString(v); },
          "joint: the gyro's and accelerometer's matrices T_g, T_a"),
      // Joint estimate: 1-sigma of the priors on the IMU's errors.
      number<double>("imu_prior_gyro_scale", CIA_MEMBER(joint.priors.gyro_scale), positive, "",
                     "prior: gyro sensitivity error (fraction)"),
      number<double>("imu_prior_gyro_cross_axis", CIA_MEMBER(joint.priors.gyro_cross_axis),
                     positive, "", "prior: gyro cross-axis / misalignment (fraction)"),
      number<double>("imu_prior_gyro_bias_walk_rad_s_sqrt_s",
                     CIA_MEMBER(joint.priors.gyro_bias_walk_rad_s_sqrt_s), positive,
                     "rad/s/sqrt(s)", "prior: gyro bias random walk between rests"),
      number<double>("imu_prior_accel_scale", CIA_MEMBER(joint.priors.accel_scale), positive, "",
                     "prior: accelerometer sensitivity error (fraction)"),
      number<double>("imu_prior_accel_cross_axis", CIA_MEMBER(joint.priors.accel_cross_axis),
                     positive, "", "prior: accelerometer non-orthogonality (fraction)"),
      number<double>("imu_prior_accel_bias_m_s2", CIA_MEMBER(joint.priors.accel_bias_m_s2),
                     positive, "m/s^2", "prior: accelerometer bias"),
      number<double>("imu_prior_accel_bias_walk_m_s2_sqrt_s",
                     CIA_MEMBER(joint.priors.accel_bias_walk_m_s2_sqrt_s), positive,
                     "m/s^2/sqrt(s)", "prior: accelerometer bias random walk between rests"),
      number<double>("imu_prior_soft_iron_scale", CIA_MEMBER(joint.priors.soft_iron_scale),
                     positive, "", "prior: magnetometer soft iron, diagonal (fraction)"),
      number<double>("imu_prior_soft_iron_cross", CIA_MEMBER(joint.priors.soft_iron_cross),
                     positive, "", "prior: magnetometer soft iron, off-diagonal (fraction)"),
      number<double>("imu_prior_hard_iron_t", CIA_MEMBER(joint.priors.hard_iron_t), positive, "T",
                     "prior: magnetometer hard iron left after mag_hard_iron_t"),
      // Magnetometer.
      number<double>("mag_scale", CIA_MEMBER(magnetometer.scale), positive, "T per unit",
                     "raw value x scale = tesla"),
      numberList<3>(
          "mag_hard_iron_t",
          [](const PipelineSettings& s) {
            const Eigen::Vector3d& v = s.magnetometer.hard_iron_t;
            return std::vector<double>{v.x(), v.y(), v.z()};
          },
          [](const std::vector<double>& v, PipelineSettings* s) {
            s->magnetometer.hard_iron_t = Eigen::Vector3d(v[0], v[1], v[2]);
          },
          [](const PipelineSettings& s) { return s.magnetometer.hard_iron_t.allFinite(); },
          "a list of 3 finite numbers (tesla)", "T", "subtracted after scaling (IMU frame)"),
      numberList<9>(
          "mag_soft_iron",
          [](const PipelineSettings& s) {
            std::vector<double> v;
            for (int i = 0; i < 9; ++i) v.push_back(s.magnetometer.soft_iron(i / 3, i % 3));
            return v;
          },
          [](const std::vector<double>& v, PipelineSettings* s) {
            for (int i = 0; i < 9; ++i) s->magnetometer.soft_iron(i / 3, i % 3) = v[i];
          },
          [](const PipelineSettings& s) {
            return s.magnetometer.soft_iron.allFinite() &&
                   std::abs(s.magnetometer.soft_iron.determinant()) >= 1e-6;
          },
          "a list of 9 finite numbers, an invertible row-major 3x3 matrix", "",
          "soft-iron matrix, applied last"),
      number<double>("mag_max_norm_change", CIA_MEMBER(disturbance.max_norm_change), positive, "",
                     "relative |B| change against the undisturbed reference"),
      number<double>("mag_max_dip_change_deg", CIA_MEMBER(disturbance.max_dip_change_deg), positive,
                     "deg", "dip angle change against the reference"),
      number<double>("mag_max_scatter_deg", CIA_MEMBER(disturbance.max_within_segment_std_deg),
                     positive, "deg", "field direction scatter within a rest"),
      // Camera.
      number<int>("min_target_points", CIA_MEMBER(detector.min_points), atLeast(4), "",
                  "fewer detected points: frame not used"),
      number<double>("max_reprojection_rms_px", CIA_MEMBER(pose.max_reprojection_rms_px), positive,
                     "px",
                     "PnP solutions at rest above are rejected (motion frames: judged by the "
                     "recording's own errors)"),
      number<double>("min_ambiguity_ratio", CIA_MEMBER(pose.min_ambiguity_ratio), positive, "",
                     "planar PnP: second solution must be this much worse"),
      number<int>("min_frames_per_pose", CIA_MEMBER(min_frames_per_pose), atLeast(1), "",
                  "frames with a camera pose needed per rest"),
      number<int>("max_frames_per_pose", CIA_MEMBER(max_frames_per_pose), atLeast(1), "",
                  "detection stops after this many per rest"),
      number<double>("min_frame_interval_s", CIA_MEMBER(min_frame_interval_s), non_negative, "s",
                     "frames closer than this to the last detection are skipped"),
      number<double>("missed_frame_interval_s", CIA_MEMBER(missed_frame_interval_s), non_negative,
                     "s", "after 3 failed detections in a row: the interval between attempts"),
      number<double>("frame_margin_s", CIA_MEMBER(frame_margin_s), non_negative, "s",
                     "frames this close to a rest's ends are not used"),
      sceneProfileKey(),
      number<double>("max_camera_spread_deg", CIA_MEMBER(max_camera_spread_deg), positive, "deg",
                     "camera orientation scatter within a rest"),
      number<double>("frame_queue_s", CIA_MEMBER(frame_queue_s), positive, "s",
                     "frames wait at most this long for the IMU to judge them"),
      // Window and solver.
      number<std::size_t>("window_poses", CIA_MEMBER(window_poses), within(2, 200), "",
                          "sliding window of stationary poses"),
      number<int>("min_poses_to_solve", CIA_MEMBER(min_poses_to_solve), atLeast(2), "",
                  "poses in the window before a solve"),
      wordKey<PipelineSettings>(
          "solver_method", CIA_MEMBER(solver.method), {"optimal", "two_step"}, parseSolverMethod,
          [](SolverMethod v) { return toString(v); }, "the pair solver"),
      number<int>("two_step_max_iterations", CIA_MEMBER(solver.two_step.max_iterations), atLeast(1),
                  "", "limit of the two-step when run alone"),
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
  if (!key) throw SettingsError(source, name, unknownKeyMessage(name, pipelineConfigKeys()));
  readKey(*key, source, value, settings);
}

void checkPipelineSettings(const std::string& source, const PipelineSettings& settings) {
  throwIfProblem(source, findProblem(settings));
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
