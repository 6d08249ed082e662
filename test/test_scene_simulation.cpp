// The natural-scene simulator (issue 26): the room's ray casting against independent geometry (a
// rotation-only homography between two renders, analytic ray/plane depths, a box corner), the
// room_robot and room_handheld rests against their specifications, feature counts of the rich
// and texture-poor rooms, and simulate_bag --scenario room_robot end to end. Frames: room = world
// (ENU, m); camera optical (z forward, x right, y down).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

#include "camera_imu_alignment/simulation/room_motion.h"
#include "camera_imu_alignment/simulation/scene_renderer.h"
#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "test_helpers.h"
#include "tool_runner.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;
using test::axisAngle;
using test::toDeg;

sim::SimulationConfig roomConfig(const std::string& scenario, std::uint64_t seed) {
  sim::SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(sim::applyScenario(scenario, &c));
  return c;
}

/// A camera at the default 640 x 480 field of view, scaled down by `scale` (faster renders).
sim::CameraModel camera(double scale) {
  sim::CameraModel cam;
  cam.width = static_cast<int>(640 * scale);
  cam.height = static_cast<int>(480 * scale);
  cam.fx = cam.fy = 500.0 * scale;
  cam.cx = 0.5 * (cam.width - 1);
  cam.cy = 0.5 * (cam.height - 1);
  return cam;
}

/// The camera looking along the room's +x, level: x_cam = -y_room, y_cam = -z_room.
Eigen::Matrix3d lookingAlongX() {
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return R;
}

Eigen::Matrix3d cameraMatrix(const sim::CameraModel& cam) {
  Eigen::Matrix3d K;
  K << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1;
  return K;
}

/// Mean |warped - second| over the pixels both views see (2 px inside view 1), divided by the
/// second view's standard deviation there; H maps view 1's pixels to view 2's.
double warpResidual(const cv::Mat& first, const cv::Mat& second, const Eigen::Matrix3d& H) {
  cv::Mat Hcv(3, 3, CV_64F), warped, mask;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Hcv.at<double>(i, j) = H(i, j);
  cv::warpPerspective(first, warped, Hcv, second.size(), cv::INTER_LINEAR);
  cv::Mat inside(first.size(), CV_8U, cv::Scalar(0));
  inside(cv::Rect(2, 2, first.cols - 4, first.rows - 4)).setTo(255);
  cv::warpPerspective(inside, mask, Hcv, second.size(), cv::INTER_NEAREST);
  cv::Mat diff;
  cv::absdiff(warped, second, diff);
  cv::Scalar mean_second, std_second;
  cv::meanStdDev(second, mean_second, std_second, mask);
  EXPECT_GT(cv::countNonZero(mask), second.total() / 2) << "the views should mostly overlap";
  return cv::mean(diff, mask)[0] / std_second[0];
}

TEST(SceneRendering, RotationAboutTheCentreIsTheInfiniteHomography) {
  // Two views from one centre: view 2 = view 1 warped by H = K R_c2_c1 K^-1 wherever both see
  // the scene, whatever the depths. An error in the ray casting (a wrong direction, a wrong
  // nearest surface, texture coordinates that depend on the view) breaks this.
  const sim::SimulationConfig config = roomConfig("room_handheld", 5);
  const sim::SceneRenderer renderer(camera(0.5), sim::RoomScene::fromConfig(config), 3, 0.6);
  const Eigen::Vector3d centre(3.0, 2.5, 1.4);  // the room's free middle
  const Eigen::Matrix3d R1 = lookingAlongX() * axisAngle(Eigen::Vector3d(1, 0, 0), -0.2);
  const Eigen::Matrix3d R2 = R1 * axisAngle(Eigen::Vector3d(0.3, 1.0, 0.4), 0.25);
  const cv::Mat first = renderer.render(R1, centre), second = renderer.render(R2, centre);
  const Eigen::Matrix3d K = cameraMatrix(renderer.camera());
  const Eigen::Matrix3d H = K * R2.transpose() * R1 * K.inverse();
  const double residual = warpResidual(first, second, H);
  // 0.5 deg off: about 1 px at this focal length.
  const Eigen::Matrix3d R_wrong = axisAngle(Eigen::Vector3d(0, 1, 0), test::kPiTest / 360.0);
  const double wrong = warpResidual(first, second, K * R_wrong * R2.transpose() * R1 * K.inverse());
  std::cout << "homography residual / contrast: " << residual << " (0.5 deg off: " << wrong
            << ")\n";
  EXPECT_LT(residual, 0.1);
  EXPECT_GT(wrong, 3.0 * residual);
}

