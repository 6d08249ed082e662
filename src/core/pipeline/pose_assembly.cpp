// CalibrationPipeline, pose side: a stationary segment ended -> IMU orientation (gyro chain /
// accelerometer + magnetometer, rule in calibration_pipeline.h), camera orientation (robust
// average of the frames at rest), pose window, solve.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "calibration_pipeline_impl.h"
#include "camera_imu_alignment/estimation/camera_link_screening.h"
#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/solver/rotation_average.h"
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

/// The board may look the same turned (TargetDetector::symmetries): among the readings
/// S * R_target_cam, the right one turns the camera by the same angle as the IMU since the earlier
/// poses of the group (a rotation angle does not depend on the frame). Keeps the detector's reading
/// when no earlier pose can tell or the best two readings agree within `kSymmetryMarginDeg`.
constexpr double kSymmetryMarginDeg = 2.0;
constexpr std::size_t kSymmetryReferencePoses = 5;

Eigen::Matrix3d resolveSymmetry(const Eigen::Matrix3d& R_target_cam,
                                const Eigen::Matrix3d& R_world_imu, int group,
                                const std::vector<StationaryPose>& poses,
                                const std::vector<Eigen::Matrix3d>& symmetries) {
  if (symmetries.empty()) return R_target_cam;
  std::vector<const StationaryPose*> references;
  for (auto it = poses.rbegin(); it != poses.rend(); ++it) {
    if (it->group != group) break;  // groups are contiguous
    references.push_back(&*it);
    if (references.size() == kSymmetryReferencePoses) break;
  }
  if (references.empty()) return R_target_cam;
  std::vector<Eigen::Matrix3d> readings{R_target_cam};
  for (const auto& S : symmetries) readings.push_back(S * R_target_cam);
  std::vector<double> cost(readings.size(), 0.0);
  for (std::size_t k = 0; k < readings.size(); ++k) {
    for (const StationaryPose* p : references) {
      const double camera = rotationAngle(p->R_target_cam.transpose() * readings[k]);
      const double imu = rotationAngle(p->R_world_imu.transpose() * R_world_imu);
      cost[k] += std::abs(camera - imu) / static_cast<double>(references.size());
    }
  }
  std::vector<std::size_t> order(readings.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return cost[a] < cost[b]; });
  if (rad2deg(cost[order[1]] - cost[order[0]]) < kSymmetryMarginDeg) return R_target_cam;
  return readings[order[0]];
}

/// Appends, dropping the oldest entry beyond CalibrationPipeline::kHistoryLimit.
template <typename T>
void pushBounded(std::vector<T>* history, const T& item) {
  if (history->size() >= CalibrationPipeline::kHistoryLimit) history->erase(history->begin());
  history->push_back(item);
}

}  // namespace

