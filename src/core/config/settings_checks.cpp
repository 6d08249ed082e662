// The checks across settings (settings_checks.h).
#include "camera_imu_alignment/config/settings_checks.h"

#include <functional>
#include <vector>

#include "camera_imu_alignment/config/pipeline_config.h"

namespace camera_imu_alignment {
namespace {

/// `lower_key` (value `lower`) must not exceed `upper_key` (value `upper`).
struct OrderRule {
  bool needs_pipeline;
  bool needs_online;
  std::string lower_key;
  std::string upper_key;
  std::function<double(const PipelineSettings&, const OnlineSettings&)> lower;
  std::function<double(const PipelineSettings&, const OnlineSettings&)> upper;
  std::string why;
  /// When the rule applies (null: always).
  std::function<bool(const PipelineSettings&, const OnlineSettings&)> applies = nullptr;
};

const std::vector<OrderRule>& rules() {
  using P = const PipelineSettings&;
  using O = const OnlineSettings&;
  static const std::vector<OrderRule> list = {
      {true, false, "min_poses_to_solve", "window_poses",
       [](P p, O) { return p.min_poses_to_solve; },
       [](P p, O) { return static_cast<double>(p.window_poses); },
       "the window never holds more poses: nothing would ever be solved"},
      {true, false, "min_frames_per_pose", "max_frames_per_pose",
       [](P p, O) { return p.min_frames_per_pose; }, [](P p, O) { return p.max_frames_per_pose; },
       "detection stops at max_frames_per_pose: no rest would become a pose"},
      {true, false, "min_frame_interval_s", "missed_frame_interval_s",
       [](P p, O) { return p.min_frame_interval_s; },
       [](P p, O) { return p.missed_frame_interval_s; },
       "after missed detections frames are tried less often, not more"},
      {false, true, "remount_min_poses_after", "remount_max_poses_after",
       [](P, O o) { return o.remount.min_poses_after; },
       [](P, O o) { return o.remount.max_poses_after; },
       "a new mount's first pose is looked for among the newest remount_max_poses_after poses"},
      {true, true, "min_poses", "window_poses", [](P, O o) { return o.min_poses; },
       [](P p, O) { return static_cast<double>(p.window_poses); },
       "the window never holds more poses: nothing would ever be broadcast"},
      {true, true, "remount_min_poses_before + remount_min_poses_after", "window_poses",
       [](P, O o) { return o.remount.min_poses_before + o.remount.min_poses_after; },
       [](P p, O) { return static_cast<double>(p.window_poses); },
       "the window never holds that many poses: the remount test would never run",
       [](P p, O) { return usesJointEstimate(p.imu_orientation); }},
  };
  return list;
}

}  // namespace

std::optional<SettingProblem> checkAcrossKeys(const PipelineSettings* pipeline,
                                              const OnlineSettings* online) {
  const PipelineSettings no_pipeline;
  const OnlineSettings no_online;
  for (const OrderRule& rule : rules()) {
    if ((rule.needs_pipeline && !pipeline) || (rule.needs_online && !online)) continue;
    const PipelineSettings& p = pipeline ? *pipeline : no_pipeline;
    const OnlineSettings& o = online ? *online : no_online;
    if (rule.applies && !rule.applies(p, o)) continue;
    const double lower = rule.lower(p, o);
    const double upper = rule.upper(p, o);
    if (lower <= upper) continue;
    return SettingProblem{rule.lower_key, rule.lower_key + " = " + formatSettingNumber(lower) +
                                              " > " + rule.upper_key + " = " +
                                              formatSettingNumber(upper) + ": " + rule.lower_key +
                                              " must be <= " + rule.upper_key + " (" + rule.why +
                                              ")"};
  }
  return std::nullopt;
}

std::optional<SettingProblem> findProblem(const PipelineSettings& settings) {
  if (auto problem = checkRanges(pipelineKeys(), settings)) return problem;
  return checkAcrossKeys(&settings, nullptr);
}

void throwIfProblem(const std::string& source, const std::optional<SettingProblem>& problem) {
  if (problem) throw SettingsError(source, problem->key, problem->message);
}

}  // namespace camera_imu_alignment
