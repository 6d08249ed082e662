// The camera's rotation between two views of a natural scene: SIFT features with bearings,
// mutual ratio-test matching, and the choice between the rotation-only and the general model
// (scene_geometry.h) by GRIC.
#include "camera_imu_alignment/vision/scene_rotation.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <tuple>
#include <utility>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "scene_geometry.h"
#include "scene_match_refinement.h"

namespace camera_imu_alignment {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
/// The general model refined from a prediction replaces RANSAC's when it keeps at least this share
/// of its inliers (the two solutions of a near-planar view explain about the same matches).
constexpr double kSeededInlierShare = 0.9;
/// OpenCV's SIFT finds keypoints in the image upsampled 2x (bilinear, pixel centres at integer
/// coordinates) and halves their coordinates, which puts them a quarter pixel right of and below
/// the image's own pixel grid. Uncorrected, the offset acts as a principal point error: 0.0023 deg
/// on test_scene_rotation's rendered 6 deg pair, normalised error 118 (corrected: 0.0004 deg, 5.8).
constexpr float kSiftOffsetPx = 0.25f;

/// Matches (from index, to index) whose best match passes Lowe's ratio test and is mutual (the
/// `to` descriptor's best match in `from` is the same feature). Exhaustive: all squared distances
/// at once from one matrix product, |a|^2 + |b|^2 - 2 a.b (serves both directions; a third of the
/// time of two brute-force k-nearest-neighbour passes).
std::vector<std::pair<int, int>> mutualRatioMatches(const cv::Mat& from, const cv::Mat& to,
                                                    double ratio) {
  std::vector<std::pair<int, int>> matches;
  if (from.rows < 2 || to.rows < 2 || from.cols != to.cols || from.type() != CV_32F ||
      to.type() != CV_32F || !from.isContinuous() || !to.isContinuous()) {
    return matches;
  }
  using RowMajor = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Map<const RowMajor> A(from.ptr<float>(), from.rows, from.cols);
  const Eigen::Map<const RowMajor> B(to.ptr<float>(), to.rows, to.cols);
  Eigen::MatrixXf d2 = -2.0f * (A * B.transpose());
  d2.colwise() += A.rowwise().squaredNorm();
  d2.rowwise() += B.rowwise().squaredNorm().transpose();
  // Per `from` feature (row) the best and second-best `to` distances; per `to` feature (column)
  // the best `from` feature. Column by column: d2 is column-major.
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> best(from.rows, inf), second(from.rows, inf);
  std::vector<int> best_to(from.rows, -1), best_from(to.rows, -1);
  for (int j = 0; j < to.rows; ++j) {
    d2.col(j).minCoeff(&best_from[j]);
    for (int i = 0; i < from.rows; ++i) {
      const float d = d2(i, j);
      if (d < best[i]) {
        second[i] = best[i];
        best[i] = d;
        best_to[i] = j;
      } else if (d < second[i]) {
        second[i] = d;
      }
    }
  }
  const float ratio2 = static_cast<float>(ratio * ratio);
  for (int i = 0; i < from.rows; ++i) {
    if (best_to[i] >= 0 && best[i] < ratio2 * second[i] && best_from[best_to[i]] == i) {
      matches.emplace_back(i, best_to[i]);
    }
  }
  return matches;
}

std::string counts(const SceneFeatures& from, const SceneFeatures& to) {
  std::ostringstream s;
  s << from.bearings.size() << " features at " << from.stamp_s << " s and " << to.bearings.size()
    << " at " << to.stamp_s << " s";
  return s.str();
}

/// `matched`'s positions in the `to` image refined at the full resolution (refine_matches).
void refineMatches(const SceneFeatures& from, const SceneFeatures& to,
                   const SceneRotationSettings& settings, SceneMatches* matched) {
  if (!settings.refine_matches || from.image.empty() || to.image.empty() ||
      from.keypoints.size() != from.bearings.size() || to.keypoints.size() != to.bearings.size())
    return;
  std::vector<cv::Point2f> from_px, to_px;
  for (const auto& [i, j] : matched->indices) {
    from_px.push_back(from.keypoints[static_cast<size_t>(i)].pt);
    to_px.push_back(to.keypoints[static_cast<size_t>(j)].pt);
  }
  std::vector<bool> refined;
  matched->to_px = scene_geometry::refineMatchesAtFullResolution(
      from.image, to.image, from_px, to_px, settings.refine_max_shift_px, &refined);
  matched->refined = static_cast<int>(std::count(refined.begin(), refined.end(), true));
}

/// The views' matches as bearings (result->matches and the counts in `why`); false with
/// result->message set when the intrinsics, the features or the matches do not allow a fit.
bool matchViews(const SceneFeatures& from, const SceneFeatures& to,
                const CameraIntrinsics& intrinsics, const SceneRotationSettings& settings,
                const SceneMatches* given, SceneRotation* result,
                scene_geometry::BearingMatches* matches, std::ostringstream* why) {
  const std::string intrinsics_error = intrinsics.validate();
  if (!intrinsics_error.empty()) {
    result->message = "camera intrinsics unusable: " + intrinsics_error;
    return false;
  }
  if (from.descriptors.rows != static_cast<int>(from.bearings.size()) ||
      to.descriptors.rows != static_cast<int>(to.bearings.size())) {
    result->message = "features inconsistent: descriptors and bearings differ in count";
    return false;
  }
  SceneMatches& matched = result->matched;
  if (given) {
    matched = *given;
  } else {
    matched.indices = mutualRatioMatches(from.descriptors, to.descriptors, settings.ratio_test);
  }
  for (const auto& [i, j] : matched.indices) {
    if (i < 0 || j < 0 || i >= static_cast<int>(from.bearings.size()) ||
        j >= static_cast<int>(to.bearings.size())) {
      result->message = "matches inconsistent with the features: index out of range";
      return false;
    }
  }
  if (!matched.to_px.empty() && matched.to_px.size() != matched.indices.size()) {
    result->message = "matches inconsistent: refined positions and matches differ in count";
    return false;
  }
  if (!given) refineMatches(from, to, settings, &matched);
  result->matches = static_cast<int>(matched.size());
  result->refined_matches = matched.refined;
  matches->fx = intrinsics.K(0, 0);
  matches->fy = intrinsics.K(1, 1);
  std::vector<cv::Point2d> refined_normalised;
  if (!matched.to_px.empty()) refined_normalised = intrinsics.undistortToNormalized(matched.to_px);
  for (size_t k = 0; k < matched.indices.size(); ++k) {
    const auto [i, j] = matched.indices[k];
    matches->from.push_back(from.bearings[static_cast<size_t>(i)]);
    Eigen::Vector3d to_bearing = to.bearings[static_cast<size_t>(j)];
    if (!refined_normalised.empty()) {
      const Eigen::Vector3d ray(refined_normalised[k].x, refined_normalised[k].y, 1.0);
      if (ray.allFinite()) to_bearing = ray.normalized();
    }
    matches->to.push_back(to_bearing);
  }
  *why << counts(from, to) << ", " << result->matches << " matches";
  if (matched.refined > 0) *why << " (" << matched.refined << " refined at full resolution)";
  if (result->matches < settings.min_inliers) {
    result->message = "too few matches (" + why->str() + "; min_inliers " +
                      std::to_string(settings.min_inliers) +
                      "): too little overlap or texture between the views";
    return false;
  }
  return true;
}

/// GRIC's choice between the two models over the matches either explains (gross mismatches say
/// nothing about the model), with the general model's noise as the common sigma: true for the
/// rotation-only model.
bool rotationOnlyChosen(const scene_geometry::ModelFit& rotation,
                        const scene_geometry::ModelFit& general) {
  if (!rotation.found || !general.found) return rotation.found;
  std::vector<bool> counted(rotation.inlier.size());
  for (size_t k = 0; k < counted.size(); ++k) counted[k] = rotation.inlier[k] || general.inlier[k];
  return scene_geometry::gric(rotation, counted, general.sigma_px, 3) <=
         scene_geometry::gric(general, counted, general.sigma_px, 5);
}

/// `fit` (of the model named) as the result, or the reason it is not one.
void takeFit(const scene_geometry::ModelFit& fit, bool rotation_only,
             const SceneRotationSettings& settings, SceneRotation* result,
             std::ostringstream* why) {
  result->inliers = fit.found ? fit.inliers : 0;
  result->second_motion_inliers = fit.found ? fit.second_motion : 0;
  *why << ", " << result->inliers << " inliers";
  if (!fit.found || result->inliers < settings.min_inliers) {
    result->message = "too few inliers (" + why->str() + "; min_inliers " +
                      std::to_string(settings.min_inliers) +
                      "): the views overlap too little, or the matches are wrong (repetitive "
                      "texture, a scene that moved)";
    return;
  }
  if (!fit.cov_rad2.allFinite() || !fit.R_from_to.allFinite()) {
    result->message = "degenerate fit (" + why->str() + "): no covariance";
    return;
  }
  result->model = rotation_only ? SceneMotionModel::kRotationOnly : SceneMotionModel::kGeneral;
  result->R_from_to = fit.R_from_to;
  result->cov_rad2 = fit.cov_rad2;
  result->translation_direction = fit.t_from;
  result->residual_rms_px = fit.sigma_px;
  *why << ", " << (rotation_only ? "rotation only" : "general motion") << ", " << fit.sigma_px
       << " px";
  if (fit.second_motion > 0)
    *why << ", " << fit.second_motion
         << " of them on a second motion with the same rotation (an object moved)";
  result->ok = true;
  result->message = why->str();
}

}  // namespace

