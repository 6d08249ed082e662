// Test harness: one simulated run (camera_imu_alignment_simulation) fed in stamp order, the way
// calibrate_bag and the nodelet feed it, without a bag: to a CalibrationPipeline (pose assembly;
// the estimate is the solve of its final window, solveFinalWindow) or to an OnlineCalibrator
// solving on the caller's thread (the product's path: an estimate after every pose).
#pragma once

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/room_scene.h"
#include "camera_imu_alignment/simulation/scene_renderer.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/solve/window_solver.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/target_description.h"

namespace camera_imu_alignment {
namespace test {

/// Bad samples injected by the harness (every n-th sample; 0 = none) and how many were sent.
struct Injection {
  int nan_imu_every = 0, duplicate_imu_every = 0, backwards_imu_every = 0;
  int nan_mag_every = 0, gauss_mag_every = 0, empty_frame_every = 0;
  double cover_fraction = 0.0;  ///< this much of every frame (from the right) painted grey
};
struct Injected {
  std::uint64_t nan_imu = 0, duplicate_imu = 0, backwards_imu = 0;
  std::uint64_t nan_mag = 0, gauss_mag = 0, empty_frames = 0;
};

/// The estimate from a pipeline's window as it is now (what the online calibrator would solve).
inline AlignmentResult solveFinalWindow(const CalibrationPipeline& pipeline) {
  return solveWindow(pipeline.snapshot(), pipeline.settings());
}

/// A simulated run fed to a CalibrationPipeline (runPipeline, feedPipeline).
struct PipelineRun {
  std::unique_ptr<simulation::SimulationRun> run;
  std::unique_ptr<CalibrationPipeline> pipeline;
  Injected injected;
  Eigen::Matrix3d R_cam_imu_true() const { return run->trajectory.R_cam_imu_final(); }
};

/// A simulated run fed to an OnlineCalibrator solving on the caller's thread (runCalibrator).
struct CalibratorRun {
  std::unique_ptr<simulation::SimulationRun> run;
  std::unique_ptr<OnlineCalibrator> calibrator;
  /// Every on_estimate, in order (shared: the calibrator's callback holds it too).
  std::shared_ptr<std::vector<EstimateEvent>> estimates;
  Injected injected;
  Eigen::Matrix3d R_cam_imu_true() const { return run->trajectory.R_cam_imu_final(); }
};

inline CameraIntrinsics simulatedIntrinsics(const simulation::SimulationConfig& c) {
  CameraIntrinsics intrinsics;
  intrinsics.width = c.width;
  intrinsics.height = c.height;
  intrinsics.K << c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0;
  intrinsics.distortion = CameraIntrinsics::Distortion::kPlumbBob;
  intrinsics.D.assign(c.distortion.begin(), c.distortion.end());
  return intrinsics;
}

inline bool every(std::size_t i, int n) {
  return n > 0 && i % n == static_cast<std::size_t>(n - 1);
}

/// Feeds a simulated run (possibly edited by the test) to `sink`: IMU, magnetometer and rendered
/// frames merged in stamp order, with `injection` bad samples mixed in. The caller calls finish().
inline Injected feedRenderedRun(const simulation::SimulationRun& run, SampleSink* sink,
                                const Injection& injection = {}) {
  namespace sim = simulation;
  const sim::SimulationConfig& c = run.config;
  sink->setCameraIntrinsics(simulatedIntrinsics(c));
  Injected injected;
  const sim::ImageRenderer renderer(sim::CameraModel::fromConfig(c),
                                    sim::makeTargetTexture(c.target, sim::textureTexelFor(c)),
                                    c.supersample, c.blur_sigma_px);
  // Frames while the rig moves are never detected on (detection runs at rest only): they are
  // rendered without supersampling, 9x cheaper, still the target as the camera sees it.
  const sim::ImageRenderer motion_renderer(
      sim::CameraModel::fromConfig(c), sim::makeTargetTexture(c.target, sim::textureTexelFor(c)), 1,
      c.blur_sigma_px);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::size_t next_imu = 0, next_mag = 0;
  auto feedInertialUpTo = [&](double t) {
    while (next_imu < run.imu.size() && run.imu[next_imu].t <= t) {
      const std::size_t i = next_imu++;
      const auto& s = run.imu[i];
      if (every(i, injection.nan_imu_every)) {
        sink->addImu({s.t, Eigen::Vector3d::Constant(nan), s.accel});
        ++injected.nan_imu;
        continue;
      }
      sink->addImu({s.t, s.gyro, s.accel});
      if (every(i, injection.duplicate_imu_every)) {
        sink->addImu({s.t, s.gyro, s.accel});
        ++injected.duplicate_imu;
      }
      if (every(i, injection.backwards_imu_every)) {
        sink->addImu({s.t - 0.5, s.gyro, s.accel});
        ++injected.backwards_imu;
      }
    }
    while (next_mag < run.mag.size() && run.mag[next_mag].t <= t) {
      const std::size_t i = next_mag++;
      const auto& s = run.mag[i];
      if (every(i, injection.nan_mag_every)) {
        sink->addMagnetic({s.t, Eigen::Vector3d(nan, 0.0, 0.0)});
        ++injected.nan_mag;
      } else if (every(i, injection.gauss_mag_every)) {
        sink->addMagnetic({s.t, s.field * 1e4});  // gauss sent as tesla
        ++injected.gauss_mag;
      } else {
        sink->addMagnetic({s.t, s.field});
      }
    }
  };
  // The room scenarios (no board): the room at rest; no frame while moving (without a target the
  // pipeline uses frames at rest only).
  const bool room = sim::isRoomMotion(c.motion);
  std::optional<sim::SceneRenderer> room_renderer;
  if (room) {
    room_renderer.emplace(sim::CameraModel::fromConfig(c), sim::RoomScene::fromConfig(c),
                          c.supersample, c.blur_sigma_px);
  }
  int cached_pose = -1;
  cv::Mat cached;
  for (std::size_t j = 0; j < run.frame_times.size(); ++j) {
    const double t = run.frame_times[j];
    const double stamp = t + c.camera_time_offset_s;
    feedInertialUpTo(stamp);
    if (room) {
      const int pose = run.trajectory.at(t).pose;
      if (pose < 0) continue;
      if (pose != cached_pose || c.moving_objects)
        cached = room_renderer->renderAt(run.trajectory, t);
      cached_pose = pose;
      sink->addFrame(
          {stamp, sim::ImageRenderer::toMono8(cached, c.noise_scale * c.pixel_noise_sigma,
                                              run.frameNoiseSeed(static_cast<long>(j)))});
      continue;
    }
    if (every(j, injection.empty_frame_every)) {
      sink->addFrame({stamp, cv::Mat()});
      ++injected.empty_frames;
      continue;
    }
    const int pose = run.trajectory.at(t).pose;
    cv::Mat grey;
    if (pose >= 0) {
      if (pose != cached_pose) cached = renderer.renderAt(run.trajectory, t);
      cached_pose = pose;
      grey = cached;
    } else {
      grey = motion_renderer.renderAt(run.trajectory, t);
    }
    cv::Mat mono8 = sim::ImageRenderer::toMono8(grey, c.noise_scale * c.pixel_noise_sigma,
                                                run.frameNoiseSeed(static_cast<long>(j)));
    if (injection.cover_fraction > 0.0) {  // the target partly or wholly out of view
      const int covered = static_cast<int>(injection.cover_fraction * mono8.cols);
      mono8(cv::Rect(mono8.cols - covered, 0, covered, mono8.rows)).setTo(cv::Scalar(128));
    }
    sink->addFrame({stamp, mono8});
  }
  feedInertialUpTo(std::numeric_limits<double>::infinity());
  return injected;
}

inline TargetDescription simulatedTarget(const simulation::SimulationConfig& c) {
  if (simulation::isRoomMotion(c.motion)) return TargetDescription{};  // no board: natural scene
  return parseTargetYaml(simulation::targetYaml(c.target), "simulated target");
}

/// Feeds a simulated run to a new pipeline (feedRenderedRun), finished.
inline PipelineRun feedPipeline(std::unique_ptr<simulation::SimulationRun> simulated,
                                const PipelineSettings& settings, const Injection& injection = {}) {
  PipelineRun out;
  out.run = std::move(simulated);
  out.pipeline = std::make_unique<CalibrationPipeline>(simulatedTarget(out.run->config), settings);
  out.injected = feedRenderedRun(*out.run, out.pipeline.get(), injection);
  out.pipeline->finish();
  return out;
}

/// Simulates `config` and feeds it to a new pipeline.
inline PipelineRun runPipeline(const simulation::SimulationConfig& config,
                               const PipelineSettings& settings = {},
                               const Injection& injection = {}) {
  return feedPipeline(std::make_unique<simulation::SimulationRun>(config), settings, injection);
}

/// Simulates `config` and feeds it to a new OnlineCalibrator (default online settings, solving on
/// the caller's thread), finished.
inline CalibratorRun runCalibrator(const simulation::SimulationConfig& config,
                                   const PipelineSettings& settings = {},
                                   const Injection& injection = {}) {
  CalibratorRun out;
  out.run = std::make_unique<simulation::SimulationRun>(config);
  out.estimates = std::make_shared<std::vector<EstimateEvent>>();
  OnlineCallbacks callbacks;
  callbacks.on_estimate = [estimates = out.estimates](const EstimateEvent& e) {
    estimates->push_back(e);
  };
  OnlineSettings online;
  online.threaded = false;
  out.calibrator =
      std::make_unique<OnlineCalibrator>(simulatedTarget(config), settings, online, callbacks);
  out.injected = feedRenderedRun(*out.run, out.calibrator.get(), injection);
  out.calibrator->finish();
  return out;
}

/// The joint estimator's priors for a simulated unit: its grade's spread of the systematic errors
/// (the consumer defaults for the ideal grade, whose errors are zero).
inline JointSettings jointSettingsFor(const simulation::SimulationConfig& c) {
  JointSettings s;
  const auto& e = c.imu_systematic;
  if (e.gyro_scale_sigma > 0.0) {
    s.priors.gyro_scale = e.gyro_scale_sigma;
    s.priors.gyro_cross_axis = e.gyro_cross_axis_sigma;
    s.priors.accel_scale = e.accel_scale_sigma;
    s.priors.accel_cross_axis = e.accel_cross_axis_sigma;
    s.priors.hard_iron_t = std::max(1e-6, e.mag_hard_iron_sigma);
    s.priors.soft_iron_scale = s.priors.soft_iron_cross = std::max(0.005, e.mag_soft_iron_sigma);
  }
  s.priors.accel_bias_m_s2 = std::max(0.01, 2.0 * c.imu_noise.accelerometer_initial_bias_sigma);
  s.priors.accel_bias_walk_m_s2_sqrt_s = c.imu_noise.accelerometer_random_walk;
  return s;
}

/// Feeds a simulated run to `sink` in stamp order with the camera orientations given (no images):
/// the true ones jittered by `camera_noise_deg` (1-sigma per axis) at 15 Hz. The caller calls
/// finish().
inline void feedSinkWithoutImages(const simulation::SimulationRun& run, SampleSink* sink,
                                  double camera_noise_deg, bool imu_orientation = false,
                                  unsigned noise_seed = 19) {
  const Eigen::Matrix3d R_world_target = run.trajectory.R_world_target();
  std::mt19937 rng(noise_seed);
  std::normal_distribution<double> noise(0.0, deg2rad(camera_noise_deg));
  auto jitter = [&](double scale) {
    return expSO3(scale * Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  };
  std::size_t next_imu = 0, next_mag = 0;
  auto feedUpTo = [&](double t) {
    while (next_imu < run.imu.size() && run.imu[next_imu].t <= t) {
      const auto& s = run.imu[next_imu++];
      ImuSample sample{s.t, s.gyro, s.accel};
      if (imu_orientation) {
        sample.q_world_imu = Eigen::Quaterniond(run.trajectory.at(s.t).R_world_imu() * jitter(2.5));
      }
      sink->addImu(sample);
    }
    while (next_mag < run.mag.size() && run.mag[next_mag].t <= t) {
      const auto& s = run.mag[next_mag++];
      sink->addMagnetic({s.t, s.field});
    }
  };
  for (double t = 0.0; t < run.imu.back().t; t += 1.0 / 15.0) {
    feedUpTo(t);
    CameraFrame frame;
    frame.stamp_s = t;
    frame.R_target_cam = R_world_target.transpose() * run.trajectory.at(t).R_world_cam * jitter(1);
    sink->addFrame(frame);
  }
  feedUpTo(std::numeric_limits<double>::infinity());
}

/// A new pipeline fed with feedSinkWithoutImages, finished.
inline std::unique_ptr<CalibrationPipeline> feedWithoutImages(const simulation::SimulationRun& run,
                                                              const PipelineSettings& settings,
                                                              double camera_noise_deg,
                                                              bool imu_orientation = false,
                                                              unsigned noise_seed = 19) {
  auto pipeline = std::make_unique<CalibrationPipeline>(
      parseTargetYaml(simulation::targetYaml(run.config.target), "target"), settings);
  feedSinkWithoutImages(run, pipeline.get(), camera_noise_deg, imu_orientation, noise_seed);
  pipeline->finish();
  return pipeline;
}

}  // namespace test
}  // namespace camera_imu_alignment
