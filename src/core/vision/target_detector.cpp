// Target detection: checkerboard, AprilGrid (tag36h11, Kalibr's layout) and circle grid, with
// the point labelling made unique (grid symmetries resolved by handedness, square colours, the
// hint and a fixed rule, in that order).
#include "camera_imu_alignment/vision/target_detector.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace camera_imu_alignment {

struct TargetDetector::Impl {
  cv::Ptr<cv::aruco::Dictionary> dictionary;
  cv::Ptr<cv::aruco::DetectorParameters> parameters;
};

TargetDetector::TargetDetector(const TargetDescription& target, const DetectorSettings& settings)
    : target_(target), settings_(settings), impl_(std::make_unique<Impl>()) {
  if (target_.type == TargetDescription::Type::kAprilGrid) {
    impl_->dictionary = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
    impl_->parameters = cv::aruco::DetectorParameters::create();
    impl_->parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
    impl_->parameters->markerBorderBits = 2;  // Kalibr prints tags with a 2-bit black border
  }
}

TargetDetector::~TargetDetector() = default;

namespace {

/// A labelling of a detected rows x cols grid: detected (i, j) -> target (r, c).
struct Labelling {
  bool transpose = false, flip_rows = false, flip_cols = false;
};

/// Points of a labelled grid, or false when the labelling does not fit the target's shape.
bool applyLabelling(const std::vector<cv::Point2f>& detected, int det_rows, int det_cols,
                    const Labelling& l, int rows, int cols, std::vector<cv::Point2f>* labelled) {
  const int out_rows = l.transpose ? det_cols : det_rows,
            out_cols = l.transpose ? det_rows : det_cols;
  if (out_rows != rows || out_cols != cols) return false;
  labelled->assign(detected.size(), cv::Point2f());
  for (int i = 0; i < det_rows; ++i) {
    for (int j = 0; j < det_cols; ++j) {
      int r = l.transpose ? j : i, c = l.transpose ? i : j;
      if (l.flip_rows) r = rows - 1 - r;
      if (l.flip_cols) c = cols - 1 - c;
      (*labelled)[r * cols + c] = detected[i * det_cols + j];
    }
  }
  return true;
}

/// Signed area of the grid's outer quadrilateral in the image (pixels^2, image y down). Negative
/// when the camera sees the printed face with the target's x to the right of its y (z = x cross
/// y towards the camera): the only physically possible labellings.
double signedArea(const std::vector<cv::Point2f>& p, int rows, int cols) {
  const cv::Point2f q[4] = {p[0], p[cols - 1], p[rows * cols - 1], p[(rows - 1) * cols]};
  double area = 0.0;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f& a = q[k];
    const cv::Point2f& b = q[(k + 1) % 4];
    area += a.x * b.y - b.x * a.y;
  }
  return 0.5 * area;
}

std::vector<cv::Point2f> planarPoints(const TargetDescription& target, int n) {
  std::vector<cv::Point2f> xy;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = target.point(i);
    xy.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  return xy;
}

/// RMS of the homography fit target plane -> image (px): a wrong labelling of a grid that is not
/// symmetric under it (e.g. an asymmetric circle grid) does not fit.
double homographyRms(const std::vector<cv::Point2f>& plane, const std::vector<cv::Point2f>& image,
                     cv::Mat* H) {
  *H = cv::findHomography(plane, image, 0);
  if (H->empty()) return std::numeric_limits<double>::infinity();
  std::vector<cv::Point2f> projected;
  cv::perspectiveTransform(plane, projected, *H);
  double sq = 0.0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    const cv::Point2f d = projected[i] - image[i];
    sq += d.dot(d);
  }
  return std::sqrt(sq / image.size());
}

/// Checkerboard colour score: mean intensity of the squares expected white minus that of the
/// squares expected black (the square diagonal to corner (0, 0), outside the grid, is black;
/// squares inside the grid alternate). Positive for the right labelling.
double colourScore(const cv::Mat& mono8, const cv::Mat& H, const TargetDescription& t) {
  double white = 0.0, black = 0.0;
  int n_white = 0, n_black = 0;
  for (int r = 0; r + 1 < t.rows; ++r) {
    for (int c = 0; c + 1 < t.cols; ++c) {
      const std::vector<cv::Point2f> centre{
          cv::Point2f(static_cast<float>((c + 0.5) * t.col_spacing_m),
                      static_cast<float>((r + 0.5) * t.row_spacing_m))};
      std::vector<cv::Point2f> px;
      cv::perspectiveTransform(centre, px, H);
      const int u = cvRound(px[0].x), v = cvRound(px[0].y);
      if (u < 1 || v < 1 || u >= mono8.cols - 1 || v >= mono8.rows - 1) continue;
      const double value = cv::mean(mono8(cv::Rect(u - 1, v - 1, 3, 3)))[0];
      if ((r + c) % 2 == 0) {
        black += value, ++n_black;
      } else {
        white += value, ++n_white;
      }
    }
  }
  if (n_white == 0 || n_black == 0) return 0.0;
  return white / n_white - black / n_black;
}

