// The natural-scene source (no target: TargetDescription::numPoints() == 0): each rest's sharpest
// frame gives natural-scene features; the camera's rotation from earlier rests
// (vision/scene_rotation.h) links the poses in the joint estimate (JointProblem::camera_links) and
// chains their orientations in a scene frame for the pair solvers. During motion it gives nothing.
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <sstream>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_source.h"

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
/// A link fitted again with the rotation held near the estimate's (sceneLinkRefitter): the inliers'
/// gate (pixels). About 3 of the images' noise; the estimate's prediction of a link is good to
/// about a pixel (0.1 deg at 500 px).
constexpr double kHeldRotationGatePx = 1.5;
/// A remembered refit serves while the prediction stays within this share of the gate.
constexpr double kRefitReuseShare = 0.5;

double rmsSigmaDeg(const Eigen::Matrix3d& cov_rad2) {
  return rad2deg(std::sqrt(std::max(0.0, cov_rad2.trace()) / 3.0));
}

/// The features of an accepted pose's view, newest last (at most window_poses + 1).
struct SceneView {
  int pose_index = 0, scene = 0, group = 0;
  Eigen::Matrix3d R_scene_cam = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_world_imu = Eigen::Matrix3d::Identity();  ///< the pose's (gyro chain)
  std::shared_ptr<const SceneFeatures> features;              ///< shared with the snapshots' refits
};

class SceneSource : public CameraSource {
 public:
  explicit SceneSource(const CameraSourceSetup& setup)
      : settings_(setup.settings), inputs_(setup.inputs), reject_(setup.reject) {}

  std::string describe() const override { return "images of the natural scene (no target)"; }
  void takeRestFrame(const CameraFrame& frame, std::optional<double> rest_since_s,
                     const PoseHistoryView& history) override;
  /// No target to find during motion.
  std::optional<MotionFrame> takeMotionFrame(const CameraFrame&, const MotionFrame*) override {
    return std::nullopt;
  }
  /// The camera orientation from features matched with earlier rests (the links go into
  /// `entry`).
  std::string assessRest(const StationarySegment& segment, const PoseHistoryView& history,
                         StationaryPose* pose, StationaryWindow::Entry* entry) override;
  std::shared_ptr<const SceneLinkRefitter> sceneLinkRefitter(
      const JointProblem& problem, const std::vector<int>& pose_indices) const override;
  void rememberRefits(const std::vector<SceneRefit>& refits) override;

 private:
  /// A frame at rest (min_frame_interval_s apart) since the last rest ended.
  struct Candidate {
    double stamp_s = 0, sharpness = 0;
    cv::Mat mono8;
  };

  const PipelineSettings& settings_;
  CameraInputs& inputs_;
  RejectInput reject_;
  std::deque<Candidate> candidates_;
  std::deque<SceneView> views_;
  /// Links fitted again with the rotation held (WindowSnapshot::scene_links), by their poses'
  /// StationaryPose::index, as solves returned them (rememberRefits): a later solve with nearly
  /// the same prediction reuses the fit.
  SceneRefitMemory refits_;
  /// The matches of each link (by its poses' StationaryPose::index), for fitting it again.
  std::map<std::pair<int, int>, std::shared_ptr<const SceneMatches>> link_matches_;
  int scenes_started_ = 0;
  std::uint64_t rotations_refused_by_imu_ = 0;  ///< scene rotations the IMU's angle contradicts
};

void SceneSource::takeRestFrame(const CameraFrame& frame, std::optional<double>,
                                const PoseHistoryView&) {
  if (!imageFitsIntrinsics(frame, &inputs_, reject_)) return;
  // Which frame is the sharpest inside the rest is known only when the rest ends (its margins):
  // every frame is kept, spaced as detection would be.
  if (!candidates_.empty() &&
      frame.stamp_s - candidates_.back().stamp_s < settings_.min_frame_interval_s) {
    return;
  }
  candidates_.push_back({frame.stamp_s, imageSharpness(frame.mono8), frame.mono8.clone()});
  while (candidates_.size() > kMaxSceneCandidates) candidates_.pop_front();
}

