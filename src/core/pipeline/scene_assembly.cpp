// CalibrationPipeline without a target: each rest's sharpest frame gives natural-scene features;
// the camera's rotation from earlier rests (vision/scene_rotation.h) links the poses in the joint
// estimate (JointProblem::camera_links) and chains their orientations in a scene frame for the
// pair solvers.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "calibration_pipeline_impl.h"
#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// Frames at rest kept (min_frame_interval_s apart) until their rest ends, when the sharpest inside
/// the rest's margins is taken: at most this many (about 10 s of rest at the default interval).
constexpr std::size_t kMaxSceneCandidates = 64;
/// A camera rotation turns by the angle the IMU turned (an angle needs no R_cam_imu). The IMU's
/// angle between rests of one gyro chain is good to its scale and cross-axis errors (the joint
/// prior's, a few percent) plus this floor (deg); a measured rotation further off, by more than
/// kAngleCheckSigmas of the two combined, is a wrong fit (e.g. the essential matrix's two-fold
/// ambiguity on a near-planar view) and is not used.
constexpr double kAngleCheckFloorDeg = 0.2;
constexpr double kAngleCheckSigmas = 4.0;
/// A link fitted again with the rotation held near the estimate's (sceneLinkRefit): the inliers'
/// gate (pixels). About 3 of the images' noise; the estimate's prediction of a link is good to
/// about a pixel (0.1 deg at 500 px).
constexpr double kHeldRotationGatePx = 1.5;
/// A cached refit serves while the prediction stays within this share of the gate.
constexpr double kRefitReuseShare = 0.5;

double rmsSigmaDeg(const Eigen::Matrix3d& cov_rad2) {
  return rad2deg(std::sqrt(std::max(0.0, cov_rad2.trace()) / 3.0));
}

}  // namespace

void CalibrationPipeline::Impl::keepSceneCandidate(const CameraFrame& frame) {
  // Which frame is the sharpest inside the rest is known only when the rest ends (its margins):
  // every frame is kept, spaced as detection would be.
  if (!scene_candidates.empty() &&
      frame.stamp_s - scene_candidates.back().stamp_s < settings.min_frame_interval_s) {
    return;
  }
  scene_candidates.push_back({frame.stamp_s, imageSharpness(frame.mono8), frame.mono8.clone()});
  while (scene_candidates.size() > kMaxSceneCandidates) scene_candidates.pop_front();
}

