// A recording built from ViSP's real images (visp_data.h): the 8 flange poses become rests of an
// IMU that follows the flange, joined by minimum-jerk rotations; at each rest the pose's real image
// with 1.5 grey levels of fresh sensor noise at 5 Hz. The IMU has the consumer grade's datasheet
// noise and constant biases, no scale or cross-axis errors (the flange frame is exact); gravity is
// the base's -z. Shared by test_visp_recording (with the board) and test_visp_natural_scene
// (without: the camera's rotation from the images' features).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/simulation/trajectory.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "visp_data.h"

namespace camera_imu_alignment {
namespace test {

constexpr int kVispPoses = 8;
constexpr double kRestS = 4.0, kMoveS = 3.0, kImuRateHz = 200.0, kFrameRateHz = 5.0;
constexpr double kGravity = 9.81;

struct VispRecording {
  std::vector<Eigen::Matrix3d> R_world_imu;
  std::vector<cv::Mat> images;
};

inline bool loadVispRecording(const std::string& dir, VispRecording* out) {
  for (int i = 1; i <= kVispPoses; ++i) {
    Eigen::Matrix3d R;
    if (!test::readVispFlangeRotation(dir + "/franka_pose_rPe_" + std::to_string(i) + ".yaml",
                                      &R)) {
      return false;
    }
    const cv::Mat image =
        cv::imread(dir + "/franka_image-" + std::to_string(i) + ".png", cv::IMREAD_GRAYSCALE);
    if (image.empty()) return false;
    out->R_world_imu.push_back(R);
    out->images.push_back(image);
  }
  return true;
}

/// Feeds the recording to `pipeline`: IMU samples (gyro = w + b_g + n, accel = R^T (0, 0, g) +
/// b_a + n) and, at rest, the real image with fresh noise.
inline void feedVispRecording(const VispRecording& rec, CalibrationPipeline* pipeline) {
  std::mt19937 rng(23);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double gyro_sigma = 2.6e-4 * std::sqrt(kImuRateHz);    // consumer datasheet density
  const double accel_sigma = 2.26e-3 * std::sqrt(kImuRateHz);  // per sample
  const Eigen::Vector3d gyro_bias(0.004, -0.006, 0.003), accel_bias(0.04, -0.03, 0.05);
  const Eigen::Vector3d specific_force_world(0.0, 0.0, kGravity);
  auto noise = [&](double sigma) {
    return Eigen::Vector3d(sigma * normal(rng), sigma * normal(rng), sigma * normal(rng));
  };
  const double start = 100.0;
  double t = start;
  const double dt = 1.0 / kImuRateHz;
  double next_frame = t;
  for (int k = 0; k < kVispPoses; ++k) {
    const double rest_end = t + kRestS;
    for (; t < rest_end; t += dt) {
      const Eigen::Matrix3d& R = rec.R_world_imu[k];
      pipeline->addImu({t, gyro_bias + noise(gyro_sigma),
                        R.transpose() * specific_force_world + accel_bias + noise(accel_sigma)});
      if (t >= next_frame && t > rest_end - kRestS + 0.3 && t < rest_end - 0.3) {
        cv::Mat noisy;
        rec.images[k].convertTo(noisy, CV_32F);
        cv::Mat sensor(noisy.size(), CV_32F);
        cv::randn(sensor, 0.0, 1.5);
        noisy += sensor;
        cv::Mat frame;
        noisy.convertTo(frame, CV_8U);
        CameraFrame camera_frame;
        camera_frame.stamp_s = t;
        camera_frame.mono8 = frame;
        pipeline->addFrame(camera_frame);
        next_frame = t + 1.0 / kFrameRateHz;
      }
    }
    if (k + 1 == kVispPoses) break;
    const Eigen::Matrix3d& Ra = rec.R_world_imu[k];
    const Eigen::Vector3d phi = logSO3(Ra.transpose() * rec.R_world_imu[k + 1]);
    const double move_start = t;
    for (; t < move_start + kMoveS; t += dt) {
      double f, df, ddf;
      simulation::minimumJerk((t - move_start) / kMoveS, &f, &df, &ddf);
      const Eigen::Matrix3d R = Ra * expSO3(f * phi);
      const Eigen::Vector3d omega_imu = (df / kMoveS) * phi;  // body rate (phi is a body axis)
      pipeline->addImu({t, omega_imu + gyro_bias + noise(gyro_sigma),
                        R.transpose() * specific_force_world + accel_bias + noise(accel_sigma)});
    }
    next_frame = t;
  }
  pipeline->finish();
}

}  // namespace test
}  // namespace camera_imu_alignment
