#include "camera_imu_alignment/simulation/room_motion.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace simulation {

namespace {

constexpr int kGridCols = 16, kGridRows = 12;

Eigen::Matrix3d rot(double angle, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

/// Camera-frame direction (not unit) of grid pixel (c, r): pinhole, distortion ignored.
Eigen::Vector3d gridRay(const CameraModel& cam, int c, int r) {
  const double u = (c + 0.5) * cam.width / kGridCols - 0.5;
  const double v = (r + 0.5) * cam.height / kGridRows - 0.5;
  return Eigen::Vector3d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
}

/// With moving objects, each rest's view has a share of them (kMovingShareMin-Max).
bool movingShareOk(const SimulationConfig& config, const RoomScene& scene, const CameraModel& cam,
                   const StationaryPose& pose) {
  if (!config.moving_objects) return true;
  const double share = movingObjectShare(scene, cam, pose.R_world_cam, pose.p_world_cam);
  return share >= kMovingShareMin && share <= kMovingShareMax;
}

/// One candidate rest and how well it meets the soft rules.
struct Candidate {
  StationaryPose pose;
  double overlap = -1.0;  ///< the smaller of the two directions
  bool admissible = false;
};

/// Overlap both ways with the previous pose (1 for the first).
double mutualOverlap(const RoomScene& scene, const CameraModel& cam, const StationaryPose* prev,
                     const StationaryPose& pose) {
  if (!prev) return 1.0;
  return std::min(viewOverlap(scene, cam, prev->R_world_cam, prev->p_world_cam, pose.R_world_cam,
                              pose.p_world_cam),
                  viewOverlap(scene, cam, pose.R_world_cam, pose.p_world_cam, prev->R_world_cam,
                              prev->p_world_cam));
}

/// Draws candidates with `draw` (false: not even the angle/distance rules hold) until one is
/// admissible; else the best by overlap. Throws if `draw` never succeeds.
template <typename Draw>
StationaryPose choose(const char* what, int index, Draw draw) {
  Candidate best;
  for (int tries = 0; tries < kMaxCandidates; ++tries) {
    Candidate c;
    if (!draw(&c)) continue;
    if (c.admissible) return c.pose;
    if (c.overlap > best.overlap) best = c;
  }
  if (best.overlap < 0.0) {
    throw std::runtime_error(std::string(what) + ": no admissible pose for rest " +
                             std::to_string(index) + " in the room");
  }
  return best.pose;
}

std::vector<StationaryPose> robotStops(const SimulationConfig& config, const RoomScene& scene,
                                       std::mt19937_64* rng) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const CameraModel cam = CameraModel::fromConfig(config);
  const Eigen::Matrix3d R_base_cam = robotCameraMount();
  const double height = 0.3 + 0.2 * uni(*rng);
  constexpr double kRadius = 0.4;  // the robot's footprint (m)
  std::vector<StationaryPose> stops;
  Eigen::Vector2d base(0.0, 0.0);
  double yaw = 0.0;
  for (int k = 0; k < config.num_poses; ++k) {
    const StationaryPose* prev = stops.empty() ? nullptr : &stops.back();
    const auto draw = [&](Candidate* c) {
      Eigen::Vector2d p;
      double new_yaw;
      if (!prev) {
        p = Eigen::Vector2d(scene.size().x() * uni(*rng), scene.size().y() * uni(*rng));
        new_yaw = 2.0 * kPi * uni(*rng);
        if (!scene.floorPointFree(p.x(), p.y(), kRadius)) return false;
      } else {
        const double distance = 0.3 + 1.7 * uni(*rng), heading = 2.0 * kPi * uni(*rng);
        const double turn = deg2rad(10.0 + 50.0 * uni(*rng)) * (uni(*rng) < 0.5 ? -1.0 : 1.0);
        p = base + distance * Eigen::Vector2d(std::cos(heading), std::sin(heading));
        new_yaw = yaw + turn;
        for (int s = 0; s <= 20; ++s) {
          const Eigen::Vector2d q = base + (s / 20.0) * (p - base);
          if (!scene.floorPointFree(q.x(), q.y(), kRadius)) return false;
        }
      }
      const double tilt =
                       deg2rad(config.robot_min_tilt_deg +
                               (config.robot_max_tilt_deg - config.robot_min_tilt_deg) * uni(*rng)),
                   direction = 2.0 * kPi * uni(*rng);
      const double pitch = tilt * std::cos(direction);
      const double roll =
          std::copysign(std::acos(std::cos(tilt) / std::cos(pitch)), std::sin(direction));
      const Eigen::Matrix3d R_world_base = rot(new_yaw, Eigen::Vector3d::UnitZ()) *
                                           rot(pitch, Eigen::Vector3d::UnitY()) *
                                           rot(roll, Eigen::Vector3d::UnitX());
      c->pose.R_world_cam = R_world_base * R_base_cam;
      c->pose.p_world_cam =
          Eigen::Vector3d(p.x(), p.y(), 0.0) + R_world_base * Eigen::Vector3d(0.0, 0.0, height);
      c->overlap = mutualOverlap(scene, cam, prev, c->pose);
      c->admissible =
          c->overlap >= kMinViewOverlap &&
          medianViewDistance(scene, cam, c->pose.R_world_cam, c->pose.p_world_cam) >= 0.8 &&
          movingShareOk(config, scene, cam, c->pose);
      return true;
    };
    const StationaryPose pose = choose("room_robot", k, draw);
    // The base of the chosen pose (its camera centre minus the mount's height along base z).
    const Eigen::Matrix3d R_world_base = pose.R_world_cam * R_base_cam.transpose();
    const Eigen::Vector3d p_base =
        pose.p_world_cam - R_world_base * Eigen::Vector3d(0.0, 0.0, height);
    base = p_base.head<2>();
    yaw = std::atan2(R_world_base(1, 0), R_world_base(0, 0));
    stops.push_back(pose);
  }
  return stops;
}

std::vector<StationaryPose> handheldRests(const SimulationConfig& config, const RoomScene& scene,
                                          std::mt19937_64* rng) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const CameraModel cam = CameraModel::fromConfig(config);
  constexpr double kRadius = 0.5;  // the person holding the rig (m)
  std::vector<StationaryPose> rests;
  Eigen::Matrix3d turned = Eigen::Matrix3d::Zero(), axis_weight = Eigen::Matrix3d::Identity();
  for (int k = 0; k < config.num_poses; ++k) {
    const StationaryPose* prev = rests.empty() ? nullptr : &rests.back();
    const auto draw = [&](Candidate* c) {
      StationaryPose& pose = c->pose;
      if (!prev) {
        pose.p_world_cam = Eigen::Vector3d(scene.size().x() * uni(*rng),
                                           scene.size().y() * uni(*rng), 1.1 + 0.5 * uni(*rng));
        pose.R_world_cam = uniformRotation(uni(*rng), uni(*rng), uni(*rng));
      } else {
        // Axes drawn with more weight on the camera axes turned about least so far.
        Eigen::Vector3d axis =
            axis_weight * Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng));
        axis.normalize();
        const double angle = deg2rad(20.0 + 40.0 * uni(*rng));
        pose.R_world_cam = prev->R_world_cam * expSO3(angle * axis);
        Eigen::Vector3d step(normal(*rng), normal(*rng), 0.5 * normal(*rng));
        step *= 0.2 * uni(*rng) / std::max(step.norm(), 1e-9);
        pose.p_world_cam = prev->p_world_cam + step;
      }
      const Eigen::Vector3d& p = pose.p_world_cam;
      if (!scene.floorPointFree(p.x(), p.y(), kRadius) || p.z() < 1.0 || p.z() > 1.7) return false;
      const Eigen::Vector3d x = pose.R_world_cam.col(0), y = pose.R_world_cam.col(1);
      const double elevation = std::asin(std::clamp(pose.R_world_cam(2, 2), -1.0, 1.0));
      const double roll = std::atan2(x.z(), -y.z());
      if (elevation < deg2rad(-50.0) || elevation > deg2rad(40.0) ||
          std::abs(roll) > deg2rad(75.0)) {
        return false;
      }
      SurfaceHit centre;
      scene.intersect(p, pose.R_world_cam.col(2), 0.0, &centre);
      const bool on_wall_or_box = centre.surface < 4 || centre.surface >= 6;
      const double distance = medianViewDistance(scene, cam, pose.R_world_cam, p);
      c->overlap = mutualOverlap(scene, cam, prev, pose);
      c->admissible = on_wall_or_box && distance >= 1.0 && distance <= 3.0 &&
                      c->overlap >= kMinViewOverlap && movingShareOk(config, scene, cam, pose);
      return true;
    };
    rests.push_back(choose("room_handheld", k, draw));
    if (k > 0) {
      // turned = sum of the turns' axis outer products; axes ~ N(0, (3 turned + I)^-1).
      const Eigen::AngleAxisd turn(rests[k - 1].R_world_cam.transpose() * rests[k].R_world_cam);
      turned += turn.axis() * turn.axis().transpose();
      axis_weight =
          Eigen::Matrix3d((3.0 * turned + Eigen::Matrix3d::Identity()).inverse()).llt().matrixL();
    }
  }
  return rests;
}

}  // namespace

