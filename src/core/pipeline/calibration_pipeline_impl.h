// Private state of CalibrationPipeline, shared by its two source files (input side:
// calibration_pipeline.cpp; segment -> pose assembly: pose_assembly.cpp). Not installed.
#pragma once

#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/pipeline/stationary_window.h"
#include "camera_model_monitor.h"
#include "rest_statistics.h"

namespace camera_imu_alignment {

/// `value` with `precision` decimals, for the pipeline's messages.
inline std::string fmt(double value, int precision = 2) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(precision);
  out << value;
  return out.str();
}

/// 1-sigma (deg per axis) assumed for a camera orientation given without covariance (camera_pose).
constexpr double kGivenOrientationSigmaDeg = 0.05;
/// Frames during motion differing by less than this (s) from motion_frame_interval_s count as
/// that far apart: a 20 Hz camera's frames (0.05 s apart, in floating point 0.0499999...) are all
/// kept with the default 0.05 s, not two of every three.
constexpr double kMotionIntervalToleranceS = 1e-4;

/// Camera pose of one frame taken at rest.
struct FrameDetection {
  double stamp_s = 0.0;
  CameraPose pose;
};

/// The magnetometer over one rest (pose_assembly.cpp).
struct SegmentField {
  int count = 0;
  Eigen::Vector3d mean_t = Eigen::Vector3d::Zero();
  Eigen::Matrix3d mean_cov_t2 = Eigen::Matrix3d::Zero();  ///< covariance of the mean (scatter / N)
  double scatter_deg = 0.0;
};

struct CalibrationPipeline::Impl {
  Impl(const TargetDescription& target, const PipelineSettings& settings,
       PipelineCallbacks callbacks);

  // --- configuration
  TargetDescription target;
  PipelineSettings settings;
  PipelineCallbacks callbacks;
  TargetDetector detector;
  std::vector<Eigen::Matrix3d> symmetries;  ///< detector.symmetries()

  // --- streaming state
  StationaryDetector stationary;
  MagneticDisturbanceDetector disturbance;
  std::optional<CameraIntrinsics> intrinsics;
  RejectionCounts rejections;
  double last_imu_stamp = -std::numeric_limits<double>::infinity();
  double last_mag_stamp = -std::numeric_limits<double>::infinity();
  double last_frame_stamp = -std::numeric_limits<double>::infinity();
  std::deque<ImuSample> imu_buffer;        ///< since the end of the last segment (gyro chain)
  bool imu_buffer_truncated = false;       ///< samples needed by the next integration were dropped
  std::deque<MagneticSample> mag_buffer;   ///< calibrated field, tesla
  std::deque<CameraFrame> frame_queue;     ///< waiting until the IMU shows rest or motion
  std::vector<FrameDetection> detections;  ///< frames at rest with a camera pose
  double last_detection_stamp = -std::numeric_limits<double>::infinity();
  int misses_in_a_row = 0;            ///< failed detections in a row at the rest misses_rest
  std::optional<double> misses_rest;  ///< start of the rest they belong to
  std::uint64_t num_imu = 0, num_mag = 0, num_frames = 0, num_detected = 0;
  std::uint64_t frames_without_intrinsics = 0, frames_dropped = 0;
  std::string target_mismatch;  ///< the detector's latest TargetObservation::mismatch
  /// What the frames at rest say about camera_info's model (every detection, pose or not).
  CameraModelMonitor camera_model{CalibrationPipeline::kHistoryLimit};

  // --- IMU orientation chain (see the rule in calibration_pipeline.h)
  bool chain_valid = false;
  StationarySegment chain_segment;  ///< the last segment, pose or not
  Eigen::Matrix3d chain_R_world_imu = Eigen::Matrix3d::Identity();
  std::optional<Eigen::Matrix3d> chain_R_world_imu_accel_mag;  ///< of chain_segment
  int group = 0;
  bool group_magnetic = false;  ///< the current group's heading comes from the magnetometer
  bool group_message = false;   ///< the current group's frame is the IMU's own (kMessage)

  // --- results
  std::vector<StationarySegment> segments;
  std::vector<StationaryPose> poses;
  std::vector<RejectedPose> rejected;
  StationaryWindow window;  ///< the poses the next solve uses, with their joint measurements
  /// Raw gyro samples since the last pose's rest (through rests that became no pose); empty
  /// optional while there is no pose yet or the gyro chain broke since.
  std::optional<GyroSegment> joint_gyro_pending;
  double last_gyro_noise_density = 0.0;  ///< of the previous rest (rad/s/sqrt(Hz))

  // --- continuous motion (settings.motion_window_s > 0)
  std::deque<MotionFrame> motion_frames;  ///< frames outside the rests with a camera orientation
  /// Raw IMU samples during the motion window: stamp, gyro (rad/s), accelerometer (m/s^2).
  struct RawImu {
    double stamp_s;
    Eigen::Vector3d gyro_rad_s, accel_m_s2;
  };
  std::deque<RawImu> motion_gyro;
  double last_motion_frame_stamp = -std::numeric_limits<double>::infinity();
  std::uint64_t motion_frames_total = 0;
  std::uint64_t motion_detections = 0;  ///< frames during motion on which detection ran
  /// The target's image points (pixels) in the last frame during motion where it was found, and
  /// that frame's stamp (s): the next frame's detection searches near them first.
  std::vector<cv::Point2f> last_motion_points;
  double last_motion_points_stamp = -std::numeric_limits<double>::infinity();

