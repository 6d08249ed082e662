// Moving objects in the natural scene (the target: with 20 % of the features on moving objects no
// worse than 1.2x the static scene; accuracy, not time). Per seed, one simulated room run with
// --moving-objects (its rests chosen to see the sliding boxes) is fed to the pipeline twice with
// the same IMU samples, rests and image noise: once with the boxes sliding (every frame rendered
// where they are then) and once with them held where they stand at t = 0 (the static scene). Each
// gives R_cam_imu against the simulated truth, its 1-sigma, the chi-square verdict and the matches
// the rotation model rejected (matches - inliers, summed over the links).
//
// The share of the features on moving objects is measured independently of the pipeline: each
// rest's middle frame with the boxes sliding, SIFT (the pipeline's settings), mutual ratio-test
// matches with the 4 rests before it, and each match's feature in the earlier view traced into the
// room (its bearing, the true camera pose): on a sliding box, and on one that moved more than 5 mm
// between the two frames (a match no rigid motion explains).
//
// Usage: bench_scene_moving [room_robot|room_handheld] [seeds] [first seed] [camera rate, Hz]
// [default|fast|halved|fullrefined] (default room_robot 20 100 3 default; the features' profiles
// at profileSettings). Prints one line per seed and the table of BENCHMARKS.md ("Moving
// objects").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <opencv2/features2d.hpp>
#include <optional>
#include <string>
#include <vector>

#include "../test/pipeline_simulation.h"
#include "camera_imu_alignment/simulation/imu_grades.h"
#include "camera_imu_alignment/solve/window_solver.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/scene_rotation.h"

namespace cia = camera_imu_alignment;
namespace sim = camera_imu_alignment::simulation;

