// CalibrationPipeline, pose side: a stationary segment ended -> IMU orientation (gyro chain /
// accelerometer + magnetometer, rule in calibration_pipeline.h), camera orientation (the camera
// source's assessment of the rest, camera_source.h), pose window, snapshot.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "calibration_pipeline_impl.h"
#include "camera_imu_alignment/estimation/camera_link_screening.h"
#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// The field of a segment: mean of the samples inside it and how much its direction wandered
/// (fieldDirectionScatterDeg).
SegmentField segmentField(const std::deque<MagneticSample>& samples, double start_s, double end_s) {
  SegmentField field;
  std::vector<Eigen::Vector3d> inside;
  for (const auto& s : samples) {
    if (s.stamp_s < start_s || s.stamp_s > end_s) continue;
    field.mean_t += s.field_t;
    inside.push_back(s.field_t);
  }
  field.count = static_cast<int>(inside.size());
  if (field.count == 0) return field;
  field.mean_t /= field.count;
  field.scatter_deg = fieldDirectionScatterDeg(inside);
  if (field.count >= 2) {
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& f : inside)
      scatter += (f - field.mean_t) * (f - field.mean_t).transpose();
    field.mean_cov_t2 = scatter / (static_cast<double>(field.count - 1) * field.count);
  }
  return field;
}

constexpr int kMinFieldSamples = 5;
/// 1-sigma per axis added to a pose's camera orientation (deg): what the frames' scatter cannot
/// show (intrinsics, the target's flatness).
constexpr double kCameraSigmaFloorDeg = 0.01;

/// Mean of the IMU's own orientations in [start_s, end_s] (sign-aligned quaternion average); none
/// with fewer than 5 samples carrying one.
std::optional<Eigen::Matrix3d> messageOrientation(const std::deque<ImuSample>& samples,
                                                  double start_s, double end_s) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero(), first = Eigen::Vector4d::Zero();
  int count = 0;
  for (const auto& s : samples) {
    if (!s.q_world_imu || s.stamp_s < start_s || s.stamp_s > end_s) continue;
    Eigen::Vector4d q = s.q_world_imu->coeffs();
    if (count == 0) first = q;
    if (q.dot(first) < 0.0) q = -q;
    sum += q;
    ++count;
  }
  if (count < 5 || !(sum.norm() > 0.0)) return std::nullopt;
  sum.normalize();
  return Eigen::Quaterniond(sum(3), sum(0), sum(1), sum(2)).toRotationMatrix();
}

/// Appends, dropping the oldest entry beyond CalibrationPipeline::kHistoryLimit.
template <typename T>
void pushBounded(std::vector<T>* history, const T& item) {
  if (history->size() >= CalibrationPipeline::kHistoryLimit) history->erase(history->begin());
  history->push_back(item);
}

}  // namespace

void CalibrationPipeline::Impl::onSegment(const StationarySegment& segment) {
  pushBounded(&records.segments, segment);
  ++records.rests_total;
  StationaryPose pose;
  pose.index = static_cast<int>(records.poses_total);
  pose.start_s = segment.start_s;
  pose.end_s = segment.end_s;
  pose.gyro_bias_rad_s = segment.gyro_bias_rad_s;
  const SegmentField field = assessMagnetometer(segment, &pose);
  integrateGyroSincePrevious(segment, &pose);
  StationaryWindow::Entry joint_entry = jointMeasurements(segment, pose, field);
  chooseImuOrientation(segment, &pose);
  const std::string rejection = source->assessRest(segment, history(), &pose, &joint_entry);
  if (!rejection.empty()) {
    const RejectedPose rejected_pose{segment.start_s, segment.end_s, rejection};
    pushBounded(&records.rejected, rejected_pose);
    if (callbacks.on_pose_rejected) callbacks.on_pose_rejected(rejected_pose);
    return;
  }
  acceptPose(pose, std::move(joint_entry));
}