Eigen::Matrix3d robotCameraMount() {
  const double m = deg2rad(kRobotCameraPitchDeg);
  Eigen::Matrix3d R_base_cam;
  // Columns: the camera's x (right = -y_base), y (down) and z (forward, pitched down by m).
  R_base_cam << 0.0, -std::sin(m), std::cos(m),  //
      -1.0, 0.0, 0.0,                            //
      0.0, -std::cos(m), -std::sin(m);
  return R_base_cam;
}

double viewOverlap(const RoomScene& scene, const CameraModel& cam, const Eigen::Matrix3d& R_a,
                   const Eigen::Vector3d& p_a, const Eigen::Matrix3d& R_b,
                   const Eigen::Vector3d& p_b, double t) {
  int seen = 0;
  for (int r = 0; r < kGridRows; ++r) {
    for (int c = 0; c < kGridCols; ++c) {
      SurfaceHit hit;
      const Eigen::Vector3d d = R_a * gridRay(cam, c, r);
      if (!scene.intersect(p_a, d, t, &hit)) continue;
      const Eigen::Vector3d point = p_a + hit.distance * d;
      const Eigen::Vector3d in_b = R_b.transpose() * (point - p_b);
      if (in_b.z() < 0.05) continue;
      const double u = cam.fx * in_b.x() / in_b.z() + cam.cx;
      const double v = cam.fy * in_b.y() / in_b.z() + cam.cy;
      if (u < -0.5 || v < -0.5 || u > cam.width - 0.5 || v > cam.height - 0.5) continue;
      // Unoccluded: from b, nothing nearer than the point on the way to it.
      SurfaceHit back;
      if (scene.intersect(p_b, point - p_b, t, &back) && back.distance > 1.0 - 1e-3) ++seen;
    }
  }
  return static_cast<double>(seen) / (kGridCols * kGridRows);
}

