#include "camera_imu_alignment/simulation/sim_config.h"

#include <cmath>
#include <sstream>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace simulation {

const std::vector<std::pair<std::string, std::string>>& scenarioList() {
  static const std::vector<std::pair<std::string, std::string>> list = {
      {"nominal", "checkerboard, 12 poses, all axes excited, realistic MEMS noise"},
      {"wall_board",
       "hand-held in front of a board on a wall: 12 rests of 3-5 s, view within 35 deg of the "
       "board's normal, roll within 45 deg (gravity spans a narrow cone; any --imu-grade)"},
      {"waving",
       "hand-held, waved in front of the board for 60 s without rests (Kalibr-style): all axes, "
       "20-90 deg/s, view within 35 deg of the board's normal, roll within 45 deg (any "
       "--imu-grade)"},
      {"aprilgrid", "nominal with a Kalibr AprilGrid (tag36h11) target"},
      {"circlegrid", "nominal with a symmetric circle grid target"},
      {"noisy_imu", "nominal with every sensor noise x5"},
      {"few_poses", "only 3 stationary poses"},
      {"degenerate", "rotations about the optical axis only: one axis not observable"},
      {"no_magnetometer", "nominal without the magnetometer topic"},
      {"magnetic_disturbance", "extra 25 uT field during the holds of poses 2 and 5"},
      {"time_offset", "camera stamps 50 ms late against the IMU stamps"},
      {"remount", "16 poses, camera at 4 Hz; R_cam_imu changes by 10 deg about camera y mid-run"},
      {"bad_input",
       "NaN IMU/magnetometer samples, duplicate and out-of-order stamps, empty and "
       "wrong-encoding images, a zero-K CameraInfo"},
      {"long_run", "40 poses (about 4 minutes), camera at 1.5 Hz"},
      {"tactical", "nominal with a tactical-grade IMU (ADIS16495 class; --imu-grade tactical)"},
      {"consumer",
       "nominal with a consumer IMU (ICM-20948 class): scale, cross-axis, biases, hard/soft "
       "iron"},
      {"noisy_consumer",
       "nominal with the noisy grade: MPU-6050/9250 on a vibrating mount, gyro bias 3 deg/s"},
      {"room_robot",
       "no board: a ground robot in a textured 6 x 5 m room with boxes, camera ~0.4 m high; 12 "
       "stops of 3-5 s, 0.3-2 m apart, turning 10-60 deg, tilted 5-20 deg by uneven ground, "
       "consecutive views overlapping (any --imu-grade; --moving-objects, --texture-poor, "
       "--remount)"},
      {"room_handheld",
       "no board: a hand-held rig in the textured room, 12 rests of 3-5 s turned 20-60 deg about "
       "all axes, small translations, walls and boxes 1-3 m away, consecutive views overlapping "
       "(any --imu-grade; --moving-objects, --texture-poor, --remount)"},
  };
  return list;
}

