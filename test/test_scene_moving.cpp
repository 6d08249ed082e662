// Moving objects in the natural scene (issue 26, item 4: people or objects moving in view are
// outliers of the rotation model: rejected, counted). Two rests of the simulator's room with
// sliding boxes (simulate_bag --moving-objects), the second rendered once with the boxes where they
// stood at the first and once with them slid by up to their amplitude: the rotation between the
// views must stay within its 3-sigma of the truth, and the matches on the slid boxes (found
// independently: each match's feature traced into the room with the true pose) must be among the
// rejected ones (matches - inliers). The Monte Carlo over whole sessions is bench_scene_moving
// (BENCHMARKS.md, "Calibration without a board"). Frames: room = world (ENU, m); camera optical.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <opencv2/features2d.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "camera_imu_alignment/simulation/room_scene.h"
#include "camera_imu_alignment/simulation/scene_renderer.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/scene_rotation.h"
#include "pipeline_simulation.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;

/// Mutual ratio-test matches (from index, to index), as SceneRotationSettings' default.
std::vector<std::pair<int, int>> mutualMatches(const cv::Mat& a, const cv::Mat& b, double ratio) {
  std::vector<std::pair<int, int>> out;
  std::vector<std::vector<cv::DMatch>> ab, ba;
  cv::BFMatcher matcher(cv::NORM_L2);
  matcher.knnMatch(a, b, ab, 2);
  matcher.knnMatch(b, a, ba, 1);
  for (const auto& m : ab) {
    if (m.size() == 2 && m[0].distance < ratio * m[1].distance && !ba[m[0].trainIdx].empty() &&
        ba[m[0].trainIdx][0].trainIdx == m[0].queryIdx)
      out.emplace_back(m[0].queryIdx, m[0].trainIdx);
  }
  return out;
}

struct PairOutcome {
  SceneRotation rotation;
  double error_deg = 0, sigma_norm_deg = 0;
  int on_slid_box = 0;  ///< matches whose first feature lies on a box slid > 5 mm between views
};

/// Rests `a` and `b` of `config`'s run, view a with the boxes where they are at `t_a` (s), view b
/// at `t_b` (s).
/// `near_gate_px` > 0: estimateSceneRotationNear with the rotation held at the truth turned by
/// `near_offset_deg` (about a fixed axis) and that gate.
PairOutcome renderedPair(const sim::SimulationConfig& config, int a, int b, double t_a, double t_b,
                         bool predicted = false, double near_gate_px = 0,
                         double near_offset_deg = 0) {
  const sim::SimulationRun run(config);
  const sim::RoomScene scene = sim::RoomScene::fromConfig(config);
  const sim::SceneRenderer renderer(sim::CameraModel::fromConfig(config), scene, config.supersample,
                                    config.blur_sigma_px);
  const sim::StationaryPose& rest_a = run.trajectory.poses()[static_cast<size_t>(a)];
  const sim::StationaryPose& rest_b = run.trajectory.poses()[static_cast<size_t>(b)];
  const CameraIntrinsics intrinsics = test::simulatedIntrinsics(config);
  const double noise = config.noise_scale * config.pixel_noise_sigma;
  const SceneFeatures from = extractSceneFeatures(
      sim::ImageRenderer::toMono8(renderer.render(rest_a.R_world_cam, rest_a.p_world_cam, t_a),
                                  noise, 1),
      intrinsics, SceneFeatureSettings(), t_a);
  const SceneFeatures to = extractSceneFeatures(
      sim::ImageRenderer::toMono8(renderer.render(rest_b.R_world_cam, rest_b.p_world_cam, t_b),
                                  noise, 2),
      intrinsics, SceneFeatureSettings(), t_b);
  PairOutcome out;
  const SceneRotationSettings settings;
  const Eigen::Matrix3d R_true = rest_a.R_world_cam.transpose() * rest_b.R_world_cam;
  // The pipeline's prediction is the gyro's rotation through the window's R_cam_imu: off by a
  // few tenths of a degree.
  const Eigen::Matrix3d R_predicted =
      R_true * expSO3(Eigen::Vector3d(0.3, -0.2, 0.25) * M_PI / 180.0);
  if (near_gate_px > 0) {
    const Eigen::Matrix3d R_near =
        R_true * expSO3(Eigen::Vector3d(0.6, -0.4, 0.5).normalized() * deg2rad(near_offset_deg));
    out.rotation = estimateSceneRotationNear(from, to, intrinsics, R_near, near_gate_px, settings);
  } else {
    out.rotation = estimateSceneRotation(
        from, to, intrinsics,
        predicted ? std::optional<Eigen::Matrix3d>(R_predicted) : std::nullopt, settings);
  }
  out.error_deg = rad2deg(geodesicDistance(out.rotation.R_from_to, R_true));
  out.sigma_norm_deg = rad2deg(std::sqrt(out.rotation.cov_rad2.trace()));
  for (const auto& [i, j] : mutualMatches(from.descriptors, to.descriptors, settings.ratio_test)) {
    (void)j;
    sim::SurfaceHit hit;
    if (!scene.intersect(rest_a.p_world_cam, rest_a.R_world_cam * from.bearings[i], t_a, &hit) ||
        hit.surface < 6)
      continue;
    const sim::SceneBox& box = scene.boxes()[static_cast<size_t>(hit.surface - 6) / 6];
    out.on_slid_box += box.moving() && (box.offsetAt(t_b) - box.offsetAt(t_a)).norm() > 0.005;
  }
  return out;
}