/// Nearest positive ray parameter of origin + s d against the planes of an axis-aligned box
/// [lo, hi] whose hit point lies on the box's face (inside: the exit; outside: the entry).
double nearestFace(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& lo,
                   const Eigen::Vector3d& hi) {
  double best = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    for (double plane : {lo(a), hi(a)}) {
      const double s = (plane - o(a)) / d(a);
      const Eigen::Vector3d p = o + s * d;
      bool on_face = s > 0.0;
      for (int b = 0; b < 3; ++b) {
        if (b != a) on_face = on_face && p(b) >= lo(b) - 1e-12 && p(b) <= hi(b) + 1e-12;
      }
      if (on_face) best = std::min(best, s);
    }
  }
  return best;
}

TEST(SceneRendering, DepthIsTheAnalyticNearestSurfaceAndBoxCornersAreEdges) {
  const Eigen::Vector3d room(6.0, 5.0, 2.7);
  sim::SceneBox box;
  box.min_m = Eigen::Vector3d(4.0, 2.0, 0.0);
  box.max_m = Eigen::Vector3d(5.0, 3.0, 1.0);
  box.slide_direction = Eigen::Vector3d(-1.0, 0.0, 0.0);
  box.slide_amplitude_m = 0.5;
  box.slide_period_s = 40.0;
  const sim::SceneRenderer renderer(camera(0.5), sim::RoomScene(room, {box}, false, 7), 1, 0.0);
  const sim::CameraModel& cam = renderer.camera();
  const Eigen::Vector3d c(1.0, 2.4, 0.5);
  const Eigen::Matrix3d R = lookingAlongX() * axisAngle(Eigen::Vector3d(0.2, 1.0, 0.1), 0.15);
  for (double t : {0.0, 20.0}) {  // at t = 20 s the box has slid its full 0.5 m towards -x
    const Eigen::Vector3d shift(t > 0.0 ? -0.5 : 0.0, 0.0, 0.0);
    const cv::Mat depth = renderer.depth(R, c, t);
    int on_box = 0;
    for (int v = 3; v < cam.height; v += 17) {
      for (int u = 5; u < cam.width; u += 19) {
        const Eigen::Vector3d ray((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
        const Eigen::Vector3d d = R * ray;
        const double to_room = nearestFace(c, d, Eigen::Vector3d::Zero(), room);
        const double to_box = nearestFace(c, d, box.min_m + shift, box.max_m + shift);
        on_box += to_box < to_room;
        // The ray's z component in the camera is 1: the parameter is the depth.
        ASSERT_NEAR(depth.at<float>(v, u), std::min(to_room, to_box), 1e-4) << u << " " << v;
      }
    }
    EXPECT_GT(on_box, 10) << "some sample rays should meet the box";
    // The upper left corner of the box's face towards the camera: in the image, the face (about
    // 3 m - slide away) below-right of it, the far wall (about 5 m) in the other three quadrants.
    const Eigen::Vector3d corner = Eigen::Vector3d(4.0, 3.0, 1.0) + shift;
    const Eigen::Vector2d px = cam.project(R.transpose() * (corner - c));
    const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
    ASSERT_TRUE(u > 2 && v > 2 && u < cam.width - 3 && v < cam.height - 3) << px.transpose();
    EXPECT_LT(depth.at<float>(v + 2, u + 2), 3.3 + shift.x()) << "corner at " << px.transpose();
    for (const auto& [du, dv] :
         {std::make_pair(-2, -2), std::make_pair(2, -2), std::make_pair(-2, 2)})
      EXPECT_GT(depth.at<float>(v + dv, u + du), 4.5) << "corner at " << px.transpose();
  }
}

/// Signed angle a - b wrapped into (-180, 180] deg.
double angleDifferenceDeg(double a, double b) {
  return toDeg(std::remainder(a - b, 2.0 * test::kPiTest));
}

TEST(SceneTrajectory, RobotStopsMeetTheirSpecification) {
  const Eigen::Matrix3d R_base_cam = sim::robotCameraMount();
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    sim::SimulationConfig config = roomConfig("room_robot", seed);
    config.moving_objects = seed > 5;  // the boxes' slides leave less room to drive
    if (seed > 8) {                    // steeper ground (simulate_bag --robot-tilt-deg 20,35)
      config.robot_min_tilt_deg = 20.0;
      config.robot_max_tilt_deg = 35.0;
    }
    const sim::Trajectory trajectory(config);
    const sim::RoomScene scene = sim::RoomScene::fromConfig(config);
    const sim::CameraModel cam = sim::CameraModel::fromConfig(config);
    const auto& stops = trajectory.poses();
    ASSERT_EQ(stops.size(), 12u);
    double height = -1.0;
    Eigen::Vector3d previous_base = Eigen::Vector3d::Zero();
    double previous_yaw = 0.0;
    for (size_t k = 0; k < stops.size(); ++k) {
      const sim::StationaryPose& s = stops[k];
      SCOPED_TRACE("seed " + std::to_string(seed) + " stop " + std::to_string(k));
      EXPECT_GE(s.end_s - s.start_s, 3.0 - 1e-9);
      EXPECT_LE(s.end_s - s.start_s, 5.0 + 1e-9);
      // The base: the camera's orientation without the mount; its origin on the floor, the
      // camera the same height above it along the base's z at every stop.
      const Eigen::Matrix3d R_world_base = s.R_world_cam * R_base_cam.transpose();
      const double tilt_deg = toDeg(std::acos(R_world_base(2, 2)));
      EXPECT_GE(tilt_deg, config.robot_min_tilt_deg - 1e-6);
      EXPECT_LE(tilt_deg, config.robot_max_tilt_deg + 1e-6);
      const double h = s.p_world_cam.z() / R_world_base(2, 2);
      if (height < 0.0) height = h;
      EXPECT_NEAR(h, height, 1e-9);
      EXPECT_GE(h, 0.3);
      EXPECT_LE(h, 0.5);
      const Eigen::Vector3d base = s.p_world_cam - R_world_base * Eigen::Vector3d(0, 0, h);
      EXPECT_TRUE(scene.floorPointFree(base.x(), base.y(), 0.39));
      // Roughly horizontal: the optical axis within the tilt and the camera's pitch (8 deg) of
      // the horizontal.
      EXPECT_LE(std::abs(toDeg(std::asin(s.R_world_cam(2, 2)))),
                config.robot_max_tilt_deg + sim::kRobotCameraPitchDeg + 1e-6);
      const double yaw = std::atan2(R_world_base(1, 0), R_world_base(0, 0));
      if (k > 0) {
        const double spacing = (base - previous_base).norm();
        EXPECT_GE(spacing, 0.3 - 1e-9);
        EXPECT_LE(spacing, 2.0 + 1e-9);
        const double turn = std::abs(angleDifferenceDeg(yaw, previous_yaw));
        EXPECT_GE(turn, 10.0 - 1e-6);
        EXPECT_LE(turn, 60.0 + 1e-6);
        const sim::StationaryPose& p = stops[k - 1];
        EXPECT_GE(sim::viewOverlap(scene, cam, p.R_world_cam, p.p_world_cam, s.R_world_cam,
                                   s.p_world_cam),
                  sim::kMinViewOverlap);
      }
      previous_base = base;
      previous_yaw = yaw;
    }
  }
}

TEST(SceneTrajectory, HandheldRestsMeetTheirSpecification) {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    sim::SimulationConfig config = roomConfig("room_handheld", seed);
    config.moving_objects = seed > 5;
    const sim::Trajectory trajectory(config);
    const sim::RoomScene scene = sim::RoomScene::fromConfig(config);
    const sim::CameraModel cam = sim::CameraModel::fromConfig(config);
    const auto& rests = trajectory.poses();
    ASSERT_EQ(rests.size(), 12u);
    Eigen::Matrix3d axes = Eigen::Matrix3d::Zero();  // sum of the turns' axis outer products
    for (size_t k = 0; k < rests.size(); ++k) {
      const sim::StationaryPose& s = rests[k];
      SCOPED_TRACE("seed " + std::to_string(seed) + " rest " + std::to_string(k));
      const double distance = sim::medianViewDistance(scene, cam, s.R_world_cam, s.p_world_cam);
      EXPECT_GE(distance, 1.0);
      EXPECT_LE(distance, 3.0);
      if (k == 0) continue;
      const sim::StationaryPose& p = rests[k - 1];
      const Eigen::AngleAxisd turn(p.R_world_cam.transpose() * s.R_world_cam);
      EXPECT_GE(toDeg(turn.angle()), 20.0 - 1e-6);
      EXPECT_LE(toDeg(turn.angle()), 60.0 + 1e-6);
      axes += turn.axis() * turn.axis().transpose();
      EXPECT_LE((s.p_world_cam - p.p_world_cam).norm(), 0.2 + 1e-9);
      EXPECT_GE(
          sim::viewOverlap(scene, cam, p.R_world_cam, p.p_world_cam, s.R_world_cam, s.p_world_cam),
          sim::kMinViewOverlap);
    }
    // Turned about all axes: no axis of the camera frame left out of the turns.
    const Eigen::Vector3d spread =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(axes).eigenvalues();
    EXPECT_GT(spread.minCoeff(), 0.08 * spread.maxCoeff())
        << "seed " << seed;  // >= 0.10 on 150 seeds
  }
}

