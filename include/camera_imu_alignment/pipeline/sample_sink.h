// Where time-stamped sensor samples go: the calibration pipeline, or the online calibrator that
// owns one. MessageInput (ROS messages -> samples) feeds either. No ROS type.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "camera_imu_alignment/config/pipeline_settings.h"
#include "camera_imu_alignment/inertial/inertial_samples.h"
#include "camera_imu_alignment/pipeline/input_rejections.h"
#include "camera_imu_alignment/vision/camera_model.h"

namespace camera_imu_alignment {

/// One camera frame: an image converted to mono8 by the caller (ROS wrapper / bag reader), or a
/// camera orientation given from elsewhere.
struct CameraFrame {
  double stamp_s = 0.0;
  cv::Mat mono8;  ///< CV_8UC1; unused when R_target_cam is given
  /// The camera orientation when it comes from elsewhere (the user's own detector, motion capture:
  /// the nodelet's camera_pose topic): then no image and no detection are needed. A pipeline takes
  /// either images or given orientations: the first frame's kind, the other refused
  /// (RejectReason::kMixedCameraSource).
  std::optional<Eigen::Matrix3d> R_target_cam;
  /// With R_target_cam: the camera's centre in the target frame (m), when given (camera_pose's
  /// position); the joint estimate's acceleration model uses it during motion.
  std::optional<Eigen::Vector3d> p_target_cam_m;
};

class SampleSink {
 public:
  virtual ~SampleSink() = default;
  virtual void addImu(const ImuSample& sample) = 0;
  virtual void addMagnetic(const MagneticSample& sample) = 0;
  /// Sets or replaces the intrinsics (validated; a bad one is counted and ignored: false).
  virtual bool setCameraIntrinsics(const CameraIntrinsics& intrinsics) = 0;
  virtual void addFrame(const CameraFrame& frame) = 0;
  /// Counts an input refused before it reached the sink (a message without a stamp, an image
  /// that cannot be converted, ...) and reports it like the sink's own refusals.
  virtual void rejectInput(RejectReason reason, InputStream stream, const std::string& detail) = 0;
  virtual ImuOrientationSource imuOrientationSource() const = 0;
};

}  // namespace camera_imu_alignment
