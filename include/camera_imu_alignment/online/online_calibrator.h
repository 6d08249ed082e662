// The online calibrator: everything the nodelet decides, without ROS. It owns the calibration
// pipeline (samples -> stationary poses -> window), solves the window (the paper's two-step, the
// optimal pair estimate and the joint maximum-likelihood estimate), tests the window for a mount
// change, applies the quality gates (broadcast_gate.h) and keeps the state. Data flow one way:
// samples in, events out (OnlineCallbacks). calibrate_bag and the nodelet both drive it, so both
// give the same answer on the same recording.
//
// Solving runs on a worker thread when OnlineSettings::threaded (the nodelet: a 30-pose window
// takes tens of ms, the change test a few solves more) so that the sample calls stay short; the
// newest request wins. Results are applied, and events emitted, on the caller's thread inside the
// sample calls or poll(): call every method from one thread. Without threading (calibrate_bag,
// tests) a solve runs inside the sample call that completed a pose.
//
// Remount (a mount change) is found in two ways:
//   joint estimate (imu_orientation: joint or magnetometer): after every solve the window is tested
//   for a change
//     point among its newest poses (estimation/mount_change.h), whether or not anything was
//     broadcast; when found, the window restarts from the poses after the change and the next
//     estimate is judged without the old one as a reference.
//   pair modes: remount_poses consecutive new poses whose pairs disagree with the broadcast
//     estimate by more than remount_residual_deg restart the window from them.
// Neither is declared while camera_info's model does not fit the images
// (CalibrationPipeline::cameraModelCheck): a wrong focal length bends every pose as a remount
// would. Then no estimate is broadcast, the verdict and the snapshot's message name camera_info.
// A clock jump back (a bag loop, a restarted simulation) clears the window and the buffers; the
// broadcast estimate stays.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "camera_imu_alignment/online/broadcast_gate.h"
#include "camera_imu_alignment/online/calibration_snapshot.h"
#include "camera_imu_alignment/online/clock_jump.h"
#include "camera_imu_alignment/online/online_types.h"
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/pipeline/sample_sink.h"

namespace camera_imu_alignment {

struct OnlineCallbacks {
  std::function<void(const StationaryPose&)> on_pose;
  /// A rest that did not become a pose; the reason says "not armed" for manual capture.
  std::function<void(const RejectedPose&)> on_pose_rejected;
  std::function<void(RejectReason, InputStream, const std::string&)> on_reject;
  /// A solve was applied: called once per solve, after its state, message and broadcast
  /// (on_broadcast) are in place; its state change comes through here, not through on_state.
  std::function<void(const EstimateEvent&)> on_estimate;
  /// The static tf must say this now (and the file be saved when source is "estimated": then an
  /// on_estimate follows).
  std::function<void(const BroadcastEstimate&)> on_broadcast;
  std::function<void(const RemountEvent&)> on_remount;
  /// The state or its message changed other than by a solve (data flowing, a reset, a remount).
  std::function<void(CalibrationState, const std::string&)> on_state;
  /// Time jumped back on `stream` by jump_s (s): window and buffers cleared.
  std::function<void(double jump_s, InputStream stream)> on_clock_jump;
};

/// The answer of calibrateNow.
struct CalibrateOutcome {
  AlignmentResult result;
  GateOutcome gate;
  bool broadcast = false;            ///< it is now what the tf says
  std::string not_broadcast_reason;  ///< "" when broadcast
  std::size_t window_poses = 0;
  /// The recording's verdict on this estimate (recordingVerdict; none when not solved).
  std::optional<CalibrationVerdict> verdict;
};

class OnlineCalibrator : public SampleSink {
 public:
  /// Throws std::invalid_argument when a setting is unusable (named by its key).
  OnlineCalibrator(const TargetDescription& target, const PipelineSettings& pipeline_settings,
                   const OnlineSettings& settings, OnlineCallbacks callbacks);
  ~OnlineCalibrator() override;  ///< stops the worker (a running solve finishes first)

  // --- samples (each also applies finished solves)
  void addImu(const ImuSample& sample) override;
  void addMagnetic(const MagneticSample& sample) override;
  bool setCameraIntrinsics(const CameraIntrinsics& intrinsics) override;
  void addFrame(const CameraFrame& frame) override;
  void rejectInput(RejectReason reason, InputStream stream, const std::string& detail) override;
  ImuOrientationSource imuOrientationSource() const override;
  /// End of data (or the IMU stopped): closes the rest in progress, and solves the window when
  /// camera frames during motion arrived since its last solve.
  void finish();
  /// Applies finished solves (threaded); call periodically.
  void poll();
  /// Waits for the worker to finish what it has, then applies it (tests, calibrate_bag, shutdown).
  void waitForSolves();

  // --- requests
  /// Solves the window now on the caller's thread and applies the gates; `force` broadcasts an
  /// estimate that fails a gate (not one that does not exist: bad input, not observable).
  CalibrateOutcome calibrateNow(bool force);
  /// Forgets the window, the buffers, the latest estimate and the remount count; the broadcast
  /// estimate stays (as the tf does) but is no longer a reference for the gates.
  void reset();
  /// A saved calibration: broadcast it (on_broadcast) and use it as the gates' reference.
  void loadBroadcast(const BroadcastEstimate& estimate);
  /// manual_capture: the current (or next) rest becomes a pose.
  void armCapture();
  /// Whether camera frames are wanted now (manual_capture: only while armed).
  bool wantsFrames() const;

  // --- state
  CalibrationState state() const;
  const std::string& stateMessage() const;
  const std::optional<EstimateEvent>& lastEstimate() const;
  const std::optional<BroadcastEstimate>& broadcast() const;
  /// Newest stamp on any input (s), -1 before the first.
  double newestStamp() const;
  const OnlineSettings& settings() const;
  /// Everything the outputs show, as one value (calibration_snapshot.h); the pose histories only
  /// with kWithHistory. Call it per output, not per sample.
  CalibrationSnapshot snapshot(SnapshotContents contents = SnapshotContents::kState) const;
  /// The input counters alone (cheap: per sample).
  InputCounts inputCounts() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace camera_imu_alignment
