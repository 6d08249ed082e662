#include "camera_imu_alignment/simulation/room_scene.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numeric>
#include <random>
#include <sstream>

#include "camera_imu_alignment/simulation/inertial_model.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace simulation {

constexpr double RoomScene::kLayerCellM[RoomScene::kLayers];

namespace {

/// Probability that a cell of each layer holds a shape (coarse to fine).
constexpr double kLayerPresence[RoomScene::kLayers] = {0.75, 0.6, 0.45, 0.35};
constexpr double kInverseCell[RoomScene::kLayers] = {
    1.0 / RoomScene::kLayerCellM[0], 1.0 / RoomScene::kLayerCellM[1],
    1.0 / RoomScene::kLayerCellM[2], 1.0 / RoomScene::kLayerCellM[3]};
/// Contrast of the shapes against the surface's base grey in the texture-poor room.
constexpr double kPoorContrast = 0.04;

/// splitmix64's finaliser: a well-mixed 64-bit hash of x.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// The next number in [0, 1) of the hash sequence `state`.
double next(std::uint64_t* state) {
  *state = mix(*state);
  return static_cast<double>(*state >> 11) * (1.0 / 9007199254740992.0);
}

/// cos and sin of the 64 shape orientations k pi / 64 (no trigonometry per sample).
struct AngleTable {
  double cos[64], sin[64];
  AngleTable() {
    for (int k = 0; k < 64; ++k) {
      cos[k] = std::cos(kPi * k / 64.0);
      sin[k] = std::sin(kPi * k / 64.0);
    }
  }
};
const AngleTable kAngles;

/// Texture axes of a face whose normal is along `axis`: (u, v) = the other two coordinates.
void faceAxes(int axis, int* a_u, int* a_v) {
  *a_u = axis == 0 ? 1 : 0;
  *a_v = axis == 2 ? 1 : 2;
}

/// Bits [shift, shift + count) of h as a number in [0, 1).
double bits(std::uint64_t h, int shift, int count) {
  return static_cast<double>((h >> shift) & ((1ULL << count) - 1)) /
         static_cast<double>(1ULL << count);
}

/// The shape of cell (i, j) of `layer`, tested at (u, v): true and its grey and priority if the
/// point is inside. All of a shape's numbers come from one 64-bit hash of the cell (presence 8
/// bits, centre 2 x 8, type 4, half sizes 2 x 7, angle 6, grey 8, priority 6). Every shape lies
/// within 0.75 cell of its centre, itself in the middle half of the cell, so a point is covered
/// only by its own cell's shape and those of the neighbours on its side (see reflectance()).
bool shapeAt(std::uint64_t surface_key, int layer, long i, long j, double u, double v, double* grey,
             double* priority) {
  const double s = RoomScene::kLayerCellM[layer];
  const std::uint64_t h = mix(surface_key ^ (static_cast<std::uint64_t>(layer) << 58) ^
                              static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ULL ^
                              static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL);
  if (bits(h, 0, 8) > kLayerPresence[layer]) return false;
  const double du = u - (i + 0.25 + 0.5 * bits(h, 8, 8)) * s;
  const double dv = v - (j + 0.25 + 0.5 * bits(h, 16, 8)) * s;
  if (std::abs(du) > 0.75 * s || std::abs(dv) > 0.75 * s) return false;  // beyond any shape
  const double type = bits(h, 24, 4);
  double a = (0.12 + 0.38 * bits(h, 28, 7)) * s, b = (0.12 + 0.38 * bits(h, 35, 7)) * s;
  const int angle_index = type < 0.4 ? 0 : static_cast<int>((h >> 42) & 63);
  const double c = kAngles.cos[angle_index], sn = kAngles.sin[angle_index];
  const double x = c * du + sn * dv, y = -sn * du + c * dv;  // in the shape's axes
  bool inside;
  if (type < 0.7) {  // rectangle, axis-aligned or rotated; bounding radius <= 0.75 s
    const double r2 = a * a + b * b, r_max = 0.75 * s;
    if (r2 > r_max * r_max) {
      const double shrink = r_max / std::sqrt(r2);
      a *= shrink;
      b *= shrink;
    }
    inside = std::abs(x) <= a && std::abs(y) <= b;
  } else {  // ellipse
    inside = (x / a) * (x / a) + (y / b) * (y / b) <= 1.0;
  }
  if (!inside) return false;
  *grey = 0.05 + 0.9 * bits(h, 48, 8);
  *priority = bits(h, 56, 6);
  return true;
}

}  // namespace

Eigen::Vector3d SceneBox::offsetAt(double t) const {
  if (!moving()) return Eigen::Vector3d::Zero();
  return slide_amplitude_m * 0.5 * (1.0 - std::cos(2.0 * kPi * t / slide_period_s)) *
         slide_direction;
}