/// Image direction (unit) of the target's x and y axes predicted from a camera orientation, for
/// views not too oblique: the camera-frame axes projected on the image plane.
bool predictedAxes(const Eigen::Matrix3d& R_target_cam, cv::Point2f* x_dir, cv::Point2f* y_dir) {
  const Eigen::Matrix3d R_cam_target = R_target_cam.transpose();
  const Eigen::Vector3d x = R_cam_target.col(0), y = R_cam_target.col(1);
  if (x.head<2>().norm() < 1e-6 || y.head<2>().norm() < 1e-6) return false;
  *x_dir = cv::Point2f(static_cast<float>(x.x()), static_cast<float>(x.y())) /
           static_cast<float>(x.head<2>().norm());
  *y_dir = cv::Point2f(static_cast<float>(y.x()), static_cast<float>(y.y())) /
           static_cast<float>(y.head<2>().norm());
  return true;
}

cv::Point2f unit(const cv::Point2f& v) {
  const float n = std::sqrt(v.dot(v));
  return n > 0.0f ? v / n : v;
}

}  // namespace

/// Picks the labelling of a full grid detection (rows x cols as detected, OpenCV order).
static bool labelGrid(const cv::Mat& mono8, const std::vector<cv::Point2f>& detected,
                      const TargetDescription& target, const Eigen::Matrix3d* hint,
                      TargetObservation* observation) {
  const int rows = target.rows, cols = target.cols, n = rows * cols;
  if (static_cast<int>(detected.size()) != n) return false;
  const std::vector<cv::Point2f> plane = planarPoints(target, n);
  struct Candidate {
    std::vector<cv::Point2f> points;
    cv::Mat H;
    double rms = 0.0, colour = 0.0;
  };
  std::vector<Candidate> candidates;
  for (int k = 0; k < 8; ++k) {
    const Labelling l{(k & 4) != 0, (k & 2) != 0, (k & 1) != 0};
    Candidate cand;
    // OpenCV returns rows x cols points; transposed labellings exist for square grids only.
    if (!applyLabelling(detected, rows, cols, l, rows, cols, &cand.points)) continue;
    if (signedArea(cand.points, rows, cols) >= 0.0) continue;  // seen from behind: impossible
    cand.rms = homographyRms(plane, cand.points, &cand.H);
    candidates.push_back(std::move(cand));
  }
  if (candidates.empty()) return false;
  const double best_rms =
      std::min_element(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
        return a.rms < b.rms;
      })->rms;
  // Keep the labellings that fit as well as the best: the symmetries of the pattern.
  candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                  [&](const Candidate& c) {
                                    return c.rms > std::max(3.0 * best_rms, best_rms + 1.0);
                                  }),
                   candidates.end());
  const Candidate* chosen = nullptr;
  if (candidates.size() > 1 && target.type == TargetDescription::Type::kCheckerboard) {
    // Square colours break the symmetry when the board is not colour-symmetric.
    for (auto& c : candidates) c.colour = colourScore(mono8, c.H, target);
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& a, const Candidate& b) { return a.colour > b.colour; });
    if (candidates[0].colour > 20.0 && candidates[1].colour < 0.0) chosen = &candidates[0];
  }
  cv::Point2f x_ref(1.0f, 0.0f), y_ref(0.0f, -1.0f);  // fixed rule: x right, y up in the image
  if (!chosen && hint) predictedAxes(*hint, &x_ref, &y_ref);
  if (!chosen) {
    double best = -std::numeric_limits<double>::infinity();
    for (const auto& c : candidates) {
      const cv::Point2f x_dir = unit(c.points[cols - 1] - c.points[0]);
      const cv::Point2f y_dir = unit(c.points[(rows - 1) * cols] - c.points[0]);
      const double score = x_dir.dot(x_ref) + y_dir.dot(y_ref);
      if (score > best) best = score, chosen = &c;
    }
  }
  observation->image_points = chosen->points;
  observation->point_ids.resize(n);
  for (int i = 0; i < n; ++i) observation->point_ids[i] = i;
  return true;
}