StationaryWindow::Entry CalibrationPipeline::Impl::jointMeasurements(
    const StationarySegment& segment, const StationaryPose& pose, const SegmentField& field) {
  StationaryWindow::Entry entry;
  JointPose& jp = entry.joint;
  jp.start_s = segment.start_s;
  jp.end_s = segment.end_s;
  const RestStatistics rest = restStatistics(buffers.imu, segment.start_s, segment.end_s);
  if (rest.count >= 2) {
    jp.accel_mean_m_s2 = rest.accel_mean_m_s2;
    jp.accel_mean_cov = rest.accel_mean_cov;
    jp.gyro_mean_rad_s = rest.gyro_mean_rad_s;
    jp.gyro_mean_cov = rest.gyro_mean_cov;
  } else {  // no samples kept (cannot happen for a detected rest): the detector's means
    jp.accel_mean_m_s2 = segment.mean_accel_m_s2;
    jp.gyro_mean_rad_s = segment.gyro_bias_rad_s;
  }
  if (field.count >= kMinFieldSamples && field.mean_t.allFinite()) {
    jp.mag_mean_t = field.mean_t;
    jp.mag_mean_cov = field.mean_cov_t2;
    // The raw check's verdict: the estimator re-judges it with the iron calibrated.
    jp.mag_flagged = !pose.magnetometer_usable;
  }
  // The gyro since the previous rest: linked only while the chain holds (the same coverage test
  // as the gyro chain's integration).
  const double density =
      std::max(rest.gyro_noise_density_rad_s_sqrt_hz, joint_gyro.last_noise_density);
  if (!pose.R_imu_previous_imu_gyro) {
    joint_gyro.pending.reset();
  } else if (joint_gyro.pending) {
    appendGyroSamples(buffers.imu, chain.segment.end_s, segment.start_s, &*joint_gyro.pending);
    joint_gyro.pending->noise_density_rad_s_sqrt_hz =
        std::max(joint_gyro.pending->noise_density_rad_s_sqrt_hz, density);
    entry.gyro_from_previous = joint_gyro.pending;
    // Should this rest become no pose, its own samples join the motion to the next pose.
    appendGyroSamples(buffers.imu, segment.start_s, segment.end_s, &*joint_gyro.pending);
    const auto& gyro_stamps = joint_gyro.pending->stamps_s;
    if (!gyro_stamps.empty() &&
        gyro_stamps.back() - gyro_stamps.front() > settings.max_gyro_span_s) {
      joint_gyro.pending.reset();  // as long a motion breaks the gyro chain too
    }
  }
  if (rest.gyro_noise_density_rad_s_sqrt_hz > 0.0) {
    joint_gyro.last_noise_density = rest.gyro_noise_density_rad_s_sqrt_hz;
  }
  return entry;
}

SegmentField CalibrationPipeline::Impl::assessMagnetometer(const StationarySegment& segment,
                                                           StationaryPose* pose) {
  // Usable when there are samples, the attitude is defined and the field is undisturbed.
  const SegmentField field = segmentField(buffers.mag, segment.start_s, segment.end_s);
  if (field.count < kMinFieldSamples) {
    pose->magnetometer_note = field.count == 0 && counts.magnetic == 0
                                  ? "no magnetometer data"
                                  : "only " + std::to_string(field.count) + " field samples";
    return field;
  }
  const AttitudeFromVectors attitude =
      attitudeFromAccelMag(segment.mean_accel_m_s2, field.mean_t, settings.accel_weight);
  std::string why;
  if (!attitude.valid) {
    pose->magnetometer_note = "field parallel to gravity or zero";
  } else if (disturbance.check(attitude.field_norm_t, attitude.dip_deg, field.scatter_deg, &why)) {
    pose->magnetometer_note = "disturbed: " + why;
  } else {
    pose->magnetometer_usable = true;
    pose->R_world_imu_accel_mag = attitude.R_world_imu;
  }
  return field;
}

void CalibrationPipeline::Impl::integrateGyroSincePrevious(const StationarySegment& segment,
                                                           StationaryPose* pose) const {
  // Bias: mean of the two rests' gyro means.
  if (!chain.valid) return;
  const double t0 = chain.segment.end_s, t1 = segment.start_s;
  const bool covered = !buffers.imu.empty() && !buffers.imu_truncated &&
                       buffers.imu.front().stamp_s <= t0 + settings.stationary.max_gap_s &&
                       t1 - t0 <= settings.max_gyro_span_s;
  Eigen::Matrix3d R_prev_cur;
  const Eigen::Vector3d bias = 0.5 * (chain.segment.gyro_bias_rad_s + segment.gyro_bias_rad_s);
  if (covered && integrateGyro(std::vector<ImuSample>(buffers.imu.begin(), buffers.imu.end()), bias,
                               t0, t1, &R_prev_cur, settings.stationary.max_gap_s)) {
    pose->R_imu_previous_imu_gyro = projectToSO3(R_prev_cur);
  }
  if (pose->R_imu_previous_imu_gyro && pose->R_world_imu_accel_mag && chain.R_world_imu_accel_mag) {
    const Eigen::Matrix3d B_mag =
        chain.R_world_imu_accel_mag->transpose() * *pose->R_world_imu_accel_mag;
    pose->gyro_mag_difference_deg =
        rad2deg(rotationAngle(pose->R_imu_previous_imu_gyro->transpose() * B_mag));
  }
}