TEST(SceneTrajectory, ARobotsRemountTurnsTheImuAloneDuringOneDrive) {
  // The room scenarios take the board scenarios' remount (SimulationConfig::remount): the same
  // stops (so the same images), the IMU turned by Exp(v) during the drive into stop n/2 (the
  // default time), seen by the gyro, and the truth file records it.
  sim::SimulationConfig plain = roomConfig("room_robot", 3);
  plain.num_poses = 6;
  plain.noise_scale = 0.0;
  sim::SimulationConfig remounted = plain;
  remounted.remount = true;
  remounted.remount_rotvec_cam = Eigen::Vector3d(0.0, 2.0, 0.0) * test::kPiTest / 180.0;
  const sim::SimulationRun a(plain), b(remounted);
  const auto& stops = b.trajectory.poses();
  ASSERT_EQ(stops.size(), a.trajectory.poses().size());
  for (size_t k = 0; k < stops.size(); ++k) {
    EXPECT_EQ(stops[k].R_world_cam, a.trajectory.poses()[k].R_world_cam) << "stop " << k;
    EXPECT_EQ(stops[k].p_world_cam, a.trajectory.poses()[k].p_world_cam) << "stop " << k;
    EXPECT_EQ(stops[k].start_s, a.trajectory.poses()[k].start_s) << "stop " << k;
  }
  // The 1 s change lies inside the drive from stop 2 to stop 3.
  const double t_remount = b.trajectory.remountTime();
  EXPECT_GT(t_remount - 0.5, stops[2].end_s);
  EXPECT_LT(t_remount + 0.5, stops[3].start_s);
  const Eigen::Matrix3d turn = axisAngle(Eigen::Vector3d::UnitY(), 2.0 * test::kPiTest / 180.0);
  EXPECT_LT(test::angleBetweenDeg(b.trajectory.R_cam_imu_final(),
                                  turn * b.trajectory.R_cam_imu_initial()),
            1e-9);
  for (size_t k = 0; k < stops.size(); ++k) {
    const double t = 0.5 * (stops[k].start_s + stops[k].end_s);
    const Eigen::Matrix3d mount =
        k < 3 ? b.trajectory.R_cam_imu_initial() : b.trajectory.R_cam_imu_final();
    EXPECT_LT(test::angleBetweenDeg(b.trajectory.at(t).R_world_imu(), stops[k].R_world_cam * mount),
              1e-9)
        << "stop " << k;
  }
  // The noise-free gyro from the first stop to the last: the IMU's own turn, remount included.
  Eigen::Matrix3d gyro = Eigen::Matrix3d::Identity();
  const double ta = stops.front().end_s, tb = stops.back().start_s;
  for (size_t i = 0; i + 1 < b.imu.size(); ++i) {
    if (b.imu[i].t < ta || b.imu[i + 1].t > tb) continue;
    const Eigen::Vector3d w =
        0.5 * (b.imu[i].gyro - b.imu[i].gyro_bias + b.imu[i + 1].gyro - b.imu[i + 1].gyro_bias);
    gyro = gyro * test::rotationFromVector(w * (b.imu[i + 1].t - b.imu[i].t));
  }
  const Eigen::Matrix3d imu_turn =
      b.trajectory.at(ta).R_world_imu().transpose() * b.trajectory.at(tb).R_world_imu();
  EXPECT_LT(test::angleBetweenDeg(gyro, imu_turn), 0.02);
  const Eigen::Matrix3d camera_turn =
      stops.front().R_world_cam.transpose() * stops.back().R_world_cam;
  const Eigen::Matrix3d one_mount =
      b.trajectory.R_cam_imu_initial().transpose() * camera_turn * b.trajectory.R_cam_imu_initial();
  EXPECT_NEAR(test::angleBetweenDeg(gyro, one_mount), 2.0, 0.02) << "the gyro sees the remount";
  const YAML::Node truth = YAML::Load(sim::truthYaml(b));
  EXPECT_TRUE(truth["remount"]["enabled"].as<bool>());
  EXPECT_NEAR(truth["remount"]["time_s"].as<double>(), remounted.start_time_s + t_remount, 1e-6);
  EXPECT_TRUE(truth["remount"]["R_cam_imu_before"]["quaternion_xyzw"]);
  EXPECT_FALSE(YAML::Load(sim::truthYaml(a))["remount"]["enabled"].as<bool>());
}

