// Simulator science without ROS: determinism, gyro integration against the true rotations,
// accelerometer/magnetometer against the true attitude at rest, rendered corners against their
// true projections, Kalibr target layout and the truth YAML.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <fstream>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/simulation/renderer.h"
#include "camera_imu_alignment/simulation/simulation_run.h"
#include "camera_imu_alignment/simulation/target.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace simulation {
namespace {

SimulationConfig shortConfig(const std::string& scenario = "nominal", std::uint64_t seed = 7) {
  SimulationConfig c;
  c.seed = seed;
  EXPECT_TRUE(applyScenario(scenario, &c));
  c.num_poses = std::min(c.num_poses, 6);
  return c;
}

/// Integrates gyro - true bias from the middle of hold a to the middle of hold b (midpoint rule on
/// consecutive samples) and returns the IMU rotation R_imu_a_imu_b.
Eigen::Matrix3d integrateGyro(const std::vector<InertialSample>& imu, double ta, double tb) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  for (size_t i = 0; i + 1 < imu.size(); ++i) {
    if (imu[i].t < ta || imu[i + 1].t > tb) continue;
    const Eigen::Vector3d w =
        0.5 * (imu[i].gyro - imu[i].gyro_bias + imu[i + 1].gyro - imu[i + 1].gyro_bias);
    R = R * expSO3(w * (imu[i + 1].t - imu[i].t));
  }
  return R;
}

TEST(Simulation, SameSeedSameDataOtherSeedOtherData) {
  const SimulationRun a(shortConfig()), b(shortConfig()), other(shortConfig("nominal", 8));
  ASSERT_EQ(a.imu.size(), b.imu.size());
  for (size_t i = 0; i < a.imu.size(); i += 97) {
    EXPECT_EQ(a.imu[i].gyro, b.imu[i].gyro);
    EXPECT_EQ(a.imu[i].accel, b.imu[i].accel);
  }
  EXPECT_EQ(truthYaml(a), truthYaml(b));
  EXPECT_NE(truthYaml(a), truthYaml(other));
  EXPECT_GT(
      test::angleBetweenDeg(a.trajectory.R_cam_imu_final(), other.trajectory.R_cam_imu_final()),
      1.0);
  // A random mounting is never near the identity.
  EXPECT_GT(test::angleBetweenDeg(a.trajectory.R_cam_imu_final(), Eigen::Matrix3d::Identity()),
            30.0);
}

TEST(Simulation, RotationPairsSatisfyAXEqualsXB) {
  const SimulationRun run(shortConfig());
  const Trajectory& tr = run.trajectory;
  const Eigen::Matrix3d X = tr.R_cam_imu_final();
  const auto& poses = tr.poses();
  for (size_t k = 1; k < poses.size(); ++k) {
    const RigState sk = tr.at(poses[0].start_s), st = tr.at(poses[k].start_s);
    const Eigen::Matrix3d A = (tr.R_world_target().transpose() * sk.R_world_cam).transpose() *
                              (tr.R_world_target().transpose() * st.R_world_cam);
    const Eigen::Matrix3d B = sk.R_world_imu().transpose() * st.R_world_imu();
    EXPECT_LT(test::angleBetweenDeg(A * X, X * B), 1e-9);
    EXPECT_GT(rotationAngle(A), deg2rad(5.0)) << "poses must differ";
  }
}

TEST(Simulation, IntegratedGyroReproducesTrueRelativeRotations) {
  for (double noise : {0.0, 1.0}) {
    SimulationConfig c = shortConfig();
    c.noise_scale = noise;
    const SimulationRun run(c);
    const auto& poses = run.trajectory.poses();
    for (size_t k = 0; k + 1 < poses.size(); ++k) {
      const double ta = 0.5 * (poses[k].start_s + poses[k].end_s);
      const double tb = 0.5 * (poses[k + 1].start_s + poses[k + 1].end_s);
      const Eigen::Matrix3d truth =
          run.trajectory.at(ta).R_world_imu().transpose() * run.trajectory.at(tb).R_world_imu();
      const double tol = noise == 0.0 ? 0.01 : 0.2;
      EXPECT_LT(test::angleBetweenDeg(integrateGyro(run.imu, ta, tb), truth), tol)
          << "noise " << noise << " poses " << k << "-" << k + 1;
    }
  }
}