const char* toString(SceneProfile profile) {
  switch (profile) {
    case SceneProfile::kFull:
      return "full";
    case SceneProfile::kFast:
      return "fast";
    case SceneProfile::kCustom:
      break;
  }
  return "custom";
}

bool parseSceneProfile(const std::string& word, SceneProfile* profile) {
  for (SceneProfile p : {SceneProfile::kFull, SceneProfile::kFast}) {
    if (word == toString(p)) {
      *profile = p;
      return true;
    }
  }
  return false;
}

void useSceneProfile(SceneProfile profile, SceneFeatureSettings* features,
                     SceneRotationSettings* rotation) {
  if (profile == SceneProfile::kCustom) return;
  const bool fast = profile == SceneProfile::kFast;
  const SceneFeatureSettings full;
  features->image_scale = fast ? 0.5 : full.image_scale;
  features->max_features = fast ? 1000 : full.max_features;
  rotation->refine_matches = fast;
}

SceneProfile sceneProfileOf(const SceneFeatureSettings& features,
                            const SceneRotationSettings& rotation) {
  for (SceneProfile p : {SceneProfile::kFull, SceneProfile::kFast}) {
    SceneFeatureSettings f = features;
    SceneRotationSettings r = rotation;
    useSceneProfile(p, &f, &r);
    if (f.image_scale == features.image_scale && f.max_features == features.max_features &&
        r.refine_matches == rotation.refine_matches) {
      return p;
    }
  }
  return SceneProfile::kCustom;
}

