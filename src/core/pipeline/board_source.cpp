// The board source: images of the calibration target. At rest a few spaced frames are detected
// (backing off after misses), their PnP poses averaged at the rest's end, and every detection
// fitted for the camera-model check; during motion each frame is detected near the previous one's
// board and its PnP pose is a motion frame.
#include <limits>
#include <sstream>

#include "camera_model_monitor.h"
#include "camera_source.h"
#include "rest_frame_poses.h"

namespace camera_imu_alignment {
namespace {

class BoardSource : public CameraSource {
 public:
  explicit BoardSource(const CameraSourceSetup& setup)
      : settings_(setup.settings),
        target_(setup.target),
        inputs_(setup.inputs),
        reject_(setup.reject),
        detector_(setup.target, setup.settings.detector),
        frames_(setup.settings, detector_.symmetries()) {}

  std::string describe() const override { return "images of the target (detection and PnP)"; }

  void takeRestFrame(const CameraFrame& frame, std::optional<double> rest_since_s,
                     const PoseHistoryView& history) override {
    // Detection is the expensive part: only a few, spaced frames per rest.
    if (rest_since_s != misses_rest_) {  // a new rest: the target may be in view again
      misses_rest_ = rest_since_s;
      misses_in_a_row_ = 0;
    }
    const double interval = misses_in_a_row_ >= PipelineSettings::kMissesBeforeBackoff
                                ? settings_.missed_frame_interval_s
                                : settings_.min_frame_interval_s;
    if (!frames_.due(frame.stamp_s, interval, rest_since_s)) return;
    if (!imageFitsIntrinsics(frame, &inputs_, reject_)) return;
    const CameraIntrinsics& intrinsics = *inputs_.intrinsics;
    frames_.markTried(frame.stamp_s);
    ++inputs_.detected;
    const Eigen::Matrix3d* hint =
        history.poses.empty() ? nullptr : &history.poses.back().R_target_cam;
    TargetObservation observation;
    if (!detector_.detect(frame.mono8, &observation, hint)) {
      ++misses_in_a_row_;
      std::ostringstream out;
      out << "image at " << formatStamp(frame.stamp_s) << " s (at rest): " << target_.describe()
          << " not found";
      if (!observation.mismatch.empty()) {
        target_mismatch_ = observation.mismatch;
        out << " (" << observation.mismatch << ")";
      }
      reject_(RejectReason::kTargetNotFound, InputStream::kImage, out.str());
      return;
    }
    // What the frame says about the camera model, whatever becomes of its pose.
    if (const auto fit = fitCameraModel(observation, target_, intrinsics)) {
      camera_model_.addFrame(frame.stamp_s, *fit);
    }
    std::string why;
    const auto pose = estimateCameraPose(observation, target_, intrinsics, settings_.pose, &why);
    if (!pose) {
      camera_model_.addRefused(frame.stamp_s, why);
      reject_(RejectReason::kPoseRejected, InputStream::kImage,
              "image at " + formatStamp(frame.stamp_s) + " s: " + why);
      return;
    }
    misses_in_a_row_ = 0;
    target_mismatch_.clear();  // the file's board is in view after all
    frames_.add(frame.stamp_s, *pose);
  }

