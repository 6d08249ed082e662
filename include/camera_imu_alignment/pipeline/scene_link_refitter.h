// The natural scene's links fitted again from their two views with the rotation held near a
// prediction (the scene-refit stage of the window solve, solve/window_solver.h;
// WindowSnapshot::scene_links). A refitter belongs to one snapshot of the window and holds what it
// needs by value or read-only: the views' features, the links' matches, the intrinsics and the fits
// earlier solves made (SceneRefitMemory, a copy). It never writes shared state: a solve returns its
// new fits (WindowSolveOutput::scene_refits) and the pipeline remembers them for the next snapshot.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "camera_imu_alignment/vision/scene_rotation.h"

namespace camera_imu_alignment {

/// A link's two views by their StationaryPose::index (from, to).
using SceneLinkKey = std::pair<int, int>;

/// One held fit: the prediction it was held near and what it found.
struct SceneRefit {
  SceneLinkKey key{-1, -1};
  Eigen::Matrix3d R_from_to_near = Eigen::Matrix3d::Identity();
  SceneRotation rotation;
};

/// Fits of earlier solves, by link.
using SceneRefitMemory = std::map<SceneLinkKey, SceneRefit>;

class SceneLinkRefitter {
 public:
  virtual ~SceneLinkRefitter() = default;
  /// The views of camera link `link` (index into the snapshot's JointProblem::camera_links);
  /// {-1, -1} when unknown.
  virtual SceneLinkKey key(int link) const = 0;
  /// An earlier fit of `link` held near nearly the same prediction, when one is remembered.
  virtual std::optional<SceneRotation> remembered(int link, const Eigen::Matrix3d& R_near) const {
    (void)link;
    (void)R_near;
    return std::nullopt;
  }
  /// Fits `link` again with the rotation held near `R_near` (`to` camera relative to `from`);
  /// nullopt when its views are no longer held. Const and pure: safe on any thread.
  virtual std::optional<SceneRotation> refit(int link, const Eigen::Matrix3d& R_near) const = 0;
};

}  // namespace camera_imu_alignment