double imageSharpness(const cv::Mat& mono8) {
  if (mono8.empty() || mono8.type() != CV_8UC1) return 0;
  cv::Mat laplacian;
  cv::Laplacian(mono8, laplacian, CV_64F);
  cv::Scalar mean, std_dev;
  cv::meanStdDev(laplacian, mean, std_dev);
  return std_dev[0] * std_dev[0];
}

SceneFeatures extractSceneFeatures(const cv::Mat& mono8, const CameraIntrinsics& intrinsics,
                                   const SceneFeatureSettings& settings, double stamp_s) {
  SceneFeatures features;
  features.stamp_s = stamp_s;
  if (mono8.empty() || mono8.type() != CV_8UC1 || mono8.cols != intrinsics.width ||
      mono8.rows != intrinsics.height || !intrinsics.validate().empty() ||
      settings.max_features <= 0 || !(settings.image_scale > 0 && settings.image_scale <= 1)) {
    return features;
  }
  cv::Mat sift_image = mono8;
  if (settings.image_scale < 1) {
    cv::resize(mono8, sift_image, cv::Size(), settings.image_scale, settings.image_scale,
               cv::INTER_AREA);
  }
  const cv::Ptr<cv::SIFT> sift =
      cv::SIFT::create(settings.max_features, settings.octave_layers, settings.contrast_threshold);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  sift->detectAndCompute(sift_image, cv::noArray(), keypoints, descriptors);
  if (keypoints.empty()) return features;
  // SIFT keeps ties at the response cut: at most max_features, the strongest. Its keypoints come
  // in an order its threads decide, and the order feeds the matching and RANSAC: sorted fully
  // (response, then position, size and angle), the same image gives the same rotation in any run.
  std::vector<int> order(keypoints.size());
  std::iota(order.begin(), order.end(), 0);
  const auto key = [&](int i) {
    const cv::KeyPoint& k = keypoints[i];
    return std::make_tuple(-k.response, k.pt.x, k.pt.y, k.size, k.angle, k.octave);
  };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  order.resize(std::min<size_t>(order.size(), settings.max_features));
  std::vector<cv::Point2f> pixels;
  // Into the full image's pixels (centres at integer coordinates in both images).
  const float scale = static_cast<float>(settings.image_scale);
  const cv::Point2f half(0.5f, 0.5f);
  for (int i : order) {
    keypoints[i].pt =
        (keypoints[i].pt - cv::Point2f(kSiftOffsetPx, kSiftOffsetPx) + half) / scale - half;
    keypoints[i].size /= scale;
    pixels.push_back(keypoints[i].pt);
  }
  const std::vector<cv::Point2d> normalised = intrinsics.undistortToNormalized(pixels);
  for (size_t k = 0; k < order.size(); ++k) {
    const Eigen::Vector3d ray(normalised[k].x, normalised[k].y, 1.0);
    if (!ray.allFinite()) continue;  // outside the distortion model's valid range
    features.keypoints.push_back(keypoints[order[k]]);
    features.descriptors.push_back(descriptors.row(order[k]));
    features.bearings.push_back(ray.normalized());
  }
  features.image = mono8;
  return features;
}