std::string SceneSource::assessRest(const StationarySegment& segment,
                                    const PoseHistoryView& history, StationaryPose* pose,
                                    StationaryWindow::Entry* entry) {
  const PipelineSettings& settings = settings_;
  const double lo = segment.start_s + settings.frame_margin_s;
  const double hi = segment.end_s - settings.frame_margin_s;
  std::optional<Candidate> best;
  for (const Candidate& c : candidates_) {
    if (c.stamp_s < lo || c.stamp_s > hi) continue;
    if (!best || c.sharpness > best->sharpness) best = c;
  }
  while (!candidates_.empty() && candidates_.front().stamp_s <= segment.end_s) {
    candidates_.pop_front();
  }
  if (!best) {
    const std::string silent = silentCameraReason(inputs_);
    return silent.empty() ? "natural scene: no image inside the rest" : silent;
  }
  SceneFeatures features = extractSceneFeatures(best->mono8, *inputs_.intrinsics,
                                                settings.scene_features, best->stamp_s);
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
  if (history.window.size() >= 3) {
    const RotationPairs pairs = history.window.pairs();
    if (!pairs.empty()) {
      const PairSolveResult guess = solveAlignment(pairs, settings.solver);
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
  for (auto it = views_.rbegin(); it != views_.rend() && tried < settings.max_scene_matches;
       ++it, ++tried) {
    std::optional<Eigen::Matrix3d> prediction;
    if (R_cam_imu_guess && it->group == pose->group) {
      prediction = *R_cam_imu_guess * it->R_world_imu.transpose() * pose->R_world_imu *
                   R_cam_imu_guess->transpose();
    }
    SceneRotation rotation = estimateSceneRotation(*it->features, features, *inputs_.intrinsics,
                                                   prediction, settings.scene_rotation);
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
        ++rotations_refused_by_imu_;
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
    link_matches_[{it->pose_index, pose->index}] =
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
                         std::to_string(scenes_started_);
    }
    pose->scene = scenes_started_++;
    pose->R_target_cam = Eigen::Matrix3d::Identity();
  }
  pose->num_frames = 1;
  pose->camera_spread_deg = 0.0;
  entry->joint.camera_absolute = false;
  views_.push_back({pose->index, pose->scene, pose->group, pose->R_target_cam, pose->R_world_imu,
                    std::make_shared<const SceneFeatures>(std::move(features))});
  while (views_.size() > settings.window_poses + 1) views_.pop_front();
  // The matches and refits of links whose first view is gone are not asked for again.
  const auto gone = [&](const std::pair<int, int>& key) {
    return key.first < views_.front().pose_index;
  };
  while (!link_matches_.empty() && gone(link_matches_.begin()->first)) {
    link_matches_.erase(link_matches_.begin());
  }
  while (!refits_.empty() && gone(refits_.begin()->first)) refits_.erase(refits_.begin());
  return "";
}

/// The pipeline's refitter: the window's views (features shared read-only), the links' matches,
/// the intrinsics and a copy of the remembered fits of its links.
class ViewSceneLinkRefitter : public SceneLinkRefitter {
 public:
  std::map<int, std::shared_ptr<const SceneFeatures>> views;
  std::vector<SceneLinkKey> link_poses;  ///< StationaryPose::index of each link's views
  std::vector<std::shared_ptr<const SceneMatches>> link_matches;  ///< null: match again
  SceneRefitMemory remembered_fits;
  CameraIntrinsics intrinsics;
  SceneRotationSettings scene_settings;
  double reuse_rad = 0.0;

  SceneLinkKey key(int link) const override {
    return link >= 0 && link < static_cast<int>(link_poses.size())
               ? link_poses[static_cast<std::size_t>(link)]
               : SceneLinkKey{-1, -1};
  }
  std::optional<SceneRotation> remembered(int link, const Eigen::Matrix3d& R_near) const override {
    const auto hit = remembered_fits.find(key(link));
    if (hit == remembered_fits.end() ||
        !(rotationAngle(hit->second.R_from_to_near.transpose() * R_near) < reuse_rad)) {
      return std::nullopt;
    }
    return hit->second.rotation;
  }
  std::optional<SceneRotation> refit(int link, const Eigen::Matrix3d& R_near) const override {
    const SceneLinkKey k = key(link);
    const auto from = views.find(k.first), to = views.find(k.second);
    if (from == views.end() || to == views.end()) return std::nullopt;
    SceneRotation again = estimateSceneRotationNear(
        *from->second, *to->second, intrinsics, R_near, kHeldRotationGatePx, scene_settings,
        link_matches[static_cast<std::size_t>(link)].get());
    again.matched = SceneMatches();  // the rotation only: it is remembered
    return again;
  }
};

std::shared_ptr<const SceneLinkRefitter> SceneSource::sceneLinkRefitter(
    const JointProblem& problem, const std::vector<int>& pose_indices) const {
  const std::optional<CameraIntrinsics>& intrinsics = inputs_.intrinsics;
  if (!intrinsics || problem.camera_links.empty()) return nullptr;
  auto refitter = std::make_shared<ViewSceneLinkRefitter>();
  for (const SceneView& v : views_) refitter->views[v.pose_index] = v.features;
  const auto global = [&](int local) {
    return local >= 0 && local < static_cast<int>(pose_indices.size())
               ? pose_indices[static_cast<std::size_t>(local)]
               : -1;
  };
  for (const CameraLink& link : problem.camera_links) {
    const SceneLinkKey key(global(link.from_pose), global(link.to_pose));
    refitter->link_poses.push_back(key);
    const auto matched = link_matches_.find(key);
    refitter->link_matches.push_back(matched == link_matches_.end() ? nullptr : matched->second);
    const auto fit = refits_.find(key);
    if (fit != refits_.end()) refitter->remembered_fits.insert(*fit);
  }
  const double focal = std::sqrt(intrinsics->K(0, 0) * intrinsics->K(1, 1));
  refitter->reuse_rad = kRefitReuseShare * kHeldRotationGatePx / focal;
  refitter->intrinsics = *intrinsics;
  refitter->scene_settings = settings_.scene_rotation;
  return refitter;
}

void SceneSource::rememberRefits(const std::vector<SceneRefit>& refits) {
  for (const SceneRefit& fit : refits) {
    if (fit.key.first < 0 || fit.key.second < 0) continue;
    // Only links whose views the source still holds (a later solve may ask for them again).
    if (views_.empty() || fit.key.first < views_.front().pose_index) continue;
    refits_[fit.key] = fit;
  }
}

}  // namespace

std::unique_ptr<CameraSource> makeSceneSource(const CameraSourceSetup& setup) {
  return std::make_unique<SceneSource>(setup);
}

}  // namespace camera_imu_alignment