  std::optional<MotionFrame> takeMotionFrame(const CameraFrame& frame,
                                             const MotionFrame* latest) override {
    const std::optional<CameraIntrinsics>& intrinsics = inputs_.intrinsics;
    if (!intrinsics || frame.mono8.cols != intrinsics->width ||
        frame.mono8.rows != intrinsics->height) {
      return std::nullopt;  // counted and said by the rests' frames
    }
    ++motion_detections_;
    const Eigen::Matrix3d* hint = latest ? &latest->R_target_cam : nullptr;
    // The previous frame's board is where this one's is looked for first (the camera turns a
    // few degrees between frames at 20 Hz; further apart, the whole image is searched).
    constexpr double kSearchNearWithinS = 0.25;
    const bool recent = frame.stamp_s - last_motion_points_stamp_ <= kSearchNearWithinS &&
                        frame.stamp_s >= last_motion_points_stamp_;
    TargetObservation observation;
    if (!detector_.detect(frame.mono8, &observation, hint,
                          recent ? &last_motion_points_ : nullptr)) {
      return std::nullopt;  // out of view or blurred
    }
    last_motion_points_ = observation.image_points;
    last_motion_points_stamp_ = frame.stamp_s;
    // No pixel threshold here: the window's frames are judged against each other
    // (screenMotionFrames, when the motion is solved).
    PoseSettings pose_settings = settings_.pose;
    pose_settings.max_reprojection_rms_px = std::numeric_limits<double>::infinity();
    std::string why;
    const auto pose = estimateCameraPose(observation, target_, *intrinsics, pose_settings, &why);
    if (!pose) return std::nullopt;  // no PnP solution
    MotionFrame motion;
    motion.stamp_s = frame.stamp_s;
    motion.R_target_cam = pose->R_target_cam;
    motion.p_target_cam_m = pose->p_target_cam;
    motion.cov_cam_rad2 = pose->cov_rotation_rad2;
    motion.reprojection_rms_px = pose->reprojection_rms_px;
    motion.reprojection_dof = 2 * pose->num_points - 6;
    return motion;
  }

  std::string assessRest(const StationarySegment& segment, const PoseHistoryView& history,
                         StationaryPose* pose, StationaryWindow::Entry*) override {
    // The frames inside the segment, margins off both ends; later ones are kept for the next rest.
    const double lo = segment.start_s + settings_.frame_margin_s;
    const double hi = segment.end_s - settings_.frame_margin_s;
    const std::vector<FrameDetection> inside = frames_.takeRest(lo, hi, segment.end_s);
    RestFrameShortfall shortfall;
    shortfall.refused = camera_model_.refusedIn(lo, hi);  // target seen, pose refused
    shortfall.refused_text = camera_model_.endRest(lo, hi, segment.end_s);
    shortfall.mismatch = target_mismatch_;
    return frames_.average(inside, shortfall, inputs_, history.poses, pose);
  }

  std::string targetNotFoundDiagnosis(const RejectionCounts& rejections) const override {
    const std::uint64_t tried = inputs_.detected;
    if (tried < CalibrationPipeline::kFramesForTargetDiagnosis ||
        rejections.count(RejectReason::kTargetNotFound) < tried) {
      return "";
    }
    std::string out = "the target (" + target_.describe() + ") was not found in any of " +
                      std::to_string(tried) +
                      " frames at rest: does the target file describe the board in view?";
    if (!target_mismatch_.empty()) out += " " + target_mismatch_;
    return out;
  }

  CameraModelCheck cameraModelCheck(double level,
                                    const CameraIntrinsics* intrinsics) const override {
    return camera_model_.check(level, intrinsics);
  }

  std::size_t heldRestFrames() const override { return frames_.size(); }

 private:
  const PipelineSettings& settings_;
  const TargetDescription& target_;
  CameraInputs& inputs_;
  RejectInput reject_;
  TargetDetector detector_;
  RestFramePoses frames_;              ///< the detections at rest
  int misses_in_a_row_ = 0;            ///< failed detections in a row at the rest misses_rest_
  std::optional<double> misses_rest_;  ///< start of the rest they belong to
  std::string target_mismatch_;        ///< the detector's latest TargetObservation::mismatch
  /// What the frames at rest say about camera_info's model (every detection, pose or not).
  CameraModelMonitor camera_model_{CalibrationPipeline::kHistoryLimit};
  /// The target's image points (pixels) in the last frame during motion where it was found, and
  /// that frame's stamp (s): the next frame's detection searches near them first.
  std::vector<cv::Point2f> last_motion_points_;
  double last_motion_points_stamp_ = -std::numeric_limits<double>::infinity();
  std::uint64_t motion_detections_ = 0;  ///< frames during motion on which detection ran
};

}  // namespace

std::unique_ptr<CameraSource> makeBoardSource(const CameraSourceSetup& setup) {
  return std::make_unique<BoardSource>(setup);
}

}  // namespace camera_imu_alignment
