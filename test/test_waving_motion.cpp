// The `waving` scenario (continuous hand-held motion, no rests) against its definition
// (waving_motion.h, issue 25): angular speed mostly 20-90 deg/s, never still for more than 0.3 s,
// all three axes excited, the board in view in every frame, body rate and acceleration equal to
// the numerical derivatives of orientation and position; and the ROS-free camera orientations of
// SimulationRun (stamps, time offset sign, noise) against the trajectory and the gyro; rendered
// frames in motion show the whole board.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/camera_pose.h"
#include "camera_imu_alignment/vision/target_description.h"
#include "camera_imu_alignment/vision/target_detector.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace simulation {
namespace {

SimulationConfig wavingConfig(std::uint64_t seed) {
  SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(applyScenario("waving", &c));
  return c;
}

TEST(WavingMotion, SpeedMostly20To90DegPerSecondAndNeverStill) {
  for (std::uint64_t seed : {1, 2, 3, 4, 5}) {
    const Trajectory tr(wavingConfig(seed));
    EXPECT_DOUBLE_EQ(tr.duration(), 60.0);
    EXPECT_TRUE(tr.poses().empty());
    const double dt = 0.002;
    int in_range = 0, n = 0;
    double still_s = 0.0, longest_still_s = 0.0, max_speed = 0.0;
    Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
    for (double t = 0.0; t <= tr.duration(); t += dt, ++n) {
      const RigState st = tr.at(t);
      EXPECT_EQ(st.pose, -1);
      const double speed = rad2deg(st.omega_cam.norm());
      max_speed = std::max(max_speed, speed);
      if (speed >= 20.0 && speed <= 90.0) ++in_range;
      still_s = speed < 10.0 ? still_s + dt : 0.0;
      longest_still_s = std::max(longest_still_s, still_s);
      sum_sq += st.omega_cam.cwiseAbs2();
    }
    const double fraction = static_cast<double>(in_range) / n;
    const Eigen::Vector3d rms_deg_s = (sum_sq / n).cwiseSqrt() * 180.0 / kPi;
    EXPECT_GE(fraction, 0.85) << "seed " << seed;
    EXPECT_LT(longest_still_s, 0.3) << "seed " << seed;  // below 10 deg/s
    EXPECT_LT(max_speed, 130.0) << "seed " << seed;
    // Every camera axis excited (rates about x, y and the optical axis z).
    EXPECT_GT(rms_deg_s.minCoeff(), 15.0) << "seed " << seed << ": " << rms_deg_s.transpose();
    std::printf(
        "seed %d: %.0f %% of the time in 20-90 deg/s, longest below 10 deg/s %.3f s, "
        "max %.0f deg/s, rms per axis %.0f %.0f %.0f deg/s\n",
        static_cast<int>(seed), 100.0 * fraction, longest_still_s, max_speed, rms_deg_s.x(),
        rms_deg_s.y(), rms_deg_s.z());
  }
}

TEST(WavingMotion, BoardInViewInEveryFrame) {
  for (std::uint64_t seed : {1, 2, 3, 4, 5}) {
    const SimulationConfig c = wavingConfig(seed);
    const SimulationRun run(c);
    const CameraModel camera = CameraModel::fromConfig(c);
    // The pattern's outermost feature points (the corners of the detected grid).
    const std::vector<Eigen::Vector3d> points = targetPoints(c.target);
    Eigen::Vector3d lo = points.front(), hi = points.front();
    for (const Eigen::Vector3d& p : points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const std::vector<Eigen::Vector3d> corners = {
        {lo.x(), lo.y(), 0.0}, {hi.x(), lo.y(), 0.0}, {lo.x(), hi.y(), 0.0}, {hi.x(), hi.y(), 0.0}};
    double worst_margin_px = 1e9, max_view_deg = 0.0;
    ASSERT_EQ(run.camera_orientations.size(), run.frame_times.size());
    for (const CameraOrientation& o : run.camera_orientations) {
      for (const Eigen::Vector3d& corner : corners) {
        const Eigen::Vector3d p_cam = o.R_target_cam_true.transpose() * (corner - o.p_target_cam);
        ASSERT_GT(p_cam.z(), 0.1);
        const Eigen::Vector2d px = camera.project(p_cam);
        worst_margin_px = std::min(
            {worst_margin_px, px.x(), px.y(), c.width - 1 - px.x(), c.height - 1 - px.y()});
      }
      // Viewing direction off the board's normal (the camera looks along -z_target).
      const Eigen::Vector3d axis = o.R_target_cam_true.col(2);
      max_view_deg = std::max(max_view_deg, rad2deg(std::acos(std::min(1.0, -axis.z()))));
    }
    EXPECT_GT(worst_margin_px, 10.0) << "seed " << seed;
    EXPECT_LE(max_view_deg, 35.0) << "seed " << seed;
    EXPECT_GT(max_view_deg, 20.0) << "seed " << seed;  // the view does sweep
    std::printf("seed %d: board corners at least %.0f px inside the image, view up to %.1f deg\n",
                static_cast<int>(seed), worst_margin_px, max_view_deg);
  }
}

TEST(WavingMotion, RenderedFramesShowTheWholeBoard) {
  // Frames in motion, rendered with a 5 ms exposure (motion blur) and pixel noise: every corner
  // detected and PnP close to the true orientation.
  SimulationConfig c = wavingConfig(2);
  c.motion_blur_exposure_s = 0.005;
  const SimulationRun run(c);
  const ImageRenderer renderer(CameraModel::fromConfig(c),
                               makeTargetTexture(c.target, textureTexelFor(c)), c.supersample,
                               c.blur_sigma_px);
  const TargetDescription target = parseTargetYaml(targetYaml(c.target), "waving target");
  const TargetDetector detector(target);
  CameraIntrinsics intrinsics;
  intrinsics.width = c.width;
  intrinsics.height = c.height;
  intrinsics.K << c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0;
  intrinsics.distortion = CameraIntrinsics::Distortion::kPlumbBob;
  intrinsics.D.assign(c.distortion.begin(), c.distortion.end());
  for (long j = 37; j < static_cast<long>(run.frame_times.size()); j += 113) {
    const CameraOrientation& o = run.camera_orientations[j];
    const cv::Mat mono = ImageRenderer::toMono8(
        renderer.renderAt(run.trajectory, o.capture_s, c.motion_blur_exposure_s),
        c.pixel_noise_sigma, run.frameNoiseSeed(j));
    TargetObservation observation;
    ASSERT_TRUE(detector.detect(mono, &observation, &o.R_target_cam_true)) << "frame " << j;
    EXPECT_EQ(static_cast<int>(observation.image_points.size()), target.numPoints());
    std::string why;
    const auto pose = estimateCameraPose(observation, target, intrinsics, PoseSettings(), &why);
    ASSERT_TRUE(pose) << "frame " << j << ": " << why;
    std::printf("frame %ld: PnP %.3f deg from the truth at %.0f deg/s\n", j,
                test::angleBetweenDeg(pose->R_target_cam, o.R_target_cam_true),
                rad2deg(run.trajectory.at(o.capture_s).omega_cam.norm()));
    EXPECT_LT(test::angleBetweenDeg(pose->R_target_cam, o.R_target_cam_true), 0.1)
        << "frame " << j << ", speed " << rad2deg(run.trajectory.at(o.capture_s).omega_cam.norm())
        << " deg/s";
  }
}

TEST(WavingMotion, RateAndAccelerationAreTheDerivatives) {
  SimulationConfig c = wavingConfig(11);
  c.remount = true;  // the IMU rate includes the mount's own motion
  const Trajectory tr(c);
  for (double t = 0.37; t < 59.0; t += 2.93) {
    const RigState st = tr.at(t);
    const double h = 1e-4;
    const Eigen::Vector3d omega_num =
        logSO3(tr.at(t - h).R_world_cam.transpose() * tr.at(t + h).R_world_cam) / (2.0 * h);
    EXPECT_LT((omega_num - st.omega_cam).norm(), 1e-5) << "t " << t;
    const Eigen::Vector3d omega_imu_num =
        logSO3(tr.at(t - h).R_world_imu().transpose() * tr.at(t + h).R_world_imu()) / (2.0 * h);
    EXPECT_LT((omega_imu_num - st.omega_imu).norm(), 1e-5) << "t " << t;
    const double g = 1e-3;
    const Eigen::Vector3d a_num =
        (tr.at(t + g).p_world_cam - 2.0 * st.p_world_cam + tr.at(t - g).p_world_cam) / (g * g);
    EXPECT_LT((a_num - st.a_world).norm(), 1e-4) << "t " << t;
    EXPECT_TRUE(isRotationMatrix(st.R_world_cam, 1e-9));
  }
}

TEST(WavingMotion, CameraOrientationsFollowTheGyroAndTheOffsetSign) {
  SimulationConfig c = wavingConfig(3);
  c.waving_duration_s = 10.0;
  c.camera_time_offset_s = 0.015;  // image stamp = true capture time + 15 ms
  c.noise_scale = 0.0;             // exact gyro and orientations
  c.camera_rate_hz = 20.0;
  const SimulationRun run(c);
  const Eigen::Matrix3d R_cam_imu = run.trajectory.R_cam_imu_final();
  const YAML::Node truth = YAML::Load(truthYaml(run));
  const double timeshift = truth["timeshift_cam_imu_s"].as<double>();
  EXPECT_DOUBLE_EQ(timeshift, -0.015);
  EXPECT_EQ(truth["stationary_intervals"].size(), 0u);
  EXPECT_EQ(truth["poses"].size(), 0u);
  EXPECT_EQ(truth["motion"].as<std::string>(), "waving");
  ASSERT_EQ(run.camera_orientations.size(), 201u);
  for (const CameraOrientation& o : run.camera_orientations) {
    EXPECT_NEAR(o.stamp_s - o.capture_s, 0.015, 1e-12);
    // Kalibr's sign: the camera's stamp on the IMU's clock (the simulation's) is
    // t_cam + timeshift, the time whose orientation the frame carries.
    const double t_imu = o.stamp_s + timeshift;
    EXPECT_NEAR(test::angleBetweenDeg(o.R_target_cam, run.trajectory.R_world_target().transpose() *
                                                          run.trajectory.at(t_imu).R_world_cam),
                0.0, 1e-6);
  }
  // Relative camera rotation between frames 0.3 s apart = R_cam_imu (gyro integral) R_cam_imu^T,
  // the gyro integrated over the frames' true capture times.
  const auto& frames = run.camera_orientations;
  for (std::size_t j = 0; j + 6 < frames.size(); j += 17) {
    const double ta = frames[j].capture_s, tb = frames[j + 6].capture_s;
    Eigen::Matrix3d R_imu = Eigen::Matrix3d::Identity();
    for (std::size_t i = 0; i + 1 < run.imu.size(); ++i) {
      if (run.imu[i].t < ta - 1e-9 || run.imu[i + 1].t > tb + 1e-9) continue;
      R_imu = R_imu * expSO3(0.5 * (run.imu[i].gyro + run.imu[i + 1].gyro) *
                             (run.imu[i + 1].t - run.imu[i].t));
    }
    const Eigen::Matrix3d R_cam = frames[j].R_target_cam.transpose() * frames[j + 6].R_target_cam;
    EXPECT_LT(test::angleBetweenDeg(R_cam, R_cam_imu * R_imu * R_cam_imu.transpose()), 0.005)
        << "frames " << j << ", " << j + 6;
  }
}

TEST(WavingMotion, CameraOrientationNoiseHasItsSigma) {
  SimulationConfig c = wavingConfig(5);
  c.camera_pose_noise_deg = 0.05;
  const SimulationRun run(c);
  double sum_sq = 0.0;
  for (const CameraOrientation& o : run.camera_orientations) {
    sum_sq += std::pow(test::angleBetweenDeg(o.R_target_cam, o.R_target_cam_true), 2);
  }
  // The angle of Exp(n), n ~ N(0, sigma^2 I_3): E[angle^2] = 3 sigma^2 (901 frames: +-5 %).
  const double rms = std::sqrt(sum_sq / run.camera_orientations.size());
  EXPECT_NEAR(rms, std::sqrt(3.0) * 0.05, 0.1 * std::sqrt(3.0) * 0.05);
}

TEST(WavingMotion, EveryImuGradeAndTheTruthFileReadBack) {
  for (ImuGrade grade :
       {ImuGrade::kIdeal, ImuGrade::kTactical, ImuGrade::kConsumer, ImuGrade::kNoisy}) {
    SimulationConfig c = wavingConfig(2);
    applyImuGrade(grade, &c);
    c.waving_duration_s = 5.0;
    EXPECT_EQ(validateConfig(c), "");
    const SimulationRun run(c);
    EXPECT_EQ(run.imu.size(), 1001u);
    for (const InertialSample& s : run.imu) ASSERT_TRUE(s.gyro.allFinite() && s.accel.allFinite());
    const std::string path = test::writeTempFile("waving.truth.yaml", truthYaml(run));
    const StoredCalibration stored = readResultYaml(path);
    EXPECT_ROTATION_NEAR_DEG(stored.R_cam_imu, run.trajectory.R_cam_imu_final(), 1e-6);
  }
}

}  // namespace
}  // namespace simulation
}  // namespace camera_imu_alignment
