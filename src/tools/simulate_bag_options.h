// simulate_bag's options: one table (setting_keys.h idiom), one entry per option with the member
// it sets, its range or words, unit and description. The option lists CliArgs accepts, the
// options part of the usage text and the range checks are generated from it.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "camera_imu_alignment/config/setting_keys.h"
#include "camera_imu_alignment/simulation/sim_config.h"
#include "cli_args.h"

namespace camera_imu_alignment {

/// How the bag is written (beyond the simulation itself).
struct BagOptions {
  std::string compression = "none";  ///< none, lz4 or bz2
  std::string mag_frame;             ///< frame_id of the magnetometer; empty: the IMU's
  double mag_frame_yaw_rad = 0.0;    ///< R_imu_mag = rotation about the IMU's z by this angle
  /// The CameraInfo's fx, fy are the rendering camera's times this (1: the true ones; else a wrong
  /// camera_info, as written by a bad camera calibration). The truth file keeps the true K.
  double camera_info_focal_scale = 1.0;
};

/// Everything simulate_bag's options set.
struct SimulateBagOptions {
  std::string out;  ///< FILE.bag
  simulation::SimulationConfig config;
  BagOptions bag;
};

/// The options, in usage order; an option's key is its name ("--num-poses"). The presets
/// (--seed, --scenario, --imu-grade) come first and are applied first.
const std::vector<SettingKey<SimulateBagOptions>>& simulateBagOptionTable();
/// Options taking a value / flags (true or false options, given without a value), for CliArgs.
std::set<std::string> simulateBagValueOptions();
std::set<std::string> simulateBagFlags();
/// "  --num-poses N: stationary poses [an integer within [2, 1000]] (12)", one line per option,
/// defaults of the nominal scenario.
std::string simulateBagOptionsUsage();
/// The options given, over the nominal scenario's defaults (after --scenario and --imu-grade).
/// Throws SettingsError (source "command line") naming the option on a bad value, and
/// UsageError for a missing --out; validateConfig's checks across settings are applied.
SimulateBagOptions parseSimulateBagOptions(const CliArgs& args);

}  // namespace camera_imu_alignment