bool applyScenario(const std::string& name, SimulationConfig* config) {
  const std::uint64_t seed = config->seed;
  *config = SimulationConfig();
  config->seed = seed;
  config->scenario = name;
  SimulationConfig& c = *config;
  if (name == "nominal") {
  } else if (name == "wall_board") {
    // The way people hold a rig in front of a wall board: the camera within 35 deg of the
    // board's normal (the default tilt), the image's roll within +-45 deg.
    c.num_poses = 12;
    c.hold_min_s = 3.0;
    c.hold_max_s = 5.0;
    c.max_tilt_deg = 35.0;
    c.max_roll_deg = 45.0;
  } else if (name == "waving") {
    c.motion = MotionKind::kWaving;
    c.waving_duration_s = 60.0;
    c.max_tilt_deg = 35.0;
    c.max_roll_deg = 45.0;
    c.min_distance_m = 0.6;
  } else if (name == "aprilgrid") {
    c.target.type = TargetType::kAprilgrid;
    c.target.cols = 4;
    c.target.rows = 3;
    c.target.spacing_m = 0.08;
    c.target.tag_spacing = 0.3;
  } else if (name == "circlegrid") {
    c.target.type = TargetType::kCirclegrid;
    c.target.cols = 7;
    c.target.rows = 5;
    c.target.spacing_m = 0.05;
  } else if (name == "noisy_imu") {
    c.noise_scale = 5.0;
  } else if (name == "few_poses") {
    c.num_poses = 3;
  } else if (name == "degenerate") {
    c.motion = MotionKind::kSingleAxis;
  } else if (name == "no_magnetometer") {
    c.magnetometer = false;
  } else if (name == "magnetic_disturbance") {
    c.mag_disturbance_poses = {2, 5};
  } else if (name == "time_offset") {
    c.camera_time_offset_s = 0.05;
  } else if (name == "remount") {
    c.num_poses = 16;
    c.camera_rate_hz = 4.0;  // keeps the bag near the nominal size
    c.remount = true;
  } else if (name == "bad_input") {
    c.bad_input = true;
  } else if (name == "long_run") {
    c.num_poses = 40;
    c.camera_rate_hz = 1.5;
  } else if (name == "tactical") {
    applyImuGrade(ImuGrade::kTactical, &c);
  } else if (name == "consumer") {
    applyImuGrade(ImuGrade::kConsumer, &c);
  } else if (name == "noisy_consumer") {
    applyImuGrade(ImuGrade::kNoisy, &c);
  } else if (name == "room_robot") {
    // Driving 0.3-2 m and turning between stops takes a robot longer than a hand a turn.
    c.motion = MotionKind::kRoomRobot;
    c.move_min_s = 3.0;
    c.move_max_s = 5.0;
    c.supersample = 2;  // the room's procedural texture costs per sample: 4 per pixel, not 9
  } else if (name == "room_handheld") {
    c.motion = MotionKind::kRoomHandheld;
    c.supersample = 2;
  } else {
    return false;
  }
  return true;
}

namespace {
bool inRange(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }
}  // namespace