namespace {

/// Half-size of the corner refinement window: as large as the grid allows (more pixels, less
/// noise) without reaching the neighbouring corners, at most 5 px.
int refinementHalfWindow(const std::vector<cv::Point2f>& corners, int cols) {
  double spacing = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < corners.size(); ++i) {
    if (static_cast<int>((i + 1) % cols) == 0) continue;  // end of a row
    const cv::Point2f d = corners[i + 1] - corners[i];
    spacing = std::min(spacing, static_cast<double>(std::sqrt(d.dot(d))));
  }
  return std::max(2, std::min(5, static_cast<int>(spacing / 2.0) - 1));
}

/// "8 x 6": the larger count first, so that a board seen turned reads as the file's.
std::string cornerCountText(int a, int b) {
  return std::to_string(std::max(a, b)) + " x " + std::to_string(std::min(a, b));
}

/// The box around `points` grown by `margin` of their extent on each side, within the image.
cv::Rect searchBox(const std::vector<cv::Point2f>& points, double margin, const cv::Size& image) {
  const cv::Rect box = cv::boundingRect(points);
  const int grow_x = static_cast<int>(std::ceil(margin * box.width));
  const int grow_y = static_cast<int>(std::ceil(margin * box.height));
  const cv::Rect grown(box.x - grow_x, box.y - grow_y, box.width + 2 * grow_x,
                       box.height + 2 * grow_y);
  return grown & cv::Rect(0, 0, image.width, image.height);
}

bool detectCheckerboard(const cv::Mat& mono8, const TargetDescription& t, bool subpixel,
                        const std::vector<cv::Point2f>* near_points,
                        std::vector<cv::Point2f>* corners, std::string* mismatch) {
  const cv::Size size(t.cols, t.rows);
  constexpr int kClassicFlags = cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
  // 0. Near a recent detection first (a camera in motion: 1.9 -> 0.8 ms per 640x480 frame of
  //    the waving simulation, the same refined corners).
  bool found = false;
  if (near_points && near_points->size() >= 2) {
    const cv::Rect box = searchBox(*near_points, TargetDetector::kSearchBoxMargin, mono8.size());
    if (box.area() > 0 && box.area() < mono8.size().area()) {
      found = cv::findChessboardCorners(mono8(box), size, *corners, kClassicFlags);
      if (found) {
        for (cv::Point2f& c : *corners) c += cv::Point2f(box.tl());
      }
    }
  }
  // 1. The classic detector without its adaptive-threshold search, after the fast rejection of
  //    frames without a board: a few ms when the board is plainly in view.
  if (!found) found = cv::findChessboardCorners(mono8, size, *corners, kClassicFlags);
  // 2. The sector-based detector (blur, strong perspective, uneven light), allowed to find a
  //    board larger than the file's. The classic detector's adaptive search is not used: on a
  //    board of another size than the file's it took 3-4 s per frame to fail (measured on a
  //    640x480 frame of an 8x6 board with a 7x6 file), this path 0.3-0.5 s.
  if (!found) {
    cv::Mat meta;
    std::vector<cv::Point2f> sb;
    if (!cv::findChessboardCornersSB(mono8, size, sb,
                                     cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_LARGER, meta)) {
      return false;
    }
    const bool no_meta = meta.empty();  // sizes unknown: the point count decides
    const bool same = no_meta ? sb.size() == static_cast<std::size_t>(t.cols) * t.rows
                              : meta.cols == t.cols && meta.rows == t.rows;
    const bool turned = !no_meta && meta.cols == t.rows && meta.rows == t.cols;
    if (turned && !same) {
      // The file's board, found turned: its corners again in the row order labelGrid expects.
      if (!cv::findChessboardCornersSB(mono8, size, sb, cv::CALIB_CB_NORMALIZE_IMAGE)) return false;
    } else if (!same) {
      if (mismatch && !no_meta) {
        *mismatch = "a checkerboard with " + cornerCountText(meta.cols, meta.rows) +
                    " inner corners is in view; the target file describes " +
                    cornerCountText(t.cols, t.rows) +
                    " (targetCols / targetRows count inner corners)";
      }
      return false;
    }
    *corners = std::move(sb);
  }
  if (subpixel) {
    const int half = refinementHalfWindow(*corners, t.cols);
    cv::cornerSubPix(mono8, *corners, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 100, 1e-4));
  }
  return true;
}

bool detectCircleGrid(const cv::Mat& mono8, const TargetDescription& t,
                      std::vector<cv::Point2f>* centres) {
  const int flags = t.asymmetric ? cv::CALIB_CB_ASYMMETRIC_GRID : cv::CALIB_CB_SYMMETRIC_GRID;
  // The default grid finder fails on some oblique, rolled views where the clustering one works.
  return cv::findCirclesGrid(mono8, cv::Size(t.cols, t.rows), *centres, flags) ||
         cv::findCirclesGrid(mono8, cv::Size(t.cols, t.rows), *centres,
                             flags | cv::CALIB_CB_CLUSTERING);
}

}  // namespace

