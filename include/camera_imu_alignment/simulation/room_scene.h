// The natural scene of the room scenarios (room_robot, room_handheld): no calibration board, a
// closed room with furniture-like boxes, every surface covered by a deterministic texture rich in
// corners, so that feature matchers (SIFT, AKAZE) find hundreds of features in a 640x480 view at
// 0.5-3 m.
//
// Room frame = the world frame (ENU, z up, metres): the floor is z = 0 and the room spans
// [0, size.x] x [0, size.y] x [0, size.z]. Boxes are axis-aligned and stand on the floor; a moving
// box slides back and forth along a horizontal axis, offset(t) = amplitude * (1 - cos(2 pi t /
// period)) / 2 * direction (t in seconds since the run's start; 0 at t = 0), its texture moving
// with it.
//
// Texture: a reflectance in [0, 1] for each point (surface, u, v) of a face, u and v in metres
// along the face's two axes from the face's (box-fixed) minimum corner. On the surface's base grey,
// four layers of shapes (axis-aligned and rotated rectangles, ellipses, one per grid cell or none)
// with cells of 0.6, 0.22, 0.08 and 0.03 m, each drawn from a hash of (scene seed, surface, layer,
// cell): the same point has the same grey from every view, so views of a surface are related by
// the exact projective geometry. The finer layers are painted over the coarser ones. Texture-poor:
// the surfaces' greys close together and the shapes' contrast x0.04 (steps of at most about 5
// grey levels, below SIFT's contrast threshold): a near-blank room.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "camera_imu_alignment/simulation/sim_config.h"

namespace camera_imu_alignment {
namespace simulation {

/// An axis-aligned box standing on the floor, optionally sliding (see the file comment).
struct SceneBox {
  Eigen::Vector3d min_m = Eigen::Vector3d::Zero();  ///< lower corner at t = 0, room frame (m)
  Eigen::Vector3d max_m = Eigen::Vector3d::Zero();  ///< upper corner at t = 0, room frame (m)
  Eigen::Vector3d slide_direction = Eigen::Vector3d::Zero();  ///< unit, horizontal; 0: static
  double slide_amplitude_m = 0.0;  ///< largest displacement from the t = 0 position (m)
  double slide_period_s = 40.0;    ///< one slide out and back (s)

  bool moving() const { return slide_amplitude_m > 0.0; }
  /// Displacement from the t = 0 position at time t (s), room frame (m).
  Eigen::Vector3d offsetAt(double t) const;
};

/// The nearest surface along a ray.
struct SurfaceHit {
  double distance = std::numeric_limits<double>::infinity();  ///< s: hit = origin + s * direction
  /// 0-5: the room's faces at x = 0, x = size.x, y = 0, y = size.y, the floor, the ceiling;
  /// 6 + 6 b + f: box b's face f (same order: -x, +x, -y, +y, bottom, top).
  int surface = -1;
  double u = 0.0, v = 0.0;  ///< texture coordinates on the face (m)
};

class RoomScene {
 public:
  /// Cell sizes of the texture layers, coarse to fine (m).
  static constexpr int kLayers = 4;
  static constexpr double kLayerCellM[kLayers] = {0.6, 0.22, 0.08, 0.03};

  RoomScene(const Eigen::Vector3d& size_m, std::vector<SceneBox> boxes, bool texture_poor,
            std::uint64_t texture_seed);

  /// The room of `config`: 6 x 5 x 2.7 m, 3-6 boxes of 0.3-1.2 m (random stream 8 of the seed);
  /// with config.moving_objects the two largest boxes slide 0.2-0.5 m with periods of 30-50 s.
  static RoomScene fromConfig(const SimulationConfig& config);

  /// Nearest surface hit by origin + s * direction, s > 0, with the boxes at time t (s). The origin
  /// must be inside the room; the direction need not be unit (s is then not in metres). False only
  /// for a non-finite or zero direction.
  bool intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t,
                 SurfaceHit* hit) const;

  /// The scene at time t with every box where it is then and none moving (same textures): the
  /// renderer intersects this copy, sparing the slide per ray.
  RoomScene frozenAt(double t) const;

  /// Reflectance (0 black, 1 white) at texture coordinates (u, v) (m) of `surface`.
  double reflectance(int surface, double u, double v) const;

  /// True when the vertical cylinder of `radius_m` about the floor point (x, y) stays inside the
  /// room and off every box, wherever a moving box slides (m).
  bool floorPointFree(double x, double y, double radius_m) const;

  const Eigen::Vector3d& size() const { return size_; }
  const std::vector<SceneBox>& boxes() const { return boxes_; }
  bool texturePoor() const { return texture_poor_; }

  /// The `scene:` block of the truth file: room, boxes (with their slides), texture.
  std::string yaml() const;

 private:
  Eigen::Vector3d size_;
  std::vector<SceneBox> boxes_;
  bool texture_poor_;
  std::uint64_t seed_;
  std::vector<double> base_grey_;  ///< per surface
};

}  // namespace simulation
}  // namespace camera_imu_alignment
