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

void CalibrationPipeline::Impl::addMotion(double from_s, JointProblem* problem) const {
  for (const MotionFrame& frame : motion.frames) {
    if (frame.stamp_s >= from_s) problem->motion_frames.push_back(frame);
  }
  if (problem->motion_frames.empty()) return;
  const double gyro_from =
      std::min(from_s, problem->motion_frames.front().stamp_s) - settings.max_timeshift_s - 0.5;
  GyroStream& gyro = problem->motion_gyro;
  for (const MotionBuffers::RawImu& sample : motion.gyro) {
    if (sample.stamp_s < gyro_from) continue;
    gyro.stamps_s.push_back(sample.stamp_s);
    gyro.gyro_rad_s.push_back(sample.gyro_rad_s);
    gyro.accel_m_s2.push_back(sample.accel_m_s2);
  }
  gyro.noise_density_rad_s_sqrt_hz = joint_gyro.last_noise_density;
  // The accelerometer's white noise during the motion itself (vibration included).
  gyro.accel_noise_density_m_s2_sqrt_hz = whiteNoiseDensityOf(gyro.stamps_s, gyro.accel_m_s2);
}

}  // namespace camera_imu_alignment