std::string CalibrationPipeline::Impl::assessScene(const StationarySegment& segment,
                                                   StationaryPose* pose,
                                                   StationaryWindow::Entry* entry) {
  const double lo = segment.start_s + settings.frame_margin_s;
  const double hi = segment.end_s - settings.frame_margin_s;
  std::optional<SceneCandidate> best;
  for (const SceneCandidate& c : scene_candidates) {
    if (c.stamp_s < lo || c.stamp_s > hi) continue;
    if (!best || c.sharpness > best->sharpness) best = c;
  }
  while (!scene_candidates.empty() && scene_candidates.front().stamp_s <= segment.end_s) {
    scene_candidates.pop_front();
  }
  if (!best) {
    const std::string silent = silentCameraReason();
    return silent.empty() ? "natural scene: no image inside the rest" : silent;
  }
  SceneFeatures features =
      extractSceneFeatures(best->mono8, *intrinsics, settings.scene_features, best->stamp_s);
  const int count = static_cast<int>(features.keypoints.size());
  pose->camera_source = PoseCameraSource::kScene;
  pose->scene_features = count;
  if (count < settings.scene_rotation.min_inliers) {
    return "natural scene: " + std::to_string(count) + " features in the sharpest frame at " +
           fmt(best->stamp_s) + " s, at least " +
           std::to_string(settings.scene_rotation.min_inliers) +
           " needed (a blank wall, a dark room or a blurred view)";
  }
  // The IMU's prediction of each rotation once the window's pairs give an R_cam_imu (seeds the
  // two-view fit: a near-planar view's essential matrix is ambiguous).
  std::optional<Eigen::Matrix3d> R_cam_imu_guess;
  if (window.size() >= 3) {
    const RotationPairs pairs = window.pairs();
    if (!pairs.empty()) {
      const AlignmentResult guess = solveAlignment(pairs, settings.solver);
      if (guess.status == SolveStatus::kOk && guess.R_cam_imu.allFinite()) {
        R_cam_imu_guess = guess.R_cam_imu;
      }
    }
  }
  // Matched with the newest earlier rests; the strongest link places the pose in its scene.
  std::string best_failure = "no inliers";
  int best_inliers = -1;
  const SceneView* anchor = nullptr;
  SceneRotation anchor_rotation;
  int tried = 0;
  for (auto it = scene_views.rbegin();
       it != scene_views.rend() && tried < settings.max_scene_matches; ++it, ++tried) {
    std::optional<Eigen::Matrix3d> prediction;
    if (R_cam_imu_guess && it->group == pose->group) {
      prediction = *R_cam_imu_guess * it->R_world_imu.transpose() * pose->R_world_imu *
                   R_cam_imu_guess->transpose();
    }
    SceneRotation rotation = estimateSceneRotation(*it->features, features, *intrinsics, prediction,
                                                   settings.scene_rotation);
    if (rotation.ok && it->group == pose->group) {
      const double imu_deg =
          rad2deg(rotationAngle(it->R_world_imu.transpose() * pose->R_world_imu));
      const double camera_deg = rad2deg(rotationAngle(rotation.R_from_to));
      const JointSettings& joint = settings.joint;
      const double scale = std::hypot(joint.priors.gyro_scale, joint.priors.gyro_cross_axis);
      const double sigma =
          std::sqrt(std::pow(scale * imu_deg, 2) + std::pow(rmsSigmaDeg(rotation.cov_rad2), 2) +
                    std::pow(kAngleCheckFloorDeg, 2));
      if (std::abs(camera_deg - imu_deg) > kAngleCheckSigmas * sigma) {
        rotation.ok = false;
        rotation.message = "the camera turned " + fmt(camera_deg) + " deg, the IMU " +
                           fmt(imu_deg) + " deg (" + std::to_string(rotation.inliers) +
                           " inliers): not used";
        ++rotations_refused_by_imu;
      }
    }
    if (!rotation.ok) {
      if (rotation.inliers > best_inliers) {
        best_inliers = rotation.inliers;
        best_failure = "pose " + std::to_string(it->pose_index) + ": " + rotation.message;
      }
      continue;
    }
    CameraLink link;
    link.from_pose = it->pose_index;
    link.to_pose = pose->index;
    link.R_from_to = rotation.R_from_to;
    link.cov_rad2 = rotation.cov_rad2;
    SceneLinkSummary summary{it->pose_index,           rotation.matches,
                             rotation.inliers,         rotation.model,
                             rotation.residual_rms_px, rmsSigmaDeg(rotation.cov_rad2),
                             rotation.R_from_to};
    for (const SceneRotationAlternative& a : rotation.alternatives) {
      link.alternatives.push_back({a.R_from_to, a.cov_rad2});
      summary.alternatives.push_back(a.R_from_to);
    }
    entry->camera_links.push_back(link);
    scene_link_matches[{it->pose_index, pose->index}] =
        std::make_shared<const SceneMatches>(rotation.matched);
    pose->scene_links.push_back(std::move(summary));
    if (!anchor || rotation.inliers > anchor_rotation.inliers) {
      anchor = &*it;
      anchor_rotation = rotation;
    }
  }
  if (anchor) {
    pose->scene = anchor->scene;
    pose->R_target_cam = projectToSO3(anchor->R_scene_cam * anchor_rotation.R_from_to);
  } else {
    // No overlap: the pose starts a new scene, whose frame is unrelated to the earlier ones'. Its
    // IMU measurements still count; its camera does once a later rest overlaps it.
    if (tried > 0) {
      pose->scene_note = "the view at " + fmt(best->stamp_s) + " s (" + std::to_string(count) +
                         " features) overlaps none of the " + std::to_string(tried) +
                         " latest rests (best: " + best_failure + "): it starts scene " +
                         std::to_string(scenes_started);
    }
    pose->scene = scenes_started++;
    pose->R_target_cam = Eigen::Matrix3d::Identity();
  }
  pose->num_frames = 1;
  pose->camera_spread_deg = 0.0;
  entry->joint.camera_absolute = false;
  scene_views.push_back({pose->index, pose->scene, pose->group, pose->R_target_cam,
                         pose->R_world_imu,
                         std::make_shared<const SceneFeatures>(std::move(features))});
  while (scene_views.size() > settings.window_poses + 1) scene_views.pop_front();
  // The matches and refits of links whose first view is gone are not asked for again.
  const auto gone = [&](const std::pair<int, int>& key) {
    return key.first < scene_views.front().pose_index;
  };
  while (!scene_link_matches.empty() && gone(scene_link_matches.begin()->first)) {
    scene_link_matches.erase(scene_link_matches.begin());
  }
  {
    const std::lock_guard<std::mutex> lock(scene_refit_cache->mutex);
    auto& entries = scene_refit_cache->entries;
    while (!entries.empty() && gone(entries.begin()->first)) entries.erase(entries.begin());
  }
  return "";
}

