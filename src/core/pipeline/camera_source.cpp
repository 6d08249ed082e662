// CameraSource (camera_source.h): the defaults, the choice of the source, and what the sources
// share.
#include "camera_source.h"

#include <sstream>

namespace camera_imu_alignment {

std::shared_ptr<const SceneLinkRefitter> CameraSource::sceneLinkRefitter(
    const JointProblem& problem, const std::vector<int>& pose_indices) const {
  (void)problem;
  (void)pose_indices;
  return nullptr;
}

void CameraSource::rememberRefits(const std::vector<SceneRefit>& refits) { (void)refits; }

std::string CameraSource::targetNotFoundDiagnosis(const RejectionCounts& rejections) const {
  (void)rejections;
  return "";
}

CameraModelCheck CameraSource::cameraModelCheck(double level,
                                                const CameraIntrinsics* intrinsics) const {
  return checkCameraModel({}, level, intrinsics);
}

std::size_t CameraSource::heldRestFrames() const { return 0; }

std::unique_ptr<CameraSource> chooseCameraSource(InputStream stream,
                                                 const CameraSourceSetup& setup) {
  if (stream == InputStream::kCameraPose) return makeGivenPoseSource(setup);
  if (setup.target.numPoints() > 0) return makeBoardSource(setup);
  return makeSceneSource(setup);
}

namespace {

/// No camera frame yet: nothing to take, every rest is no pose for want of camera data.
class NoCameraSource : public CameraSource {
 public:
  std::string describe() const override { return "no camera frame yet"; }
  void takeRestFrame(const CameraFrame&, std::optional<double>, const PoseHistoryView&) override {}
  std::optional<MotionFrame> takeMotionFrame(const CameraFrame&, const MotionFrame*) override {
    return std::nullopt;
  }
  std::string assessRest(const StationarySegment&, const PoseHistoryView&, StationaryPose*,
                         StationaryWindow::Entry*) override {
    return kNoCameraDataReason;
  }
};

}  // namespace

std::unique_ptr<CameraSource> makeNoCameraSource() { return std::make_unique<NoCameraSource>(); }

std::string silentCameraReason(const CameraInputs& inputs) {
  // Nothing arrived at all: the caller may name the silent topic (kNoCameraDataReason). Images
  // that came without intrinsics are the camera info's fault.
  if (inputs.frames == 0) return kNoCameraDataReason;
  if (!inputs.intrinsics && inputs.without_intrinsics > 0) {
    return "no camera info received yet (" + std::to_string(inputs.without_intrinsics) +
           " image(s) waiting for it)";
  }
  return "";
}

bool imageFitsIntrinsics(const CameraFrame& frame, CameraInputs* inputs,
                         const RejectInput& reject) {
  if (!inputs->intrinsics) {
    ++inputs->without_intrinsics;
    return false;
  }
  const CameraIntrinsics& intrinsics = *inputs->intrinsics;
  if (frame.mono8.cols != intrinsics.width || frame.mono8.rows != intrinsics.height) {
    std::ostringstream out;
    out << frame.mono8.cols << "x" << frame.mono8.rows << " differs from the camera info's "
        << intrinsics.width << "x" << intrinsics.height << "; frame dropped";
    reject(RejectReason::kBadImage, InputStream::kImage, out.str());
    return false;
  }
  return true;
}

std::string fmt(double value, int precision) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(precision);
  out << value;
  return out.str();
}

}  // namespace camera_imu_alignment
