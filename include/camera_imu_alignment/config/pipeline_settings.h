// The pipeline's settings (pipeline/calibration_pipeline.h says what each stage does with them):
// one struct of the domain rooms' settings and the pipeline's own. Their keys, ranges and defaults
// are one table (config/pipeline_config.h); config/default.yaml documents every key; the one check
// of a struct is findProblem (config/settings_checks.h).
#pragma once

#include <cstddef>
#include <string>

#include "camera_imu_alignment/estimation/joint_types.h"
#include "camera_imu_alignment/inertial/magnetometer.h"
#include "camera_imu_alignment/inertial/stationary_detector.h"
#include "camera_imu_alignment/solver/alignment_solver.h"
#include "camera_imu_alignment/vision/camera_pose.h"
#include "camera_imu_alignment/vision/scene_rotation.h"
#include "camera_imu_alignment/vision/target_detector.h"

namespace camera_imu_alignment {

/// Where the IMU orientation of a pose comes from (pipeline/calibration_pipeline.h).
enum class ImuOrientationSource { kJoint, kAuto, kMagnetometer, kMessage };
const char* toString(ImuOrientationSource source);
bool parseImuOrientationSource(const std::string& text, ImuOrientationSource* source);
/// The modes whose answer is a joint maximum-likelihood estimate (estimation/joint_estimator.h):
/// kJoint (every sensor) and kMagnetometer (camera, accelerometer and magnetometer, the gyro left
/// out). The others answer with the pair solve.
bool usesJointEstimate(ImuOrientationSource source);

struct PipelineSettings {
  StationaryDetectorSettings stationary;
  DisturbanceSettings disturbance;
  MagnetometerCalibration magnetometer;
  DetectorSettings detector;
  PoseSettings pose;
  SolverOptions solver;
  ImuOrientationSource imu_orientation = ImuOrientationSource::kJoint;
  JointSettings joint;            ///< the joint estimate (imu_orientation: joint or magnetometer)
  std::size_t window_poses = 30;  ///< sliding window of stationary poses
  int min_poses_to_solve = 3;     ///< solve only with at least this many poses in the window
  int min_frames_per_pose = 2;    ///< camera frames with a pose needed for a stationary pose
  int max_frames_per_pose = 10;   ///< detection stops after this many good frames per rest
  double min_frame_interval_s = 0.15;  ///< frames closer than this to the last detected one skipped
  /// After kMissesBeforeBackoff failed detections in a row at one rest (target out of view, a
  /// miss costs up to 15x a hit), frames closer than this to the last attempt are skipped.
  double missed_frame_interval_s = 1.0;
  static constexpr int kMissesBeforeBackoff = 3;
  double frame_margin_s = 0.15;        ///< see "Time offsets" in pipeline/calibration_pipeline.h
  double max_camera_spread_deg = 0.5;  ///< camera orientation scatter within a pose
  double max_gyro_span_s = 120.0;      ///< longer motion between poses breaks the gyro chain
  /// Continuous motion: camera frames outside the rests (the target seen, or a camera_pose) and
  /// the raw gyro are kept this long (s) for the joint estimate's motion nodes; 0: rests only.
  double motion_window_s = 120.0;
  /// Frames during motion closer than this (s) to the last one used are skipped (detection cost).
  double motion_frame_interval_s = 0.03;
  /// The camera-IMU time offset (timeshift_cam_imu) is searched within +- this (s).
  double max_timeshift_s = 0.1;
  double frame_queue_s = 3.0;  ///< frames older than the IMU by more are dropped (no IMU)
  double accel_weight = 0.9;   ///< attitudeFromAccelMag
  /// Without a target (an empty TargetDescription): the camera's rotation between rests from the
  /// natural scene (vision/scene_rotation.h), features of each rest's sharpest frame. Not keys.
  SceneFeatureSettings scene_features;
  SceneRotationSettings scene_rotation;
  /// A new rest is matched with at most this many earlier rests (newest first).
  int max_scene_matches = 4;
};

/// The joint estimate's settings as the pipeline uses them: `settings.joint` with the local
/// gravity of the setting gravity_m_s2 (stationary.gravity_m_s2), so that one value feeds the
/// stationary detector and the joint estimate's accelerometer model alike.
JointSettings jointSettingsOf(const PipelineSettings& settings);

}  // namespace camera_imu_alignment
