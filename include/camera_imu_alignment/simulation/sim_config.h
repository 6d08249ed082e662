// Settings of the camera + inertial/magnetic unit simulator (simulate_bag) and its scenario
// presets. Units: seconds, metres, radians (names ending in _deg: degrees), tesla for magnetic
// fields, Hz. Frames (doc/CONVENTIONS.md): world is ENU with gravity (0, 0, -9.81); the camera
// frame is optical (z forward, x right, y down); R_cam_imu maps IMU vectors into the camera frame.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "camera_imu_alignment/simulation/imu_grades.h"

namespace camera_imu_alignment {
namespace simulation {

/// How the rig moves between stationary poses.
enum class MotionKind {
  kFull,          ///< roll, pitch and yaw diversity with some translation: all axes excited
  kSingleAxis,    ///< rotations about the optical axis only (degenerate: one axis unobservable)
  kSmallAngle,    ///< full motion but within a few degrees (poorly conditioned)
  kWaving,        ///< continuous hand-held motion, no rests (waving_motion.h); num_poses, hold and
                  ///< move times unused, the run lasts waving_duration_s
  kRoomRobot,     ///< a ground robot stopping in a textured room, no board (room_motion.h)
  kRoomHandheld,  ///< a hand-held rig resting in a textured room, no board (room_motion.h)
};

/// True for the natural-scene motions (kRoomRobot, kRoomHandheld): the camera sees the room of
/// room_scene.h instead of a board, and there is no target frame.
inline bool isRoomMotion(MotionKind kind) {
  return kind == MotionKind::kRoomRobot || kind == MotionKind::kRoomHandheld;
}

enum class TargetType { kCheckerboard, kAprilgrid, kCirclegrid };

/// Planar target in Kalibr's terms (doc/CONVENTIONS.md "Target description").
struct TargetSpec {
  TargetType type = TargetType::kCheckerboard;
  int cols = 8;                  ///< checkerboard inner corners / aprilgrid tags / circles along x
  int rows = 6;                  ///< same along y
  double spacing_m = 0.04;       ///< checkerboard square, circle spacing, aprilgrid tagSize (m)
  double tag_spacing = 0.3;      ///< aprilgrid: gap between tags as a fraction of tagSize
  bool asymmetric_grid = false;  ///< circlegrid only
};

struct SimulationConfig {
  std::string scenario = "nominal";
  std::uint64_t seed = 1;

  // Motion.
  int num_poses = 12;
  double hold_min_s = 3.0, hold_max_s = 5.0;  ///< stationary time at each pose
  double move_min_s = 2.0, move_max_s = 3.0;  ///< smooth motion between poses
  MotionKind motion = MotionKind::kFull;
  double max_tilt_deg = 35.0;                          ///< viewing direction off the target normal
  double max_roll_deg = 80.0;                          ///< rotation about the optical axis
  double min_distance_m = 0.55, max_distance_m = 0.9;  ///< camera to target centre
  double waving_duration_s = 60.0;                     ///< length of a kWaving run

  // Natural scene (room motions only; room_scene.h).
  bool moving_objects = false;  ///< the two largest boxes slide 0.2-0.5 m back and forth
  bool texture_poor = false;    ///< near-blank surfaces: faint texture, few features
  /// room_robot: the base's tilt at each stop, acos(cos(pitch) cos(roll)), uniform in [min, max]
  /// (deg; uneven ground), in a random direction.
  double robot_min_tilt_deg = 5.0, robot_max_tilt_deg = 20.0;

  // Mounting. Random per seed (at least 30 deg from the identity) unless given.
  bool given_R_cam_imu = false;
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();

  // Environment.
  Eigen::Vector3d gravity_world{0.0, 0.0, -9.81};         ///< m/s^2, ENU
  Eigen::Vector3d earth_field_world{0.0, 22e-6, -42e-6};  ///< T, ENU