TEST(Simulation, RemountIsSeenByTheGyroAndRecorded) {
  SimulationConfig c = shortConfig("remount");
  c.noise_scale = 0.0;
  const SimulationRun run(c);
  const Trajectory& tr = run.trajectory;
  ASSERT_TRUE(tr.remount());
  EXPECT_NEAR(test::angleBetweenDeg(tr.R_cam_imu_initial(), tr.R_cam_imu_final()), 10.0, 1e-6);
  const double ta = tr.poses().front().start_s + 0.1, tb = tr.poses().back().end_s - 0.1;
  const Eigen::Matrix3d truth = tr.at(ta).R_world_imu().transpose() * tr.at(tb).R_world_imu();
  EXPECT_LT(test::angleBetweenDeg(integrateGyro(run.imu, ta, tb), truth), 0.02);
  const YAML::Node y = YAML::Load(truthYaml(run));
  EXPECT_TRUE(y["remount"]["enabled"].as<bool>());
  EXPECT_TRUE(y["remount"]["R_cam_imu_before"]["quaternion_xyzw"]);
}

TEST(Simulation, AccelerometerAndMagnetometerAgreeWithTrueAttitudeAtRest) {
  SimulationConfig c = shortConfig();
  c.mag_hard_iron = Eigen::Vector3d(1e-6, -2e-6, 0.5e-6);
  const SimulationRun run(c);
  for (const StationaryPose& p : run.trajectory.poses()) {
    const Eigen::Matrix3d R_world_imu = run.trajectory.at(p.start_s).R_world_imu();
    Eigen::Vector3d acc = Eigen::Vector3d::Zero(), mag = Eigen::Vector3d::Zero();
    int na = 0, nm = 0;
    for (const InertialSample& s : run.imu) {
      if (s.t < p.start_s || s.t > p.end_s) continue;
      acc += s.accel - s.accel_bias;
      ++na;
    }
    for (const MagSample& s : run.mag) {
      if (s.t < p.start_s || s.t > p.end_s) continue;
      mag += s.field - c.mag_hard_iron;
      ++nm;
    }
    acc /= na;
    mag /= nm;
    // +9.81 along the IMU's up axis at rest (REP-145 specific force).
    EXPECT_LT((acc - R_world_imu.transpose() * Eigen::Vector3d(0, 0, 9.81)).norm(), 0.01);
    EXPECT_LT((mag - R_world_imu.transpose() * c.earth_field_world).norm(), 0.1e-6);
    // Gravity and the field directions alone give back the attitude (TRIAD).
    const auto triad = [](const Eigen::Vector3d& g, const Eigen::Vector3d& m) {
      const Eigen::Vector3d up = g.normalized(), east = m.cross(up).normalized();
      Eigen::Matrix3d R;
      R << east, up.cross(east), up;
      return R;  // columns: world east, north, up in the sensor frame
    };
    const Eigen::Matrix3d R_imu_world = triad(acc, mag);
    EXPECT_LT(test::angleBetweenDeg(R_imu_world.transpose(), R_world_imu), 0.2);
  }
}

TEST(Simulation, MagneticDisturbanceOnlyDuringChosenPoses) {
  const SimulationRun run(shortConfig("magnetic_disturbance"));
  ASSERT_EQ(run.disturbances.size(), 2u);
  const auto& pose2 = run.trajectory.poses()[2];
  for (const MagSample& s : run.mag) {
    const bool inside = s.t >= pose2.start_s && s.t <= pose2.end_s;
    if (inside) {
      EXPECT_TRUE(s.disturbed);
    }
  }
  EXPECT_TRUE(run.mag.front().disturbed == false);
}

struct CornerCheck {
  double max_error_px = 0.0;
  int found = 0;
};

