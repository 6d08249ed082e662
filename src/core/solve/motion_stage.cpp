// The motion stage (window_solver.h): the frames during motion screened, the camera-IMU time
// offset's coarse value from the angular speeds, the report's figures of the motion and, without
// rests, pairs of motion frames for the pair estimators.
#include <cstdio>

#include "camera_imu_alignment/estimation/gyro_preintegration.h"
#include "camera_imu_alignment/estimation/time_offset.h"
#include "camera_imu_alignment/pipeline/frame_screening.h"
#include "window_stage.h"

namespace camera_imu_alignment {
namespace {

/// Motion pairs for the pair solvers: frames at least this far apart (s).
constexpr double kPairSpacingS = 0.3;
/// 1-sigma (s) of the time offset's prior around its coarse value (1 ms grid).
constexpr double kTimeshiftPriorSigmaS = 0.01;

/// Pairs of motion frames (camera relative rotation, gyro over the shifted interval with the
/// ideal gyro and no bias), kPairSpacingS to twice that apart.
void addMotionPairs(double timeshift_s, WindowSnapshot* window) {
  const std::vector<MotionFrame>& frames = window->joint.motion_frames;
  const GyroStream& gyro = window->joint.motion_gyro;
  size_t from = 0;
  for (size_t k = 1; k < frames.size(); ++k) {
    const double dt = frames[k].stamp_s - frames[from].stamp_s;
    if (dt < kPairSpacingS) continue;
    if (dt <= 2.0 * kPairSpacingS) {
      const double t_from = frames[from].stamp_s + timeshift_s;
      const double t_to = frames[k].stamp_s + timeshift_s;
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
  if (window->pairs.empty()) addMotionPairs(coarse.timeshift_cam_imu_s, window);
  return said;
}

class MotionStage : public WindowStage {
 public:
  const char* name() const override { return "motion"; }
  std::string run(WindowSolveState* state) const override {
    if (state->window.joint.motion_frames.empty()) return "";
    state->motion_note = prepareMotion(state->settings, &state->window, &state->motion);
    return state->motion_note;
  }
};

}  // namespace

std::unique_ptr<WindowStage> makeMotionStage() { return std::make_unique<MotionStage>(); }

}  // namespace camera_imu_alignment