  // Inertial/magnetic unit.
  double imu_rate_hz = 200.0;
  /// Multiplies every sensor noise (IMU, magnetometer, pixels) and the initial IMU biases; not the
  /// systematic errors (T_g, T_a, hard and soft iron).
  double noise_scale = 1.0;
  ImuGrade imu_grade = ImuGrade::kIdeal;  ///< name of the numbers below (applyImuGrade sets them)
  SensorNoise imu_noise;                  ///< noise terms of the grade (options may override them)
  ImuSystematicSigmas imu_systematic;     ///< spread of T_g, T_a, hard and soft iron (imu_grades.h)
  bool magnetometer = true;
  double mag_rate_hz = 100.0;
  Eigen::Vector3d mag_hard_iron{0.0, 0.0, 0.0};  ///< T, IMU frame, added to every sample (and to
                                                 ///< the grade's drawn hard iron)
  std::vector<int> mag_disturbance_poses;        ///< 0-based poses whose hold is disturbed
  double mag_disturbance_t = 25e-6;              ///< T, magnitude of the extra (world) field

  // Camera (pinhole + plumb_bob distortion k1, k2, p1, p2, k3).
  int width = 640, height = 480;
  double fx = 500.0, fy = 500.0, cx = 319.5, cy = 239.5;
  std::array<double, 5> distortion{0.0, 0.0, 0.0, 0.0, 0.0};
  /// 15 Hz, a typical camera: the nominal 80 s run is then a ~380 MB bag (pixel noise defeats
  /// compression). Tests use --camera-rate-hz 5 (~130 MB, 15-25 frames per hold) for speed.
  double camera_rate_hz = 15.0;
  /// image stamp = true capture time + offset (Kalibr's timeshift_cam_imu = -offset)
  double camera_time_offset_s = 0.0;
  /// 1-sigma noise per axis (deg) of the camera orientations R_target_cam published as
  /// camera_pose (cameraOrientations in simulation_run.h): R_true * Exp(n), n in the camera frame
  double camera_pose_noise_deg = 0.02;
  /// 1-sigma noise per axis (m) of those camera_pose positions p_target_cam, in the camera frame
  /// (PnP's at 0.5-1 m from a board: a few tenths of a millimetre); noise_scale applies.
  double camera_pose_position_noise_m = 0.3e-3;
  double blur_sigma_px = 0.6;           ///< Gaussian optical blur
  double pixel_noise_sigma = 1.5;       ///< grey levels (0-255), before noise_scale
  int supersample = 3;                  ///< samples per pixel along each axis
  double motion_blur_exposure_s = 0.0;  ///< > 0: frames in motion average renders over it
  TargetSpec target;

  // Remount: R_cam_imu becomes Exp(remount_rotvec_cam) * R_cam_imu over 1 s centred on the time.
  bool remount = false;
  double remount_time_s = -1.0;  ///< since the start; < 0: middle of the central motion
  Eigen::Vector3d remount_rotvec_cam{0.0, 10.0 * 3.14159265358979323846 / 180.0,
                                     0.0};  ///< rad, camera frame

  bool bad_input = false;  ///< inject NaNs, duplicate/out-of-order stamps, bad images/info

  // ROS names and time base (used by the tool only).
  std::string imu_topic = "imu/data_raw", mag_topic = "imu/mag";
  std::string image_topic = "camera/image_raw", camera_info_topic = "camera/camera_info";
  std::string imu_frame = "imu_link", camera_frame = "camera_optical_frame";
  bool images = true;        ///< write Image + CameraInfo messages (false: nothing is rendered)
  bool camera_pose = false;  ///< write camera_orientations as geometry_msgs/PoseStamped
  std::string camera_pose_topic = "camera_pose";
  std::string target_frame = "calibration_target";  ///< frame_id of the camera_pose messages
  double start_time_s = 1700000000.0;               ///< bag time of the simulation's t = 0
};

/// Scenario names with a one-line description each, in --help order.
const std::vector<std::pair<std::string, std::string>>& scenarioList();

/// Resets `config` to the defaults and applies the preset `name` (seed kept). Returns false for an
/// unknown name.
bool applyScenario(const std::string& name, SimulationConfig* config);

/// Checks every setting; returns an empty string when usable, else a message naming the setting.
std::string validateConfig(const SimulationConfig& config);

const char* toString(TargetType type);
const char* toString(MotionKind kind);

}  // namespace simulation
}  // namespace camera_imu_alignment
