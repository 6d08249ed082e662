// The offline and online calibration pipeline: time-stamped IMU, magnetometer and camera
// observations in, stationary poses and their window out (solve/window_solver.h gives R_cam_imu).
// The online calibrator drives this class (for calibrate_bag and the nodelet); it holds no ROS
// type.
//
// Data path:
//   IMU samples -> validation -> StationaryDetector -> segments (gyro bias, mean accel)
//   magnetometer samples -> validation, unit check, calibration -> per-segment mean field
//   camera frames -> queued until the IMU shows whether the frame time is at rest; detection + PnP
//     only on frames at rest (never while moving), at most max_frames_per_pose per pose
//   segment end -> StationaryPose (camera: robust average of the frame orientations; IMU: see
//     below) -> StationaryWindow -> on_pose. The pipeline does not solve: its owner
//     (OnlineCalibrator) takes a snapshot() of the window and solves it with the WindowSolver
//     (solve/window_solver.h), e.g. on a worker thread.
//
// R_cam_imu (PipelineSettings::imu_orientation):
//   kJoint (default): one maximum-likelihood estimate over the window's poses from every sensor
//     (estimation/joint_estimator.h): the camera orientations, each rest's mean accelerometer and
//     magnetometer, the raw gyro samples between consecutive poses, with the IMU's own errors
//     (gyro and accelerometer matrices and biases, hard and soft iron) estimated where the poses
//     excite them. Each measurement is weighted by its noise as measured on the recording (the
//     rest's own scatter). It starts from the pair solve below (kAuto's poses).
//   kMagnetometer: the same estimate without the gyro (the paper's sensors: camera, gravity and
//     field, the accelerometer's errors and the iron calibrated); it starts from its own pairs.
//   kAuto and kMessage solve relative-rotation pairs of the poses with the IMU orientation below.
// IMU orientation of a pose for the pairs:
//   kAuto (default): the gyro, integrated bias-corrected from the previous pose (bias: mean of the
//     two segments' gyro means), chained onto the previous pose's R_world_imu. The chain is
//     anchored by accelerometer + magnetometer at its first pose (accelerometer alone, heading 0,
//     without a usable magnetometer). When the chain breaks (IMU gap, buffer limit) it restarts at
//     the next pose; without a magnetometer the new chain's heading is unrelated to the old one, so
//     the poses get a new group and pairs are formed only within a group. When the magnetometer is
//     usable at both poses, the gyro and the accelerometer+magnetometer relative rotations are
//     compared and the difference is reported (gyro_mag_difference_deg).
//   kMagnetometer (the paper's): accelerometer + magnetometer (raw: no iron or bias corrected) at
//     every pose where the field is usable, the gyro chain otherwise.
//   kMessage: the IMU's own orientation estimate (sensor_msgs/Imu orientation, e.g. an AHRS with
//     an onboard filter), averaged over the rest, at every pose where at least 5 samples carry one;
//     the gyro chain otherwise. Its world frame is the sensor's: one group.
// Why the gyro first: over the few seconds between poses a bias-corrected MEMS gyro is accurate to
// a few hundredths of a degree, while an accelerometer + magnetometer attitude carries the
// accelerometer bias (tilt) and any uncalibrated iron or disturbance (heading) at every pose.
//
// Time offsets between camera and IMU stamps: a frame is used only when its stamp lies inside a
// stationary segment shrunk by frame_margin_s at both ends (the segment itself is already trimmed
// by half a detector window); within a rest the orientation is constant, so any offset smaller
// than the margin changes nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/config/pipeline_settings.h"
#include "camera_imu_alignment/estimation/camera_link_consensus.h"
#include "camera_imu_alignment/estimation/joint_types.h"
#include "camera_imu_alignment/inertial/imu_attitude.h"
#include "camera_imu_alignment/inertial/inertial_samples.h"
#include "camera_imu_alignment/inertial/magnetometer.h"
#include "camera_imu_alignment/inertial/stationary_detector.h"
#include "camera_imu_alignment/pipeline/input_rejections.h"
#include "camera_imu_alignment/pipeline/sample_sink.h"
#include "camera_imu_alignment/pipeline/scene_link_refitter.h"
#include "camera_imu_alignment/solver/alignment_solver.h"
#include "camera_imu_alignment/solver/pose_window.h"
#include "camera_imu_alignment/vision/camera_model.h"
#include "camera_imu_alignment/vision/camera_model_check.h"
#include "camera_imu_alignment/vision/camera_pose.h"
#include "camera_imu_alignment/vision/scene_rotation.h"
#include "camera_imu_alignment/vision/target_detector.h"

