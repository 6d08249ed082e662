#include "camera_imu_alignment/simulation/target.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <opencv2/aruco.hpp>
#include <sstream>
#include <stdexcept>

namespace camera_imu_alignment {
namespace simulation {

namespace {

/// Pattern extent (without margin) in the target frame.
struct Extent {
  double x0, y0, x1, y1;
};

Extent patternExtent(const TargetSpec& t) {
  const double s = t.spacing_m;
  switch (t.type) {
    case TargetType::kAprilgrid: {
      const double pitch = (1.0 + t.tag_spacing) * s, gap = t.tag_spacing * s;
      return {-gap, -gap, (t.cols - 1) * pitch + s + gap, (t.rows - 1) * pitch + s + gap};
    }
    case TargetType::kCirclegrid: {
      const double r = 0.25 * s;
      const double width = t.asymmetric_grid ? (2 * (t.cols - 1) + 1) * s : (t.cols - 1) * s;
      return {-r, -r, width + r, (t.rows - 1) * s + r};
    }
    default:
      return {-s, -s, t.cols * s, t.rows * s};
  }
}

/// Darkness accumulator with exact area coverage of axis-aligned rectangles.
class Painter {
 public:
  explicit Painter(TargetTexture* tex) : tex_(tex) {}
  void rect(double x0, double y0, double x1, double y1) {
    const double t = tex_->texel_m;
    const int c0 = std::max(0, static_cast<int>(std::floor((x0 - tex_->x_min_m) / t)));
    const int c1 = std::min(tex_->reflectance.cols - 1,
                            static_cast<int>(std::floor((x1 - tex_->x_min_m) / t)));
    const int r0 = std::max(0, static_cast<int>(std::floor((tex_->y_max_m - y1) / t)));
    const int r1 = std::min(tex_->reflectance.rows - 1,
                            static_cast<int>(std::floor((tex_->y_max_m - y0) / t)));
    for (int r = r0; r <= r1; ++r) {
      const double ty1 = tex_->y_max_m - r * t, ty0 = ty1 - t;
      const double cy = std::max(0.0, std::min(y1, ty1) - std::max(y0, ty0)) / t;
      if (cy <= 0.0) continue;
      float* row = tex_->reflectance.ptr<float>(r);
      for (int c = c0; c <= c1; ++c) {
        const double tx0 = tex_->x_min_m + c * t, tx1 = tx0 + t;
        const double cx = std::max(0.0, std::min(x1, tx1) - std::max(x0, tx0)) / t;
        row[c] += static_cast<float>(cx * cy);
      }
    }
  }
  /// Disc with coverage from 4x4 samples per texel on its boundary.
  void disc(double xc, double yc, double radius) {
    const double t = tex_->texel_m;
    const int c0 = std::max(0, static_cast<int>(std::floor(tex_->col(xc - radius))));
    const int c1 =
        std::min(tex_->reflectance.cols - 1, static_cast<int>(std::ceil(tex_->col(xc + radius))));
    const int r0 = std::max(0, static_cast<int>(std::floor(tex_->row(yc + radius))));
    const int r1 =
        std::min(tex_->reflectance.rows - 1, static_cast<int>(std::ceil(tex_->row(yc - radius))));
    constexpr int kSub = 4;
    for (int r = r0; r <= r1; ++r) {
      float* row = tex_->reflectance.ptr<float>(r);
      for (int c = c0; c <= c1; ++c) {
        int inside = 0;
        for (int i = 0; i < kSub; ++i) {
          for (int j = 0; j < kSub; ++j) {
            const double x = tex_->x_min_m + (c + (j + 0.5) / kSub) * t - xc;
            const double y = tex_->y_max_m - (r + (i + 0.5) / kSub) * t - yc;
            inside += x * x + y * y <= radius * radius;
          }
        }
        row[c] += static_cast<float>(inside) / (kSub * kSub);
      }
    }
  }

 private:
  TargetTexture* tex_;
};

void paintAprilTag(Painter& p, const TargetSpec& t, int id, double x, double y) {
  const double s = t.spacing_m, bit = s / 10.0, border = 2.0 * bit;
  p.rect(x, y, x + s, y + border);                            // bottom border
  p.rect(x, y + s - border, x + s, y + s);                    // top border
  p.rect(x, y + border, x + border, y + s - border);          // left border
  p.rect(x + s - border, y + border, x + s, y + s - border);  // right border
  const std::vector<int> bits = tag36h11Bits(id);
  for (int i = 0; i < 6; ++i) {    // row from the top
    for (int j = 0; j < 6; ++j) {  // column from the left
      if (bits[6 * i + j]) continue;
      const double cx = x + border + j * bit, cy = y + s - border - (i + 1) * bit;
      p.rect(cx, cy, cx + bit, cy + bit);
    }
  }
  const double g = t.tag_spacing * s;
  p.rect(x - g, y - g, x, y);
  p.rect(x + s, y - g, x + s + g, y);
  p.rect(x + s, y + s, x + s + g, y + s + g);
  p.rect(x - g, y + s, x, y + s + g);
}

}  // namespace

std::vector<int> tag36h11Bits(int id) {
  static const cv::Ptr<cv::aruco::Dictionary> dict =
      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  if (id < 0 || id >= dict->bytesList.rows) {
    throw std::runtime_error("tag36h11 has no tag id " + std::to_string(id));
  }
  cv::Mat img;
  cv::aruco::drawMarker(dict, id, 8, img, 1);  // one pixel per cell, 1-cell border
  // OpenCV draws its APRILTAG_36h11 markers turned by 180 deg against the AprilTag code order
  // (and Kalibr's print), which puts the code's most significant bit at the upright tag's top-left.
  std::vector<int> bits(36);
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) bits[6 * i + j] = img.at<unsigned char>(6 - i, 6 - j) > 127;
  }
  return bits;
}