double movingObjectShare(const RoomScene& scene, const CameraModel& cam,
                         const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& p_world_cam,
                         double t) {
  int on_moving = 0;
  for (int r = 0; r < kGridRows; ++r) {
    for (int c = 0; c < kGridCols; ++c) {
      SurfaceHit hit;
      if (scene.intersect(p_world_cam, R_world_cam * gridRay(cam, c, r), t, &hit) &&
          hit.surface >= 6 && scene.boxes()[static_cast<size_t>(hit.surface - 6) / 6].moving())
        ++on_moving;
    }
  }
  return static_cast<double>(on_moving) / (kGridCols * kGridRows);
}

double medianViewDistance(const RoomScene& scene, const CameraModel& cam,
                          const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& p_world_cam,
                          double t) {
  std::vector<double> distances;
  for (int r = 0; r < kGridRows; ++r) {
    for (int c = 0; c < kGridCols; ++c) {
      SurfaceHit hit;
      if (scene.intersect(p_world_cam, (R_world_cam * gridRay(cam, c, r)).normalized(), t, &hit))
        distances.push_back(hit.distance);
    }
  }
  if (distances.empty()) return 0.0;
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  return distances[distances.size() / 2];
}

std::vector<StationaryPose> roomRests(const SimulationConfig& config, const RoomScene& scene,
                                      std::mt19937_64* rng) {
  if (config.motion == MotionKind::kRoomRobot) return robotStops(config, scene, rng);
  if (config.motion == MotionKind::kRoomHandheld) return handheldRests(config, scene, rng);
  throw std::runtime_error("roomRests: not a room motion");
}

}  // namespace simulation
}  // namespace camera_imu_alignment