TEST(SceneTrajectory, MovingObjectsAreInViewAndMoveDuringTheRests) {
  for (const char* scenario : {"room_robot", "room_handheld"}) {
    sim::SimulationConfig config = roomConfig(scenario, 2);
    config.moving_objects = true;
    const sim::Trajectory trajectory(config);
    const sim::RoomScene scene = sim::RoomScene::fromConfig(config);
    const sim::CameraModel cam = sim::CameraModel::fromConfig(config);
    int moving_boxes = 0;
    for (const sim::SceneBox& box : scene.boxes()) moving_boxes += box.moving();
    EXPECT_EQ(moving_boxes, 2);
    // Per rest: the share of a 32 x 24 grid of pixels that sees a moving box, and how far the
    // boxes slide during the rest.
    double share_sum = 0.0;
    int rests_sliding = 0;
    for (const sim::StationaryPose& rest : trajectory.poses()) {
      const double t = 0.5 * (rest.start_s + rest.end_s);
      int on_moving = 0;
      for (int r = 0; r < 24; ++r) {
        for (int c = 0; c < 32; ++c) {
          const Eigen::Vector3d ray(((c + 0.5) * 20 - 0.5 - cam.cx) / cam.fx,
                                    ((r + 0.5) * 20 - 0.5 - cam.cy) / cam.fy, 1.0);
          sim::SurfaceHit hit;
          ASSERT_TRUE(scene.intersect(rest.p_world_cam, rest.R_world_cam * ray, t, &hit));
          on_moving += hit.surface >= 6 && scene.boxes()[(hit.surface - 6) / 6].moving();
        }
      }
      share_sum += on_moving / (32.0 * 24.0);
      double slide = 0.0;
      for (const sim::SceneBox& box : scene.boxes())
        slide = std::max(slide, (box.offsetAt(rest.end_s) - box.offsetAt(rest.start_s)).norm());
      rests_sliding += slide > 0.005;
    }
    const double mean_share = share_sum / trajectory.poses().size();
    std::cout << scenario << " seed 2: " << 100.0 * mean_share
              << " % of the rests' views on moving boxes; " << rests_sliding << " of "
              << trajectory.poses().size() << " rests with a box sliding > 5 mm\n";
    EXPECT_GT(mean_share, 0.08) << scenario;
    EXPECT_LT(mean_share, 0.3) << scenario;
    EXPECT_GE(rests_sliding, 6) << scenario;
  }
}