std::vector<Eigen::Vector3d> targetPoints(const TargetSpec& t) {
  std::vector<Eigen::Vector3d> pts;
  const double s = t.spacing_m;
  if (t.type == TargetType::kAprilgrid) {
    const double pitch = (1.0 + t.tag_spacing) * s;
    for (int r = 0; r < 2 * t.rows; ++r) {
      for (int c = 0; c < 2 * t.cols; ++c) {
        pts.emplace_back((c / 2) * pitch + (c % 2) * s, (r / 2) * pitch + (r % 2) * s, 0.0);
      }
    }
    return pts;
  }
  for (int r = 0; r < t.rows; ++r) {
    for (int c = 0; c < t.cols; ++c) {
      const bool asym = t.type == TargetType::kCirclegrid && t.asymmetric_grid;
      pts.emplace_back(asym ? (2 * c + r % 2) * s : c * s, r * s, 0.0);
    }
  }
  return pts;
}

Eigen::Vector3d targetCentre(const TargetSpec& t) {
  const Extent e = patternExtent(t);
  return Eigen::Vector3d(0.5 * (e.x0 + e.x1), 0.5 * (e.y0 + e.y1), 0.0);
}

std::string targetYaml(const TargetSpec& t) {
  std::ostringstream o;
  o << std::setprecision(12);
  o << "# Kalibr calibration target, written by camera_imu_alignment simulate_bag\n";
  o << "target_type: '" << toString(t.type) << "'\n";
  switch (t.type) {
    case TargetType::kAprilgrid:
      o << "tagCols: " << t.cols << "\ntagRows: " << t.rows << "\ntagSize: " << t.spacing_m
        << "  # m\ntagSpacing: " << t.tag_spacing << "  # ratio of tagSize\n";
      break;
    case TargetType::kCirclegrid:
      o << "targetCols: " << t.cols << "\ntargetRows: " << t.rows
        << "\nspacingMeters: " << t.spacing_m
        << "\nasymmetricGrid: " << (t.asymmetric_grid ? "True" : "False") << "\n";
      break;
    default:
      o << "targetCols: " << t.cols << "  # inner corners\ntargetRows: " << t.rows
        << "  # inner corners\nrowSpacingMeters: " << t.spacing_m
        << "\ncolSpacingMeters: " << t.spacing_m << "\n";
  }
  return o.str();
}

TargetTexture makeTargetTexture(const TargetSpec& t, double texel_m) {
  const Extent e = patternExtent(t);
  const double margin = std::max(t.spacing_m, 0.02);
  TargetTexture tex;
  tex.texel_m = texel_m;
  tex.x_min_m = e.x0 - margin;
  tex.y_max_m = e.y1 + margin;
  const double cols = std::ceil((e.x1 + margin - tex.x_min_m) / texel_m);
  const double rows = std::ceil((tex.y_max_m - (e.y0 - margin)) / texel_m);
  if (cols * rows > 12.5e6) {
    throw std::runtime_error("target texture too large (" + std::to_string(cols) + " x " +
                             std::to_string(rows) + " texels): use a smaller target");
  }
  tex.reflectance = cv::Mat::zeros(static_cast<int>(rows), static_cast<int>(cols), CV_32F);
  Painter paint(&tex);
  const double s = t.spacing_m;
  if (t.type == TargetType::kCheckerboard) {
    for (int i = 0; i <= t.cols; ++i) {
      for (int j = 0; j <= t.rows; ++j) {
        if ((i + j) % 2 == 0) paint.rect((i - 1) * s, (j - 1) * s, i * s, j * s);
      }
    }
  } else if (t.type == TargetType::kAprilgrid) {
    const double pitch = (1.0 + t.tag_spacing) * s;
    for (int r = 0; r < t.rows; ++r) {
      for (int c = 0; c < t.cols; ++c)
        paintAprilTag(paint, t, r * t.cols + c, c * pitch, r * pitch);
    }
  } else {
    for (const Eigen::Vector3d& p : targetPoints(t)) paint.disc(p.x(), p.y(), 0.25 * s);
  }
  // Darkness -> reflectance; identical overlapping squares (aprilgrid corners) clamp to black.
  cv::min(tex.reflectance, 1.0, tex.reflectance);
  tex.reflectance = 1.0 - tex.reflectance;
  return tex;
}

}  // namespace simulation
}  // namespace camera_imu_alignment
