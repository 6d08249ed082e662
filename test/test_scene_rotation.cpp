// The camera's rotation between two views of a natural scene (vision/scene_rotation.h) against
// independent truth: analytic bearings of random 3-D points with pixel noise and outliers (the
// rotation, the model choice, and over 50 seeds the covariance's honesty), rendered views of a
// texture under a known pure rotation, ViSP's real Franka images against the flange poses and
// ViSP's hand-eye rotation (skipped without the data), and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/scene_rotation.h"
#include "scene_texture.h"
#include "test_helpers.h"
#include "visp_data.h"

namespace camera_imu_alignment {
namespace {

using test::toDeg;

constexpr double kF = 500, kNoisePx = 0.5;
constexpr int kWidth = 640, kHeight = 480;
// Chi-square(3) 99.7 % quantile: a 3-D error "within 3 sigma".
constexpr double kChi2Of3Sigma = 14.16;

CameraIntrinsics syntheticIntrinsics() {
  const double K[9] = {kF, 0, kWidth / 2.0, 0, kF, kHeight / 2.0, 0, 0, 1};
  CameraIntrinsics intrinsics;
  std::string error;
  EXPECT_TRUE(CameraIntrinsics::fromCameraInfo(kWidth, kHeight, K, "", {}, &intrinsics, &error));
  return intrinsics;
}

/// The normalised error e^T cov^-1 e of R_est against R_true, e = Log(R_est^T R_true) (the
/// right perturbation of the result's covariance).
double normalisedError(const SceneRotation& r, const Eigen::Matrix3d& R_true) {
  const Eigen::Vector3d e = logSO3(r.R_from_to.transpose() * R_true);
  return e.dot(r.cov_rad2.inverse() * e);
}

double errorDeg(const SceneRotation& r, const Eigen::Matrix3d& R_true) {
  return toDeg(rotationAngle(r.R_from_to.transpose() * R_true));
}

/// Two views of `points` random points 2-5 m in front of the `from` camera, seen by the `to`
/// camera at R_from_to, t_from (its centre in the `from` frame, m); 0.5 px noise in both images;
/// a fraction `outliers` of the `to` features moved to random pixels. Descriptors: one random
/// vector per point, identical in both views, so the matching is exact and the outliers are
/// geometric.
struct AnalyticViews {
  SceneFeatures from, to;
};

Eigen::Vector3d bearingOfPixel(const Eigen::Vector2d& px) {
  return Eigen::Vector3d((px.x() - kWidth / 2.0) / kF, (px.y() - kHeight / 2.0) / kF, 1)
      .normalized();
}

AnalyticViews analyticViews(std::mt19937_64& rng, const Eigen::Matrix3d& R_from_to,
                            const Eigen::Vector3d& t_from, double outliers, int points,
                            const std::optional<Eigen::Vector4d>& plane = std::nullopt) {
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> noise(0, kNoisePx);
  AnalyticViews v;
  v.from.descriptors = cv::Mat(0, 128, CV_32F);
  v.to.descriptors = cv::Mat(0, 128, CV_32F);
  while (static_cast<int>(v.from.bearings.size()) < points) {
    const Eigen::Vector2d px_from(u(rng) * kWidth, u(rng) * kHeight);
    const Eigen::Vector3d ray = bearingOfPixel(px_from) / bearingOfPixel(px_from).z();
    // On the plane n.p = d (`from` frame) when given, else at a depth of 2-5 m.
    const double depth = plane ? plane->w() / plane->head<3>().dot(ray) : 2 + 3 * u(rng);
    if (!(depth > 0.5)) continue;
    const Eigen::Vector3d p_from = depth * ray;
    const Eigen::Vector3d p_to = R_from_to.transpose() * (p_from - t_from);
    if (p_to.z() < 0.5) continue;
    Eigen::Vector2d px_to(kF * p_to.x() / p_to.z() + kWidth / 2.0,
                          kF * p_to.y() / p_to.z() + kHeight / 2.0);
    if (px_to.x() < 0 || px_to.x() > kWidth || px_to.y() < 0 || px_to.y() > kHeight) continue;
    if (u(rng) < outliers) px_to = Eigen::Vector2d(u(rng) * kWidth, u(rng) * kHeight);
    v.from.bearings.push_back(bearingOfPixel(px_from + Eigen::Vector2d(noise(rng), noise(rng))));
    v.to.bearings.push_back(bearingOfPixel(px_to + Eigen::Vector2d(noise(rng), noise(rng))));
    cv::Mat descriptor(1, 128, CV_32F);
    for (int k = 0; k < 128; ++k) descriptor.at<float>(k) = static_cast<float>(u(rng));
    v.from.descriptors.push_back(descriptor);
    v.to.descriptors.push_back(descriptor);
  }
  return v;
}

struct MonteCarloCase {
  const char* name;
  double baseline_m;
  SceneMotionModel model;
};

TEST(SceneRotation, AnalyticBearingsRecoverRotationModelAndHonestCovariance) {
  const CameraIntrinsics intrinsics = syntheticIntrinsics();
  for (const MonteCarloCase& c :
       {MonteCarloCase{"pure rotation", 0.0, SceneMotionModel::kRotationOnly},
        MonteCarloCase{"0.5 m baseline", 0.5, SceneMotionModel::kGeneral}}) {
    constexpr int kSeeds = 50;
    double sum_nees = 0, max_error_deg = 0;
    int within_3_sigma = 0;
    for (int seed = 0; seed < kSeeds; ++seed) {
      std::mt19937_64 rng(1000 + seed);
      const Eigen::Matrix3d R_from_to =
          test::axisAngle(test::randomUnitVector(rng), (5 + 10 * (seed % 5) / 4.0) * M_PI / 180);
      const Eigen::Vector3d t_from = c.baseline_m * test::randomUnitVector(rng);
      const AnalyticViews v = analyticViews(rng, R_from_to, t_from, 0.3, 300);
      const SceneRotation r =
          estimateSceneRotation(v.from, v.to, intrinsics, std::nullopt, SceneRotationSettings());
      ASSERT_TRUE(r.ok) << c.name << " seed " << seed << ": " << r.message;
      EXPECT_EQ(r.model, c.model) << c.name << " seed " << seed << ": " << r.message;
      // 30 % outliers, a few of which fall near the model by chance: about 210 inliers.
      EXPECT_NEAR(r.inliers, 210, 25) << c.name << " seed " << seed;
      EXPECT_NEAR(r.residual_rms_px, kNoisePx, 0.1) << c.name << " seed " << seed;
      if (c.model == SceneMotionModel::kGeneral) {
        EXPECT_GT(r.translation_direction.dot(t_from.normalized()), 0.99) << c.name << seed;
      }
      const double nees = normalisedError(r, R_from_to);
      if (getenv("CIA_VERBOSE")) {
        std::printf("%s seed %d: %s error %.4f nees %.1f t.t %.4f\n", c.name, seed,
                    r.message.c_str(), errorDeg(r, R_from_to), nees,
                    r.translation_direction.dot(t_from.normalized()));
      }
      sum_nees += nees;
      within_3_sigma += nees < kChi2Of3Sigma;
      max_error_deg = std::max(max_error_deg, errorDeg(r, R_from_to));
    }
    const double mean_nees = sum_nees / kSeeds;
    std::printf(
        "%s: mean normalised error %.2f (chi-square(3): 3), %d/%d within 3 sigma, max error "
        "%.4f deg\n",
        c.name, mean_nees, within_3_sigma, kSeeds, max_error_deg);
    EXPECT_GT(mean_nees, 2.0) << c.name;
    EXPECT_LT(mean_nees, 4.5) << c.name;
    EXPECT_GE(within_3_sigma, 0.95 * kSeeds) << c.name;
    EXPECT_LT(max_error_deg, c.baseline_m > 0 ? 0.3 : 0.05) << c.name;
  }
}

// A wall (one plane 2 m away, tilted 20-40 deg) seen from two places 10-20 cm apart, turned 20-40
// deg: the essential matrix has two solutions that explain the matches about equally. Whichever
// the fit takes, the truth is near one of the chosen rotation and its alternatives (which the gyro
// then chooses between: estimation/camera_link_consensus.h).
TEST(SceneRotation, ANearPlanarViewKeepsItsOtherSolution) {
  const CameraIntrinsics intrinsics = syntheticIntrinsics();
  int wrong_chosen = 0, with_alternatives = 0, near_truth = 0;
  for (int seed = 0; seed < 20; ++seed) {
    std::mt19937_64 rng(7000 + seed);
    std::uniform_real_distribution<double> u(0, 1);
    const Eigen::Matrix3d R_from_to =
        test::axisAngle(test::randomUnitVector(rng), (20 + 20 * u(rng)) * M_PI / 180);
    const Eigen::Vector3d t_from = (0.1 + 0.1 * u(rng)) * test::randomUnitVector(rng);
    const double tilt = (20 + 20 * u(rng)) * M_PI / 180;
    const Eigen::Vector3d normal(std::sin(tilt), 0, std::cos(tilt));
    const AnalyticViews v = analyticViews(rng, R_from_to, t_from, 0.1, 300,
                                          Eigen::Vector4d(normal.x(), 0, normal.z(), 2.0));
    const SceneRotation r =
        estimateSceneRotation(v.from, v.to, intrinsics, std::nullopt, SceneRotationSettings());
    ASSERT_TRUE(r.ok) << "seed " << seed << ": " << r.message;
    double best = errorDeg(r, R_from_to);
    wrong_chosen += best > 0.5;
    with_alternatives += !r.alternatives.empty();
    for (const SceneRotationAlternative& a : r.alternatives) {
      EXPECT_GT(a.inliers, 0) << "seed " << seed;
      EXPECT_TRUE(a.cov_rad2.allFinite());
      best = std::min(best, rad2deg(geodesicDistance(a.R_from_to, R_from_to)));
    }
    if (std::getenv("CIA_VERBOSE")) {
      std::printf("seed %d: chosen %.3f deg off, nearest solution %.3f deg, %zu alternatives\n",
                  seed, errorDeg(r, R_from_to), best, r.alternatives.size());
    }
    near_truth += best < 0.4;
  }
  std::printf(
      "20 planar pairs: %d took a solution over 0.5 deg off, %d have alternatives, %d have one "
      "within 0.4 deg\n",
      wrong_chosen, with_alternatives, near_truth);
  // Measured (2026-11-27): 15 chosen 1.4-4.5 deg off; the nearest solution within 0.03-0.38 deg
  // on 18 (an exact plane is the essential matrix's degenerate case: the refined alternative is
  // near, not at, the truth), 0.56 and 1.42 deg on the other two.
  EXPECT_GE(near_truth, 17);
  EXPECT_GE(with_alternatives, wrong_chosen);
}

/// A robot's motion between two stops: turned 10-30 deg about a random axis, moved 0.5-1 m in a
/// random direction (R_from_to, t_from as estimateSceneRotation's).
std::pair<Eigen::Matrix3d, Eigen::Vector3d> robotPairMotion(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::Matrix3d R_from_to =
      test::axisAngle(test::randomUnitVector(rng), (10 + 20 * u(rng)) * M_PI / 180);
  const Eigen::Vector3d t_from = (0.5 + 0.5 * u(rng)) * test::randomUnitVector(rng);
  return {R_from_to, t_from};
}

// A robot's pair with an object slid between the views: 200 points of the room seen from places
// 0.5-1 m apart, turned 10-30 deg, and 100 points (a third) on an object 2-5 m away that slid
// 2-6 cm between the views (the same rotation, another translation: its points move up to 1.5
// deg, a few pixels, off the room's epipolar lines, less where the slide runs along them). With
// the rotation held 0.1 deg off the truth (the gyro's consensus is about that good) while the
// inliers are chosen, the rotation found is within its 3 sigma of the truth far more often than
// the free fit's. Measured (2026-11-27): held 17 of 20 within 3 sigma, free 10; the held fits
// kept the object's matches that lie within the gate of the room's motion (199-299 inliers). With
// the second motion fitted (2026-11-28): 19 of 20 within 3 sigma, 17 fitted as two motions (62-100
// matches outside the room's gate; the second motion's inliers also take room points with little
// parallax, which lie within both gates), every error below 0.2 deg.
TEST(SceneRotation, TwoMotionsSharingTheRotationAreNotAveragedWithTheRotationHeld) {
  const CameraIntrinsics intrinsics = syntheticIntrinsics();
  int held_within = 0, free_within = 0, two_motions = 0;
  constexpr int kSeeds = 20;
  for (int seed = 0; seed < kSeeds; ++seed) {
    std::mt19937_64 rng(9100 + seed);
    std::uniform_real_distribution<double> u(0, 1);
    const auto [R_from_to, t_from] = robotPairMotion(rng);
    const Eigen::Vector3d slide = (0.02 + 0.04 * u(rng)) * test::randomUnitVector(rng);
    AnalyticViews v = analyticViews(rng, R_from_to, t_from, 0.0, 200);
    const AnalyticViews moved = analyticViews(rng, R_from_to, t_from + slide, 0.0, 100);
    v.from.descriptors.push_back(moved.from.descriptors);
    v.to.descriptors.push_back(moved.to.descriptors);
    v.from.bearings.insert(v.from.bearings.end(), moved.from.bearings.begin(),
                           moved.from.bearings.end());
    v.to.bearings.insert(v.to.bearings.end(), moved.to.bearings.begin(), moved.to.bearings.end());
    const Eigen::Matrix3d R_near = R_from_to * expSO3(test::randomUnitVector(rng) * deg2rad(0.1));
    const SceneRotation held =
        estimateSceneRotationNear(v.from, v.to, intrinsics, R_near, 1.5, SceneRotationSettings());
    const SceneRotation free =
        estimateSceneRotation(v.from, v.to, intrinsics, std::nullopt, SceneRotationSettings());
    ASSERT_TRUE(held.ok) << "seed " << seed << ": " << held.message;
    EXPECT_NE(held.message.find("held near the prediction"), std::string::npos) << held.message;
    held_within += normalisedError(held, R_from_to) < kChi2Of3Sigma;
    free_within += free.ok && normalisedError(free, R_from_to) < kChi2Of3Sigma;
    two_motions += held.second_motion_inliers > 0;
    if (std::getenv("CIA_VERBOSE")) {
      std::printf(
          "seed %d: held %.3f deg (nees %.1f, %d inliers, %d on the second motion), free %.3f deg "
          "(nees %.1f)\n",
          seed, errorDeg(held, R_from_to), normalisedError(held, R_from_to), held.inliers,
          held.second_motion_inliers, errorDeg(free, R_from_to), normalisedError(free, R_from_to));
    }
  }
  std::printf(
      "%d pairs with a slid object: within 3 sigma held %d, free %d; %d fitted as two motions\n",
      kSeeds, held_within, free_within, two_motions);
  EXPECT_GE(held_within, 17);
  EXPECT_GE(held_within, free_within + 4);
  EXPECT_GE(two_motions, 15);
}

// The control of the above: the room alone (300 points, 10 % mismatches), held 0.3 deg off the
// truth (2.6 px at f = 500, beyond the 1.5 px gate: the room's points fall outside the first
// translation's gate as a second motion's would). A room split in two by the prediction's error
// would give two near-equal translations and a rotation bent towards the prediction: never taken as
// two motions, and the rotation within its 3 sigma as often as the held fit of one motion is.
TEST(SceneRotation, ARoomAloneIsNotSplitIntoTwoMotions) {
  const CameraIntrinsics intrinsics = syntheticIntrinsics();
  int within = 0, two_motions = 0;
  constexpr int kSeeds = 20;
  for (int seed = 0; seed < kSeeds; ++seed) {
    std::mt19937_64 rng(9200 + seed);
    const auto [R_from_to, t_from] = robotPairMotion(rng);
    const AnalyticViews v = analyticViews(rng, R_from_to, t_from, 0.1, 300);
    const Eigen::Matrix3d R_near = R_from_to * expSO3(test::randomUnitVector(rng) * deg2rad(0.3));
    const SceneRotation held =
        estimateSceneRotationNear(v.from, v.to, intrinsics, R_near, 1.5, SceneRotationSettings());
    ASSERT_TRUE(held.ok) << "seed " << seed << ": " << held.message;
    two_motions += held.second_motion_inliers > 0;
    within += normalisedError(held, R_from_to) < kChi2Of3Sigma;
    if (std::getenv("CIA_VERBOSE")) {
      std::printf("seed %d: %.3f deg (nees %.1f), %s\n", seed, errorDeg(held, R_from_to),
                  normalisedError(held, R_from_to), held.message.c_str());
    }
  }
  std::printf("%d static pairs held 0.3 deg off: %d within 3 sigma, %d taken as two motions\n",
              kSeeds, within, two_motions);
  EXPECT_EQ(two_motions, 0);
  EXPECT_GE(within, 17);
}

// Known limitation, measured, not asserted (run with --gtest_also_run_disabled_tests): baselines of
// 0.5-10 cm at 2-5 m depth. There a translation shifts every point by about |t| / depth, which the
// rotation-only model takes for a rotation and GRIC cannot tell apart until the depth spread makes
// the parallax uneven; the general model, chosen from about 2 cm, marginalises a translation
// direction its data barely determine. Measured (50 seeds each, 300 points, 30 % outliers;
// 2026-11-27 after recoverPose's cheirality was extended to every depth, which lets the general
// model be found at small baselines; the earlier counts in brackets):
//   baseline   general chosen   mean normalised error (rotation-only / general)   max error
//   0.5 cm      0/50            167 / -                                           0.09 deg
//   1 cm        2/50            575 / 81                                          0.17 deg
//   2 cm       19/50 (12)       1892 / 157                                        0.59 deg
//   5 cm       43/50 (38)       4689 / 35                                         0.78 deg
//   10 cm      50/50            - / 9.4                                           0.30 deg
// (0 and 50 cm: honest, the test above.) A hand-held rig moves this much between rests; in the
// joint estimate the links' excess noise, measured on the recording, covers it
// (estimation/camera_excess.h).
TEST(SceneRotation, DISABLED_SmallBaselinesMeasured) {
  const CameraIntrinsics intrinsics = syntheticIntrinsics();
  for (double baseline_m : {0.005, 0.01, 0.02, 0.05, 0.1}) {
    double sum_nees[2] = {0, 0}, max_error_deg = 0;
    int count[2] = {0, 0};
    for (int seed = 0; seed < 50; ++seed) {
      std::mt19937_64 rng(5000 + seed);
      const Eigen::Matrix3d R_from_to = test::axisAngle(test::randomUnitVector(rng), 0.15);
      const Eigen::Vector3d t_from = baseline_m * test::randomUnitVector(rng);
      const AnalyticViews v = analyticViews(rng, R_from_to, t_from, 0.3, 300);
      const SceneRotation r =
          estimateSceneRotation(v.from, v.to, intrinsics, std::nullopt, SceneRotationSettings());
      if (!r.ok) continue;
      const int k = r.model == SceneMotionModel::kGeneral;
      sum_nees[k] += normalisedError(r, R_from_to);
      ++count[k];
      max_error_deg = std::max(max_error_deg, errorDeg(r, R_from_to));
    }
    std::printf(
        "baseline %.3f m: general chosen %d/%d, mean normalised error %.1f / %.1f "
        "(rotation-only / general), max error %.3f deg\n",
        baseline_m, count[1], count[0] + count[1], count[0] ? sum_nees[0] / count[0] : 0.0,
        count[1] ? sum_nees[1] / count[1] : 0.0, max_error_deg);
  }
}

// Views of the texture at infinity: the pure rotation R_from_to between two orientations.
struct RenderedPair {
  cv::Mat from, to;
  Eigen::Matrix3d R_from_to;
};

RenderedPair renderedPair(uint64_t texture_seed) {
  const cv::Mat texture = test::cornerTexture(1600, 1200, texture_seed);
  const Eigen::Matrix3d K = syntheticIntrinsics().K;
  const Eigen::Matrix3d R_G_from = test::axisAngle(Eigen::Vector3d(0.3, -1, 0.2), 0.05);
  const Eigen::Matrix3d R_G_to = test::axisAngle(Eigen::Vector3d(1, 0.4, -0.5), 0.09);
  RenderedPair pair;
  pair.from = test::renderRotatedView(texture, kF, K, R_G_from, cv::Size(kWidth, kHeight));
  pair.to = test::renderRotatedView(texture, kF, K, R_G_to, cv::Size(kWidth, kHeight));
  pair.R_from_to = R_G_from.transpose() * R_G_to;
  return pair;
}

TEST(SceneRotation, RenderedViewsUnderPureRotation) {
  const CameraIntrinsics intrinsics = syntheticIntrinsics();
  const RenderedPair pair = renderedPair(7);
  const SceneFeatureSettings feature_settings;
  const SceneFeatures from = extractSceneFeatures(pair.from, intrinsics, feature_settings, 1.0);
  const SceneFeatures to = extractSceneFeatures(pair.to, intrinsics, feature_settings, 2.0);
  ASSERT_GT(from.keypoints.size(), 500u);
  ASSERT_LE(from.keypoints.size(), static_cast<size_t>(feature_settings.max_features));
  ASSERT_EQ(from.bearings.size(), from.keypoints.size());
  ASSERT_EQ(from.descriptors.rows, static_cast<int>(from.keypoints.size()));
  // Bearings: unit vectors through the keypoints' pixels (no distortion here).
  const Eigen::Vector3d b = from.bearings[0];
  EXPECT_NEAR(b.norm(), 1.0, 1e-12);
  EXPECT_NEAR(kF * b.x() / b.z() + kWidth / 2.0, from.keypoints[0].pt.x, 1e-3);
  EXPECT_NEAR(kF * b.y() / b.z() + kHeight / 2.0, from.keypoints[0].pt.y, 1e-3);

  const SceneRotation r =
      estimateSceneRotation(from, to, intrinsics, std::nullopt, SceneRotationSettings());
  ASSERT_TRUE(r.ok) << r.message;
  const double error_deg = errorDeg(r, pair.R_from_to), nees = normalisedError(r, pair.R_from_to);
  std::printf(
      "rendered pure rotation (%.2f deg): %s; error %.4f deg, normalised error %.2f, "
      "1-sigma %.4f deg\n",
      toDeg(rotationAngle(pair.R_from_to)), r.message.c_str(), error_deg, nees,
      toDeg(std::sqrt(r.cov_rad2.trace())));
  EXPECT_EQ(r.model, SceneMotionModel::kRotationOnly);
  EXPECT_LT(error_deg, 0.05);
  EXPECT_LT(nees, kChi2Of3Sigma);

  // The fast profile: SIFT on the image halved (1000 features), each match refined at the full
  // resolution. The same features with the matches where they were detected: within 3 sigma too,
  // but further from the truth than the refined ones.
  SceneFeatureSettings halved;
  SceneRotationSettings refine;
  useSceneProfile(SceneProfile::kFast, &halved, &refine);
  ASSERT_EQ(halved.image_scale, 0.5);
  ASSERT_TRUE(refine.refine_matches);
  const SceneFeatures from_halved = extractSceneFeatures(pair.from, intrinsics, halved, 1.0);
  const SceneFeatures to_halved = extractSceneFeatures(pair.to, intrinsics, halved, 2.0);
  const SceneRotation r_refined =
      estimateSceneRotation(from_halved, to_halved, intrinsics, std::nullopt, refine);
  const SceneRotation r_unrefined = estimateSceneRotation(from_halved, to_halved, intrinsics,
                                                          std::nullopt, SceneRotationSettings());
  ASSERT_TRUE(r_refined.ok) << r_refined.message;
  ASSERT_TRUE(r_unrefined.ok) << r_unrefined.message;
  for (const SceneRotation* x : {&r_refined, &r_unrefined}) {
    std::printf("image_scale 0.5, %s: %s; error %.4f deg, normalised error %.2f\n",
                x == &r_refined ? "refined" : "not refined", x->message.c_str(),
                errorDeg(*x, pair.R_from_to), normalisedError(*x, pair.R_from_to));
    EXPECT_LT(normalisedError(*x, pair.R_from_to), kChi2Of3Sigma);
  }
  EXPECT_GE(r_refined.refined_matches, r_refined.matches * 9 / 10) << r_refined.message;
  EXPECT_EQ(r_unrefined.refined_matches, 0);
  EXPECT_LT(errorDeg(r_refined, pair.R_from_to), errorDeg(r_unrefined, pair.R_from_to));

  // An exposure jump between the views (gain 1.25, offset -20): the refinement matches the
  // brightness first, so it still refines nearly every match, as precisely. (Measured with gain
  // 1.4, offset -30, where much of the texture clips: normalised error 13.9, at the bound.)
  cv::Mat brighter;
  pair.to.convertTo(brighter, CV_8UC1, 1.25, -20.0);
  const SceneRotation r_exposed =
      estimateSceneRotation(from_halved, extractSceneFeatures(brighter, intrinsics, halved, 2.0),
                            intrinsics, std::nullopt, refine);
  ASSERT_TRUE(r_exposed.ok) << r_exposed.message;
  std::printf("exposure jump: %s; error %.4f deg, normalised error %.2f\n",
              r_exposed.message.c_str(), errorDeg(r_exposed, pair.R_from_to),
              normalisedError(r_exposed, pair.R_from_to));
  EXPECT_GE(r_exposed.refined_matches, r_exposed.matches * 9 / 10);
  EXPECT_LT(errorDeg(r_exposed, pair.R_from_to), errorDeg(r_unrefined, pair.R_from_to));
  EXPECT_LT(normalisedError(r_exposed, pair.R_from_to), kChi2Of3Sigma);

  // A prediction 10 deg off fails the pair; a close one passes.
  SceneRotationSettings settings;
  const Eigen::Matrix3d R_wrong = pair.R_from_to * test::axisAngle(Eigen::Vector3d::UnitY(), 0.17);
  const SceneRotation flagged = estimateSceneRotation(from, to, intrinsics, R_wrong, settings);
  EXPECT_FALSE(flagged.ok);
  EXPECT_NE(flagged.message.find("from the prediction"), std::string::npos) << flagged.message;
  const Eigen::Matrix3d R_close = pair.R_from_to * test::axisAngle(Eigen::Vector3d::UnitX(), 0.02);
  EXPECT_TRUE(estimateSceneRotation(from, to, intrinsics, R_close, settings).ok);
}

TEST(SceneRotation, BadInputSaysSo) {
  const CameraIntrinsics intrinsics = syntheticIntrinsics();
  const cv::Mat blank(kHeight, kWidth, CV_8UC1, cv::Scalar(90));
  const SceneFeatures none = extractSceneFeatures(blank, intrinsics, SceneFeatureSettings(), 3.0);
  EXPECT_TRUE(none.keypoints.empty());
  EXPECT_EQ(imageSharpness(blank), 0.0);
  EXPECT_TRUE(
      extractSceneFeatures(cv::Mat(), intrinsics, SceneFeatureSettings(), 0).bearings.empty());
  EXPECT_TRUE(extractSceneFeatures(cv::Mat(100, 100, CV_8UC1, cv::Scalar(0)), intrinsics,
                                   SceneFeatureSettings(), 0)
                  .bearings.empty());  // another size than the intrinsics'

  const RenderedPair a = renderedPair(7), b = renderedPair(8);
  const SceneFeatures from = extractSceneFeatures(a.from, intrinsics, SceneFeatureSettings(), 1.0);
  const SceneRotation blank_pair =
      estimateSceneRotation(from, none, intrinsics, std::nullopt, SceneRotationSettings());
  EXPECT_FALSE(blank_pair.ok);
  EXPECT_NE(blank_pair.message.find(" and 0 at 3 s"), std::string::npos) << blank_pair.message;

  const SceneFeatures other = extractSceneFeatures(b.to, intrinsics, SceneFeatureSettings(), 2.0);
  const SceneRotation unrelated =
      estimateSceneRotation(from, other, intrinsics, std::nullopt, SceneRotationSettings());
  std::printf("unrelated textures: %s\n", unrelated.message.c_str());
  EXPECT_FALSE(unrelated.ok);
  EXPECT_NE(unrelated.message.find(std::to_string(unrelated.matches) + " matches"),
            std::string::npos)
      << unrelated.message;
  EXPECT_LT(unrelated.inliers, SceneRotationSettings().min_inliers);

  // A blurred view is less sharp.
  cv::Mat blurred;
  cv::GaussianBlur(a.from, blurred, cv::Size(0, 0), 2.0);
  EXPECT_GT(imageSharpness(a.from), 2 * imageSharpness(blurred));
}

// ViSP's 8 real images of a chessboard on a plain table from a camera on a Franka flange. Truth:
// the flange poses and ViSP's hand-eye rotation, R_ci_cj = R_imu_cam^T R_base_flange_i^T
// R_base_flange_j R_imu_cam (the flange as the IMU). This is close to the worst scene for natural
// features: SIFT finds 190-300 keypoints per image, nearly all on the board, whose repeated corners
// the ratio test rightly rejects as ambiguous; the views differ by 23-168 deg. Measured with the
// default settings: 12-59 matches per pair and at most 34 inliers, so every one of the 28 pairs is
// refused with its counts -- what must not happen is a confident wrong rotation. With min_inliers
// lowered to 15, three pairs give rotations 17-29 deg wrong (wrong but consistent matches on the
// board): min_inliers is what protects. The one pair with enough consistent matches (views 6-7,
// 34 inliers, a turn about the optical axis) lands 0.53 deg from the truth with a 1-sigma of 0.26
// deg: its normalised error (98) is not honest. A plane seen from 0.4 m leaves the essential
// matrix nearly degenerate, the 34 inliers barely constrain the translation's coupling with the
// rotation, and ViSP's intrinsics carry no distortion (PnP reprojection 0.3-0.55 px); the
// joint estimate must not trust a pair of so few inliers on one plane.
TEST(SceneRotation, VispRealImagesAgainstFlangePoses) {
  CameraIntrinsics intrinsics;
  std::string error;
  ASSERT_TRUE(test::vispIntrinsics(&intrinsics, &error)) << error;
  std::vector<SceneFeatures> features;
  std::vector<Eigen::Matrix3d> R_base_flange;
  for (int i = 1; i <= 8; ++i) {
    const cv::Mat image = cv::imread(
        test::vispDir() + "/franka_image-" + std::to_string(i) + ".png", cv::IMREAD_GRAYSCALE);
    Eigen::Matrix3d R;
    if (image.empty() ||
        !test::readVispFlangeRotation(
            test::vispDir() + "/franka_pose_rPe_" + std::to_string(i) + ".yaml", &R)) {
      GTEST_SKIP() << "ViSP data absent in " << test::vispDir();
    }
    features.push_back(extractSceneFeatures(image, intrinsics, SceneFeatureSettings(), i));
    R_base_flange.push_back(R);
    EXPECT_GT(features.back().keypoints.size(), 150u) << "image " << i;
  }
  const Eigen::Matrix3d R_imu_cam = test::vispCameraImu().transpose();
  SceneRotationSettings permissive;
  permissive.min_inliers = 30;
  for (int i = 0; i < 8; ++i) {
    for (int j = i + 1; j < 8; ++j) {
      const Eigen::Matrix3d R_true =
          R_imu_cam.transpose() * R_base_flange[i].transpose() * R_base_flange[j] * R_imu_cam;
      const SceneRotation r = estimateSceneRotation(features[i], features[j], intrinsics,
                                                    std::nullopt, SceneRotationSettings());
      std::printf("views %d-%d (%.1f deg apart): %s\n", i + 1, j + 1, toDeg(rotationAngle(R_true)),
                  r.message.c_str());
      // Refused (with the counts), or right: never a confident wrong rotation.
      if (r.ok) {
        EXPECT_LT(errorDeg(r, R_true), 0.5) << r.message;
        EXPECT_LT(normalisedError(r, R_true), kChi2Of3Sigma) << r.message;
      } else {
        EXPECT_NE(r.message.find(std::to_string(r.matches) + " matches"), std::string::npos)
            << r.message;
      }
      const SceneRotation loose =
          estimateSceneRotation(features[i], features[j], intrinsics, std::nullopt, permissive);
      if (!loose.ok) continue;
      const double loose_error_deg = errorDeg(loose, R_true);
      std::printf("  min_inliers %d: %s; error %.3f deg, 1-sigma %.3f deg, normalised %.1f\n",
                  permissive.min_inliers, loose.message.c_str(), loose_error_deg,
                  toDeg(std::sqrt(loose.cov_rad2.trace())), normalisedError(loose, R_true));
      EXPECT_LT(loose_error_deg, 0.8) << "views " << i + 1 << "-" << j + 1;
    }
  }
}

}  // namespace
}  // namespace camera_imu_alignment