/// Renders the held frames of a run, detects checkerboard corners and compares them with the
/// true projections of the target points.
CornerCheck checkCorners(const SimulationConfig& c, int max_poses) {
  const SimulationRun run(c);
  const CameraModel cam = CameraModel::fromConfig(c);
  const ImageRenderer renderer(cam, makeTargetTexture(c.target, textureTexelFor(c)), c.supersample,
                               c.blur_sigma_px);
  const std::vector<Eigen::Vector3d> points = targetPoints(c.target);
  CornerCheck result;
  const Trajectory& tr = run.trajectory;
  for (int k = 0; k < std::min<int>(max_poses, tr.poses().size()); ++k) {
    const StationaryPose& p = tr.poses()[k];
    const cv::Mat img = ImageRenderer::toMono8(renderer.renderAt(tr, p.start_s + 0.1),
                                               c.pixel_noise_sigma, 1234 + k);
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(img, cv::Size(c.target.cols, c.target.rows), corners,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      ADD_FAILURE() << "no checkerboard found at pose " << k;
      continue;
    }
    cv::cornerSubPix(img, corners, cv::Size(5, 5), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
    const Eigen::Matrix3d R_cam_target =
        (tr.R_world_target().transpose() * p.R_world_cam).transpose();
    const Eigen::Vector3d p_target_cam =
        tr.R_world_target().transpose() * (p.p_world_cam - tr.p_world_target());
    for (const cv::Point2f& d : corners) {
      double best = 1e9;
      for (const Eigen::Vector3d& P : points) {
        const Eigen::Vector2d uv = cam.project(R_cam_target * (P - p_target_cam));
        best = std::min(best, std::hypot(uv.x() - d.x, uv.y() - d.y));
      }
      result.max_error_px = std::max(result.max_error_px, best);
    }
    ++result.found;
  }
  return result;
}

TEST(Simulation, DetectedCheckerboardCornersWithinATenthOfAPixel) {
  const CornerCheck check = checkCorners(shortConfig(), 6);
  EXPECT_EQ(check.found, 6);
  EXPECT_LT(check.max_error_px, 0.1);
}

TEST(Simulation, DistortedRenderingKeepsCornersWithinATenthOfAPixel) {
  SimulationConfig c = shortConfig();
  c.distortion = {-0.25, 0.08, 0.001, -0.0005, 0.0};
  const CornerCheck check = checkCorners(c, 4);
  EXPECT_EQ(check.found, 4);
  EXPECT_LT(check.max_error_px, 0.1);
}

TEST(Simulation, UndistortInvertsDistort) {
  CameraModel cam;
  cam.distortion = {-0.25, 0.08, 0.001, -0.0005, 0.01};
  for (double x = -0.6; x <= 0.6; x += 0.2) {
    for (double y = -0.45; y <= 0.45; y += 0.15) {
      const Eigen::Vector2d pix = cam.project(Eigen::Vector3d(x, y, 1.0));
      Eigen::Vector2d back;
      ASSERT_TRUE(cam.undistort(pix, &back));
      EXPECT_LT((back - Eigen::Vector2d(x, y)).norm(), 1e-9);
    }
  }
}

TEST(Simulation, Tag36h11BitsMatchTheAprilTagCodeOrder) {
  // tag36h11 code 0 (AprilTag family table): bits MSB first, row-major from the top-left of the
  // upright tag, 1 = white. Kalibr prints its tags this way.
  const std::uint64_t code0 = 0xd5d628584ULL;
  const std::vector<int> bits = tag36h11Bits(0);
  for (int b = 0; b < 36; ++b) EXPECT_EQ(bits[b], static_cast<int>((code0 >> (35 - b)) & 1u)) << b;
}

TEST(Simulation, AprilgridTagsAreDetectedWithKalibrIds) {
  SimulationConfig c = shortConfig("aprilgrid");
  const SimulationRun run(c);
  const ImageRenderer renderer(CameraModel::fromConfig(c),
                               makeTargetTexture(c.target, textureTexelFor(c)), c.supersample,
                               c.blur_sigma_px);
  auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  auto params = cv::aruco::DetectorParameters::create();
  params->markerBorderBits = 2;
  for (const StationaryPose& p : run.trajectory.poses()) {
    const cv::Mat img =
        ImageRenderer::toMono8(renderer.renderAt(run.trajectory, p.start_s), 1.0, 5);
    std::vector<int> ids;
    std::vector<std::vector<cv::Point2f>> corners;
    cv::aruco::detectMarkers(img, dict, corners, ids, params);
    std::sort(ids.begin(), ids.end());
    ASSERT_EQ(ids.size(), static_cast<size_t>(c.target.cols * c.target.rows));
    for (size_t i = 0; i < ids.size(); ++i) EXPECT_EQ(ids[i], static_cast<int>(i));
  }
}

TEST(Simulation, KalibrTargetYamls) {
  SimulationConfig c;
  YAML::Node y = YAML::Load(targetYaml(c.target));
  EXPECT_EQ(y["target_type"].as<std::string>(), "checkerboard");
  EXPECT_EQ(y["targetCols"].as<int>(), 8);
  EXPECT_EQ(y["targetRows"].as<int>(), 6);
  EXPECT_DOUBLE_EQ(y["rowSpacingMeters"].as<double>(), 0.04);
  EXPECT_DOUBLE_EQ(y["colSpacingMeters"].as<double>(), 0.04);
  applyScenario("aprilgrid", &c);
  y = YAML::Load(targetYaml(c.target));
  EXPECT_EQ(y["target_type"].as<std::string>(), "aprilgrid");
  EXPECT_EQ(y["tagCols"].as<int>(), 4);
  EXPECT_EQ(y["tagRows"].as<int>(), 3);
  EXPECT_DOUBLE_EQ(y["tagSize"].as<double>(), 0.08);
  EXPECT_DOUBLE_EQ(y["tagSpacing"].as<double>(), 0.3);
  // Kalibr's point order: tag 0's corners are points 0, 1, 2*cols+1, 2*cols.
  const auto pts = targetPoints(c.target);
  ASSERT_EQ(pts.size(), 4u * 4 * 3);
  EXPECT_LT((pts[1] - Eigen::Vector3d(0.08, 0, 0)).norm(), 1e-12);
  EXPECT_LT((pts[2] - Eigen::Vector3d(0.104, 0, 0)).norm(), 1e-12);
  EXPECT_LT((pts[9] - Eigen::Vector3d(0.08, 0.08, 0)).norm(), 1e-12);
  applyScenario("circlegrid", &c);
  y = YAML::Load(targetYaml(c.target));
  EXPECT_EQ(y["target_type"].as<std::string>(), "circlegrid");
  EXPECT_DOUBLE_EQ(y["spacingMeters"].as<double>(), 0.05);
  EXPECT_FALSE(y["asymmetricGrid"].as<bool>());
}

TEST(Simulation, TruthYamlIsReadableAndComplete) {
  const SimulationRun run(shortConfig());
  const std::string path = ::testing::TempDir() + "cia_sim_truth.yaml";
  std::ofstream(path) << truthYaml(run);
  const StoredCalibration stored = readResultYaml(path);
  EXPECT_LT(test::angleBetweenDeg(stored.R_cam_imu, run.trajectory.R_cam_imu_final()), 1e-6);
  const YAML::Node y = YAML::LoadFile(path);
  ASSERT_EQ(y["stationary_intervals"].size(), run.trajectory.poses().size());
  ASSERT_EQ(y["poses"].size(), run.trajectory.poses().size());
  EXPECT_EQ(y["seed"].as<int>(), 7);
  EXPECT_EQ(y["scenario"].as<std::string>(), "nominal");
  const auto first = y["stationary_intervals"][0].as<std::vector<double>>();
  EXPECT_DOUBLE_EQ(first[0], run.config.start_time_s);
  EXPECT_TRUE(y["imu"]["gyroscope_noise_density"]);
  std::remove(path.c_str());
}

// The wall-board session: 12 rests of 3-5 s, the optical axis within 35 deg of the board's normal
// (plus the aim point's +-2 cm jitter, < 3 deg), the image's roll within 45 deg of the board's
// rows, so that gravity spans a narrow cone in the camera (and IMU) frame.
TEST(Simulation, WallBoardSessionKeepsTheViewNearTheNormalAndTheRollWithin45Deg) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    SimulationConfig c;
    c.seed = seed;
    ASSERT_TRUE(applyScenario("wall_board", &c));
    ASSERT_EQ(validateConfig(c), "");
    const Trajectory trajectory(c);
    ASSERT_EQ(trajectory.poses().size(), 12u);
    double largest_roll_deg = 0.0;
    for (const StationaryPose& pose : trajectory.poses()) {
      const double hold = pose.end_s - pose.start_s;
      EXPECT_GE(hold, 3.0);
      EXPECT_LE(hold, 5.0);
      const Eigen::Matrix3d R_target_cam =
          trajectory.R_world_target().transpose() * pose.R_world_cam;
      const Eigen::Vector3d optical_axis = R_target_cam.col(2);
      // The camera is on the board's +z side, looking back along -z.
      const double view_deg = rad2deg(std::acos(std::min(1.0, -optical_axis.z())));
      EXPECT_LT(view_deg, 38.0) << "seed " << seed;
      // Roll: the image x axis against the board's x axis projected into the image plane.
      const Eigen::Vector3d board_x = Eigen::Vector3d::UnitX();
      const Eigen::Vector3d x0 = (board_x - board_x.dot(optical_axis) * optical_axis).normalized();
      const Eigen::Vector3d y0 = optical_axis.cross(x0);
      const double roll_deg =
          rad2deg(std::atan2(R_target_cam.col(0).dot(y0), R_target_cam.col(0).dot(x0)));
      EXPECT_LE(std::abs(roll_deg), 45.0 + 1e-9) << "seed " << seed;
      largest_roll_deg = std::max(largest_roll_deg, std::abs(roll_deg));
    }
    EXPECT_GT(largest_roll_deg, 25.0) << "seed " << seed << ": the roll range is used";
  }
}

TEST(Simulation, ScenariosAreAllValid) {
  for (const auto& s : scenarioList()) {
    SimulationConfig c;
    ASSERT_TRUE(applyScenario(s.first, &c)) << s.first;
    EXPECT_EQ(validateConfig(c), "") << s.first;
  }
  SimulationConfig c;
  EXPECT_FALSE(applyScenario("no_such_scenario", &c));
  c.imu_rate_hz = -1;
  EXPECT_NE(validateConfig(c).find("imu_rate_hz"), std::string::npos);
}

}  // namespace
}  // namespace simulation
}  // namespace camera_imu_alignment
