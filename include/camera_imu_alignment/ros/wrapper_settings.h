// Settings of the ROS wrapper (topics are remapped, not configured), read together with the
// pipeline's from the node's private parameters. config/default.yaml documents every key.
#pragma once

#include <ros/node_handle.h>

#include <string>
#include <vector>

#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/online/online_types.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"

namespace camera_imu_alignment {

struct WrapperSettings {
  std::string target_file;       ///< Kalibr target YAML (required)
  std::string camera_frame;      ///< tf frame of the camera; "" = the image header's frame_id
  std::string imu_frame;         ///< tf frame of the IMU; "" = the Imu header's frame_id
  bool publish_inverse = false;  ///< broadcast imu -> camera (parent IMU) instead of camera -> imu
  /// Each accepted calibration is written here ("" = not saved); "~" is the user's home
  /// (resolvePaths expands it), so ~save works out of the box.
  std::string output_file = "~/.ros/camera_imu_alignment.yaml";
  bool load_on_start = true;  ///< broadcast output_file's calibration at start if it exists
  /// The calibrator's gates, change detection and capture policy (its keys: online_config.h).
  OnlineSettings online;
  double status_period_s = 1.0;  ///< ~status is also published this often (s)
  /// image_transport's own parameter: "raw", or "compressed" for CompressedImage topics.
  std::string image_transport = "raw";
};

/// "~" and "~/..." with $HOME; every other path as it is.
std::string expandHome(const std::string& path);

/// At start: expands "~" in target_file and output_file and makes them absolute. A relative path
/// resolves from the node's working directory, which under roslaunch is ROS_HOME (~/.ros), not
/// where the user typed the command: a missing target file is a SettingsError naming the
/// parameter, the path given, that rule and the absolute path tried. Returns notices for the log
/// (a relative output_file: where it will be written).
std::vector<std::string> resolvePaths(WrapperSettings* settings);

/// The wrapper's own keys (the calibrator's are onlineConfigKeys(), the pipeline's
/// pipelineConfigKeys()).
const std::vector<std::string>& wrapperKeys();
/// Their table (setting_keys.h).
const std::vector<SettingKey<WrapperSettings>>& wrapperKeyTable();

/// Reads the private parameters of `private_nh`: wrapper keys into `wrapper`, pipeline keys into
/// `pipeline` (same reader and checks as calibrate_bag --config). Throws SettingsError naming the
/// parameter on an unknown key (with "did you mean" the closest key), a wrong type or an
/// unusable value.
void readSettings(const ros::NodeHandle& private_nh, WrapperSettings* wrapper,
                  PipelineSettings* pipeline);

/// Same from a flat YAML map of parameters; `source` names it in messages.
void parseSettings(const YAML::Node& root, const std::string& source, WrapperSettings* wrapper,
                   PipelineSettings* pipeline);
/// Same from YAML text.
void parseSettings(const std::string& yaml_text, const std::string& source,
                   WrapperSettings* wrapper, PipelineSettings* pipeline);

}  // namespace camera_imu_alignment