TEST(SceneRendering, RichRoomsHaveManyFeaturesAndTexturePoorOnesFew) {
  for (const bool poor : {false, true}) {
    sim::SimulationConfig config = roomConfig("room_handheld", 3);
    config.texture_poor = poor;
    const sim::Trajectory trajectory(config);
    const sim::SceneRenderer renderer(sim::CameraModel::fromConfig(config),
                                      sim::RoomScene::fromConfig(config), config.supersample,
                                      config.blur_sigma_px);
    const auto start = std::chrono::steady_clock::now();
    const sim::StationaryPose& rest = trajectory.poses()[2];
    const cv::Mat grey = renderer.render(rest.R_world_cam, rest.p_world_cam);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const cv::Mat image = sim::ImageRenderer::toMono8(grey, config.pixel_noise_sigma, 11);
    std::vector<cv::KeyPoint> sift;
    cv::SIFT::create()->detect(image, sift);
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(image, corners, 2000, 0.01, 5.0);
    std::cout << (poor ? "texture-poor" : "rich") << " room, 640x480 at supersample "
              << config.supersample << ": " << seconds << " s per frame, " << sift.size()
              << " SIFT features, " << corners.size() << " corners (goodFeaturesToTrack)\n";
    if (poor) {
      EXPECT_LT(sift.size(), 30u);
    } else {
      EXPECT_GT(sift.size(), 200u);
      EXPECT_GT(corners.size(), 200u);
    }
  }
}