// Measured (2026-11-27, seed 3, rests 0-1, the first sliding box at its furthest): the robot's
// pair with the boxes held is 0.03 deg off (1-sigma norm 0.06); slid, half the matches lie on the
// boxes and RANSAC's consensus is a compromise between the two motions, 28.6 deg off at a 1-sigma
// norm of 0.67 deg (a single pair is not honest here: the prediction check, the IMU's angle check
// and the joint estimate's chi-square screening must catch it). Asserted: the held pair is right
// within its 3 sigma; the slid pair's rejected matches are counted and named; with a prediction
// (the pipeline's once the window has an R_cam_imu; here the true rotation) a slid pair is either
// refused with its counts or within its 3 sigma, never passed on confidently wrong.
TEST(SceneMovingObjects, SlidBoxesAreCountedAndAPredictedPairIsNeverConfidentlyWrong) {
  // The robot's stops only: hand-held pairs of a near-planar view are wrong with the boxes held
  // too (BENCHMARKS.md), which would say nothing about the moving boxes.
  for (const char* scenario : {"room_robot"}) {
    sim::SimulationConfig config;
    config.seed = 3;
    ASSERT_TRUE(sim::applyScenario(scenario, &config));
    config.moving_objects = true;
    // The second view when the first sliding box is furthest out (half its period).
    double t_b = 0.0;
    for (const sim::SceneBox& box : sim::RoomScene::fromConfig(config).boxes()) {
      if (box.moving()) {
        t_b = 0.5 * box.slide_period_s;
        break;
      }
    }
    ASSERT_GT(t_b, 0.0);
    const PairOutcome held = renderedPair(config, 0, 1, 0.0, 0.0);
    const PairOutcome slid = renderedPair(config, 0, 1, 0.0, t_b);
    const PairOutcome predicted = renderedPair(config, 0, 1, 0.0, t_b, true);
    for (const auto& [name, o] : {std::make_pair("held", &held), std::make_pair("slid", &slid),
                                  std::make_pair("slid, predicted", &predicted)}) {
      std::printf(
          "%s seed 3, rests 0-1, boxes %s: %s; %d matches on slid boxes; error %.4f deg, "
          "1-sigma norm %.4f deg\n",
          scenario, name, o->rotation.message.c_str(), o->on_slid_box, o->error_deg,
          o->sigma_norm_deg);
    }
    ASSERT_TRUE(held.rotation.ok) << scenario << ": " << held.rotation.message;
    EXPECT_LT(held.error_deg, 3.0 * held.sigma_norm_deg) << scenario;
    EXPECT_EQ(held.on_slid_box, 0) << scenario;
    // The slid boxes carry a fair share of the matches (the case: 20 %); the matches the
    // model rejects are counted and the message names the counts.
    EXPECT_GT(slid.on_slid_box, slid.rotation.matches / 10) << scenario;
    EXPECT_GT(slid.rotation.matches - slid.rotation.inliers, slid.rotation.matches / 10)
        << scenario;
    EXPECT_NE(slid.rotation.message.find(std::to_string(slid.rotation.matches) + " matches"),
              std::string::npos)
        << slid.rotation.message;
    EXPECT_NE(slid.rotation.message.find(std::to_string(slid.rotation.inliers) + " inliers"),
              std::string::npos)
        << slid.rotation.message;
    EXPECT_TRUE(!predicted.rotation.ok || predicted.error_deg < 3.0 * predicted.sigma_norm_deg)
        << scenario << ": " << predicted.rotation.message << ", " << predicted.error_deg
        << " deg off";
  }
}

/// Calls `pair(config, a, t_a, t_b)` for rests a and a + 1 (a = 0-3) of seeds 1-6 of `scenario`
/// with moving objects, each view at its rest's middle (s).
template <typename Pair>
void forConsecutiveMovingPairs(const char* scenario, const Pair& pair) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    sim::SimulationConfig config;
    config.seed = seed;
    ASSERT_TRUE(sim::applyScenario(scenario, &config));
    config.moving_objects = true;
    const sim::Trajectory trajectory(config);
    for (int a = 0; a < 4; ++a) {
      const double t_a = 0.5 * (trajectory.poses()[a].start_s + trajectory.poses()[a].end_s);
      const double t_b =
          0.5 * (trajectory.poses()[a + 1].start_s + trajectory.poses()[a + 1].end_s);
      pair(config, a, t_a, t_b);
    }
  }
}

