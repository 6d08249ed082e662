// OnlineCalibrator (online_calibrator.h): state, gates, remounts; solving in solve_worker.
#include "camera_imu_alignment/online/online_calibrator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "camera_imu_alignment/config/online_config.h"
#include "camera_imu_alignment/config/settings_checks.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/solver/solution_quality.h"
#include "solve_worker.h"

namespace camera_imu_alignment {

const char* toString(CalibrationState state) {
  switch (state) {
    case CalibrationState::kWaitingForData:
      return "waiting_for_data";
    case CalibrationState::kCollecting:
      return "collecting";
    case CalibrationState::kCalibrated:
      return "calibrated";
    case CalibrationState::kNotObservable:
      return "not_observable";
    case CalibrationState::kRecalibrating:
      return "recalibrating";
  }
  return "?";
}

struct OnlineCalibrator::Impl {
  Impl(const TargetDescription& target, const PipelineSettings& pipeline_settings,
       const OnlineSettings& online, OnlineCallbacks cb);

  PipelineSettings pipeline_settings;
  OnlineSettings settings;
  OnlineCallbacks callbacks;
  std::unique_ptr<CalibrationPipeline> pipeline;
  std::unique_ptr<SolveWorker> worker;  ///< when threaded
  ClockJumpDetector clock;

  std::uint64_t generation = 0;  ///< bumped when the window loses poses: older solves are stale
  CalibrationState state = CalibrationState::kWaitingForData;
  std::string message = "waiting for IMU and camera data";
  std::optional<EstimateEvent> last_estimate;
  /// The newest solve applied as an estimate (no remount, not stale), for calibrateNow.
  std::optional<SolveOutput> last_solved;
  std::uint64_t finishes = 0;  ///< finish() calls (each may close a rest)
  InputMark inputMark() const {
    return {generation, pipeline->imuSamples(), pipeline->magneticSamples(), pipeline->frames(),
            finishes};
  }
  std::optional<BroadcastEstimate> broadcast;
  std::optional<StationaryPose> last_pose;
  bool fresh_start = false;    ///< the broadcast estimate is no reference (remount, reset)
  bool recalibrating = false;  ///< a remount was found and nothing broadcast since
  int remounts = 0;
  std::vector<RemountEvent> remount_events;  ///< the newest kRemountHistory
  static constexpr std::size_t kRemountHistory = 100;
  int inconsistent_poses = 0;  ///< pair modes: consecutive poses off the broadcast estimate
  bool capture_armed = false;

