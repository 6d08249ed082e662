// Checks across settings, all in one place: each rule names both keys, and a settings struct is
// usable when every key is within its table's range (setting_keys.h) and every rule here holds.
// The rules (settings_checks.cpp):
//   min_poses_to_solve <= window_poses          (pipeline)
//   min_frames_per_pose <= max_frames_per_pose  (pipeline)
//   min_frame_interval_s <= missed_frame_interval_s (pipeline)
//   remount_min_poses_after <= remount_max_poses_after (calibrator)
//   min_poses <= window_poses                   (both: else nothing is ever broadcast)
//   remount_min_poses_before + remount_min_poses_after <= window_poses
//                      (both, joint modes: else the remount test never runs)
#pragma once

#include <optional>
#include <string>

#include "camera_imu_alignment/config/online_settings.h"
#include "camera_imu_alignment/config/pipeline_settings.h"
#include "camera_imu_alignment/config/setting_keys.h"

namespace camera_imu_alignment {

/// The first rule broken by what is given (rules needing a struct not given are skipped): key =
/// the rule's first key, message "<key> = <v> > <other key> = <w>: <key> must be <= <other key>
/// (why)".
std::optional<SettingProblem> checkAcrossKeys(const PipelineSettings* pipeline,
                                              const OnlineSettings* online);

/// The pipeline's settings: their ranges (pipelineKeys), then the rules across them.
std::optional<SettingProblem> findProblem(const PipelineSettings& settings);

/// Throws SettingsError(source, key, message) when there is a problem.
void throwIfProblem(const std::string& source, const std::optional<SettingProblem>& problem);

}  // namespace camera_imu_alignment