std::string validateConfig(const SimulationConfig& c) {
  std::ostringstream e;
  if (c.num_poses < 2 || c.num_poses > 1000) e << "num_poses must be in [2, 1000]; ";
  if (!inRange(c.hold_min_s, 0.1, 600) || !inRange(c.hold_max_s, c.hold_min_s, 600))
    e << "hold time range must satisfy 0.1 <= hold_min_s <= hold_max_s <= 600; ";
  if (!inRange(c.move_min_s, 0.2, 600) || !inRange(c.move_max_s, c.move_min_s, 600))
    e << "motion time range must satisfy 0.2 <= move_min_s <= move_max_s <= 600; ";
  if (!inRange(c.waving_duration_s, 1, 3600)) e << "waving_duration_s must be in [1, 3600]; ";
  if (!inRange(c.camera_pose_noise_deg, 0, 10)) e << "camera_pose_noise_deg must be in [0, 10]; ";
  if (!inRange(c.camera_pose_position_noise_m, 0, 0.1)) {
    e << "camera_pose_position_noise_m must be in [0, 0.1]; ";
  }
  if (!inRange(c.max_tilt_deg, 0, 60)) e << "max_tilt_deg must be in [0, 60]; ";
  if (!inRange(c.max_roll_deg, 0, 180)) e << "max_roll_deg must be in [0, 180]; ";
  if (!inRange(c.min_distance_m, 0.1, 10) || !inRange(c.max_distance_m, c.min_distance_m, 10))
    e << "distance range must satisfy 0.1 <= min_distance_m <= max_distance_m <= 10; ";
  if (!isRotationMatrix(c.R_cam_imu, 1e-6)) e << "R_cam_imu is not a rotation; ";
  if (!inRange(c.imu_rate_hz, 1, 10000)) e << "imu_rate_hz must be in [1, 10000]; ";
  if (!inRange(c.mag_rate_hz, 1, 10000)) e << "mag_rate_hz must be in [1, 10000]; ";
  if (!inRange(c.camera_rate_hz, 0.1, 200)) e << "camera_rate_hz must be in [0.1, 200]; ";
  if (!inRange(c.noise_scale, 0, 1000)) e << "noise_scale must be in [0, 1000]; ";
  if (!inRange(std::abs(c.camera_time_offset_s), 0, 10))
    e << "camera_time_offset_s must be in [-10, 10]; ";
  if (c.width < 16 || c.height < 16 || c.width > 4096 || c.height > 4096)
    e << "image size must be in [16, 4096]; ";
  if (!inRange(c.fx, 1, 1e5) || !inRange(c.fy, 1, 1e5)) e << "fx, fy must be in [1, 1e5]; ";
  if (!std::isfinite(c.cx) || !std::isfinite(c.cy)) e << "cx, cy must be finite; ";
  for (double d : c.distortion) {
    if (!inRange(d, -2, 2)) e << "distortion coefficients must be in [-2, 2]; ";
  }
  if (!inRange(c.blur_sigma_px, 0, 10)) e << "blur_sigma_px must be in [0, 10]; ";
  if (!inRange(c.pixel_noise_sigma, 0, 100)) e << "pixel_noise_sigma must be in [0, 100]; ";
  if (c.supersample < 1 || c.supersample > 8) e << "supersample must be in [1, 8]; ";
  if (!inRange(c.motion_blur_exposure_s, 0, 1)) e << "motion_blur_exposure_s must be in [0, 1]; ";
  if (c.target.cols < 2 || c.target.rows < 2 || c.target.cols > 50 || c.target.rows > 50)
    e << "target cols/rows must be in [2, 50]; ";
  if (!inRange(c.target.spacing_m, 0.001, 1)) e << "target spacing must be in [0.001, 1] m; ";
  if (!inRange(c.target.tag_spacing, 0.05, 1)) e << "aprilgrid tag_spacing must be in [0.05, 1]; ";
  for (int p : c.mag_disturbance_poses) {
    if (p < 0 || p >= c.num_poses) e << "magnetic disturbance pose " << p << " out of range; ";
  }
  if (!inRange(c.mag_disturbance_t, 0, 1e-3)) e << "mag_disturbance must be in [0, 1000] uT; ";
  if (!c.remount_rotvec_cam.allFinite() || c.remount_rotvec_cam.norm() > kPi)
    e << "remount rotation must be finite and at most 180 deg; ";
  if (!std::isfinite(c.remount_time_s)) e << "remount_time_s must be finite; ";
  if (!inRange(c.start_time_s, 1.0, 4e9)) e << "start_time_s must be in [1, 4e9]; ";
  if (!isRoomMotion(c.motion) && (c.moving_objects || c.texture_poor))
    e << "moving objects and texture-poor are options of the room scenarios (room_robot, "
         "room_handheld); ";
  if (isRoomMotion(c.motion) && c.camera_pose)
    e << "camera_pose gives the camera in the board's frame: the room scenarios have no board; ";
  const SensorNoise& n = c.imu_noise;
  bool noise_ok = inRange(n.magnetometer_noise_sigma, 0, 1e-4);
  for (double v : {n.accelerometer_noise_density, n.accelerometer_random_walk,
                   n.gyroscope_noise_density, n.gyroscope_random_walk,
                   n.gyroscope_initial_bias_sigma, n.accelerometer_initial_bias_sigma}) {
    noise_ok = noise_ok && inRange(v, 0, 10);
  }
  if (!noise_ok) e << "IMU noise terms must be in [0, 10] (magnetometer: [0, 100] uT); ";
  const ImuSystematicSigmas& sys = c.imu_systematic;
  bool sigmas_ok = inRange(sys.mag_hard_iron_sigma, 0, 1e-3);
  for (double v : {sys.gyro_scale_sigma, sys.gyro_cross_axis_sigma, sys.accel_scale_sigma,
                   sys.accel_cross_axis_sigma, sys.mag_soft_iron_sigma}) {
    sigmas_ok = sigmas_ok && inRange(v, 0, 0.2);
  }
  if (!sigmas_ok) e << "IMU systematic sigmas must be in [0, 0.2] (hard iron: [0, 1000] uT); ";
  if (!c.earth_field_world.allFinite() || !c.mag_hard_iron.allFinite() ||
      !c.gravity_world.allFinite())
    e << "fields must be finite; ";
  std::string s = e.str();
  if (s.size() >= 2) s.resize(s.size() - 2);
  return s;
}

const char* toString(TargetType type) {
  switch (type) {
    case TargetType::kAprilgrid:
      return "aprilgrid";
    case TargetType::kCirclegrid:
      return "circlegrid";
    default:
      return "checkerboard";
  }
}

const char* toString(MotionKind kind) {
  switch (kind) {
    case MotionKind::kSingleAxis:
      return "single_axis";
    case MotionKind::kSmallAngle:
      return "small_angle";
    case MotionKind::kWaving:
      return "waving";
    case MotionKind::kRoomRobot:
      return "room_robot";
    case MotionKind::kRoomHandheld:
      return "room_handheld";
    default:
      return "full";
  }
}

}  // namespace simulation
}  // namespace camera_imu_alignment
