// RestFramePoses (rest_frame_poses.h): the frames' camera poses at rest and their robust average.
#include "rest_frame_poses.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>

#include "camera_imu_alignment/solver/rotation_average.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// The board may look the same turned (TargetDetector::symmetries): among the readings
/// S * R_target_cam, the right one turns the camera by the same angle as the IMU since the earlier
/// poses of the group (a rotation angle does not depend on the frame). Keeps the detector's reading
/// when no earlier pose can tell or the best two readings agree within `kSymmetryMarginDeg`.
constexpr double kSymmetryMarginDeg = 2.0;
constexpr std::size_t kSymmetryReferencePoses = 5;

Eigen::Matrix3d resolveSymmetry(const Eigen::Matrix3d& R_target_cam,
                                const Eigen::Matrix3d& R_world_imu, int group,
                                const std::vector<StationaryPose>& poses,
                                const std::vector<Eigen::Matrix3d>& symmetries) {
  if (symmetries.empty()) return R_target_cam;
  std::vector<const StationaryPose*> references;
  for (auto it = poses.rbegin(); it != poses.rend(); ++it) {
    if (it->group != group) break;  // groups are contiguous
    references.push_back(&*it);
    if (references.size() == kSymmetryReferencePoses) break;
  }
  if (references.empty()) return R_target_cam;
  std::vector<Eigen::Matrix3d> readings{R_target_cam};
  for (const auto& S : symmetries) readings.push_back(S * R_target_cam);
  std::vector<double> cost(readings.size(), 0.0);
  for (std::size_t k = 0; k < readings.size(); ++k) {
    for (const StationaryPose* p : references) {
      const double camera = rotationAngle(p->R_target_cam.transpose() * readings[k]);
      const double imu = rotationAngle(p->R_world_imu.transpose() * R_world_imu);
      cost[k] += std::abs(camera - imu) / static_cast<double>(references.size());
    }
  }
  std::vector<std::size_t> order(readings.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return cost[a] < cost[b]; });
  if (rad2deg(cost[order[1]] - cost[order[0]]) < kSymmetryMarginDeg) return R_target_cam;
  return readings[order[0]];
}

}  // namespace

RestFramePoses::RestFramePoses(const PipelineSettings& settings,
                               std::vector<Eigen::Matrix3d> symmetries)
    : settings_(settings), symmetries_(std::move(symmetries)) {}

bool RestFramePoses::due(double stamp_s, double interval_s,
                         std::optional<double> rest_since_s) const {
  if (stamp_s - last_tried_s_ < interval_s) return false;
  int in_this_rest = 0;
  for (const auto& d : frames_) in_this_rest += (rest_since_s && d.stamp_s >= *rest_since_s);
  return in_this_rest < settings_.max_frames_per_pose;
}

std::vector<FrameDetection> RestFramePoses::takeRest(double lo_s, double hi_s, double end_s) {
  std::vector<FrameDetection> inside, later;
  for (const auto& d : frames_) {
    if (d.stamp_s >= lo_s && d.stamp_s <= hi_s) inside.push_back(d);
    if (d.stamp_s > end_s) later.push_back(d);
  }
  frames_.swap(later);
  return inside;
}

std::string RestFramePoses::average(const std::vector<FrameDetection>& inside,
                                    const RestFrameShortfall& shortfall, const CameraInputs& inputs,
                                    const std::vector<StationaryPose>& poses,
                                    StationaryPose* pose) const {
  std::vector<Eigen::Matrix3d> rotations;
  double reprojection_sum = 0.0;
  Eigen::Matrix3d pnp_cov_sum = Eigen::Matrix3d::Zero();
  for (const auto& d : inside) {
    rotations.push_back(d.pose.R_target_cam);
    reprojection_sum += d.pose.reprojection_rms_px;
    pnp_cov_sum += d.pose.cov_rotation_rad2;
    pose->p_target_cam = d.pose.p_target_cam;
  }
  if (static_cast<int>(rotations.size()) < settings_.min_frames_per_pose) {
    const std::string silent = silentCameraReason(inputs);
    if (!silent.empty()) return silent;
    std::string out =
        "target seen in " + std::to_string(rotations.size() + shortfall.refused) + " frame(s), " +
        std::to_string(settings_.min_frames_per_pose) +
        (shortfall.refused > 0 ? " with a camera pose needed; " + shortfall.refused_text
                               : " needed");
    if (!shortfall.mismatch.empty()) out += " (" + shortfall.mismatch + ")";
    return out;
  }
  const RotationAverage average =
      averageRotations(rotations, 4.0 * settings_.max_camera_spread_deg);
  if (average.num_inliers < settings_.min_frames_per_pose ||
      average.spread_rms_deg > settings_.max_camera_spread_deg) {
    return "camera orientation scatter " + fmt(average.spread_rms_deg) + " deg over " +
           std::to_string(rotations.size()) + " frames (limit " +
           fmt(settings_.max_camera_spread_deg) + ")";
  }
  pose->R_target_cam =
      resolveSymmetry(average.mean, pose->R_world_imu, pose->group, poses, symmetries_);
  pose->num_frames = average.num_inliers;
  pose->camera_spread_deg = average.spread_rms_deg;
  pose->reprojection_rms_px = reprojection_sum / static_cast<double>(rotations.size());
  pose->camera_pnp_cov_rad2 = pnp_cov_sum / static_cast<double>(rotations.size());
  return "";
}

}  // namespace camera_imu_alignment
