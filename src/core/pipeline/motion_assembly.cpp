// Continuous motion for the joint estimate: the frames and gyro the pipeline kept during motion
// become the joint problem's motion frames (estimation/joint_types.h), with the time offset's
// coarse value; without rests, pairs of motion nodes start the solve.
#include <cmath>
#include <cstdio>

#include "calibration_pipeline_impl.h"
#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/estimation/time_offset.h"
#include "camera_imu_alignment/pipeline/frame_screening.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

/// Motion pairs for the pair solvers: frames at least this far apart (s).
constexpr double kPairSpacingS = 0.3;
/// 1-sigma (s) of the time offset's prior around its coarse value (1 ms grid).
constexpr double kTimeshiftPriorSigmaS = 0.01;

}  // namespace

void CalibrationPipeline::Impl::addMotion(double from_s, JointProblem* problem) const {
  for (const MotionFrame& frame : motion_frames) {
    if (frame.stamp_s >= from_s) problem->motion_frames.push_back(frame);
  }
  if (problem->motion_frames.empty()) return;
  const double gyro_from =
      std::min(from_s, problem->motion_frames.front().stamp_s) - settings.max_timeshift_s - 0.5;
  GyroStream& gyro = problem->motion_gyro;
  for (const RawImu& sample : motion_gyro) {
    if (sample.stamp_s < gyro_from) continue;
    gyro.stamps_s.push_back(sample.stamp_s);
    gyro.gyro_rad_s.push_back(sample.gyro_rad_s);
    gyro.accel_m_s2.push_back(sample.accel_m_s2);
  }
  gyro.noise_density_rad_s_sqrt_hz = last_gyro_noise_density;
  // The accelerometer's white noise during the motion itself (vibration included).
  gyro.accel_noise_density_m_s2_sqrt_hz = whiteNoiseDensityOf(gyro.stamps_s, gyro.accel_m_s2);
}

std::string prepareMotion(const PipelineSettings& settings, WindowSnapshot* window,
                          MotionFigures* figures) {
  JointProblem& joint = window->joint;
  // Frames whose fit is far beyond the recording's own (a misdetected corner, a blurred board):
  // dropped before they can bend the time offset or the estimate.
  const FrameScreening screening =
      screenMotionFrames(&joint.motion_frames, settings.pose.max_reprojection_rms_px);
  figures->frames_dropped = screening.dropped;
  if (joint.motion_frames.empty()) {
    joint.motion_gyro = GyroStream{};
    return screening.note + " (no motion frames left)";
  }
  const TimeshiftSearch coarse =
      coarseTimeshift(joint.motion_frames, joint.motion_gyro, settings.max_timeshift_s);
  // The report's figures of the motion (JointResult::motion), once, from the data solved on.
  figures->timeshift_candidates_s = coarse.candidates_s;
  figures->timeshift_rms_difference_rad = coarse.rms_difference_rad;
  figures->coarse_timeshift_s = coarse.timeshift_cam_imu_s;
  const MotionExcitation excitation = motionExcitation(joint.motion_frames);
  figures->excitation_rad = excitation.about_cam_rad;
  figures->excitation_duration_s = excitation.duration_s;
  if (!coarse.ok) {
    joint.motion_frames.clear();
    joint.motion_gyro = GyroStream{};
    return coarse.message + " (" + "motion frames not used)";
  }
  joint.timeshift_initial_s = coarse.timeshift_cam_imu_s;
  joint.timeshift_prior_sigma_s = kTimeshiftPriorSigmaS;
  if (!(joint.motion_gyro.noise_density_rad_s_sqrt_hz > 0.0)) {
    joint.motion_gyro.noise_density_rad_s_sqrt_hz = gyroNoiseDensityOf(joint.motion_gyro);
  }
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer),
                "%zu frames; timeshift_cam_imu %.1f ms from the angular speeds (+-%.3f s searched)",
                joint.motion_frames.size(), 1e3 * coarse.timeshift_cam_imu_s,
                settings.max_timeshift_s);
  const std::string said = screening.note.empty() ? buffer : buffer + ("; " + screening.note);
  if (!window->pairs.empty()) return said;
  // No rest pairs: pairs of motion frames (camera relative rotation, gyro over the shifted
  // interval with the ideal gyro and no bias) for the pair solvers.
  const std::vector<MotionFrame>& frames = joint.motion_frames;
  const GyroStream& gyro = joint.motion_gyro;
  size_t from = 0;
  for (size_t k = 1; k < frames.size(); ++k) {
    const double dt = frames[k].stamp_s - frames[from].stamp_s;
    if (dt < kPairSpacingS) continue;
    if (dt <= 2.0 * kPairSpacingS) {
      const double t_from = frames[from].stamp_s + coarse.timeshift_cam_imu_s;
      const double t_to = frames[k].stamp_s + coarse.timeshift_cam_imu_s;
      if (!gyro.stamps_s.empty() && gyro.stamps_s.front() <= t_from &&
          gyro.stamps_s.back() >= t_to) {
        RotationPair pair;
        pair.A_cam = frames[from].R_target_cam.transpose() * frames[k].R_target_cam;
        pair.B_imu = preintegrateGyroInterval(gyro.stamps_s, gyro.gyro_rad_s, t_from, t_to,
                                              Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(),
                                              Eigen::Vector3d::Zero())
                         .delta_R;
        window->pairs.push_back(pair);
      }
    }
    from = k;
  }
  return said;
}

}  // namespace camera_imu_alignment