// Not run by default (a measurement, about a minute): robot pairs of consecutive rests at their
// middles, the boxes sliding or held where they are at the first: how many are more than 3 sigma
// off the truth.
TEST(SceneMovingObjects, DISABLED_ConsecutiveRobotPairsMeasured) {
  int pairs = 0, off_held = 0, off_slid = 0, refused_held = 0, refused_slid = 0;
  int off_predicted = 0, refused_predicted = 0;
  forConsecutiveMovingPairs("room_robot", [&](const sim::SimulationConfig& config, int a,
                                              double t_a, double t_b) {
    const PairOutcome held = renderedPair(config, a, a + 1, t_a, t_a);
    const PairOutcome slid = renderedPair(config, a, a + 1, t_a, t_b);
    const PairOutcome predicted = renderedPair(config, a, a + 1, t_a, t_b, true);
    refused_predicted += !predicted.rotation.ok;
    off_predicted += predicted.rotation.ok && predicted.error_deg > 3.0 * predicted.sigma_norm_deg;
    std::printf("  predicted: %.3f deg (3 sigma %.3f)%s\n", predicted.error_deg,
                3 * predicted.sigma_norm_deg, predicted.rotation.ok ? "" : " refused");
    ++pairs;
    refused_held += !held.rotation.ok;
    refused_slid += !slid.rotation.ok;
    off_held += held.rotation.ok && held.error_deg > 3.0 * held.sigma_norm_deg;
    off_slid += slid.rotation.ok && slid.error_deg > 3.0 * slid.sigma_norm_deg;
    std::printf(
        "seed %llu rests %d-%d: held %.3f deg (3 sigma %.3f), slid %.3f deg (3 sigma %.3f, "
        "%d of %d matches on slid boxes, %d rejected)\n",
        static_cast<unsigned long long>(config.seed), a, a + 1, held.error_deg,
        3 * held.sigma_norm_deg, slid.error_deg, 3 * slid.sigma_norm_deg, slid.on_slid_box,
        slid.rotation.matches, slid.rotation.matches - slid.rotation.inliers);
  });
  std::printf(
      "%d pairs: held %d refused, %d beyond 3 sigma; slid %d refused, %d beyond 3 sigma; slid "
      "and predicted %d refused, %d beyond 3 sigma\n",
      pairs, refused_held, off_held, refused_slid, off_slid, refused_predicted, off_predicted);
}

// Not run by default (a measurement): the slid pairs of DISABLED_ConsecutiveRobotPairsMeasured (and
// hand-held ones) with the rotation held near the truth while the inliers are chosen
// (estimateSceneRotationNear), at several prediction errors and gates.
TEST(SceneMovingObjects, DISABLED_RotationHeldNearThePredictionMeasured) {
  for (const char* scenario : {"room_robot", "room_handheld"}) {
    for (const auto& [offset_deg, gate_px] : {std::make_pair(0.0, 0.0), std::make_pair(0.1, 1.5),
                                              std::make_pair(0.3, 1.5), std::make_pair(0.3, 3.0)}) {
      // Per pair: the boxes slid, and held where they stood at the first view (the same views).
      int pairs = 0, off = 0, refused = 0, off_held = 0;
      double sum_sq = 0, sum_sq_held = 0;
      forConsecutiveMovingPairs(scenario, [&](const sim::SimulationConfig& config, int a,
                                              double t_a, double t_b) {
        const PairOutcome o = renderedPair(config, a, a + 1, t_a, t_b, false, gate_px, offset_deg);
        const PairOutcome h = renderedPair(config, a, a + 1, t_a, t_a, false, gate_px, offset_deg);
        ++pairs;
        refused += !o.rotation.ok || !h.rotation.ok;
        if (!o.rotation.ok || !h.rotation.ok) return;
        off += o.error_deg > 3.0 * o.sigma_norm_deg;
        off_held += h.error_deg > 3.0 * h.sigma_norm_deg;
        sum_sq += o.error_deg * o.error_deg;
        sum_sq_held += h.error_deg * h.error_deg;
        std::printf(
            "  %s seed %d rests %d: %.3f deg (3 sigma %.3f; boxes held: %.3f, 3 sigma "
            "%.3f), %d on slid, %s; boxes held: %s\n",
            scenario, static_cast<int>(config.seed), a, o.error_deg, 3 * o.sigma_norm_deg,
            h.error_deg, 3 * h.sigma_norm_deg, o.on_slid_box, o.rotation.message.c_str(),
            h.rotation.message.c_str());
      });
      const int counted = std::max(1, pairs - refused);
      std::printf(
          "%s, held %.1f deg off, gate %.1f px: %d pairs, %d refused; slid: %d beyond 3 sigma, RMS "
          "%.3f deg; boxes held: %d beyond 3 sigma, RMS %.3f deg\n",
          scenario, offset_deg, gate_px, pairs, refused, off, std::sqrt(sum_sq / counted), off_held,
          std::sqrt(sum_sq_held / counted));
    }
  }
}

}  // namespace
}  // namespace camera_imu_alignment