  bool joint() const { return usesJointEstimate(pipeline_settings.imu_orientation); }
  /// True while an estimate is applied: its state change is reported by the on_estimate that
  /// follows (one status per solve, with its own message), not by on_state.
  bool applying_estimate = false;
  void setState(CalibrationState s, const std::string& text) {
    const bool changed = s != state || text != message;
    state = s;
    message = text;
    if (changed && !applying_estimate && callbacks.on_state) callbacks.on_state(state, message);
  }
  /// The estimate's effects (state, broadcast), then on_estimate once they are all in place.
  template <typename Effects>
  void applyThenReport(const EstimateEvent& event, Effects effects) {
    applying_estimate = true;
    effects();
    applying_estimate = false;
    if (callbacks.on_estimate) callbacks.on_estimate(event);
  }
  /// waiting_for_data -> collecting once IMU and camera data flow.
  void refreshWaiting() {
    if (state != CalibrationState::kWaitingForData) return;
    if (pipeline->imuSamples() > 0 && (pipeline->hasIntrinsics() || pipeline->frames() > 0)) {
      setState(CalibrationState::kCollecting, "waiting for stationary poses");
    }
  }
  /// A stamp far behind the input's newest (a bag loop): window and buffers cleared.
  void checkClock(double stamp_s, InputStream stream);
  void onPose(const StationaryPose& pose);
  void onPoseRejected(const RejectedPose& rejected);
  void checkPairRemount(const StationaryPose& pose);
  void requestSolve();
  /// Continuous motion: a solve after kMotionFramesPerSolve motion frames without one.
  void onMotionFrames();
  std::uint64_t motion_frames_solved = 0;  ///< pipeline->motionFrames() at the last such solve
  /// Motion frames in the window of the last solve (OnlineSettings::motion_solves_double).
  std::uint64_t motion_frames_in_solved_window = 0;
  /// StationaryPose::index of the newest pose a change-point test had in its window (-1: none
  /// since the poses were last cleared).
  int newest_pose_change_tested = -1;
  /// Applies what the worker finished (threaded, not solves_in_order); call periodically.
  void poll();
  /// Waits for the worker's solve, if any, and applies it (every mode).
  void applyFinished();
  void apply(SolveOutput output);
  void applyRemount(const SolveOutput& output);
  /// Keeps the window's poses from `kept_index` on (the mount changed before `first_index` <=
  /// kept_index) and says so (state, on_remount).
  /// `change_stamp_s`: a change during the motion (RemountEvent::change_stamp_s), else NaN.
  void restartWindowAt(int first_index, int kept_index, double change_deg, const std::string& text,
                       double change_stamp_s = std::numeric_limits<double>::quiet_NaN());
  /// The output as an estimate judged by the gates against what is broadcast now.
  EstimateEvent judged(SolveOutput output) const;
  void applyEstimate(EstimateEvent event);
  /// `forced_although`: "" unless broadcast on request (force) although this gate failed.
  void doBroadcast(const AlignmentResult& result, std::size_t poses,
                   const std::string& forced_although = "");
  /// A more precise estimate within min_change_deg: the tf keeps its rotation, the saved file
  /// and the broadcast 1-sigma become the new estimate's (on_broadcast saves it).
  void refineBroadcast(const AlignmentResult& result, std::size_t poses);
};

OnlineCalibrator::Impl::Impl(const TargetDescription& target,
                             const PipelineSettings& pipeline_settings_in,
                             const OnlineSettings& online, OnlineCallbacks cb)
    : pipeline_settings(pipeline_settings_in), settings(online), callbacks(std::move(cb)) {
  throwIfProblem("", findProblem(pipeline_settings, settings));
  PipelineCallbacks pc;
  pc.on_pose = [this](const StationaryPose& p) { onPose(p); };
  pc.on_pose_rejected = [this](const RejectedPose& r) { onPoseRejected(r); };
  pc.on_reject = [this](RejectReason reason, InputStream stream, const std::string& detail) {
    if (callbacks.on_reject) callbacks.on_reject(reason, stream, detail);
  };
  pipeline = std::make_unique<CalibrationPipeline>(target, pipeline_settings, pc);
  if (settings.threaded) worker = std::make_unique<SolveWorker>(pipeline_settings, settings);
}

void OnlineCalibrator::Impl::checkClock(double stamp_s, InputStream stream) {
  const double jump_s = clock.update(toString(stream), stamp_s);
  if (jump_s <= 0.0) return;
  pipeline->reset();
  motion_frames_solved = 0;
  newest_pose_change_tested = -1;
  ++generation;
  inconsistent_poses = 0;
  last_pose.reset();
  if (callbacks.on_clock_jump) callbacks.on_clock_jump(jump_s, stream);
}

void OnlineCalibrator::Impl::onPose(const StationaryPose& pose) {
  last_pose = pose;
  capture_armed = false;
  if (callbacks.on_pose) callbacks.on_pose(pose);
  if (!joint()) checkPairRemount(pose);
  if (static_cast<int>(pipeline->windowSize()) >= pipeline_settings.min_poses_to_solve) {
    requestSolve();
  }
}

void OnlineCalibrator::Impl::onPoseRejected(const RejectedPose& rejected) {
  RejectedPose out = rejected;
  // manual_capture: a rest during which capture was not armed saw no camera data on purpose; the
  // pipeline's reason ("no camera data") would send the user looking for a fault.
  if (settings.manual_capture && !capture_armed) {
    out.reason = "not armed (manual_capture: arm the capture during a rest to make it a pose)";
  }
  capture_armed = false;
  if (callbacks.on_pose_rejected) callbacks.on_pose_rejected(out);
}

void OnlineCalibrator::Impl::checkPairRemount(const StationaryPose& pose) {
  if (!broadcast || pipeline->cameraModelCheck().wrong) return;
  // The new pose's pairs with the rest of the window against the broadcast estimate.
  const RotationPairs pairs = pipeline->windowPairs();
  int newest = -1;
  for (const auto& p : pairs) newest = std::max(newest, p.pose_t);
  double sum_sq = 0.0;
  int count = 0;
  for (const auto& p : pairs) {
    if (p.pose_t != newest) continue;
    sum_sq += pairResidual(p, broadcast->R_cam_imu).squaredNorm();
    ++count;
  }
  const double rms_deg = count > 0 ? rad2deg(std::sqrt(sum_sq / count)) : 0.0;
  inconsistent_poses = rms_deg > settings.remount_residual_deg ? inconsistent_poses + 1 : 0;
  if (inconsistent_poses < settings.remount_poses) return;
  const int first_index = pose.index - settings.remount_poses + 1;
  char text[256];
  std::snprintf(text, sizeof(text),
                "mount changed before pose %d: the last %d poses disagree with the broadcast "
                "estimate by more than remount_residual_deg %.2f deg; window restarted from them",
                first_index, settings.remount_poses, settings.remount_residual_deg);
  restartWindowAt(first_index, first_index, 0.0, text);
}

void OnlineCalibrator::Impl::restartWindowAt(int first_index, int kept_index, double change_deg,
                                             const std::string& text, double change_stamp_s) {
  pipeline->keepPosesFrom(kept_index);
  ++generation;  // solves still running saw the old mount's poses
  ++remounts;
  inconsistent_poses = 0;
  recalibrating = fresh_start = true;
  setState(CalibrationState::kRecalibrating, text);
  RemountEvent event{first_index, kept_index, change_deg, pipeline->windowSize(), text};
  event.change_stamp_s = change_stamp_s;
  if (remount_events.size() >= kRemountHistory) remount_events.erase(remount_events.begin());
  remount_events.push_back(event);
  if (callbacks.on_remount) callbacks.on_remount(event);
}

void OnlineCalibrator::Impl::requestSolve() {
  if (worker && settings.solves_in_order) applyFinished();  // the previous solve's, first
  motion_frames_solved = pipeline->motionFrames();
  SolveJob job;
  job.inputs = inputMark();
  job.window = pipeline->snapshot();
  motion_frames_in_solved_window = job.window.joint.motion_frames.size();
  job.test_mount_change = joint();
  job.poses_not_yet_tested = static_cast<int>(
      std::count_if(job.window.pose_indices.begin(), job.window.pose_indices.end(),
                    [this](int index) { return index > newest_pose_change_tested; }));
  if (worker) {
    worker->submit(std::move(job));
  } else {
    apply(runSolveJob(std::move(job), pipeline_settings, settings));
  }
}

void OnlineCalibrator::Impl::onMotionFrames() {
  constexpr std::uint64_t kMotionFramesPerSolve = 100;  // 5 s at 20 Hz
  const std::uint64_t frames = pipeline->motionFrames();
  const std::uint64_t wait = settings.motion_solves_double
                                 ? std::max(kMotionFramesPerSolve, motion_frames_in_solved_window)
                                 : kMotionFramesPerSolve;
  if (frames < motion_frames_solved + wait) return;
  requestSolve();
}

void OnlineCalibrator::Impl::poll() {
  if (!worker || settings.solves_in_order) return;  // in order: applied at the defined points
  for (SolveOutput& output : worker->takeFinished()) apply(std::move(output));
}

void OnlineCalibrator::Impl::applyFinished() {
  if (!worker) return;
  worker->waitIdle();
  for (SolveOutput& output : worker->takeFinished()) apply(std::move(output));
}

void OnlineCalibrator::Impl::apply(SolveOutput output) {
  pipeline->rememberSceneRefits(output.scene_refits);
  if (output.inputs.generation != generation) return;  // the window lost poses since: stale
  if (output.result.status == SolveStatus::kBadInput) return;
  if (output.mount_test && output.mount_test->tested && !output.window.pose_indices.empty()) {
    newest_pose_change_tested =
        std::max(newest_pose_change_tested, output.window.pose_indices.back());
  }
  // A camera model that does not fit the images biases the poses as a remount would: no remount
  // is declared then (the estimate is refused, naming camera_info).
  if (output.mount_test && output.mount_test->detected && !pipeline->cameraModelCheck().wrong) {
    applyRemount(output);
    return;
  }
  // For calibrateNow: the estimate and its window's poses, not the window's data.
  last_solved.emplace();
  last_solved->inputs = output.inputs;
  last_solved->window.pose_indices = output.window.pose_indices;
  last_solved->result = output.result;
  applyEstimate(judged(std::move(output)));
}

EstimateEvent OnlineCalibrator::Impl::judged(SolveOutput output) const {
  EstimateEvent event;
  event.result = std::move(output.result);
  event.window_poses = output.window.pose_indices.size();
  event.mount_test = std::move(output.mount_test);
  event.gate = judgeEstimate(event.result, event.window_poses, settings, broadcast, fresh_start);
  // The gate's consistency verdict travels with the result: the YAML and the report print it.
  if (event.result.joint) event.result.joint->consistency_level = settings.consistency_level;
  const CameraModelCheck camera_model = pipeline->cameraModelCheck();
  if (camera_model.wrong) {  // the poses are biased: neither broadcast nor a remount verdict
    event.camera_model_problem = camera_model.message;
    event.gate.decision = GateDecision::kReject;
    event.gate.why = camera_model.message;
  } else if (event.mount_test && event.mount_test->pending &&
             event.gate.decision == GateDecision::kBroadcast) {
    // The newest pose disagrees with the window as a remount would: an estimate over both mounts
    // (or with a bad pose) is not broadcast; the next pose decides.
    event.gate.decision = GateDecision::kReject;
    event.gate.why = event.mount_test->message;
  }
  return event;
}

void OnlineCalibrator::Impl::applyRemount(const SolveOutput& output) {
  const MountChangeTest& test = *output.mount_test;
  if (std::isfinite(test.change_stamp_s)) {  // during continuous motion
    const double from_s = test.change_stamp_s + 0.5 * settings.remount.motion_gap_s;
    pipeline->keepMotionFrom(from_s);
    const int next_index = static_cast<int>(pipeline->poses().size());
    char text[400];
    std::snprintf(text, sizeof(text),
                  "mount changed during the motion at %.2f s (by %.2f deg; chi-square change test "
                  "p %.2g < remount_level %.2g): window restarted from the motion after %.2f s",
                  test.change_stamp_s, test.change_deg, test.p_value, settings.remount.level,
                  from_s);
    const std::vector<StationaryPose> kept = pipeline->windowPoses();
    const int first = kept.empty() ? next_index : kept.front().index;
    restartWindowAt(first, first, test.change_deg, text, test.change_stamp_s);
    motion_frames_solved = pipeline->motionFrames();  // the next solve waits for new motion
    motion_frames_in_solved_window = 0;
    return;
  }
  const int first_index = output.window.pose_indices.at(test.first_pose_after);
  const int kept_index = output.window.pose_indices.at(test.first_pose_kept);
  const std::size_t kept = static_cast<std::size_t>(
      std::count_if(output.window.pose_indices.begin(), output.window.pose_indices.end(),
                    [&](int index) { return index >= kept_index; }));
  char text[400];
  const int length = std::snprintf(
      text, sizeof(text),
      "mount changed before pose %d (by %.2f deg; chi-square change test p %.2g < remount_level "
      "%.2g): window restarted from the %zu poses after it",
      first_index, test.change_deg, test.p_value, settings.remount.level, kept);
  if (kept_index != first_index && length > 0 && length < static_cast<int>(sizeof(text))) {
    std::snprintf(text + length, sizeof(text) - length,
                  ", from pose %d on (a change before it fits as well; an old-mount pose would "
                  "bias the new estimate)",
                  kept_index);
  }
  const std::string message = text;
  restartWindowAt(first_index, kept_index, test.change_deg, message);
  if (static_cast<int>(pipeline->windowSize()) >= pipeline_settings.min_poses_to_solve) {
    requestSolve();
  }
}

void OnlineCalibrator::Impl::applyEstimate(EstimateEvent event) {
  last_estimate = event;
  applyThenReport(event, [&] {
    switch (event.gate.decision) {
      case GateDecision::kReject:
        setState(event.result.status == SolveStatus::kNotObservable
                     ? CalibrationState::kNotObservable
                 : recalibrating             ? CalibrationState::kRecalibrating
                 : broadcast && !fresh_start ? CalibrationState::kCalibrated
                                             : CalibrationState::kCollecting,
                 "estimate not broadcast: " + event.gate.why);
        return;
      case GateDecision::kKeep:
        if (event.gate.refines_broadcast) refineBroadcast(event.result, event.window_poses);
        setState(CalibrationState::kCalibrated, "the broadcast estimate stays: " + event.gate.why);
        return;
      case GateDecision::kBroadcast:
        doBroadcast(event.result, event.window_poses);
        return;
    }
  });
}

void OnlineCalibrator::Impl::doBroadcast(const AlignmentResult& result, std::size_t poses,
                                         const std::string& forced_although) {
  BroadcastEstimate b;
  b.forced_although = forced_although;
  b.R_cam_imu = result.R_cam_imu;
  b.std_dev_deg = result.quality.std_dev_deg;
  if (result.joint && result.joint->ok) b.covariance_rad2 = result.joint->covariance_rad2;
  b.poses = static_cast<int>(poses);
  b.source = "estimated";
  b.result = result;
  broadcast = b;
  fresh_start = recalibrating = false;
  inconsistent_poses = 0;
  setState(CalibrationState::kCalibrated, result.message);
  if (callbacks.on_broadcast) callbacks.on_broadcast(b);
}

void OnlineCalibrator::Impl::refineBroadcast(const AlignmentResult& result, std::size_t poses) {
  if (!broadcast) return;
  BroadcastEstimate& b = *broadcast;
  b.std_dev_deg = result.quality.std_dev_deg;
  b.covariance_rad2.reset();
  if (result.joint && result.joint->ok) b.covariance_rad2 = result.joint->covariance_rad2;
  b.poses = static_cast<int>(poses);
  b.source = "estimated";
  b.result = result;
  b.forced_although.clear();  // this estimate passed the gates
  if (callbacks.on_broadcast) callbacks.on_broadcast(b);
}

// --- public

OnlineCalibrator::OnlineCalibrator(const TargetDescription& target,
                                   const PipelineSettings& pipeline_settings,
                                   const OnlineSettings& settings, OnlineCallbacks callbacks)
    : impl_(std::make_unique<Impl>(target, pipeline_settings, settings, std::move(callbacks))) {}

OnlineCalibrator::~OnlineCalibrator() = default;

void OnlineCalibrator::addImu(const ImuSample& sample) {
  impl_->checkClock(sample.stamp_s, InputStream::kImu);
  impl_->pipeline->addImu(sample);
  impl_->refreshWaiting();
  impl_->poll();
}

void OnlineCalibrator::addMagnetic(const MagneticSample& sample) {
  impl_->checkClock(sample.stamp_s, InputStream::kMagnetometer);
  impl_->pipeline->addMagnetic(sample);
  impl_->poll();
}

bool OnlineCalibrator::setCameraIntrinsics(const CameraIntrinsics& intrinsics) {
  const bool ok = impl_->pipeline->setCameraIntrinsics(intrinsics);
  impl_->refreshWaiting();
  return ok;
}

void OnlineCalibrator::addFrame(const CameraFrame& frame) {
  impl_->checkClock(frame.stamp_s,
                    frame.R_target_cam ? InputStream::kCameraPose : InputStream::kImage);
  impl_->pipeline->addFrame(frame);
  impl_->onMotionFrames();
  impl_->refreshWaiting();
  impl_->poll();
}

void OnlineCalibrator::rejectInput(RejectReason reason, InputStream stream,
                                   const std::string& detail) {
  impl_->pipeline->rejectInput(reason, stream, detail);
}

ImuOrientationSource OnlineCalibrator::imuOrientationSource() const {
  return impl_->pipeline_settings.imu_orientation;
}

void OnlineCalibrator::finish() {
  impl_->pipeline->finish();
  ++impl_->finishes;
  // Motion since the last solve: its window is solved now, so that the change-point test also
  // sees the end of the recording.
  if (impl_->pipeline->motionFrames() > impl_->motion_frames_solved) impl_->requestSolve();
  impl_->poll();
}

void OnlineCalibrator::poll() { impl_->poll(); }

void OnlineCalibrator::waitForSolves() { impl_->applyFinished(); }

CalibrateOutcome OnlineCalibrator::calibrateNow(bool force) {
  waitForSolves();
  SolveOutput output;
  if (impl_->last_solved && impl_->last_solved->inputs == impl_->inputMark()) {
    output = *impl_->last_solved;  // nothing came in since: the same window, solved
  } else {
    SolveJob job;
    job.inputs = impl_->inputMark();
    job.window = impl_->pipeline->snapshot();
    output = runSolveJob(std::move(job), impl_->pipeline_settings, impl_->settings);
    impl_->pipeline->rememberSceneRefits(output.scene_refits);
  }
  const std::size_t poses = output.window.pose_indices.size();
  CalibrateOutcome out;
  out.window_poses = poses;
  out.result = output.result;
  if (output.result.status == SolveStatus::kBadInput) {
    out.not_broadcast_reason = output.result.message;
    return out;
  }
  EstimateEvent event = impl_->judged(std::move(output));
  out.result = event.result;
  out.gate = event.gate;
  out.verdict = recordingVerdict(event, impl_->remount_events);
  const bool forcible = force && event.gate.decision != GateDecision::kBroadcast &&
                        event.result.status == SolveStatus::kOk &&
                        event.result.R_cam_imu.allFinite();
  if (forcible) {
    event.forced = true;
    impl_->last_estimate = event;
    // Kept (good, not new enough to replace the tf) is no failure; rejected is, and the saved file
    // says so.
    const bool failed = event.gate.decision == GateDecision::kReject;
    impl_->applyThenReport(event, [&] {
      impl_->doBroadcast(event.result, poses,
                         !failed                  ? std::string()
                         : event.gate.why.empty() ? std::string("a quality gate failed")
                                                  : event.gate.why);
      impl_->setState(CalibrationState::kCalibrated,
                      "broadcast on request (force) although: " + event.gate.why);
    });
  } else {
    impl_->applyEstimate(event);
  }
  out.broadcast = forcible || event.gate.decision == GateDecision::kBroadcast;
  if (!out.broadcast) {
    out.not_broadcast_reason =
        event.gate.why.empty() ? std::string("not broadcast") : event.gate.why;
  }
  return out;
}

void OnlineCalibrator::reset() {
  impl_->applyFinished();
  impl_->pipeline->reset();
  impl_->motion_frames_solved = 0;
  impl_->newest_pose_change_tested = -1;
  ++impl_->generation;
  impl_->last_estimate.reset();
  impl_->last_solved.reset();
  impl_->last_pose.reset();
  impl_->inconsistent_poses = 0;
  impl_->remounts = 0;
  impl_->remount_events.clear();
  impl_->recalibrating = false;
  impl_->capture_armed = false;
  impl_->fresh_start = true;  // starting over: the next good estimate replaces the tf
  impl_->setState(
      impl_->broadcast ? CalibrationState::kCollecting : CalibrationState::kWaitingForData,
      "reset: window and buffers cleared" +
          std::string(impl_->broadcast ? "; the broadcast calibration stays until a new one" : ""));
}

void OnlineCalibrator::loadBroadcast(const BroadcastEstimate& estimate) {
  impl_->broadcast = estimate;
  impl_->fresh_start = false;
  impl_->setState(CalibrationState::kCalibrated, "calibration " + estimate.source);
  if (impl_->callbacks.on_broadcast) impl_->callbacks.on_broadcast(estimate);
}

void OnlineCalibrator::armCapture() { impl_->capture_armed = true; }

bool OnlineCalibrator::wantsFrames() const {
  return !impl_->settings.manual_capture || impl_->capture_armed;
}

CalibrationState OnlineCalibrator::state() const { return impl_->state; }
const std::string& OnlineCalibrator::stateMessage() const { return impl_->message; }
const std::optional<EstimateEvent>& OnlineCalibrator::lastEstimate() const {
  return impl_->last_estimate;
}
const std::optional<BroadcastEstimate>& OnlineCalibrator::broadcast() const {
  return impl_->broadcast;
}
double OnlineCalibrator::newestStamp() const { return impl_->clock.newest(); }
const OnlineSettings& OnlineCalibrator::settings() const { return impl_->settings; }

InputCounts OnlineCalibrator::inputCounts() const {
  const CalibrationPipeline& p = *impl_->pipeline;
  InputCounts counts;
  counts.imu_samples = p.imuSamples();
  counts.magnetic_samples = p.magneticSamples();
  counts.frames = p.frames();
  counts.frames_detected = p.framesDetected();
  counts.motion_frames = p.motionFrames();
  counts.imu_gaps = p.imuGaps();
  counts.has_intrinsics = p.hasIntrinsics();
  return counts;
}

CalibrationSnapshot OnlineCalibrator::snapshot(SnapshotContents contents) const {
  const Impl& c = *impl_;
  const CalibrationPipeline& p = *c.pipeline;
  CalibrationSnapshot s;
  s.state = c.state;
  s.message = c.message;
  s.newest_stamp_s = c.clock.newest();
  s.inputs = inputCounts();
  s.target_diagnosis = p.targetNotFoundDiagnosis();
  s.camera_model = p.cameraModelCheck();
  if (s.camera_model.wrong) s.message = s.camera_model.message;  // what the user must fix first
  s.rejections = p.rejections();
  s.rests_total = p.restsTotal();
  s.poses_total = p.posesTotal();
  s.window = p.windowPoses();
  if (contents == SnapshotContents::kWithHistory) {
    s.poses = p.poses();
    s.rejected_poses = p.rejectedPoses();
    s.rests = p.segments();
  }
  s.last_pose = c.last_pose;
  s.latest = c.last_estimate;
  s.broadcast = c.broadcast;
  s.latest_is_broadcast = c.last_estimate && c.broadcast &&
                          rad2deg(rotationAngle(c.broadcast->R_cam_imu.transpose() *
                                                c.last_estimate->result.R_cam_imu)) <= 1e-9;
  if (c.last_estimate) {
    EstimateEvent latest = *c.last_estimate;  // judged again: the check may have fired since
    if (s.camera_model.wrong) latest.camera_model_problem = s.camera_model.message;
    s.verdict = recordingVerdict(latest, c.remount_events);
  }
  s.remount_events = c.remount_events;
  if (c.last_estimate && c.broadcast) {
    s.check = checkCalibration(c.last_estimate->result, *c.broadcast, c.settings.consistency_level);
    s.broadcast_warning =
        broadcastWarning(s.check, s.latest_is_broadcast, c.last_estimate->gate.why);
    if (!s.broadcast_warning.empty()) s.message += "; " + s.broadcast_warning;
  }
  s.remounts = c.remounts;
  // The vertical at the newest rest in the camera frame: R_world_imu's z is up (gravity).
  std::optional<Eigen::Vector3d> up_cam;
  if (c.last_estimate && !s.window.empty()) {
    up_cam = c.last_estimate->result.R_cam_imu * s.window.back().R_world_imu.transpose() *
             Eigen::Vector3d::UnitZ();
  }
  s.progress = progressOf(c.last_estimate, c.settings.max_std_dev_deg, up_cam);
  return s;
}

}  // namespace camera_imu_alignment