bool TargetDetector::detect(const cv::Mat& mono8, TargetObservation* observation,
                            const Eigen::Matrix3d* R_target_cam_hint,
                            const std::vector<cv::Point2f>* near_points) const {
  if (!observation || mono8.empty() || mono8.type() != CV_8UC1) return false;
  observation->image_points.clear();
  observation->point_ids.clear();
  observation->mismatch.clear();
  switch (target_.type) {
    case TargetDescription::Type::kCheckerboard: {
      std::vector<cv::Point2f> corners;
      if (!detectCheckerboard(mono8, target_, settings_.subpixel, near_points, &corners,
                              &observation->mismatch)) {
        return false;
      }
      if (!labelGrid(mono8, corners, target_, R_target_cam_hint, observation)) return false;
      break;
    }
    case TargetDescription::Type::kCircleGrid: {
      std::vector<cv::Point2f> centres;
      if (!detectCircleGrid(mono8, target_, &centres)) return false;
      if (!labelGrid(mono8, centres, target_, R_target_cam_hint, observation)) return false;
      break;
    }
    case TargetDescription::Type::kAprilGrid:
      if (!detectAprilGrid(mono8, observation)) return false;
      break;
  }
  return static_cast<int>(observation->image_points.size()) >= settings_.min_points;
}

std::vector<Eigen::Matrix3d> TargetDetector::symmetries() const {
  std::vector<Eigen::Matrix3d> out;
  if (target_.type == TargetDescription::Type::kAprilGrid) return out;
  const int n = target_.numPoints();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) centre += target_.point(i);
  centre /= n;
  const double spacing = std::max(target_.col_spacing_m, target_.row_spacing_m);
  for (int quarter = 1; quarter < 4; ++quarter) {
    const Eigen::Matrix3d S =
        Eigen::AngleAxisd(quarter * M_PI / 2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    // The point pattern must map onto itself ...
    bool invariant = true;
    for (int i = 0; i < n && invariant; ++i) {
      const Eigen::Vector3d q = S * (target_.point(i) - centre) + centre;
      bool hit = false;
      for (int k = 0; k < n && !hit; ++k) hit = (target_.point(k) - q).norm() < 1e-3 * spacing;
      invariant = hit;
    }
    if (!invariant) continue;
    // ... and, on a checkerboard, the square colours too: colour = parity of the square's
    // lower-left corner indices; a quarter turn changes that parity by `rows`, a half turn by `cols
    // + rows`.
    if (target_.type == TargetDescription::Type::kCheckerboard) {
      const int parity_change = quarter == 2 ? target_.cols + target_.rows : target_.rows;
      if (parity_change % 2 != 0) continue;
    }
    out.push_back(S);
  }
  return out;
}

bool TargetDetector::detectAprilGrid(const cv::Mat& mono8, TargetObservation* observation) const {
  std::vector<int> ids;
  std::vector<std::vector<cv::Point2f>> corners;
  cv::aruco::detectMarkers(mono8, impl_->dictionary, corners, ids, impl_->parameters);
  const int num_tags = target_.cols * target_.rows, grid_cols = 2 * target_.cols;
  std::vector<cv::Point2f> points;
  std::vector<int> point_ids;
  std::vector<bool> seen(num_tags, false);
  for (std::size_t m = 0; m < ids.size(); ++m) {
    const int id = ids[m];
    if (id < 0 || id >= num_tags || seen[id]) continue;  // not part of this grid, or twice
    seen[id] = true;
    const int row = id / target_.cols, col = id % target_.cols;
    // OpenCV's corner k of a DICT_APRILTAG_36h11 marker, in the upright tag of Kalibr's print
    // (OpenCV's marker frame is turned by 180 degrees against it): 0 lower right, 1 lower left,
    // 2 upper left, 3 upper right; (i, j) = (upper, right).
    static const int kI[4] = {0, 0, 1, 1}, kJ[4] = {1, 0, 0, 1};
    for (int k = 0; k < 4; ++k) {
      points.push_back(corners[m][k]);
      point_ids.push_back((2 * row + kI[k]) * grid_cols + 2 * col + kJ[k]);
    }
  }
  if (points.size() < 16) return false;  // fewer than 4 tags: too little for a reliable pose
  // Kalibr's grid puts a black square at every tag corner: the corners are checkerboard-like
  // saddle points that cornerSubPix locates better than the tag's edge fit.
  cv::cornerSubPix(mono8, points, cv::Size(3, 3), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 40, 0.001));
  observation->image_points = points;
  observation->point_ids = point_ids;
  return true;
}

}  // namespace camera_imu_alignment