void CalibrationPipeline::Impl::chooseImuOrientation(const StationarySegment& segment,
                                                     StationaryPose* pose) {
  // The rule in calibration_pipeline.h.
  const bool prefer_mag = settings.imu_orientation == ImuOrientationSource::kMagnetometer;
  const std::optional<Eigen::Matrix3d> R_message =
      settings.imu_orientation == ImuOrientationSource::kMessage
          ? messageOrientation(buffers.imu, segment.start_s, segment.end_s)
          : std::nullopt;
  if (R_message) {
    if (chain.valid && !chain.group_message) ++chain.group;  // the sensor's frame, not ours
    chain.group_message = true;
    chain.group_magnetic = false;
    pose->R_world_imu = *R_message;
    pose->imu_source = PoseImuSource::kMessage;
  } else if (pose->R_imu_previous_imu_gyro &&
             !(prefer_mag && pose->magnetometer_usable && chain.group_magnetic)) {
    pose->R_world_imu = projectToSO3(chain.R_world_imu * *pose->R_imu_previous_imu_gyro);
    pose->imu_source = PoseImuSource::kGyro;
  } else if (pose->magnetometer_usable) {
    if (chain.valid && !chain.group_magnetic) ++chain.group;  // the old heading was arbitrary
    chain.group_magnetic = true;
    chain.group_message = false;
    pose->R_world_imu = *pose->R_world_imu_accel_mag;
    pose->imu_source = PoseImuSource::kAccelMag;
  } else {
    if (chain.valid) ++chain.group;  // heading unknown relative to everything before
    chain.group_magnetic = false;
    chain.group_message = false;
    pose->R_world_imu = attitudeFromAccel(segment.mean_accel_m_s2);
    pose->imu_source = PoseImuSource::kAccelOnly;
  }
  pose->group = chain.group;
  chain.valid = true;
  chain.segment = segment;
  chain.R_world_imu = pose->R_world_imu;
  chain.R_world_imu_accel_mag = pose->R_world_imu_accel_mag;
  buffers.imu_truncated = false;
  while (!buffers.imu.empty() && buffers.imu.front().stamp_s < segment.end_s) {
    buffers.imu.pop_front();
  }
  while (!buffers.mag.empty() && buffers.mag.front().stamp_s < segment.end_s) {
    buffers.mag.pop_front();
  }
}

void CalibrationPipeline::Impl::acceptPose(const StationaryPose& pose,
                                           StationaryWindow::Entry joint_entry) {
  // The camera's covariance from the frames' scatter about their average (per axis, of the mean),
  // with a floor for what the scatter cannot show (the target's flatness), plus the part of one
  // frame's PnP covariance (from its reprojection residuals) beyond that scatter: residuals that
  // the frames' scatter shows (pixel noise, as simulated) average out over the frames; the rest
  // (the camera model's error: the frames of a rest see the same lens) repeats in every frame and
  // is not divided by their number.
  const double spread_rad = deg2rad(pose.camera_spread_deg);
  const double frame_variance = spread_rad * spread_rad / 3.0;  // per axis, one frame
  const double variance =
      frame_variance / std::max(1, pose.num_frames) + std::pow(deg2rad(kCameraSigmaFloorDeg), 2);
  Eigen::Matrix3d beyond_scatter = Eigen::Matrix3d::Zero();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pnp(pose.camera_pnp_cov_rad2);
  if (pnp.info() == Eigen::Success) {
    const Eigen::Vector3d excess = (pnp.eigenvalues().array() - frame_variance).max(0.0).matrix();
    beyond_scatter = pnp.eigenvectors() * excess.asDiagonal() * pnp.eigenvectors().transpose();
  }
  joint_entry.joint.R_target_cam = pose.R_target_cam;
  joint_entry.joint.cov_cam_rad2 = variance * Eigen::Matrix3d::Identity() + beyond_scatter;
  joint_entry.joint.group = pose.group;
  joint_entry.pose = pose;
  window.add(std::move(joint_entry));
  joint_gyro.pending = GyroSegment{};  // the next motion starts at this rest
  pushBounded(&records.poses, pose);
  ++records.poses_total;
  if (callbacks.on_pose) callbacks.on_pose(pose);
}

WindowSnapshot CalibrationPipeline::Impl::snapshot() const {
  WindowSnapshot out;
  out.pairs = window.pairs();
  if (usesJointEstimate(settings.imu_orientation)) out.joint = window.problem();
  // The paper's sensors: the IMU orientation from gravity and the field alone, the gyro left out.
  if (settings.imu_orientation == ImuOrientationSource::kMagnetometer) {
    out.joint.segments.clear();
  } else if (usesJointEstimate(settings.imu_orientation) && settings.motion_window_s > 0.0) {
    // Motion since the window's first rest (all of it without rests).
    const std::vector<StationaryPose> window_poses = window.poses();
    addMotion(window_poses.empty() ? -1e300 : window_poses.front().start_s, &out.joint);
  }
  for (const StationaryPose& pose : window.poses()) out.pose_indices.push_back(pose.index);
  out.scene_links = source->sceneLinkRefitter(out.joint, out.pose_indices);
  return out;
}

}  // namespace camera_imu_alignment