  // --- natural scene (no target: TargetDescription::numPoints() == 0; scene_assembly.cpp)
  bool natural_scene = false;
  std::uint64_t given_orientations = 0;  ///< frames that came with R_target_cam (camera_pose)
  /// Frames at rest (min_frame_interval_s apart) since the last rest ended.
  struct SceneCandidate {
    double stamp_s = 0, sharpness = 0;
    cv::Mat mono8;
  };
  std::deque<SceneCandidate> scene_candidates;
  /// The features of accepted poses, newest last (at most window_poses + 1).
  struct SceneView {
    int pose_index = 0, scene = 0, group = 0;
    Eigen::Matrix3d R_scene_cam = Eigen::Matrix3d::Identity();
    Eigen::Matrix3d R_world_imu = Eigen::Matrix3d::Identity();  ///< the pose's (gyro chain)
    std::shared_ptr<const SceneFeatures> features;  ///< shared with the snapshots' refits
  };
  std::deque<SceneView> scene_views;
  /// Links fitted again with the rotation held (WindowSnapshot::scene_links), by their poses'
  /// StationaryPose::index, as solves returned them (rememberSceneRefits): a later solve with
  /// nearly the same prediction reuses the fit.
  SceneRefitMemory scene_refits;
  /// The matches of each link (by its poses' StationaryPose::index), for fitting it again.
  std::map<std::pair<int, int>, std::shared_ptr<const SceneMatches>> scene_link_matches;
  int scenes_started = 0;
  std::uint64_t rotations_refused_by_imu = 0;  ///< scene rotations the IMU's angle contradicts

  std::size_t poses_total = 0, rests_total = 0;
  std::uint64_t imu_gaps = 0;  ///< IMU stamp gaps longer than settings.stationary.max_gap_s

  void reject(RejectReason reason, InputStream stream, const std::string& detail);
  /// Stamp order check shared by the three streams; false (counted) when rejected.
  bool checkStamp(double stamp, double* last, InputStream stream);
  /// Processes queued frames whose rest/motion status the IMU has settled.
  void processFrames(bool flush);
  void processFrame(const CameraFrame& frame);
  /// A frame during motion: its camera orientation (detection and PnP, or the given one) joins
  /// motion_frames.
  void processMotionFrame(const CameraFrame& frame);
  /// The motion frames and gyro for the joint problem: frames from `from_s` on.
  void addMotion(double from_s, JointProblem* problem) const;
  /// A stationary segment ended: build the pose (pose_assembly.cpp) in these steps.
  void onSegment(const StationarySegment& segment);
  /// The rest's mean field: sets magnetometer_usable / R_world_imu_accel_mag or the note why not.
  SegmentField assessMagnetometer(const StationarySegment& segment, StationaryPose* pose);
  /// The gyro rotation since the previous rest (R_imu_previous_imu_gyro) and its difference to
  /// the accelerometer + magnetometer one.
  void integrateGyroSincePrevious(const StationarySegment& segment, StationaryPose* pose) const;
  /// R_world_imu, imu_source and group by the rule in calibration_pipeline.h; advances the chain.
  void chooseImuOrientation(const StationarySegment& segment, StationaryPose* pose);
  /// The camera orientation from the frames inside the rest; the reason the rest is no pose, or "".
  std::string assessCamera(const StationarySegment& segment, StationaryPose* pose);
  /// Why a rest has no camera frame when no camera data or no camera info came at all, else "".
  std::string silentCameraReason() const;
  /// Natural scene: keeps the frame if it is the sharpest of its rest so far.
  void keepSceneCandidate(const CameraFrame& frame);
  /// Natural scene: the camera orientation from features matched with earlier rests (the links
  /// go into `entry`); the reason the rest is no pose, or "".
  std::string assessScene(const StationarySegment& segment, StationaryPose* pose,
                          StationaryWindow::Entry* entry);
  /// Adds the pose to the history and the window and reports it (on_pose).
  void acceptPose(const StationaryPose& pose, StationaryWindow::Entry joint_entry);
  /// The rest's measurements for the joint estimate (before the buffers move on); advances
  /// joint_gyro_pending by the gyro samples since the previous rest.
  StationaryWindow::Entry jointMeasurements(const StationarySegment& segment,
                                            const StationaryPose& pose, const SegmentField& field);
  /// Natural scene: WindowSnapshot::scene_links for `problem`'s links (pose indices local to the
  /// window, `pose_indices` their StationaryPose::index); null without a natural scene.
  std::shared_ptr<const SceneLinkRefitter> sceneLinkRefitter(
      const JointProblem& problem, const std::vector<int>& pose_indices) const;
  WindowSnapshot snapshot() const;
};

}  // namespace camera_imu_alignment
