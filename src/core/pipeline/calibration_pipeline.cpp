// CalibrationPipeline, input side: validation of samples and frames, the choice of the camera
// source, the frame queue (frames to the source at rest or during motion). Segment -> pose
// assembly is in pose_assembly.cpp.
#include "camera_imu_alignment/pipeline/calibration_pipeline.h"

#include <Eigen/Dense>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "calibration_pipeline_impl.h"
#include "camera_imu_alignment/config/settings_checks.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

const char* toString(PoseImuSource source) {
  switch (source) {
    case PoseImuSource::kGyro:
      return "gyro";
    case PoseImuSource::kAccelMag:
      return "accel_mag";
    case PoseImuSource::kAccelOnly:
      return "accel_only";
    case PoseImuSource::kMessage:
      return "message";
  }
  return "unknown";
}

const char* toString(PoseCameraSource source) {
  return source == PoseCameraSource::kScene ? "scene" : "target";
}

namespace {

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

CalibrationPipeline::Impl::Impl(const TargetDescription& target_, const PipelineSettings& settings_,
                                PipelineCallbacks callbacks_)
    : target(target_),
      settings(settings_),
      callbacks(std::move(callbacks_)),
      stationary(settings_.stationary),
      disturbance(settings_.disturbance),
      window(settings_.window_poses) {}

void CalibrationPipeline::Impl::chooseSource(InputStream stream) {
  camera_stream = stream;
  source = chooseCameraSource(
      stream, {target, settings, camera,
               [this](RejectReason reason, InputStream from, const std::string& detail) {
                 reject(reason, from, detail);
               }});
}

void CalibrationPipeline::Impl::reject(RejectReason reason, InputStream stream,
                                       const std::string& detail) {
  counts.rejections.add(reason);
  if (callbacks.on_reject) callbacks.on_reject(reason, stream, detail);
}

void CalibrationPipeline::rejectInput(RejectReason reason, InputStream stream,
                                      const std::string& detail) {
  impl_->reject(reason, stream, detail);
}

CalibrationPipeline::CalibrationPipeline(const TargetDescription& target,
                                         const PipelineSettings& settings,
                                         PipelineCallbacks callbacks) {
  throwIfProblem("", findProblem(settings));
  impl_ = std::make_unique<Impl>(target, settings, std::move(callbacks));
}

CalibrationPipeline::~CalibrationPipeline() = default;

bool CalibrationPipeline::Impl::checkStamp(double stamp, double* last, InputStream stream) {
  Impl* impl = this;
  if (stamp < *last) {
    std::ostringstream out;
    out << "stamp " << formatStamp(stamp) << " s is earlier than the previous one ("
        << formatStamp(*last) << " s); sample dropped";
    impl->reject(RejectReason::kStampBackwards, stream, out.str());
    return false;
  }
  if (stamp == *last) {
    std::ostringstream out;
    out << "duplicate stamp " << formatStamp(stamp) << " s; sample dropped";
    impl->reject(RejectReason::kDuplicateStamp, stream, out.str());
    return false;
  }
  *last = stamp;
  return true;
}

void CalibrationPipeline::addImu(const ImuSample& sample) {
  Impl& s = *impl_;
  if (!std::isfinite(sample.stamp_s) || !finite(sample.gyro_rad_s) || !finite(sample.accel_m_s2)) {
    s.reject(RejectReason::kNonFinite, InputStream::kImu, "NaN or Inf in a sample; sample dropped");
    return;
  }
  if (sample.accel_m_s2.norm() < 1e-6) {
    s.reject(RejectReason::kZeroVector, InputStream::kImu,
             "zero accelerometer vector; sample dropped");
    return;
  }
  if (sample.q_world_imu && !(std::abs(sample.q_world_imu->norm() - 1.0) < 1e-3)) {
    ImuSample without = sample;  // the rates are fine: keep them, drop the orientation
    without.q_world_imu.reset();
    s.reject(RejectReason::kNonFinite, InputStream::kImu,
             "orientation is not a unit quaternion; orientation ignored, rates used");
    addImu(without);
    return;
  }
  const double previous_s = s.stamps.imu;
  if (!s.checkStamp(sample.stamp_s, &s.stamps.imu, InputStream::kImu)) return;
  ++s.counts.imu;
  if (std::isfinite(previous_s) && sample.stamp_s - previous_s > s.settings.stationary.max_gap_s) {
    ++s.counts.imu_gaps;
  }
  // Frames are judged with the rest state before this sample: a rest that ends with this sample
  // still counts for frames taken inside it.
  s.processFrames(false);
  s.buffers.imu.push_back(sample);
  if (s.settings.motion_window_s > 0.0) {
    s.motion.gyro.push_back({sample.stamp_s, sample.gyro_rad_s, sample.accel_m_s2});
    const double keep_s = s.settings.motion_window_s + s.settings.max_timeshift_s + 1.0;
    while (s.motion.gyro.front().stamp_s < sample.stamp_s - keep_s) s.motion.gyro.pop_front();
  }
  while (!s.buffers.imu.empty() &&
         s.buffers.imu.front().stamp_s < sample.stamp_s - s.settings.max_gyro_span_s) {
    s.buffers.imu.pop_front();
    s.buffers.imu_truncated = true;
  }
  if (auto segment = s.stationary.add(sample)) s.onSegment(*segment);
}

void CalibrationPipeline::addMagnetic(const MagneticSample& sample) {
  Impl& s = *impl_;
  if (!std::isfinite(sample.stamp_s) || !finite(sample.field_t)) {
    s.reject(RejectReason::kNonFinite, InputStream::kMagnetometer,
             "NaN or Inf in a sample; sample dropped");
    return;
  }
  if (sample.field_t.norm() == 0.0) {
    s.reject(RejectReason::kZeroVector, InputStream::kMagnetometer,
             "zero field vector; sample dropped");
    return;
  }
  if (!s.checkStamp(sample.stamp_s, &s.stamps.magnetic, InputStream::kMagnetometer)) return;
  MagneticSample corrected = sample;
  corrected.field_t = s.settings.magnetometer.apply(sample.field_t);
  const double norm = corrected.field_t.norm();
  const FieldUnits units = classifyFieldUnits(norm);
  if (units != FieldUnits::kTesla) {
    s.reject(RejectReason::kMagneticUnits, InputStream::kMagnetometer,
             describeFieldUnits(units, norm));
    return;
  }
  ++s.counts.magnetic;
  s.buffers.mag.push_back(corrected);
  while (!s.buffers.mag.empty() &&
         s.buffers.mag.front().stamp_s < sample.stamp_s - s.settings.max_gyro_span_s) {
    s.buffers.mag.pop_front();
  }
}

bool CalibrationPipeline::setCameraIntrinsics(const CameraIntrinsics& intrinsics) {
  const std::string error = intrinsics.validate();
  if (!error.empty()) {
    impl_->reject(RejectReason::kBadCameraInfo, InputStream::kCameraInfo, error + "; ignored");
    return false;
  }
  impl_->camera.intrinsics = intrinsics;
  return true;
}

void CalibrationPipeline::addFrame(const CameraFrame& frame) {
  Impl& s = *impl_;
  const InputStream stream = frame.R_target_cam ? InputStream::kCameraPose : InputStream::kImage;
  if (!std::isfinite(frame.stamp_s)) {
    s.reject(RejectReason::kNonFinite, stream, "stamp is not finite; frame dropped");
    return;
  }
  if (frame.R_target_cam) {
    if (!isRotationMatrix(*frame.R_target_cam, 1e-6)) {
      s.reject(RejectReason::kNonFinite, stream, "not a finite unit rotation; dropped");
      return;
    }
  } else if (frame.mono8.empty() || frame.mono8.type() != CV_8UC1) {
    s.reject(RejectReason::kBadImage, stream, "empty or not mono8 after conversion; frame dropped");
    return;
  }
  if (!s.camera_stream) s.chooseSource(stream);  // the first camera frame chooses the source
  if (stream != *s.camera_stream) {
    s.reject(RejectReason::kMixedCameraSource, stream,
             "the camera source is " + s.source->describe() +
                 ", chosen by the first camera frame: images and camera poses are not used "
                 "together; frame dropped");
    return;
  }
  if (!s.checkStamp(frame.stamp_s, &s.stamps.frame, stream)) return;
  ++s.camera.frames;
  s.frame_queue.push_back(frame);
  // Without IMU data frames cannot be judged: keep a bounded backlog only.
  while (s.frame_queue.size() > 1 &&
         s.frame_queue.front().stamp_s < frame.stamp_s - s.settings.frame_queue_s) {
    s.frame_queue.pop_front();
    ++s.counts.frames_dropped;
  }
  s.processFrames(false);
}

void CalibrationPipeline::Impl::processFrames(bool flush) {
  const double settle = 0.5 * settings.stationary.window_s + settings.frame_margin_s;
  while (!frame_queue.empty()) {
    const CameraFrame& frame = frame_queue.front();
    if (!flush && frame.stamp_s > stamps.imu - settle) return;  // IMU not far enough yet
    const std::optional<double> rest_since = stationary.restSince();
    const bool at_rest = stationary.atRest() && rest_since &&
                         frame.stamp_s >= *rest_since + settle && frame.stamp_s <= stamps.imu;
    if (at_rest) {
      source->takeRestFrame(frame, rest_since, history());
    } else if (settings.motion_window_s > 0.0 && frame.stamp_s <= stamps.imu) {
      processMotionFrame(frame);
    }
    frame_queue.pop_front();
  }
}

void CalibrationPipeline::Impl::processMotionFrame(const CameraFrame& frame) {
  if (frame.stamp_s - motion.last_frame_stamp <
      settings.motion_frame_interval_s - kMotionIntervalToleranceS) {
    return;
  }
  const std::optional<MotionFrame> taken =
      source->takeMotionFrame(frame, motion.frames.empty() ? nullptr : &motion.frames.back());
  if (!taken) return;
  motion.last_frame_stamp = frame.stamp_s;
  motion.frames.push_back(*taken);
  ++motion.frames_total;
  while (!motion.frames.empty() &&
         motion.frames.front().stamp_s < frame.stamp_s - settings.motion_window_s) {
    motion.frames.pop_front();
  }
}

void CalibrationPipeline::finish() {
  impl_->processFrames(true);
  if (auto segment = impl_->stationary.flush()) impl_->onSegment(*segment);
}

WindowSnapshot CalibrationPipeline::snapshot() const { return impl_->snapshot(); }

std::uint64_t CalibrationPipeline::motionFrames() const { return impl_->motion.frames_total; }

ImuOrientationSource CalibrationPipeline::imuOrientationSource() const {
  return impl_->settings.imu_orientation;
}

void CalibrationPipeline::keepPosesFrom(int pose_index) { impl_->window.keepFrom(pose_index); }

void CalibrationPipeline::keepMotionFrom(double stamp_s) {
  int first_kept = static_cast<int>(impl_->records.poses.size());  // the next pose's index
  for (const StationaryPose& pose : impl_->window.poses()) {
    if (pose.start_s >= stamp_s) {
      first_kept = pose.index;
      break;
    }
  }
  impl_->window.keepFrom(first_kept);
  while (!impl_->motion.frames.empty() && impl_->motion.frames.front().stamp_s < stamp_s) {
    impl_->motion.frames.pop_front();
  }
}

std::vector<StationaryPose> CalibrationPipeline::windowPoses() const {
  return impl_->window.poses();
}

void CalibrationPipeline::reset(bool clear_counts) {
  InputCounts counts = impl_->counts;
  counts.frames_dropped = 0;
  const CameraInputs camera = impl_->camera;
  const std::optional<InputStream> camera_stream = impl_->camera_stream;
  impl_ = std::make_unique<Impl>(impl_->target, impl_->settings, impl_->callbacks);
  // Configuration, not data: kept. The camera source starts afresh on the same stream.
  impl_->camera.intrinsics = camera.intrinsics;
  if (camera_stream) impl_->chooseSource(*camera_stream);
  if (!clear_counts) {
    impl_->counts = counts;
    impl_->camera.frames = camera.frames;
    impl_->camera.detected = camera.detected;
  }
}

std::size_t CalibrationPipeline::windowSize() const { return impl_->window.size(); }

const std::vector<StationaryPose>& CalibrationPipeline::poses() const {
  return impl_->records.poses;
}
RotationPairs CalibrationPipeline::windowPairs() const { return impl_->window.pairs(); }
const std::vector<RejectedPose>& CalibrationPipeline::rejectedPoses() const {
  return impl_->records.rejected;
}
const std::vector<StationarySegment>& CalibrationPipeline::segments() const {
  return impl_->records.segments;
}
const RejectionCounts& CalibrationPipeline::rejections() const { return impl_->counts.rejections; }
std::uint64_t CalibrationPipeline::imuGaps() const { return impl_->counts.imu_gaps; }
std::size_t CalibrationPipeline::posesTotal() const { return impl_->records.poses_total; }
std::size_t CalibrationPipeline::restsTotal() const { return impl_->records.rests_total; }

PipelineBufferSizes CalibrationPipeline::bufferSizes() const {
  const Impl& s = *impl_;
  PipelineBufferSizes sizes;
  sizes.imu = s.buffers.imu.size();
  sizes.mag = s.buffers.mag.size();
  sizes.frame_queue = s.frame_queue.size();
  sizes.detections = s.source->heldRestFrames();
  sizes.poses = s.records.poses.size();
  sizes.rests = s.records.segments.size();
  sizes.rejected_rests = s.records.rejected.size();
  sizes.window = s.window.size();
  return sizes;
}
std::uint64_t CalibrationPipeline::imuSamples() const { return impl_->counts.imu; }
std::uint64_t CalibrationPipeline::magneticSamples() const { return impl_->counts.magnetic; }
std::uint64_t CalibrationPipeline::frames() const { return impl_->camera.frames; }

std::string CalibrationPipeline::targetNotFoundDiagnosis() const {
  return impl_->source->targetNotFoundDiagnosis(impl_->counts.rejections);
}
CameraModelCheck CalibrationPipeline::cameraModelCheck() const {
  const CameraIntrinsics* intrinsics =
      impl_->camera.intrinsics ? &*impl_->camera.intrinsics : nullptr;
  return impl_->source->cameraModelCheck(kCameraModelLevel, intrinsics);
}
std::uint64_t CalibrationPipeline::framesDetected() const { return impl_->camera.detected; }
bool CalibrationPipeline::hasIntrinsics() const { return impl_->camera.intrinsics.has_value(); }
void CalibrationPipeline::rememberSceneRefits(const std::vector<SceneRefit>& refits) {
  impl_->source->rememberRefits(refits);
}
const PipelineSettings& CalibrationPipeline::settings() const { return impl_->settings; }

}  // namespace camera_imu_alignment
