// libFuzzer: the pipeline's sample input path. The input is read as a stream of records (a type
// byte, a stamp and three or nine doubles taken raw from the bytes: NaN, Inf, huge and denormal
// values included) fed to a CalibrationPipeline as IMU samples, magnetometer samples, given camera
// orientations and small images. Nothing may crash; any result must be finite.
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>

#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/vision/target_description.h"

namespace cia = camera_imu_alignment;

namespace {

struct Reader {
  const std::uint8_t* data;
  std::size_t size, pos = 0;
  bool more() const { return pos < size; }
  std::uint8_t byte() { return pos < size ? data[pos++] : 0; }
  double number() {
    double v = 0.0;
    if (pos + sizeof(double) <= size) std::memcpy(&v, data + pos, sizeof(double));
    pos += sizeof(double);
    return v;
  }
  Eigen::Vector3d vec() {
    const double x = number(), y = number(), z = number();
    return {x, y, z};
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const cia::TargetDescription target = cia::parseTargetYaml(
      "target_type: checkerboard\ntargetCols: 4\ntargetRows: 3\nrowSpacingMeters: 0.04\n"
      "colSpacingMeters: 0.04\n",
      "fuzz");
  cia::PipelineSettings settings;
  settings.min_poses_to_solve = 2;
  bool finite_results = true;
  cia::PipelineCallbacks callbacks;
  callbacks.on_result = [&](const cia::AlignmentResult& r) {
    finite_results = finite_results && r.R_cam_imu.allFinite();
  };
  cia::CalibrationPipeline pipeline(target, settings, callbacks);
  Reader in{data, size};
  while (in.more()) {
    const std::uint8_t type = in.byte() % 5;
    const double stamp = in.number();
    if (type == 0) {
      const Eigen::Vector3d gyro = in.vec();
      pipeline.addImu({stamp, gyro, in.vec()});
    } else if (type == 1) {
      pipeline.addMagnetic({stamp, in.vec()});
    } else if (type == 2) {
      cia::CameraFrame frame;
      frame.stamp_s = stamp;
      Eigen::Matrix3d R;
      for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = in.number();
      frame.R_target_cam = R;
      pipeline.addFrame(frame);
    } else if (type == 3) {
      cia::CameraFrame frame;
      frame.stamp_s = stamp;
      frame.mono8 = cv::Mat(24, 32, CV_8UC1, cv::Scalar(in.byte()));
      pipeline.addFrame(frame);
    } else {
      cia::CameraIntrinsics intrinsics;
      intrinsics.width = 32;
      intrinsics.height = 24;
      for (int i = 0; i < 9; ++i) intrinsics.K(i / 3, i % 3) = in.number();
      pipeline.setCameraIntrinsics(intrinsics);
    }
  }
  pipeline.finish();
  const cia::AlignmentResult r = pipeline.solve();
  if (!finite_results || !r.R_cam_imu.allFinite()) __builtin_trap();
  return 0;
}
