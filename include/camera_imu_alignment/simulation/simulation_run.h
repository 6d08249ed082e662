// One complete simulated run: trajectory, inertial/magnetic samples, camera frame times, the
// camera's orientation at every frame and the bad-input plan, all determined by the configuration
// (seed included). Times are seconds since the start of the run (bag time = config.start_time_s +
// t). Rendering is done per frame by the caller (ImageRenderer), so a run costs little memory, and
// a run without images (IMU + camera orientations, e.g. for estimator unit tests) costs no
// rendering at all:
//   const SimulationRun run(config);   // run.imu, run.camera_orientations, run.trajectory
//   run.trajectory.R_cam_imu_final()   // the truth
#pragma once

#include <string>
#include <vector>

#include "camera_imu_alignment/simulation/inertial_model.h"
#include "camera_imu_alignment/simulation/sim_config.h"
#include "camera_imu_alignment/simulation/trajectory.h"

namespace camera_imu_alignment {
namespace simulation {

/// Bad-input injections (indices into the run's sample/frame vectors), sorted.
struct BadInputPlan {
  std::vector<long> nan_imu;                ///< IMU samples sent with NaN gyro and accelerometer
  std::vector<long> duplicate_imu;          ///< IMU samples sent twice with the same stamp
  std::vector<long> out_of_order_imu;       ///< i: samples i and i + 1 sent with swapped stamps
  std::vector<long> nan_mag;                ///< magnetometer samples sent as NaN
  std::vector<long> empty_images;           ///< frames sent as a 0 x 0 image (no data)
  std::vector<long> wrong_encoding_images;  ///< frames sent as "rgb8" with 3 bytes per pixel
  std::vector<long> zero_k_camera_infos;    ///< frames whose CameraInfo has K (and P) all zero
  bool empty() const {
    return nan_imu.empty() && duplicate_imu.empty() && out_of_order_imu.empty() &&
           nan_mag.empty() && empty_images.empty() && wrong_encoding_images.empty() &&
           zero_k_camera_infos.empty();
  }
};

/// The camera's orientation at one frame, as a camera_pose message (geometry_msgs/PoseStamped,
/// the camera in the target frame) carries it.
struct CameraOrientation {
  double capture_s = 0.0;  ///< true capture time (s since the start)
  double stamp_s = 0.0;    ///< camera stamp: capture_s + config.camera_time_offset_s
  /// Orientation with the noise: R_target_cam_true * Exp(n), n ~ N(0, sigma^2 I) in the camera
  /// frame, sigma = config.noise_scale * config.camera_pose_noise_deg (random stream 7).
  Eigen::Matrix3d R_target_cam = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_target_cam_true = Eigen::Matrix3d::Identity();  ///< at capture_s
  /// Camera centre (m) with the noise: p_true + R_target_cam_true m, m ~ N(0, sigma_p^2 I) in the
  /// camera frame, sigma_p = config.noise_scale * config.camera_pose_position_noise_m (stream 9).
  Eigen::Vector3d p_target_cam = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_target_cam_true = Eigen::Vector3d::Zero();  ///< at capture_s
};

/// The camera's orientation at every frame of `frame_times` (see CameraOrientation).
std::vector<CameraOrientation> simulateCameraOrientations(const SimulationConfig& config,
                                                          const Trajectory& trajectory,
                                                          const std::vector<double>& frame_times);

struct SimulationRun {
  SimulationConfig config;
  Trajectory trajectory;
  std::vector<InertialSample> imu;
  std::vector<MagSample> mag;
  std::vector<MagDisturbance> disturbances;
  ImuErrors imu_errors;             ///< the unit's drawn errors (drawImuErrors(config))
  std::vector<double> frame_times;  ///< true capture times (s); stamps add camera_time_offset_s
  /// The camera's orientation in the target frame at every frame (no rendering needed), stamped
  /// as the images are: what simulate_bag --camera-pose publishes.
  std::vector<CameraOrientation> camera_orientations;
  BadInputPlan bad_input;

  explicit SimulationRun(const SimulationConfig& c);
  /// Image noise seed of frame j (independent of every other random stream).
  std::uint64_t frameNoiseSeed(long j) const;
};

/// The truth YAML (R_cam_imu in the result format of doc/CONVENTIONS.md, stationary intervals
/// in bag time, per-pose orientations, noise settings, seed, scenario, injections) and the
/// `imu_errors:` block (grade, T_g, T_a, initial biases and walks, hard and soft iron, noise
/// densities; written with 17 digits, so it reads back exactly). The room scenarios have no board:
/// their poses carry the camera in the world = room frame only (q_world_cam_xyzw, p_world_cam_m),
/// and a `scene:` block (RoomScene::yaml) takes the place of `target:`.
std::string truthYaml(const SimulationRun& run);

}  // namespace simulation
}  // namespace camera_imu_alignment
