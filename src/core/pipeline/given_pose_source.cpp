// The given-pose source: each frame carries the camera's orientation (CameraFrame::R_target_cam,
// the camera_pose topic: the user's own detector, motion capture); nothing is detected. At rest a
// few spaced frames are averaged as the board's are; during motion every frame is a motion frame
// with an assumed 1-sigma.
#include <cmath>

#include "camera_source.h"
#include "rest_frame_poses.h"

namespace camera_imu_alignment {
namespace {

/// 1-sigma (deg per axis) assumed for a camera orientation given without covariance (camera_pose).
constexpr double kGivenOrientationSigmaDeg = 0.05;

class GivenPoseSource : public CameraSource {
 public:
  explicit GivenPoseSource(const CameraSourceSetup& setup)
      : settings_(setup.settings),
        inputs_(setup.inputs),
        // The poses are of the target file's board: its symmetries are resolved as a detection's.
        frames_(setup.settings,
                TargetDetector(setup.target, setup.settings.detector).symmetries()) {}

  std::string describe() const override { return "camera poses (camera_pose)"; }

  void takeRestFrame(const CameraFrame& frame, std::optional<double> rest_since_s,
                     const PoseHistoryView&) override {
    if (!frame.R_target_cam ||
        !frames_.due(frame.stamp_s, settings_.min_frame_interval_s, rest_since_s)) {
      return;
    }
    frames_.markTried(frame.stamp_s);
    CameraPose given;
    given.R_target_cam = *frame.R_target_cam;
    frames_.add(frame.stamp_s, given);
  }

  std::optional<MotionFrame> takeMotionFrame(const CameraFrame& frame,
                                             const MotionFrame*) override {
    if (!frame.R_target_cam) return std::nullopt;
    MotionFrame motion;
    motion.stamp_s = frame.stamp_s;
    motion.R_target_cam = *frame.R_target_cam;
    motion.p_target_cam_m = frame.p_target_cam_m;
    // A given orientation states no covariance: a motion-capture or PnP class 1-sigma; the joint
    // estimate scales its covariance by chi2/dof when the data say it is larger.
    const double sigma_rad = kGivenOrientationSigmaDeg * 3.14159265358979323846 / 180.0;
    motion.cov_cam_rad2 = sigma_rad * sigma_rad * Eigen::Matrix3d::Identity();
    return motion;
  }

  std::string assessRest(const StationarySegment& segment, const PoseHistoryView& history,
                         StationaryPose* pose, StationaryWindow::Entry*) override {
    const double lo = segment.start_s + settings_.frame_margin_s;
    const double hi = segment.end_s - settings_.frame_margin_s;
    return frames_.average(frames_.takeRest(lo, hi, segment.end_s), RestFrameShortfall{}, inputs_,
                           history.poses, pose);
  }

  std::size_t heldRestFrames() const override { return frames_.size(); }

 private:
  const PipelineSettings& settings_;
  const CameraInputs& inputs_;
  RestFramePoses frames_;
};

}  // namespace

std::unique_ptr<CameraSource> makeGivenPoseSource(const CameraSourceSetup& setup) {
  return std::make_unique<GivenPoseSource>(setup);
}

}  // namespace camera_imu_alignment