SceneRotation estimateSceneRotation(const SceneFeatures& from, const SceneFeatures& to,
                                    const CameraIntrinsics& intrinsics,
                                    const std::optional<Eigen::Matrix3d>& R_from_to_prediction,
                                    const SceneRotationSettings& settings) {
  SceneRotation result;
  std::ostringstream why;
  scene_geometry::BearingMatches matches;
  if (!matchViews(from, to, intrinsics, settings, nullptr, &result, &matches, &why)) return result;
  const scene_geometry::ModelFit rotation =
      scene_geometry::fitRotationOnly(matches, settings.ransac_threshold_px, R_from_to_prediction);
  scene_geometry::ModelFit general =
      scene_geometry::fitGeneral(matches, settings.ransac_threshold_px, false);
  const bool use_rotation = rotationOnlyChosen(rotation, general);
  if (!use_rotation) {
    general = scene_geometry::fitGeneral(matches, settings.ransac_threshold_px, true);
    // A near-planar view has two essential matrices that explain it about equally well: with a
    // prediction, the one refined from it is taken when it explains nearly as many matches and is
    // nearer the prediction.
    if (R_from_to_prediction && general.found) {
      const scene_geometry::ModelFit seeded = scene_geometry::fitGeneralFrom(
          matches, settings.ransac_threshold_px, *R_from_to_prediction, general.t_from);
      const auto off = [&](const Eigen::Matrix3d& R) {
        return rotationAngle(R_from_to_prediction->transpose() * R);
      };
      if (seeded.found && seeded.inliers >= kSeededInlierShare * general.inliers &&
          off(seeded.R_from_to) < off(general.R_from_to)) {
        general = seeded;
      }
    }
  }
  const scene_geometry::ModelFit& fit = use_rotation ? rotation : general;
  takeFit(fit, use_rotation, settings, &result, &why);
  if (!result.ok) return result;
  if (R_from_to_prediction && settings.max_prediction_difference_deg > 0) {
    const double difference_deg =
        rotationAngle(R_from_to_prediction->transpose() * fit.R_from_to) * kRadToDeg;
    if (difference_deg > settings.max_prediction_difference_deg) {
      std::ostringstream s;
      s << "the rotation is " << difference_deg << " deg from the prediction (more than "
        << settings.max_prediction_difference_deg
        << " deg; repetitive texture or a wrong prediction): " << why.str();
      result.message = s.str();
      result.ok = false;
      return result;
    }
  }
  // The other solutions a near-planar view allows (from the general model's inliers; a
  // rotation-only choice on such a view may be a small translation absorbed as a rotation).
  if (general.found) {
    const double sigma_rad = std::sqrt(std::max(fit.cov_rad2.trace() / 3.0, 0.0));
    const double separation = std::max(3.0 * sigma_rad, 1e-4);
    std::vector<scene_geometry::ModelFit> others = scene_geometry::planarAlternatives(
        matches, general, settings.ransac_threshold_px, separation);
    if (use_rotation) others.insert(others.begin(), general);
    for (const scene_geometry::ModelFit& other : others) {
      // Against the general model's own count (the two models select inliers differently).
      if (other.inliers < settings.alternative_inlier_share * general.inliers) continue;
      if (rotationAngle(other.R_from_to.transpose() * fit.R_from_to) < separation) continue;
      if (!other.cov_rad2.allFinite()) continue;
      result.alternatives.push_back(
          {other.R_from_to, other.cov_rad2, other.inliers, other.sigma_px});
    }
  }
  result.ok = true;
  result.message = why.str();
  return result;
}

SceneRotation estimateSceneRotationNear(const SceneFeatures& from, const SceneFeatures& to,
                                        const CameraIntrinsics& intrinsics,
                                        const Eigen::Matrix3d& R_from_to_near, double gate_px,
                                        const SceneRotationSettings& settings,
                                        const SceneMatches* matched) {
  SceneRotation result;
  std::ostringstream why;
  scene_geometry::BearingMatches matches;
  if (!matchViews(from, to, intrinsics, settings, matched, &result, &matches, &why)) return result;
  const double gate = std::min(gate_px, settings.ransac_threshold_px);
  const scene_geometry::HeldRotationFits fits =
      scene_geometry::fitNearRotation(matches, R_from_to_near, gate);
  const bool use_rotation = rotationOnlyChosen(fits.rotation, fits.general);
  why << ", the rotation held near the prediction (gate " << gate << " px)";
  const scene_geometry::ModelFit& general =
      fits.two_motions.found ? fits.two_motions : fits.general;
  takeFit(use_rotation ? fits.rotation : general, use_rotation, settings, &result, &why);
  return result;
}

}  // namespace camera_imu_alignment
