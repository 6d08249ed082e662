// CalibrationPipeline, input side: validation of samples and frames, the frame queue, detection
// only at rest. Segment -> pose assembly is in pose_assembly.cpp.
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

const char* toString(ImuOrientationSource source) {
  switch (source) {
    case ImuOrientationSource::kMagnetometer:
      return "magnetometer";
    case ImuOrientationSource::kMessage:
      return "message";
    case ImuOrientationSource::kJoint:
      return "joint";
    default:
      return "auto";
  }
}

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

bool usesJointEstimate(ImuOrientationSource source) {
  return source == ImuOrientationSource::kJoint || source == ImuOrientationSource::kMagnetometer;
}

bool parseImuOrientationSource(const std::string& text, ImuOrientationSource* source) {
  if (text == "joint") {
    *source = ImuOrientationSource::kJoint;
  } else if (text == "auto") {
    *source = ImuOrientationSource::kAuto;
  } else if (text == "magnetometer") {
    *source = ImuOrientationSource::kMagnetometer;
  } else if (text == "message") {
    *source = ImuOrientationSource::kMessage;
  } else {
    return false;
  }
  return true;
}

JointSettings jointSettingsOf(const PipelineSettings& settings) {
  JointSettings joint = settings.joint;
  joint.gravity_m_s2 = settings.stationary.gravity_m_s2;
  return joint;
}