namespace camera_imu_alignment {

/// Where a pose's R_world_imu came from (the rule above).
enum class PoseImuSource {
  kGyro,       ///< the gyro chain
  kAccelMag,   ///< accelerometer + magnetometer
  kAccelOnly,  ///< accelerometer alone (heading 0; a new group)
  kMessage,    ///< the Imu message's own orientation
};
/// "gyro", "accel_mag", "accel_only", "message".
const char* toString(PoseImuSource source);

/// Where a pose's camera orientation came from.
enum class PoseCameraSource {
  kTarget,  ///< the target (PnP) or given camera poses (camera_pose)
  kScene    ///< the natural scene: features matched with earlier rests (no target)
};
/// "target", "scene".
const char* toString(PoseCameraSource source);

/// A natural-scene rotation measured between a pose and an earlier one (vision/scene_rotation.h).
struct SceneLinkSummary {
  int from_pose = 0;  ///< StationaryPose::index of the earlier pose
  int matches = 0, inliers = 0;
  SceneMotionModel model = SceneMotionModel::kRotationOnly;
  double residual_rms_px = 0.0;
  double sigma_deg = 0.0;  ///< RMS 1-sigma per axis of the measured rotation
  /// The measured rotation (vision/scene_rotation.h: R_G_cam_this = R_G_cam_from R_from_to).
  Eigen::Matrix3d R_from_to = Eigen::Matrix3d::Identity();
  /// Other rotations that explain the matches about as well (SceneRotation::alternatives).
  std::vector<Eigen::Matrix3d> alternatives;
};

/// A stationary pose as the pipeline assembled it.
struct StationaryPose {
  int index = 0;  ///< 0-based, in order of the recording
  int group = 0;  ///< poses of different groups never form a pair (see the rule above)
  double start_s = 0.0, end_s = 0.0;  ///< the IMU segment (s)
  // Camera.
  Eigen::Matrix3d R_target_cam = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_target_cam = Eigen::Vector3d::Zero();  ///< m, from the last frame used
  int num_frames = 0;
  double camera_spread_deg = 0.0;    ///< RMS of frame orientations about the average
  double reprojection_rms_px = 0.0;  ///< mean over the frames used
  /// Mean over the frames of their PnP orientation covariance (CameraPose::cov_rotation_rad2;
  /// rad^2, camera axes): the reprojection residuals beyond what the frames' scatter shows.
  Eigen::Matrix3d camera_pnp_cov_rad2 = Eigen::Matrix3d::Zero();
  PoseCameraSource camera_source = PoseCameraSource::kTarget;
  /// Natural scene: R_target_cam is the camera in the frame of scene `scene` (its first rest's
  /// camera frame; a rest whose view overlaps none in the window starts the next scene), chained
  /// through the strongest link; the links themselves enter the joint estimate.
  int scene = 0;
  int scene_features = 0;  ///< features in the rest's sharpest frame
  std::vector<SceneLinkSummary> scene_links;
  std::string scene_note;  ///< why the pose starts a new scene (its view overlaps no earlier one)
  // IMU.
  Eigen::Matrix3d R_world_imu = Eigen::Matrix3d::Identity();  ///< used for the pairs
  PoseImuSource imu_source = PoseImuSource::kGyro;            ///< where R_world_imu came from
  bool magnetometer_usable = false;
  std::string magnetometer_note;  ///< why not usable ("disturbed: dip changed by 5.1 deg", ...)
  std::optional<Eigen::Matrix3d> R_world_imu_accel_mag;  ///< when the field is usable
  std::optional<Eigen::Matrix3d>
      R_imu_previous_imu_gyro;                    ///< gyro rotation since the previous pose
  std::optional<double> gyro_mag_difference_deg;  ///< gyro vs accel+mag relative rotation
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();
};

/// A rest period that did not become a pose, and why.
struct RejectedPose {
  double start_s = 0.0, end_s = 0.0;
  std::string reason;  ///< "target seen in 1 frame (2 needed)", "camera spread 0.8 deg", ...
};
/// The start of RejectedPose::reason when no camera frame (image or camera pose) reached the
/// pipeline at all: the caller, who knows its topics, may say which one is silent.
inline constexpr char kNoCameraDataReason[] = "no camera data";

/// A copy of the window, to be solved away from the pipeline (WindowSolver), e.g. on a worker
/// thread while samples keep arriving.
struct WindowSnapshot {
  RotationPairs pairs;  ///< StationaryWindow::pairs
  JointProblem joint;   ///< the joint estimator's problem (imu_orientation: joint or magnetometer)
  std::vector<int> pose_indices;  ///< StationaryPose::index of each window pose, oldest first
  /// The natural-scene links' solutions as the gyro's consensus chose them
  /// (estimation/camera_link_consensus.h; joint.camera_links hold the chosen ones): filled by the
  /// solve's consensus stage (solve/window_solver.h), empty in a fresh snapshot.
  CameraLinkConsensus link_consensus;
  /// Natural scene: the links fitted again from their views near a prediction (the solve's scene
  /// refit stage); null without a natural scene. Shared, read-only.
  std::shared_ptr<const SceneLinkRefitter> scene_links;
};

struct PipelineCallbacks {
  std::function<void(const StationaryPose&)> on_pose;
  std::function<void(const RejectedPose&)> on_pose_rejected;
  /// Every rejected input: reason, the stream it came from, and a detail without the stream's
  /// name ("stamp 12.5 s is earlier than ..."); the caller names the topic and throttles.
  std::function<void(RejectReason, InputStream, const std::string&)> on_reject;
};

/// Sizes of everything the pipeline keeps, for diagnostics and the bounded-memory tests. Every
/// one is capped: the buffers by time (max_gyro_span_s, frame_queue_s), the window by
/// window_poses, the histories by CalibrationPipeline::kHistoryLimit.
struct PipelineBufferSizes {
  std::size_t imu = 0, mag = 0, frame_queue = 0, detections = 0;
  std::size_t poses = 0, rests = 0, rejected_rests = 0, window = 0;
};

class CalibrationPipeline : public SampleSink {
 public:
  /// poses(), segments() and rejectedPoses() keep the newest this many entries (a node running
  /// for days must not grow); the totals count all.
  static constexpr std::size_t kHistoryLimit = 1000;