void CalibrationPipeline::Impl::onSegment(const StationarySegment& segment) {
  pushBounded(&segments, segment);
  ++rests_total;
  StationaryPose pose;
  pose.index = static_cast<int>(poses_total);
  pose.start_s = segment.start_s;
  pose.end_s = segment.end_s;
  pose.gyro_bias_rad_s = segment.gyro_bias_rad_s;
  const SegmentField field = assessMagnetometer(segment, &pose);
  integrateGyroSincePrevious(segment, &pose);
  StationaryWindow::Entry joint_entry = jointMeasurements(segment, pose, field);
  chooseImuOrientation(segment, &pose);
  // Given camera poses (camera_pose) come with an orientation: no scene needed.
  const std::string rejection = natural_scene && given_orientations == 0
                                    ? assessScene(segment, &pose, &joint_entry)
                                    : assessCamera(segment, &pose);
  if (!rejection.empty()) {
    const RejectedPose rejected_pose{segment.start_s, segment.end_s, rejection};
    pushBounded(&rejected, rejected_pose);
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
  const RestStatistics rest = restStatistics(imu_buffer, segment.start_s, segment.end_s);
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
  const double density = std::max(rest.gyro_noise_density_rad_s_sqrt_hz, last_gyro_noise_density);
  if (!pose.R_imu_previous_imu_gyro) {
    joint_gyro_pending.reset();
  } else if (joint_gyro_pending) {
    appendGyroSamples(imu_buffer, chain_segment.end_s, segment.start_s, &*joint_gyro_pending);
    joint_gyro_pending->noise_density_rad_s_sqrt_hz =
        std::max(joint_gyro_pending->noise_density_rad_s_sqrt_hz, density);
    entry.gyro_from_previous = joint_gyro_pending;
    // Should this rest become no pose, its own samples join the motion to the next pose.
    appendGyroSamples(imu_buffer, segment.start_s, segment.end_s, &*joint_gyro_pending);
    const auto& stamps = joint_gyro_pending->stamps_s;
    if (!stamps.empty() && stamps.back() - stamps.front() > settings.max_gyro_span_s) {
      joint_gyro_pending.reset();  // as long a motion breaks the gyro chain too
    }
  }
  if (rest.gyro_noise_density_rad_s_sqrt_hz > 0.0) {
    last_gyro_noise_density = rest.gyro_noise_density_rad_s_sqrt_hz;
  }
  return entry;
}

SegmentField CalibrationPipeline::Impl::assessMagnetometer(const StationarySegment& segment,
                                                           StationaryPose* pose) {
  // Usable when there are samples, the attitude is defined and the field is undisturbed.
  const SegmentField field = segmentField(mag_buffer, segment.start_s, segment.end_s);
  if (field.count < kMinFieldSamples) {
    pose->magnetometer_note = field.count == 0 && num_mag == 0
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
  if (!chain_valid) return;
  const double t0 = chain_segment.end_s, t1 = segment.start_s;
  const bool covered = !imu_buffer.empty() && !imu_buffer_truncated &&
                       imu_buffer.front().stamp_s <= t0 + settings.stationary.max_gap_s &&
                       t1 - t0 <= settings.max_gyro_span_s;
  Eigen::Matrix3d R_prev_cur;
  const Eigen::Vector3d bias = 0.5 * (chain_segment.gyro_bias_rad_s + segment.gyro_bias_rad_s);
  if (covered && integrateGyro(std::vector<ImuSample>(imu_buffer.begin(), imu_buffer.end()), bias,
                               t0, t1, &R_prev_cur, settings.stationary.max_gap_s)) {
    pose->R_imu_previous_imu_gyro = projectToSO3(R_prev_cur);
  }
  if (pose->R_imu_previous_imu_gyro && pose->R_world_imu_accel_mag && chain_R_world_imu_accel_mag) {
    const Eigen::Matrix3d B_mag =
        chain_R_world_imu_accel_mag->transpose() * *pose->R_world_imu_accel_mag;
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
          ? messageOrientation(imu_buffer, segment.start_s, segment.end_s)
          : std::nullopt;
  if (R_message) {
    if (chain_valid && !group_message) ++group;  // the sensor's frame, unrelated to ours
    group_message = true;
    group_magnetic = false;
    pose->R_world_imu = *R_message;
    pose->imu_source = PoseImuSource::kMessage;
  } else if (pose->R_imu_previous_imu_gyro &&
             !(prefer_mag && pose->magnetometer_usable && group_magnetic)) {
    pose->R_world_imu = projectToSO3(chain_R_world_imu * *pose->R_imu_previous_imu_gyro);
    pose->imu_source = PoseImuSource::kGyro;
  } else if (pose->magnetometer_usable) {
    if (chain_valid && !group_magnetic) ++group;  // the old chain's heading was arbitrary
    group_magnetic = true;
    group_message = false;
    pose->R_world_imu = *pose->R_world_imu_accel_mag;
    pose->imu_source = PoseImuSource::kAccelMag;
  } else {
    if (chain_valid) ++group;  // heading unknown relative to everything before
    group_magnetic = false;
    group_message = false;
    pose->R_world_imu = attitudeFromAccel(segment.mean_accel_m_s2);
    pose->imu_source = PoseImuSource::kAccelOnly;
  }
  pose->group = group;
  chain_valid = true;
  chain_segment = segment;
  chain_R_world_imu = pose->R_world_imu;
  chain_R_world_imu_accel_mag = pose->R_world_imu_accel_mag;
  imu_buffer_truncated = false;
  while (!imu_buffer.empty() && imu_buffer.front().stamp_s < segment.end_s) imu_buffer.pop_front();
  while (!mag_buffer.empty() && mag_buffer.front().stamp_s < segment.end_s) mag_buffer.pop_front();
}

std::string CalibrationPipeline::Impl::assessCamera(const StationarySegment& segment,
                                                    StationaryPose* pose) {
  // The frames inside the segment, margins off both ends; later ones are kept for the next rest.
  std::vector<Eigen::Matrix3d> rotations;
  double reprojection_sum = 0.0;
  Eigen::Matrix3d pnp_cov_sum = Eigen::Matrix3d::Zero();
  const double lo = segment.start_s + settings.frame_margin_s;
  const double hi = segment.end_s - settings.frame_margin_s;
  for (const auto& d : detections) {
    if (d.stamp_s < lo || d.stamp_s > hi) continue;
    rotations.push_back(d.pose.R_target_cam);
    reprojection_sum += d.pose.reprojection_rms_px;
    pnp_cov_sum += d.pose.cov_rotation_rad2;
    pose->p_target_cam = d.pose.p_target_cam;
  }
  std::vector<FrameDetection> later;
  for (const auto& d : detections) {
    if (d.stamp_s > segment.end_s) later.push_back(d);
  }
  detections.swap(later);
  const int refused = camera_model.refusedIn(lo, hi);  // target seen, pose refused
  const std::string refused_text = camera_model.endRest(lo, hi, segment.end_s);

  if (static_cast<int>(rotations.size()) < settings.min_frames_per_pose) {
    const std::string silent = silentCameraReason();
    if (!silent.empty()) return silent;
    std::string out = "target seen in " + std::to_string(rotations.size() + refused) +
                      " frame(s), " + std::to_string(settings.min_frames_per_pose) +
                      (refused > 0 ? " with a camera pose needed; " + refused_text : " needed");
    if (!target_mismatch.empty()) out += " (" + target_mismatch + ")";
    return out;
  }
  const RotationAverage average = averageRotations(rotations, 4.0 * settings.max_camera_spread_deg);
  if (average.num_inliers < settings.min_frames_per_pose ||
      average.spread_rms_deg > settings.max_camera_spread_deg) {
    return "camera orientation scatter " + fmt(average.spread_rms_deg) + " deg over " +
           std::to_string(rotations.size()) + " frames (limit " +
           fmt(settings.max_camera_spread_deg) + ")";
  }
  pose->R_target_cam =
      resolveSymmetry(average.mean, pose->R_world_imu, pose->group, poses, symmetries);
  pose->num_frames = average.num_inliers;
  pose->camera_spread_deg = average.spread_rms_deg;
  pose->reprojection_rms_px = reprojection_sum / static_cast<double>(rotations.size());
  pose->camera_pnp_cov_rad2 = pnp_cov_sum / static_cast<double>(rotations.size());
  return "";
}

std::string CalibrationPipeline::Impl::silentCameraReason() const {
  // Nothing arrived at all: the caller may name the silent topic (kNoCameraDataReason). Images
  // that came without intrinsics are the camera info's fault.
  if (num_frames == 0) return kNoCameraDataReason;
  if (!intrinsics && frames_without_intrinsics > 0) {
    return "no camera info received yet (" + std::to_string(frames_without_intrinsics) +
           " image(s) waiting for it)";
  }
  return "";
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
  joint_gyro_pending = GyroSegment{};  // the next motion starts at this rest
  pushBounded(&poses, pose);
  ++poses_total;
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
  out.scene_links = sceneLinkRefitter(out.joint, out.pose_indices);
  return out;
}

}  // namespace camera_imu_alignment
