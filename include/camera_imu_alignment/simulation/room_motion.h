// Rests of the natural-scene scenarios (MotionKind::kRoomRobot, kRoomHandheld) in the room of
// room_scene.h. Room frame = world (ENU, z up, metres); camera frame optical (z forward, x right,
// y down). Only the poses are drawn here; Trajectory gives them their hold and motion times and
// joins them by minimum-jerk rotation + straight-line translation.
//
// Robot (room_robot): at a stop the base's orientation is R_world_base = Rz(yaw) Ry(pitch) Rx(roll)
// (rollPitchYawDeg's convention), its origin on the floor; the camera sits h above the base origin
// along the base's z axis (h in [0.3, 0.5] m, one per seed) with R_base_cam = robotCameraMount()
// (looking along the base's x, pitched down by kRobotCameraPitchDeg). From one stop to the next the
// base moves 0.3-2 m along a straight path clear of the boxes (0.4 m), the yaw changes by 10-60 deg
// either way, and at every stop the tilt acos(cos(pitch) cos(roll)) is 5-20 deg in a random
// direction (uneven ground).
//
// Hand-held (room_handheld): the camera 1.1-1.6 m above the floor; between rests a rotation of
// 20-60 deg about a random axis (camera frame, drawn with more weight on the axes turned about
// least so far) and a translation of at most 0.2 m; the optical axis within
// [-50, 40] deg of the horizontal, the image's roll within 75 deg, the centre of the view on a
// wall or a box, the median distance to what the view sees within [1, 3] m.
//
// Both: each rest's view shares at least kMinViewOverlap of its scene with the previous rest's
// (viewOverlap, both ways); with config.moving_objects, kMovingShareMin-Max of each rest's view is
// on the sliding boxes (movingObjectShare at t = 0). Candidates are drawn (from `rng`) until one
// meets every rule, at most kMaxCandidates per rest; then the candidate meeting the angle and
// distance rules with the largest overlap is taken (a fallback that the tested seeds never reach).
#pragma once

#include <Eigen/Core>
#include <random>
#include <vector>

#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/room_scene.h"
#include "camera_imu_alignment/simulation/trajectory.h"

namespace camera_imu_alignment {
namespace simulation {

constexpr double kRobotCameraPitchDeg = 8.0;  ///< robot camera's optical axis below the base's x
constexpr double kMinViewOverlap = 0.3;       ///< of the sample rays, seen from both rests
constexpr double kMovingShareMin = 0.1;       ///< with moving objects: share of each rest's view
constexpr double kMovingShareMax = 0.25;  ///< on the sliding boxes (issue 26: 20 % of the features)
constexpr int kMaxCandidates = 4000;

/// R_base_cam of the robot (base: x forward, y left, z up).
Eigen::Matrix3d robotCameraMount();

/// Fraction of a 16 x 12 grid of view a's pixels (pinhole, distortion ignored) whose scene point,
/// at time t (s), view b sees within its image and unoccluded. R_world_cam, p_world_cam (m).
double viewOverlap(const RoomScene& scene, const CameraModel& camera, const Eigen::Matrix3d& R_a,
                   const Eigen::Vector3d& p_a, const Eigen::Matrix3d& R_b,
                   const Eigen::Vector3d& p_b, double t = 0.0);

/// Share of the same 16 x 12 grid of pixels that sees a sliding box at time t (s).
double movingObjectShare(const RoomScene& scene, const CameraModel& camera,
                         const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& p_world_cam,
                         double t = 0.0);

/// Median distance (m) from the camera to the scene over the same 16 x 12 grid of pixels.
double medianViewDistance(const RoomScene& scene, const CameraModel& camera,
                          const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& p_world_cam,
                          double t = 0.0);

/// The config.num_poses rests of config.motion (a room motion) in `scene`, times unset.
/// Throws std::runtime_error when no admissible pose is found (a room too cluttered to drive).
std::vector<StationaryPose> roomRests(const SimulationConfig& config, const RoomScene& scene,
                                      std::mt19937_64* rng);

}  // namespace simulation
}  // namespace camera_imu_alignment