RoomScene::RoomScene(const Eigen::Vector3d& size_m, std::vector<SceneBox> boxes, bool texture_poor,
                     std::uint64_t texture_seed)
    : size_(size_m), boxes_(std::move(boxes)), texture_poor_(texture_poor), seed_(texture_seed) {
  const size_t surfaces = 6 + 6 * boxes_.size();
  std::uint64_t h = mix(seed_ ^ 0x7A3D1C55ULL);
  for (size_t k = 0; k < surfaces; ++k) {
    const double u = next(&h);
    base_grey_.push_back(texture_poor_ ? 0.56 + 0.1 * u : 0.3 + 0.45 * u);
  }
}

RoomScene RoomScene::fromConfig(const SimulationConfig& config) {
  std::mt19937_64 rng(streamSeed(config.seed, 8));
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const Eigen::Vector3d size(6.0, 5.0, 2.7);
  const int count = std::min(6, 3 + static_cast<int>(4.0 * uni(rng)));
  std::vector<SceneBox> boxes;
  const Eigen::Vector2d centre = 0.5 * size.head<2>();
  for (int tries = 0; static_cast<int>(boxes.size()) < count && tries < 1000; ++tries) {
    SceneBox box;
    const Eigen::Vector3d extent(0.3 + 0.9 * uni(rng), 0.3 + 0.9 * uni(rng), 0.3 + 0.9 * uni(rng));
    box.min_m = Eigen::Vector3d((size.x() - extent.x()) * uni(rng),
                                (size.y() - extent.y()) * uni(rng), 0.0);
    box.max_m = box.min_m + extent;
    // A free middle (1 m around the centre) for the rigs, 0.4 m gaps between the boxes.
    const Eigen::Vector2d nearest =
        centre.cwiseMax(box.min_m.head<2>()).cwiseMin(box.max_m.head<2>());
    bool ok = (nearest - centre).norm() > 1.0;
    for (const SceneBox& other : boxes) {
      ok = ok && ((box.min_m.head<2>().array() > other.max_m.head<2>().array() + 0.4).any() ||
                  (other.min_m.head<2>().array() > box.max_m.head<2>().array() + 0.4).any());
    }
    if (ok) boxes.push_back(box);
  }
  if (config.moving_objects) {
    // The two largest boxes (by the area they show) slide along the horizontal direction with
    // the most room to the walls.
    std::vector<size_t> order(boxes.size());
    std::iota(order.begin(), order.end(), 0);
    const auto area = [&](size_t k) {
      const Eigen::Vector3d e = boxes[k].max_m - boxes[k].min_m;
      return e.x() * e.z() + e.y() * e.z() + e.x() * e.y();
    };
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return area(a) > area(b); });
    for (size_t n = 0; n < std::min<size_t>(2, order.size()); ++n) {
      SceneBox& box = boxes[order[n]];
      const double space[4] = {box.min_m.x(), size.x() - box.max_m.x(), box.min_m.y(),
                               size.y() - box.max_m.y()};
      const int d = static_cast<int>(std::max_element(space, space + 4) - space);
      box.slide_direction = Eigen::Vector3d::Zero();
      box.slide_direction(d / 2) = d % 2 ? 1.0 : -1.0;
      box.slide_amplitude_m = std::min(0.2 + 0.3 * uni(rng), space[d]);
      box.slide_period_s = 30.0 + 20.0 * uni(rng);
    }
  }
  return RoomScene(size, std::move(boxes), config.texture_poor, streamSeed(config.seed, 8));
}

bool RoomScene::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t,
                          SurfaceHit* hit) const {
  if (!d.allFinite() || d.squaredNorm() == 0.0) return false;
  // The room: the ray leaves it through the nearest of its faces.
  SurfaceHit best;
  Eigen::Vector3d corner = Eigen::Vector3d::Zero();
  int best_axis = 0;
  for (int a = 0; a < 3; ++a) {
    if (d(a) == 0.0) continue;
    const double s = ((d(a) > 0.0 ? size_(a) : 0.0) - o(a)) / d(a);
    if (s < best.distance) {
      best.distance = s;
      best.surface = 2 * a + (d(a) > 0.0 ? 1 : 0);
      best_axis = a;
    }
  }
  // The boxes (slab test): the entry face of the nearest one in front of the origin.
  for (size_t b = 0; b < boxes_.size(); ++b) {
    const Eigen::Vector3d offset = boxes_[b].offsetAt(t);
    const Eigen::Vector3d lo = boxes_[b].min_m + offset, hi = boxes_[b].max_m + offset;
    double s_in = -std::numeric_limits<double>::infinity();
    double s_out = std::numeric_limits<double>::infinity();
    int in_face = -1;
    for (int a = 0; a < 3 && s_in <= s_out; ++a) {
      if (d(a) == 0.0) {
        if (o(a) < lo(a) || o(a) > hi(a)) s_out = -1.0;
        continue;
      }
      const double s_lo = (lo(a) - o(a)) / d(a), s_hi = (hi(a) - o(a)) / d(a);
      const double enter = std::min(s_lo, s_hi), leave = std::max(s_lo, s_hi);
      if (enter > s_in) {
        s_in = enter;
        in_face = 2 * a + (d(a) > 0.0 ? 0 : 1);
      }
      s_out = std::min(s_out, leave);
    }
    if (in_face >= 0 && s_in <= s_out && s_in > 0.0 && s_in < best.distance) {
      best.distance = s_in;
      best.surface = 6 + 6 * static_cast<int>(b) + in_face;
      best_axis = in_face / 2;
      corner = lo;
    }
  }
  if (best.surface < 0) return false;
  const Eigen::Vector3d p = o + best.distance * d - corner;
  int a_u, a_v;
  faceAxes(best_axis, &a_u, &a_v);
  best.u = p(a_u);
  best.v = p(a_v);
  *hit = best;
  return true;
}