namespace {

constexpr int kLinkedRests = 4;     ///< as the pipeline: each rest with the 4 before it
constexpr double kMovedM = 0.005;   ///< a box that slid more than this between two frames
constexpr double kRatioTest = 0.8;  ///< SceneRotationSettings::ratio_test's default

struct Session {
  bool solved = false, consistent = false;
  double error_deg = 0, sigma_norm_deg = 0;
  int links = 0, matches = 0, inliers = 0;
  // The final window's links as the joint estimate gets them, against the truth.
  int window_links = 0, links_beyond = 0, refitted = 0;
  double consensus_scale_deg = 0;
};

struct Share {
  long matches = 0, on_moving = 0, on_moved = 0;
};

/// Mutual ratio-test matches (from index, to index), brute force.
std::vector<std::pair<int, int>> matchFeatures(const cv::Mat& a, const cv::Mat& b) {
  std::vector<std::pair<int, int>> out;
  if (a.rows < 2 || b.rows < 2) return out;
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> ab, ba;
  matcher.knnMatch(a, b, ab, 2);
  matcher.knnMatch(b, a, ba, 1);
  for (const auto& m : ab) {
    if (m.size() < 2 || m[0].distance >= kRatioTest * m[1].distance) continue;
    if (!ba[m[0].trainIdx].empty() && ba[m[0].trainIdx][0].trainIdx == m[0].queryIdx)
      out.emplace_back(m[0].queryIdx, m[0].trainIdx);
  }
  return out;
}

Share measureShare(const sim::SimulationRun& run, const cia::SceneFeatureSettings& features) {
  const sim::SimulationConfig& c = run.config;
  const sim::RoomScene scene = sim::RoomScene::fromConfig(c);
  const sim::SceneRenderer renderer(sim::CameraModel::fromConfig(c), scene, c.supersample,
                                    c.blur_sigma_px);
  const cia::CameraIntrinsics intrinsics = cia::test::simulatedIntrinsics(c);
  std::vector<cia::SceneFeatures> views;
  std::vector<double> times;
  for (const sim::StationaryPose& rest : run.trajectory.poses()) {
    const double t = 0.5 * (rest.start_s + rest.end_s);
    const cv::Mat mono8 =
        sim::ImageRenderer::toMono8(renderer.renderAt(run.trajectory, t),
                                    c.noise_scale * c.pixel_noise_sigma, 7000 + times.size());
    views.push_back(cia::extractSceneFeatures(mono8, intrinsics, features, t));
    times.push_back(t);
  }
  Share share;
  for (size_t b = 1; b < views.size(); ++b) {
    for (size_t a = b > kLinkedRests ? b - kLinkedRests : 0; a < b; ++a) {
      const sim::RigState at_a = run.trajectory.at(times[a]);
      for (const auto& [i, j] : matchFeatures(views[a].descriptors, views[b].descriptors)) {
        (void)j;
        ++share.matches;
        sim::SurfaceHit hit;
        if (!scene.intersect(at_a.p_world_cam, at_a.R_world_cam * views[a].bearings[i], times[a],
                             &hit) ||
            hit.surface < 6)
          continue;
        const sim::SceneBox& box = scene.boxes()[static_cast<size_t>(hit.surface - 6) / 6];
        if (!box.moving()) continue;
        ++share.on_moving;
        share.on_moved += (box.offsetAt(times[b]) - box.offsetAt(times[a])).norm() > kMovedM;
      }
    }
  }
  return share;
}

/// The features' profile (argument 5): "default" or "full" (SIFT on the full image, 1500
/// features, the matches where they were detected), "fast" (SIFT on the image halved, 1000
/// features, each match refined at the full resolution), or the two halves of the difference:
/// "halved" (fast, not refined) and "fullrefined" (default, refined). Empty settings: not a
/// profile.
std::optional<cia::PipelineSettings> profileSettings(const std::string& profile) {
  cia::PipelineSettings settings;
  cia::SceneProfile named = cia::SceneProfile::kFull;
  if (profile == "default") return settings;
  if (cia::parseSceneProfile(profile, &named)) {  // full, fast: the setting scene_profile's
    cia::useSceneProfile(named, &settings.scene_features, &settings.scene_rotation);
  } else if (profile == "halved") {
    cia::useSceneProfile(cia::SceneProfile::kFast, &settings.scene_features,
                         &settings.scene_rotation);
    settings.scene_rotation.refine_matches = false;
  } else if (profile == "fullrefined") {
    settings.scene_rotation.refine_matches = true;
  } else {
    return std::nullopt;
  }
  return settings;
}

Session solve(std::unique_ptr<sim::SimulationRun> run, const cia::PipelineSettings& settings) {
  cia::test::PipelineRun p = cia::test::feedPipeline(std::move(run), settings);
  Session s;
  for (const cia::StationaryPose& pose : p.pipeline->poses()) {
    for (const cia::SceneLinkSummary& link : pose.scene_links) {
      ++s.links;
      s.matches += link.matches;
      s.inliers += link.inliers;
    }
  }
  // The links as measured (before the solve's consensus and refit), and the solve.
  const cia::WindowSnapshot window = p.pipeline->snapshot();
  const cia::WindowSolveOutput solved = cia::WindowSolver(p.pipeline->settings()).solve(window);
  const cia::AlignmentResult& result = solved.result;
  s.refitted = result.joint ? static_cast<int>(result.joint->camera_links_refitted.size()) : 0;
  s.consensus_scale_deg = solved.window.link_consensus.residual_scale_deg;
  const auto trueCamera = [&](int local) {
    const int index = window.pose_indices[static_cast<size_t>(local)];
    for (const cia::StationaryPose& pose : p.pipeline->poses()) {
      if (pose.index == index)
        return p.run->trajectory.at(0.5 * (pose.start_s + pose.end_s)).R_world_cam;
    }
    return Eigen::Matrix3d(Eigen::Matrix3d::Constant(std::nan("")));
  };
  // Beyond chi-square(3) 99.9 % of the truth under their own covariance, as measured.
  const auto beyond = [&](const cia::CameraLink& link) {
    const Eigen::Matrix3d R_true =
        trueCamera(link.from_pose).transpose() * trueCamera(link.to_pose);
    const Eigen::Vector3d e = cia::logSO3(R_true.transpose() * link.R_from_to);
    return e.dot(link.cov_rad2.inverse() * e) > 16.27;
  };
  for (const cia::CameraLink& link : window.joint.camera_links) {
    ++s.window_links;
    s.links_beyond += beyond(link);
  }
  // CIA_BENCH_LINKS=1: each window link against the truth, as measured and fitted again with the
  // rotation held near the estimate's (a diagnosis, not part of the table).
  if (std::getenv("CIA_BENCH_LINKS") && result.joint && window.scene_links &&
      result.joint->camera_orientation_fit.size() == window.joint.poses.size()) {
    const auto describe = [&](const char* what, const cia::CameraLink& link,
                              const Eigen::Matrix3d& R, const Eigen::Matrix3d& cov) {
      const Eigen::Matrix3d R_true =
          trueCamera(link.from_pose).transpose() * trueCamera(link.to_pose);
      const Eigen::Vector3d e = cia::logSO3(R_true.transpose() * R);
      std::printf(" %s %.3f deg (sigma %.3f, chi2 %.1f)", what, cia::rad2deg(e.norm()),
                  cia::rad2deg(std::sqrt(cov.trace())), e.dot(cov.inverse() * e));
    };
    std::printf("  links' excess noise %.3f deg per axis, %zu left out\n",
                cia::rad2deg(std::sqrt(result.joint->camera_link_excess_variance_rad2)),
                result.joint->camera_links_left_out.size());
    for (size_t j = 0; j < window.joint.camera_links.size(); ++j) {
      const cia::CameraLink& link = window.joint.camera_links[j];
      const auto& fit = result.joint->camera_orientation_fit;
      const Eigen::Matrix3d R_fit = fit[static_cast<size_t>(link.from_pose)].transpose() *
                                    fit[static_cast<size_t>(link.to_pose)];
      const auto& left_out = result.joint->camera_links_left_out;
      const bool out =
          std::find(left_out.begin(), left_out.end(), static_cast<int>(j)) != left_out.end();
      const auto& refitted = result.joint->camera_links_refitted;
      const bool refit =
          std::find(refitted.begin(), refitted.end(), static_cast<int>(j)) != refitted.end();
      std::printf(
          "  link %zu (%d->%d)%s%s chi2 %.1f:", j, link.from_pose, link.to_pose,
          out ? " LEFT OUT" : "", refit ? " refitted" : "",
          j < result.joint->camera_link_chi2.size() ? result.joint->camera_link_chi2[j] : -1.0);
      describe("measured", link, link.R_from_to, link.cov_rad2);
      const std::optional<cia::SceneRotation> again =
          window.scene_links->refit(static_cast<int>(j), R_fit);
      if (again && again->ok) {
        describe("held", link, again->R_from_to, again->cov_rad2 + link.undecided_rad2);
        std::printf(" %s, %d of %d inliers, %d second motion",
                    again->model == cia::SceneMotionModel::kGeneral ? "general" : "rotation",
                    again->inliers, again->matches, again->second_motion_inliers);
      }
      const Eigen::Matrix3d R_true =
          trueCamera(link.from_pose).transpose() * trueCamera(link.to_pose);
      const std::optional<cia::SceneRotation> at_truth =
          window.scene_links->refit(static_cast<int>(j), R_true);
      if (at_truth && at_truth->ok) {
        describe("| near the truth", link, at_truth->R_from_to, at_truth->cov_rad2);
        std::printf(" %d second motion", at_truth->second_motion_inliers);
      }
      std::printf("\n");
    }
  }
  s.solved = result.status == cia::SolveStatus::kOk;
  if (!s.solved) return s;
  s.error_deg = cia::rad2deg(cia::geodesicDistance(result.R_cam_imu, p.R_cam_imu_true()));
  s.sigma_norm_deg = result.quality.std_dev_deg.norm();
  s.consistent = result.joint && result.joint->consistent();
  return s;
}

struct Column {
  int seeds = 0, consistent = 0, within = 0;
  double sum_sq = 0;
  long matches = 0, rejected = 0;
  void add(const Session& s) {
    ++seeds;
    matches += s.matches;
    rejected += s.matches - s.inliers;
    if (!s.consistent) return;
    ++consistent;
    sum_sq += s.error_deg * s.error_deg;
    within += s.error_deg < 3.0 * s.sigma_norm_deg;
  }
  double rms() const { return consistent ? std::sqrt(sum_sq / consistent) : 0.0; }
};

}  // namespace