TEST(SceneRendering, ConsecutiveRestsShareFeaturesWhereTheGeometrySaysSo) {
  // SIFT between the first two rests of each scenario: a match is right when the keypoint of the
  // first view, lifted to 3D with its depth and the true poses, projects within 2 px of its match
  // in the second. The views must share many right matches (what a natural-scene calibration
  // needs), and most ratio-test matches must be right (the rendering is geometrically exact).
  for (const char* scenario : {"room_robot", "room_handheld"}) {
    const sim::SimulationConfig config = roomConfig(scenario, 1);
    const sim::Trajectory trajectory(config);
    const sim::SceneRenderer renderer(sim::CameraModel::fromConfig(config),
                                      sim::RoomScene::fromConfig(config), config.supersample,
                                      config.blur_sigma_px);
    const sim::StationaryPose& a = trajectory.poses()[0];
    const sim::StationaryPose& b = trajectory.poses()[1];
    const cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
    std::vector<cv::KeyPoint> keys_a, keys_b;
    cv::Mat desc_a, desc_b;
    sift->detectAndCompute(
        sim::ImageRenderer::toMono8(renderer.render(a.R_world_cam, a.p_world_cam), 1.5, 1),
        cv::noArray(), keys_a, desc_a);
    sift->detectAndCompute(
        sim::ImageRenderer::toMono8(renderer.render(b.R_world_cam, b.p_world_cam), 1.5, 2),
        cv::noArray(), keys_b, desc_b);
    const cv::Mat depth_a = renderer.depth(a.R_world_cam, a.p_world_cam);
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(cv::NORM_L2).knnMatch(desc_a, desc_b, knn, 2);
    const sim::CameraModel& cam = renderer.camera();
    int matches = 0, right = 0;
    for (const auto& m : knn) {
      if (m.size() < 2 || m[0].distance > 0.75 * m[1].distance) continue;
      ++matches;
      const cv::Point2f pa = keys_a[m[0].queryIdx].pt, pb = keys_b[m[0].trainIdx].pt;
      const float z = depth_a.at<float>(static_cast<int>(std::lround(pa.y)),
                                        static_cast<int>(std::lround(pa.x)));
      const Eigen::Vector3d in_a(z * (pa.x - cam.cx) / cam.fx, z * (pa.y - cam.cy) / cam.fy, z);
      const Eigen::Vector3d world = a.R_world_cam * in_a + a.p_world_cam;
      const Eigen::Vector2d expected =
          cam.project(b.R_world_cam.transpose() * (world - b.p_world_cam));
      right += (expected - Eigen::Vector2d(pb.x, pb.y)).norm() < 2.0;
    }
    std::cout << scenario << " seed 1, rests 0-1: " << keys_a.size() << " and " << keys_b.size()
              << " SIFT features, " << matches << " ratio-test matches, " << right
              << " where the geometry puts them\n";
    EXPECT_GT(right, 100) << scenario;
    EXPECT_GT(right, matches / 2) << scenario;
  }
}