std::function<std::optional<SceneRotation>(int, const Eigen::Matrix3d&)>
CalibrationPipeline::Impl::sceneLinkRefit(const JointProblem& problem,
                                          const std::vector<int>& pose_indices) const {
  if (!natural_scene || !intrinsics || problem.camera_links.empty()) return {};
  std::map<int, std::shared_ptr<const SceneFeatures>> views;
  for (const SceneView& v : scene_views) views[v.pose_index] = v.features;
  std::vector<std::pair<int, int>> link_poses;  // StationaryPose::index of each link's views
  std::vector<std::shared_ptr<const SceneMatches>> link_matches;  // null: match again
  const auto global = [&](int local) {
    return local >= 0 && local < static_cast<int>(pose_indices.size())
               ? pose_indices[static_cast<std::size_t>(local)]
               : -1;
  };
  for (const CameraLink& link : problem.camera_links) {
    link_poses.emplace_back(global(link.from_pose), global(link.to_pose));
    const auto matched = scene_link_matches.find(link_poses.back());
    link_matches.push_back(matched == scene_link_matches.end() ? nullptr : matched->second);
  }
  const double focal = std::sqrt(intrinsics->K(0, 0) * intrinsics->K(1, 1));
  const double reuse_rad = kRefitReuseShare * kHeldRotationGatePx / focal;
  return [views = std::move(views), link_poses = std::move(link_poses),
          link_matches = std::move(link_matches), intrinsics = *intrinsics,
          scene_settings = settings.scene_rotation, cache = scene_refit_cache,
          reuse_rad](int link, const Eigen::Matrix3d& R_near) -> std::optional<SceneRotation> {
    if (link < 0 || link >= static_cast<int>(link_poses.size())) return std::nullopt;
    const std::pair<int, int> key = link_poses[static_cast<std::size_t>(link)];
    const auto from = views.find(key.first), to = views.find(key.second);
    if (from == views.end() || to == views.end()) return std::nullopt;
    {
      const std::lock_guard<std::mutex> lock(cache->mutex);
      const auto hit = cache->entries.find(key);
      if (hit != cache->entries.end() &&
          rotationAngle(hit->second.R_from_to_near.transpose() * R_near) < reuse_rad) {
        return hit->second.rotation;
      }
    }
    SceneRotation again = estimateSceneRotationNear(
        *from->second, *to->second, intrinsics, R_near, kHeldRotationGatePx, scene_settings,
        link_matches[static_cast<std::size_t>(link)].get());
    again.matched = SceneMatches();  // the cache keeps the rotation only
    const std::lock_guard<std::mutex> lock(cache->mutex);
    cache->entries[key] = {R_near, again};
    return again;
  };
}

}  // namespace camera_imu_alignment
