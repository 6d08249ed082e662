// Private state of CalibrationPipeline, shared by its source files (input side:
// calibration_pipeline.cpp; segment -> pose assembly: pose_assembly.cpp; motion:
// motion_assembly.cpp). The camera's side is its CameraSource (camera_source.h). Not installed.
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
#include "camera_source.h"
#include "rest_statistics.h"

namespace camera_imu_alignment {

/// Frames during motion differing by less than this (s) from motion_frame_interval_s count as
/// that far apart: a 20 Hz camera's frames (0.05 s apart, in floating point 0.0499999...) are all
/// kept with the default 0.05 s, not two of every three.
constexpr double kMotionIntervalToleranceS = 1e-4;

/// The magnetometer over one rest (pose_assembly.cpp).
struct SegmentField {
  int count = 0;
  Eigen::Vector3d mean_t = Eigen::Vector3d::Zero();
  Eigen::Matrix3d mean_cov_t2 = Eigen::Matrix3d::Zero();  ///< covariance of the mean (scatter / N)
  double scatter_deg = 0.0;
};

/// The inputs as counted. reset() keeps all but frames_dropped unless it clears the counts.
struct InputCounts {
  RejectionCounts rejections;
  std::uint64_t imu = 0, magnetic = 0;  ///< samples accepted
  std::uint64_t imu_gaps = 0;        ///< IMU stamp gaps longer than settings.stationary.max_gap_s
  std::uint64_t frames_dropped = 0;  ///< frames that waited longer than frame_queue_s for the IMU
};

/// Each stream's latest accepted stamp (s), for the order check (checkStamp).
struct StreamStamps {
  double imu = -std::numeric_limits<double>::infinity();
  double magnetic = -std::numeric_limits<double>::infinity();
  double frame = -std::numeric_limits<double>::infinity();  ///< images or camera poses
};

/// The IMU's and the magnetometer's samples since the end of the last rest (at most
/// max_gyro_span_s): the gyro chain's integration and each rest's means.
struct ImuBuffers {
  std::deque<ImuSample> imu;
  bool imu_truncated = false;      ///< samples needed by the next integration were dropped
  std::deque<MagneticSample> mag;  ///< calibrated field, tesla
};

/// The IMU orientation chain (see the rule in calibration_pipeline.h).
struct ImuChain {
  bool valid = false;
  StationarySegment segment;  ///< the last segment, pose or not
  Eigen::Matrix3d R_world_imu = Eigen::Matrix3d::Identity();
  std::optional<Eigen::Matrix3d> R_world_imu_accel_mag;  ///< of segment
  int group = 0;
  bool group_magnetic = false;  ///< the current group's heading comes from the magnetometer
  bool group_message = false;   ///< the current group's frame is the IMU's own (kMessage)
};

/// The raw gyro between poses for the joint estimate.
struct JointGyro {
  /// Raw gyro samples since the last pose's rest (through rests that became no pose); empty
  /// optional while there is no pose yet or the gyro chain broke since.
  std::optional<GyroSegment> pending;
  double last_noise_density = 0.0;  ///< of the previous rest (rad/s/sqrt(Hz))
};

/// What the pipeline assembled: the newest CalibrationPipeline::kHistoryLimit of each, and totals.
struct PoseRecords {
  std::vector<StationarySegment> segments;  ///< the rests, pose or not
  std::vector<StationaryPose> poses;
  std::vector<RejectedPose> rejected;
  std::size_t poses_total = 0, rests_total = 0;
};

/// Continuous motion (settings.motion_window_s > 0): what the joint estimate's motion nodes use.
struct MotionBuffers {
  /// A raw IMU sample: stamp (s), gyro (rad/s), accelerometer (m/s^2).
  struct RawImu {
    double stamp_s;
    Eigen::Vector3d gyro_rad_s, accel_m_s2;
  };
  std::deque<MotionFrame> frames;  ///< frames outside the rests with a camera orientation
  std::deque<RawImu> gyro;         ///< the raw IMU during the motion window
  double last_frame_stamp = -std::numeric_limits<double>::infinity();
  std::uint64_t frames_total = 0;  ///< since the start or the last reset
};

struct CalibrationPipeline::Impl {
  Impl(const TargetDescription& target, const PipelineSettings& settings,
       PipelineCallbacks callbacks);

  // --- configuration
  TargetDescription target;
  PipelineSettings settings;
  PipelineCallbacks callbacks;

  // --- input side
  StationaryDetector stationary;
  MagneticDisturbanceDetector disturbance;
  InputCounts counts;
  StreamStamps stamps;
  ImuBuffers buffers;
  std::deque<CameraFrame> frame_queue;  ///< waiting until the IMU shows rest or motion

  // --- the camera
  CameraInputs camera;  ///< intrinsics and frame counts, read by the source
  /// The stream of the first camera frame, which chose the source (kept across reset()); frames
  /// of the other stream are refused.
  std::optional<InputStream> camera_stream;
  std::unique_ptr<CameraSource> source = makeNoCameraSource();

  // --- rests to poses
  ImuChain chain;
  JointGyro joint_gyro;
  PoseRecords records;
  StationaryWindow window;  ///< the poses the next solve uses, with their joint measurements

  MotionBuffers motion;

  void reject(RejectReason reason, InputStream stream, const std::string& detail);
  /// Stamp order check shared by the three streams; false (counted) when rejected.
  bool checkStamp(double stamp, double* last, InputStream stream);
  /// The source for frames of `stream` (chooseCameraSource), remembered in camera_stream.
  void chooseSource(InputStream stream);
  /// The poses so far, for the source.
  PoseHistoryView history() const { return {records.poses, window}; }
  /// Processes queued frames whose rest/motion status the IMU has settled.
  void processFrames(bool flush);
  /// A frame during motion: its camera orientation (CameraSource::takeMotionFrame) joins
  /// motion.frames.
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
  /// Adds the pose to the history and the window and reports it (on_pose).
  void acceptPose(const StationaryPose& pose, StationaryWindow::Entry joint_entry);
  /// The rest's measurements for the joint estimate (before the buffers move on); advances
  /// joint_gyro.pending by the gyro samples since the previous rest.
  StationaryWindow::Entry jointMeasurements(const StationarySegment& segment,
                                            const StationaryPose& pose, const SegmentField& field);
  WindowSnapshot snapshot() const;
};

}  // namespace camera_imu_alignment