namespace {

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

CalibrationPipeline::Impl::Impl(const TargetDescription& target_, const PipelineSettings& settings_,
                                PipelineCallbacks callbacks_)
    : target(target_),
      settings(settings_),
      callbacks(std::move(callbacks_)),
      detector(target_, settings_.detector),
      symmetries(detector.symmetries()),
      stationary(settings_.stationary),
      disturbance(settings_.disturbance),
      window(settings_.window_poses),
      natural_scene(target_.numPoints() == 0) {}

void CalibrationPipeline::Impl::reject(RejectReason reason, InputStream stream,
                                       const std::string& detail) {
  rejections.add(reason);
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
  const double previous_s = s.last_imu_stamp;
  if (!s.checkStamp(sample.stamp_s, &s.last_imu_stamp, InputStream::kImu)) return;
  ++s.num_imu;
  if (std::isfinite(previous_s) && sample.stamp_s - previous_s > s.settings.stationary.max_gap_s) {
    ++s.imu_gaps;
  }
  // Frames are judged with the rest state before this sample: a rest that ends with this sample
  // still counts for frames taken inside it.
  s.processFrames(false);
  s.imu_buffer.push_back(sample);
  if (s.settings.motion_window_s > 0.0) {
    s.motion_gyro.push_back({sample.stamp_s, sample.gyro_rad_s, sample.accel_m_s2});
    const double keep_s = s.settings.motion_window_s + s.settings.max_timeshift_s + 1.0;
    while (s.motion_gyro.front().stamp_s < sample.stamp_s - keep_s) s.motion_gyro.pop_front();
  }
  while (!s.imu_buffer.empty() &&
         s.imu_buffer.front().stamp_s < sample.stamp_s - s.settings.max_gyro_span_s) {
    s.imu_buffer.pop_front();
    s.imu_buffer_truncated = true;
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
  if (!s.checkStamp(sample.stamp_s, &s.last_mag_stamp, InputStream::kMagnetometer)) return;
  MagneticSample corrected = sample;
  corrected.field_t = s.settings.magnetometer.apply(sample.field_t);
  const double norm = corrected.field_t.norm();
  const FieldUnits units = classifyFieldUnits(norm);
  if (units != FieldUnits::kTesla) {
    s.reject(RejectReason::kMagneticUnits, InputStream::kMagnetometer,
             describeFieldUnits(units, norm));
    return;
  }
  ++s.num_mag;
  s.mag_buffer.push_back(corrected);
  while (!s.mag_buffer.empty() &&
         s.mag_buffer.front().stamp_s < sample.stamp_s - s.settings.max_gyro_span_s) {
    s.mag_buffer.pop_front();
  }
}

bool CalibrationPipeline::setCameraIntrinsics(const CameraIntrinsics& intrinsics) {
  const std::string error = intrinsics.validate();
  if (!error.empty()) {
    impl_->reject(RejectReason::kBadCameraInfo, InputStream::kCameraInfo, error + "; ignored");
    return false;
  }
  impl_->intrinsics = intrinsics;
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
  if (!s.checkStamp(frame.stamp_s, &s.last_frame_stamp, stream)) return;
  ++s.num_frames;
  s.frame_queue.push_back(frame);
  // Without IMU data frames cannot be judged: keep a bounded backlog only.
  while (s.frame_queue.size() > 1 &&
         s.frame_queue.front().stamp_s < frame.stamp_s - s.settings.frame_queue_s) {
    s.frame_queue.pop_front();
    ++s.frames_dropped;
  }
  s.processFrames(false);
}

void CalibrationPipeline::Impl::processFrames(bool flush) {
  const double settle = 0.5 * settings.stationary.window_s + settings.frame_margin_s;
  while (!frame_queue.empty()) {
    const CameraFrame& frame = frame_queue.front();
    if (!flush && frame.stamp_s > last_imu_stamp - settle) return;  // IMU not far enough yet
    const std::optional<double> rest_since = stationary.restSince();
    const bool at_rest = stationary.atRest() && rest_since &&
                         frame.stamp_s >= *rest_since + settle && frame.stamp_s <= last_imu_stamp;
    if (at_rest) {
      processFrame(frame);
    } else if (settings.motion_window_s > 0.0 && frame.stamp_s <= last_imu_stamp) {
      processMotionFrame(frame);
    }
    frame_queue.pop_front();
  }
}

void CalibrationPipeline::Impl::processFrame(const CameraFrame& frame) {
  // Detection is the expensive part: only a few, spaced frames per rest.
  const std::optional<double> rest_since = stationary.restSince();
  if (rest_since != misses_rest) {  // a new rest: the target may be in view again
    misses_rest = rest_since;
    misses_in_a_row = 0;
  }
  const double interval = misses_in_a_row >= PipelineSettings::kMissesBeforeBackoff
                              ? settings.missed_frame_interval_s
                              : settings.min_frame_interval_s;
  if (frame.stamp_s - last_detection_stamp < interval) return;
  int in_this_rest = 0;
  for (const auto& d : detections) in_this_rest += (rest_since && d.stamp_s >= *rest_since);
  if (in_this_rest >= settings.max_frames_per_pose) return;
  if (frame.R_target_cam) {  // given orientation: nothing to detect
    ++given_orientations;
    last_detection_stamp = frame.stamp_s;
    CameraPose given;
    given.R_target_cam = *frame.R_target_cam;
    detections.push_back({frame.stamp_s, given});
    return;
  }
  if (!intrinsics) {
    ++frames_without_intrinsics;
    return;
  }
  if (frame.mono8.cols != intrinsics->width || frame.mono8.rows != intrinsics->height) {
    std::ostringstream out;
    out << frame.mono8.cols << "x" << frame.mono8.rows << " differs from the camera info's "
        << intrinsics->width << "x" << intrinsics->height << "; frame dropped";
    reject(RejectReason::kBadImage, InputStream::kImage, out.str());
    return;
  }
  if (natural_scene) {  // no target: the rest's sharpest frame gives features (at its end)
    keepSceneCandidate(frame);
    return;
  }
  last_detection_stamp = frame.stamp_s;
  ++num_detected;
  const Eigen::Matrix3d* hint = poses.empty() ? nullptr : &poses.back().R_target_cam;
  TargetObservation observation;
  if (!detector.detect(frame.mono8, &observation, hint)) {
    ++misses_in_a_row;
    std::ostringstream out;
    out << "image at " << formatStamp(frame.stamp_s) << " s (at rest): " << target.describe()
        << " not found";
    if (!observation.mismatch.empty()) {
      target_mismatch = observation.mismatch;
      out << " (" << observation.mismatch << ")";
    }
    reject(RejectReason::kTargetNotFound, InputStream::kImage, out.str());
    return;
  }
  // What the frame says about the camera model, whatever becomes of its pose.
  if (const auto fit = fitCameraModel(observation, target, *intrinsics)) {
    camera_model.addFrame(frame.stamp_s, *fit);
  }
  std::string why;
  const auto pose = estimateCameraPose(observation, target, *intrinsics, settings.pose, &why);
  if (!pose) {
    camera_model.addRefused(frame.stamp_s, why);
    reject(RejectReason::kPoseRejected, InputStream::kImage,
           "image at " + formatStamp(frame.stamp_s) + " s: " + why);
    return;
  }
  misses_in_a_row = 0;
  target_mismatch.clear();  // the file's board is in view after all
  detections.push_back({frame.stamp_s, *pose});
}

void CalibrationPipeline::Impl::processMotionFrame(const CameraFrame& frame) {
  if (frame.stamp_s - last_motion_frame_stamp <
      settings.motion_frame_interval_s - kMotionIntervalToleranceS) {
    return;
  }
  MotionFrame motion;
  motion.stamp_s = frame.stamp_s;
  if (frame.R_target_cam) {
    ++given_orientations;
    motion.R_target_cam = *frame.R_target_cam;
    motion.p_target_cam_m = frame.p_target_cam_m;
    // A given orientation states no covariance: a motion-capture or PnP class 1-sigma; the joint
    // estimate scales its covariance by chi2/dof when the data say it is larger.
    const double sigma_rad = kGivenOrientationSigmaDeg * 3.14159265358979323846 / 180.0;
    motion.cov_cam_rad2 = sigma_rad * sigma_rad * Eigen::Matrix3d::Identity();
  } else {
    if (natural_scene) return;  // no target to find during motion
    if (!intrinsics || frame.mono8.cols != intrinsics->width ||
        frame.mono8.rows != intrinsics->height) {
      return;  // counted and said by the rests' frames
    }
    ++motion_detections;
    const Eigen::Matrix3d* hint =
        motion_frames.empty() ? nullptr : &motion_frames.back().R_target_cam;
    // The previous frame's board is where this one's is looked for first (the camera turns a
    // few degrees between frames at 20 Hz; further apart, the whole image is searched).
    constexpr double kSearchNearWithinS = 0.25;
    const bool recent = frame.stamp_s - last_motion_points_stamp <= kSearchNearWithinS &&
                        frame.stamp_s >= last_motion_points_stamp;
    TargetObservation observation;
    if (!detector.detect(frame.mono8, &observation, hint, recent ? &last_motion_points : nullptr)) {
      return;  // out of view or blurred
    }
    last_motion_points = observation.image_points;
    last_motion_points_stamp = frame.stamp_s;
    // No pixel threshold here: the window's frames are judged against each other
    // (screenMotionFrames, when the motion is solved).
    PoseSettings pose_settings = settings.pose;
    pose_settings.max_reprojection_rms_px = std::numeric_limits<double>::infinity();
    std::string why;
    const auto pose = estimateCameraPose(observation, target, *intrinsics, pose_settings, &why);
    if (!pose) return;  // no PnP solution
    motion.R_target_cam = pose->R_target_cam;
    motion.p_target_cam_m = pose->p_target_cam;
    motion.cov_cam_rad2 = pose->cov_rotation_rad2;
    motion.reprojection_rms_px = pose->reprojection_rms_px;
    motion.reprojection_dof = 2 * pose->num_points - 6;
  }
  last_motion_frame_stamp = frame.stamp_s;
  motion_frames.push_back(motion);
  ++motion_frames_total;
  while (!motion_frames.empty() &&
         motion_frames.front().stamp_s < frame.stamp_s - settings.motion_window_s) {
    motion_frames.pop_front();
  }
}

void CalibrationPipeline::finish() {
  impl_->processFrames(true);
  if (auto segment = impl_->stationary.flush()) impl_->onSegment(*segment);
}

WindowSnapshot CalibrationPipeline::snapshot() const { return impl_->snapshot(); }

std::uint64_t CalibrationPipeline::motionFrames() const { return impl_->motion_frames_total; }

ImuOrientationSource CalibrationPipeline::imuOrientationSource() const {
  return impl_->settings.imu_orientation;
}

void CalibrationPipeline::keepPosesFrom(int pose_index) { impl_->window.keepFrom(pose_index); }

void CalibrationPipeline::keepMotionFrom(double stamp_s) {
  int first_kept = static_cast<int>(impl_->poses.size());  // the next pose's index
  for (const StationaryPose& pose : impl_->window.poses()) {
    if (pose.start_s >= stamp_s) {
      first_kept = pose.index;
      break;
    }
  }
  impl_->window.keepFrom(first_kept);
  while (!impl_->motion_frames.empty() && impl_->motion_frames.front().stamp_s < stamp_s) {
    impl_->motion_frames.pop_front();
  }
}

std::vector<StationaryPose> CalibrationPipeline::windowPoses() const {
  return impl_->window.poses();
}

void CalibrationPipeline::reset(bool clear_counts) {
  const RejectionCounts counts = impl_->rejections;
  const std::uint64_t n_imu = impl_->num_imu, n_mag = impl_->num_mag, n_frames = impl_->num_frames,
                      n_detected = impl_->num_detected, n_gaps = impl_->imu_gaps;
  const std::optional<CameraIntrinsics> intrinsics = impl_->intrinsics;
  impl_ = std::make_unique<Impl>(impl_->target, impl_->settings, impl_->callbacks);
  impl_->intrinsics = intrinsics;  // configuration, not data: kept
  if (!clear_counts) {
    impl_->rejections = counts;
    impl_->num_imu = n_imu;
    impl_->num_mag = n_mag;
    impl_->num_frames = n_frames;
    impl_->num_detected = n_detected;
    impl_->imu_gaps = n_gaps;
  }
}

std::size_t CalibrationPipeline::windowSize() const { return impl_->window.size(); }

const std::vector<StationaryPose>& CalibrationPipeline::poses() const { return impl_->poses; }
RotationPairs CalibrationPipeline::windowPairs() const { return impl_->window.pairs(); }
const std::vector<RejectedPose>& CalibrationPipeline::rejectedPoses() const {
  return impl_->rejected;
}
const std::vector<StationarySegment>& CalibrationPipeline::segments() const {
  return impl_->segments;
}
const RejectionCounts& CalibrationPipeline::rejections() const { return impl_->rejections; }
std::uint64_t CalibrationPipeline::imuGaps() const { return impl_->imu_gaps; }
std::size_t CalibrationPipeline::posesTotal() const { return impl_->poses_total; }
std::size_t CalibrationPipeline::restsTotal() const { return impl_->rests_total; }

PipelineBufferSizes CalibrationPipeline::bufferSizes() const {
  const Impl& s = *impl_;
  PipelineBufferSizes sizes;
  sizes.imu = s.imu_buffer.size();
  sizes.mag = s.mag_buffer.size();
  sizes.frame_queue = s.frame_queue.size();
  sizes.detections = s.detections.size();
  sizes.poses = s.poses.size();
  sizes.rests = s.segments.size();
  sizes.rejected_rests = s.rejected.size();
  sizes.window = s.window.size();
  return sizes;
}
std::uint64_t CalibrationPipeline::imuSamples() const { return impl_->num_imu; }
std::uint64_t CalibrationPipeline::magneticSamples() const { return impl_->num_mag; }
std::uint64_t CalibrationPipeline::frames() const { return impl_->num_frames; }

std::string CalibrationPipeline::targetNotFoundDiagnosis() const {
  const std::uint64_t tried = impl_->num_detected;
  if (tried < kFramesForTargetDiagnosis ||
      impl_->rejections.count(RejectReason::kTargetNotFound) < tried) {
    return "";
  }
  std::string out = "the target (" + impl_->target.describe() + ") was not found in any of " +
                    std::to_string(tried) +
                    " frames at rest: does the target file describe the board in view?";
  if (!impl_->target_mismatch.empty()) out += " " + impl_->target_mismatch;
  return out;
}
CameraModelCheck CalibrationPipeline::cameraModelCheck() const {
  const CameraIntrinsics* intrinsics = impl_->intrinsics ? &*impl_->intrinsics : nullptr;
  return impl_->camera_model.check(kCameraModelLevel, intrinsics);
}
std::uint64_t CalibrationPipeline::framesDetected() const { return impl_->num_detected; }
bool CalibrationPipeline::hasIntrinsics() const { return impl_->intrinsics.has_value(); }
const PipelineSettings& CalibrationPipeline::settings() const { return impl_->settings; }

}  // namespace camera_imu_alignment