  /// Throws SettingsError (an std::invalid_argument) when findProblem(settings) finds one
  /// (config/settings_checks.h).
  CalibrationPipeline(const TargetDescription& target, const PipelineSettings& settings,
                      PipelineCallbacks callbacks = {});
  ~CalibrationPipeline();

  void addImu(const ImuSample& sample) override;
  void addMagnetic(const MagneticSample& sample) override;
  /// Sets or replaces the intrinsics (validated; a bad one is counted and ignored).
  bool setCameraIntrinsics(const CameraIntrinsics& intrinsics) override;
  void addFrame(const CameraFrame& frame) override;
  /// Counts an input refused before it reached the pipeline (a ROS message without a stamp, an
  /// image that cannot be converted, ...) and reports it through on_reject like its own.
  void rejectInput(RejectReason reason, InputStream stream, const std::string& detail) override;
  ImuOrientationSource imuOrientationSource() const override;
  /// End of data: closes the rest in progress and processes the queued frames.
  void finish();
  /// A copy of the window for the WindowSolver.
  WindowSnapshot snapshot() const;
  /// The held fits a solve of an earlier snapshot made (WindowSolveOutput::scene_refits): the next
  /// snapshots' refitters reuse a fit whose prediction nearly matches.
  void rememberSceneRefits(const std::vector<SceneRefit>& refits);
  /// Forgets all data (poses, window, buffers; counts kept unless clear_counts); the camera
  /// intrinsics stay. Not from a callback.
  void reset(bool clear_counts = false);
  /// Keeps the window's poses with StationaryPose::index >= `pose_index` (a remount found by
  /// index, which stays valid while newer poses arrive).
  void keepPosesFrom(int pose_index);
  /// A mount change during continuous motion (MountChangeTest::change_stamp_s): the motion frames
  /// before `stamp_s` (camera clock) and the rests that began before it leave the window.
  void keepMotionFrom(double stamp_s);
  std::size_t windowSize() const;  ///< poses in the solver's window
  /// The poses in the solver's window, oldest first: the one answer to "which poses are in the
  /// window" (the snapshot, the solve, a remount's restart, --export-poses all use it).
  std::vector<StationaryPose> windowPoses() const;

  const std::vector<StationaryPose>& poses() const;  ///< the newest kHistoryLimit poses
  RotationPairs windowPairs() const;                 ///< the pairs of the window (as in snapshot())
  const std::vector<RejectedPose>& rejectedPoses() const;
  const std::vector<StationarySegment>& segments() const;  ///< the newest kHistoryLimit rests
  std::size_t posesTotal() const;  ///< poses since the start or the last reset
  /// Gaps in the IMU stamps longer than max_imu_gap_s (each ends a rest in progress).
  std::uint64_t imuGaps() const;
  std::size_t restsTotal() const;  ///< IMU rests (segments) since the start or the last reset
  PipelineBufferSizes bufferSizes() const;
  const RejectionCounts& rejections() const;
  /// Counters for progress and diagnostics.
  std::uint64_t imuSamples() const;
  std::uint64_t magneticSamples() const;
  std::uint64_t frames() const;
  std::uint64_t framesDetected() const;  ///< frames on which detection ran
  /// Frames during motion with a camera orientation (the joint estimate's motion frames), since
  /// the start or the last reset.
  std::uint64_t motionFrames() const;
  /// Detection ran on at least this many frames before targetNotFoundDiagnosis() speaks.
  static constexpr std::uint64_t kFramesForTargetDiagnosis = 3;
  /// "" unless the target was never found in kFramesForTargetDiagnosis or more frames at rest;
  /// then what is wrong: "the target (...) was not found in any of N frames at rest: does the
  /// target file describe the board in view?", with the size of the board seen when the detector
  /// found one of another size (TargetObservation::mismatch).
  std::string targetNotFoundDiagnosis() const;
  bool hasIntrinsics() const;
  /// Significance level of each of cameraModelCheck()'s two tests.
  static constexpr double kCameraModelLevel = 1e-4;
  /// Does camera_info's model fit the frames at rest (vision/camera_model_check.h)? One view per
  /// rest, from every frame whose target was detected (its pose accepted or refused).
  CameraModelCheck cameraModelCheck() const;
  const PipelineSettings& settings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace camera_imu_alignment
