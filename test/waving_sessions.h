// Test and benchmark harness for recordings without rests (issue 25): a simulated run's IMU,
// magnetometer and camera orientations (SimulationRun::camera_orientations: the truth with the
// simulator's camera_pose noise, stamped at capture time + camera_time_offset_s, no rendering) fed
// in stamp order to a SampleSink (a CalibrationPipeline or an OnlineCalibrator), as calibrate_bag
// feeds a bag with a camera_pose topic. The caller calls finish().
#pragma once

#include <limits>

#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/simulation/simulation_run.h"

namespace camera_imu_alignment {
namespace test {

/// The waving scenario (60 s of continuous hand-held motion, no rests) of `grade` with camera
/// orientations at `camera_rate_hz` whose stamps are `timeshift_cam_imu_s` behind the IMU's
/// clock (Kalibr's sign: t_imu = t_cam + timeshift, i.e. camera_time_offset_s = -timeshift).
inline simulation::SimulationConfig wavingConfig(simulation::ImuGrade grade, std::uint64_t seed,
                                                 double timeshift_cam_imu_s = 0.015,
                                                 double camera_rate_hz = 20.0) {
  simulation::SimulationConfig c;
  c.seed = seed;
  simulation::applyScenario("waving", &c);
  simulation::applyImuGrade(grade, &c);
  c.camera_time_offset_s = -timeshift_cam_imu_s;
  c.camera_rate_hz = camera_rate_hz;
  c.images = false;
  return c;
}

/// Feeds `run` to `sink` in stamp order (IMU, magnetometer, camera orientations as camera_pose
/// messages would carry them).
inline void feedOrientations(const simulation::SimulationRun& run, SampleSink* sink) {
  std::size_t next_imu = 0, next_mag = 0;
  auto feedUpTo = [&](double t) {
    while (next_imu < run.imu.size() && run.imu[next_imu].t <= t) {
      const auto& s = run.imu[next_imu++];
      sink->addImu({s.t, s.gyro, s.accel});
    }
    while (next_mag < run.mag.size() && run.mag[next_mag].t <= t) {
      const auto& s = run.mag[next_mag++];
      sink->addMagnetic({s.t, s.field});
    }
  };
  for (const simulation::CameraOrientation& o : run.camera_orientations) {
    feedUpTo(o.stamp_s);
    CameraFrame frame;
    frame.stamp_s = o.stamp_s;
    frame.R_target_cam = o.R_target_cam;
    sink->addFrame(frame);
  }
  feedUpTo(std::numeric_limits<double>::infinity());
}

}  // namespace test
}  // namespace camera_imu_alignment