int main(int argc, char** argv) {
  const std::string scenario = argc > 1 ? argv[1] : "room_robot";
  const int seeds = argc > 2 ? std::atoi(argv[2]) : 20;
  const std::uint64_t first = argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 100;
  const double rate_hz = argc > 4 ? std::atof(argv[4]) : 3.0;
  const std::string profile = argc > 5 ? argv[5] : "default";
  const std::optional<cia::PipelineSettings> chosen = profileSettings(profile);
  if (!chosen) {
    std::fprintf(stderr,
                 "bench_scene_moving: profile %s is not one of default, full, fast, halved, "
                 "fullrefined\n",
                 profile.c_str());
    return 2;
  }
  const cia::PipelineSettings& settings = *chosen;
  Column fixed, moving;
  Share share;
  for (int k = 0; k < seeds; ++k) {
    sim::SimulationConfig c;
    c.seed = first + k;
    if (!sim::applyScenario(scenario, &c) || !sim::isRoomMotion(c.motion)) {
      std::fprintf(stderr, "bench_scene_moving: %s is not a room scenario\n", scenario.c_str());
      return 2;
    }
    sim::applyImuGrade(sim::ImuGrade::kConsumer, &c);
    c.camera_rate_hz = rate_hz;
    c.moving_objects = true;
    auto with_moving = std::make_unique<sim::SimulationRun>(c);
    const Share s = measureShare(*with_moving, settings.scene_features);
    share.matches += s.matches;
    share.on_moving += s.on_moving;
    share.on_moved += s.on_moved;
    auto held = std::make_unique<sim::SimulationRun>(c);
    held->config.moving_objects = false;  // same run, the boxes held where they stand at t = 0
    const Session a = solve(std::move(held), settings);
    const Session b = solve(std::move(with_moving), settings);
    fixed.add(a);
    moving.add(b);
    std::printf(
        "%s seed %llu: matches on sliding boxes %.1f %% (moved > 5 mm %.1f %%); static %.4f deg "
        "(1-sigma %.4f, %s, rejected %d of %d); moving %.4f deg (1-sigma %.4f, %s, rejected %d of "
        "%d); window links beyond 99.9 %% of the truth %d of %d (%d fitted again with the "
        "rotation held), consensus scale %.3f deg\n",
        scenario.c_str(), static_cast<unsigned long long>(c.seed),
        s.matches ? 100.0 * s.on_moving / s.matches : 0.0,
        s.matches ? 100.0 * s.on_moved / s.matches : 0.0, a.error_deg, a.sigma_norm_deg,
        a.consistent ? "consistent" : (a.solved ? "INCONSISTENT" : "no answer"),
        a.matches - a.inliers, a.matches, b.error_deg, b.sigma_norm_deg,
        b.consistent ? "consistent" : (b.solved ? "INCONSISTENT" : "no answer"),
        b.matches - b.inliers, b.matches, b.links_beyond, b.window_links, b.refitted,
        b.consensus_scale_deg);
    std::fflush(stdout);
  }
  std::printf(
      "\n%s, seeds %llu-%llu, frames at %.0f Hz; matches on sliding boxes %.1f %%, on "
      "boxes moved > 5 mm between the views %.1f %%\n\n",
      scenario.c_str(), static_cast<unsigned long long>(first),
      static_cast<unsigned long long>(first + seeds - 1), rate_hz,
      share.matches ? 100.0 * share.on_moving / share.matches : 0.0,
      share.matches ? 100.0 * share.on_moved / share.matches : 0.0);
  std::printf("| boxes | consistent | RMS error over them | within 3 sigma | matches rejected |\n");
  std::printf("|---|---|---|---|---|\n");
  for (const auto& [name, col] :
       {std::make_pair("held (static)", &fixed), std::make_pair("sliding", &moving)}) {
    char rms[32] = "-";  // none consistent: no RMS
    if (col->consistent > 0) std::snprintf(rms, sizeof(rms), "%.3f deg", col->rms());
    std::printf("| %s | %d / %d | %s | %d / %d | %ld of %ld (%.1f %%) |\n", name, col->consistent,
                col->seeds, rms, col->within, col->consistent, col->rejected, col->matches,
                col->matches ? 100.0 * col->rejected / col->matches : 0.0);
  }
  return 0;
}