TEST(SceneSimulateBag, RoomRobotBagHasImagesAndNoCameraPose) {
  const std::string sim_exe = SIMULATE_BAG_EXE;
  const std::string small =
      " --scenario room_robot --seed 4 --num-poses 3 --hold-min-s 1 --hold-max-s 1.5 --move-min-s"
      " 1 --move-max-s 1.5 --width 160 --height 120 --fx 125 --fy 125 --supersample 1"
      " --imu-grade consumer";
  const std::string bag = test::simulateBag(sim_exe, "room_robot", small);
  const test::ToolRun info = test::runTool("rosbag info --yaml " + bag);
  ASSERT_EQ(info.exit_code, 0) << info.err;
  std::map<std::string, long> topics;
  for (const YAML::Node& n : YAML::Load(info.out)["topics"])
    topics[n["topic"].as<std::string>()] = n["messages"].as<long>();
  const YAML::Node truth = YAML::LoadFile(test::bagStem(bag) + ".truth.yaml");
  EXPECT_EQ(topics.size(), 4u) << info.out;
  EXPECT_EQ(topics.count("/camera_pose"), 0u);
  EXPECT_EQ(topics["/camera/image_raw"], truth["counts"]["images"].as<long>());
  EXPECT_GT(topics["/camera/image_raw"], 10);
  EXPECT_EQ(topics["/camera/camera_info"], topics["/camera/image_raw"]);
  EXPECT_GT(topics["/imu/data_raw"], 1000);
  EXPECT_GT(topics["/imu/mag"], 500);
  EXPECT_EQ(truth["scene"]["type"].as<std::string>(), "room");
  EXPECT_FALSE(truth["target"]);
  EXPECT_EQ(truth["poses"].size(), 3u);
  // The truth's rests are the simulator's: the same configuration gives the same camera in the
  // room frame (what a test of the natural-scene rotation compares relative rotations against).
  sim::SimulationConfig config = roomConfig("room_robot", 4);
  config.num_poses = 3;
  config.hold_min_s = config.move_min_s = 1.0;
  config.hold_max_s = config.move_max_s = 1.5;
  config.width = 160;
  config.height = 120;
  config.fx = config.fy = 125.0;
  config.cx = 79.5;
  config.cy = 59.5;
  const sim::Trajectory trajectory(config);
  for (size_t k = 0; k < 3; ++k) {
    const auto q = truth["poses"][k]["q_world_cam_xyzw"].as<std::vector<double>>();
    ASSERT_EQ(q.size(), 4u);
    const Eigen::Quaterniond q_truth(q[3], q[0], q[1], q[2]);
    EXPECT_LT(q_truth.angularDistance(Eigen::Quaterniond(trajectory.poses()[k].R_world_cam)), 1e-9)
        << "rest " << k;
  }
  EXPECT_FALSE(std::ifstream(test::bagStem(bag) + ".target.yaml").good()) << "no board";
  const test::ToolRun help = test::runTool(sim_exe + " --help");
  for (const char* word : {"room_robot:", "room_handheld:", "--moving-objects", "--texture-poor"})
    EXPECT_NE(help.out.find(word), std::string::npos) << word;
  // A board's options are refused with the room, and the room's with a board.
  test::ToolRun r =
      test::runTool(sim_exe + " --out " + test::tempPath("x.bag") + small + " --camera-pose");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--camera-pose"), std::string::npos) << r.err;
  r = test::runTool(sim_exe + " --out " + test::tempPath("x.bag") + " --texture-poor");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--texture-poor"), std::string::npos) << r.err;
  // The robot's tilt: only for the robot, and a range.
  r = test::runTool(sim_exe + " --out " + test::tempPath("x.bag") +
                    " --scenario room_handheld --robot-tilt-deg 10,30");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--robot-tilt-deg tilts the robot's base"), std::string::npos) << r.err;
  r = test::runTool(sim_exe + " --out " + test::tempPath("x.bag") +
                    " --scenario room_robot --robot-tilt-deg 30,10");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--robot-tilt-deg = 30,10: must be two numbers MIN,MAX"), std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace camera_imu_alignment