double RoomScene::reflectance(int surface, double u, double v) const {
  const double base = base_grey_[static_cast<size_t>(surface)];
  const std::uint64_t key = mix(seed_ + 0x2545F491ULL * static_cast<std::uint64_t>(surface + 1));
  // The finest layer is on top: the first layer with a shape at (u, v) gives the grey. Among the
  // 2 x 2 cells that can reach the point (its own and the neighbours on its side), the highest
  // priority wins.
  for (int layer = kLayers - 1; layer >= 0; --layer) {
    const double fu = u * kInverseCell[layer], fv = v * kInverseCell[layer];
    const long i = static_cast<long>(std::floor(fu)), j = static_cast<long>(std::floor(fv));
    const long i2 = fu - i < 0.5 ? i - 1 : i + 1, j2 = fv - j < 0.5 ? j - 1 : j + 1;
    double grey = 0.0, priority = -1.0;
    for (const long ci : {i, i2}) {
      for (const long cj : {j, j2}) {
        double g, p;
        if (shapeAt(key, layer, ci, cj, u, v, &g, &p) && p > priority) {
          priority = p;
          grey = g;
        }
      }
    }
    if (priority >= 0.0) return texture_poor_ ? base + kPoorContrast * (grey - base) : grey;
  }
  return base;
}

RoomScene RoomScene::frozenAt(double t) const {
  RoomScene frozen = *this;
  for (SceneBox& box : frozen.boxes_) {
    const Eigen::Vector3d offset = box.offsetAt(t);
    box.min_m += offset;
    box.max_m += offset;
    box.slide_amplitude_m = 0.0;
    box.slide_direction.setZero();
  }
  return frozen;
}

bool RoomScene::floorPointFree(double x, double y, double r) const {
  if (x < r || y < r || x > size_.x() - r || y > size_.y() - r) return false;
  for (const SceneBox& box : boxes_) {
    const Eigen::Vector3d swing = box.slide_amplitude_m * box.slide_direction;
    const Eigen::Vector3d lo = box.min_m + swing.cwiseMin(0.0),
                          hi = box.max_m + swing.cwiseMax(0.0);
    if (x > lo.x() - r && x < hi.x() + r && y > lo.y() - r && y < hi.y() + r) return false;
  }
  return true;
}

std::string RoomScene::yaml() const {
  std::ostringstream o;
  o << std::setprecision(12);
  const auto vec = [&](const Eigen::Vector3d& v) {
    o << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  };
  o << "scene:  # natural scene, no board; room frame = world (ENU), floor z = 0\n"
    << "  type: room\n  size_m: ";
  vec(size_);
  o << "  # the room spans [0, size] per axis\n  texture_poor: "
    << (texture_poor_ ? "true" : "false") << "\n  boxes:" << (boxes_.empty() ? " []" : "")
    << "  # axis-aligned; a slide: offset(t) = amplitude (1 - cos(2 pi t / period)) / 2 "
       "direction, t since the start\n";
  for (const SceneBox& box : boxes_) {
    o << "    - min_m: ";
    vec(box.min_m);
    o << "\n      max_m: ";
    vec(box.max_m);
    o << "\n      moving: " << (box.moving() ? "true" : "false") << "\n";
    if (box.moving()) {
      o << "      slide_direction: ";
      vec(box.slide_direction);
      o << "\n      slide_amplitude_m: " << box.slide_amplitude_m
        << "\n      slide_period_s: " << box.slide_period_s << "\n";
    }
  }
  return o.str();
}

}  // namespace simulation
}  // namespace camera_imu_alignment
