// Where a pose's camera orientation comes from: one CameraSource per pipeline, chosen by the first
// camera frame (chooseCameraSource). Private to the pipeline; not installed.
//
//   board       images of the target: detection and PnP at rest, detection during motion
//               (board_source.cpp)
//   given pose  the camera's orientation given with each frame (CameraFrame::R_target_cam, the
//               camera_pose topic): nothing to detect (given_pose_source.cpp)
//   scene       images without a target (TargetDescription::numPoints() == 0): the natural
//               scene's features, the rotation from earlier rests (scene_source.cpp)
//
// The pipeline owns the source and calls it in stamp order: takeRestFrame for a frame inside a rest
// (the IMU at rest), takeMotionFrame for a frame during motion, assessRest when the rest has
// ended; it never asks which source it has.
//
// Units and frames, as everywhere in the package (doc/CONVENTIONS.md): stamps in seconds (a
// frame's on the camera's clock, a rest's on the IMU's; the rest's margins, frame_margin_s, absorb
// an offset between them), angles in radians unless named _deg, covariances in rad^2 about the
// camera's axes (right perturbation). R_target_cam maps camera vectors into the target frame (p_t =
// R_target_cam p_cam); for the natural scene the "target" frame is the camera frame of the scene's
// first rest (StationaryPose::scene).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/pipeline/calibration_pipeline.h"
#include "camera_imu_alignment/pipeline/stationary_window.h"

namespace camera_imu_alignment {

/// What the pipeline knows of the camera's inputs: owned by the pipeline, read and counted into by
/// its source.
struct CameraInputs {
  std::optional<CameraIntrinsics> intrinsics;  ///< camera_info's model, the latest valid one
  std::uint64_t frames = 0;    ///< camera frames accepted by the pipeline (images or camera poses)
  std::uint64_t detected = 0;  ///< frames at rest on which target detection ran (board)
  std::uint64_t without_intrinsics = 0;  ///< images at rest that came before any camera info
};

/// How a source refuses an input: counted by reason and reported (PipelineCallbacks::on_reject).
using RejectInput = std::function<void(RejectReason, InputStream, const std::string&)>;

/// What a source is made with; the references are the pipeline's and outlive the source.
struct CameraSourceSetup {
  const TargetDescription& target;  ///< the target file's (empty: no target)
  const PipelineSettings& settings;
  CameraInputs& inputs;
  RejectInput reject;
};

/// The poses the pipeline has assembled, for a source to read (the pipeline's, read-only).
struct PoseHistoryView {
  const std::vector<StationaryPose>& poses;  ///< accepted poses, oldest first (the newest 1000)
  const StationaryWindow& window;            ///< the solver's window
};

class CameraSource {
 public:
  virtual ~CameraSource() = default;

  /// What the source is, for messages: "images of the target (detection and PnP)", ... (the
  /// pipeline refuses frames of the other stream than the one that chose the source:
  /// RejectReason::kMixedCameraSource).
  virtual std::string describe() const = 0;

  /// A frame inside the rest in progress, which began at `rest_since_s` (IMU clock, s: a new value
  /// is a new rest). The source keeps what it needs of it for assessRest (spacing and per-rest
  /// caps are its own) and counts or refuses what it cannot use.
  virtual void takeRestFrame(const CameraFrame& frame, std::optional<double> rest_since_s,
                             const PoseHistoryView& history) = 0;
  /// A frame during motion, at least motion_frame_interval_s after the last motion frame kept:
  /// its camera orientation (R_target_cam with its covariance; the position and the PnP fit when
  /// known), or nothing when the frame gives none (target out of view, no target to find). `latest`
  /// is the newest motion frame kept, or null.
  virtual std::optional<MotionFrame> takeMotionFrame(const CameraFrame& frame,
                                                     const MotionFrame* latest) = 0;
  /// A rest ended. `pose` comes with its IMU side (index, group, R_world_imu); the source fills its
  /// camera side (R_target_cam, p_target_cam, num_frames, camera_spread_deg, reprojection and PnP
  /// covariance, camera_source, the scene's fields) from the frames it took inside `segment`
  /// shrunk by frame_margin_s, and, for the natural scene, `entry`'s camera links (and
  /// entry->joint.camera_absolute). Frames after the segment stay for the next rest. Returns the
  /// reason the rest is no pose ("target seen in 1 frame(s), 2 needed", kNoCameraDataReason ...),
  /// or "" for a pose.
  virtual std::string assessRest(const StationarySegment& segment, const PoseHistoryView& history,
                                 StationaryPose* pose, StationaryWindow::Entry* entry) = 0;

  /// The snapshot's refitter of the natural scene's links (WindowSnapshot::scene_links; the links
  /// of `problem`, whose pose indices are local to the window, `pose_indices` their
  /// StationaryPose::index); null for a source without such links.
  virtual std::shared_ptr<const SceneLinkRefitter> sceneLinkRefitter(
      const JointProblem& problem, const std::vector<int>& pose_indices) const;
  /// The held fits a solve made (CalibrationPipeline::rememberSceneRefits); ignored by default.
  virtual void rememberRefits(const std::vector<SceneRefit>& refits);

  /// CalibrationPipeline::targetNotFoundDiagnosis: "" unless the source looks for a target it never
  /// found (`rejections`: the pipeline's counts).
  virtual std::string targetNotFoundDiagnosis(const RejectionCounts& rejections) const;
  /// CalibrationPipeline::cameraModelCheck at `level`: no views unless the source fits the camera
  /// model on what it sees.
  virtual CameraModelCheck cameraModelCheck(double level, const CameraIntrinsics* intrinsics) const;
  /// Frames at rest held with a camera orientation until their rest ends
  /// (PipelineBufferSizes::detections); 0 by default.
  virtual std::size_t heldRestFrames() const;
};

/// The source for a pipeline whose first camera frame came on `stream`: kCameraPose: the given
/// poses; kImage: the board when the target has points, else the natural scene. The one place
/// sources are chosen: a new source adds its line here.
std::unique_ptr<CameraSource> chooseCameraSource(InputStream stream,
                                                 const CameraSourceSetup& setup);
/// Until a camera frame arrives: every rest is no pose, for want of camera data.
std::unique_ptr<CameraSource> makeNoCameraSource();
std::unique_ptr<CameraSource> makeBoardSource(const CameraSourceSetup& setup);
std::unique_ptr<CameraSource> makeGivenPoseSource(const CameraSourceSetup& setup);
std::unique_ptr<CameraSource> makeSceneSource(const CameraSourceSetup& setup);

/// Why a rest has no camera frame when no camera data or no camera info came at all, else "".
std::string silentCameraReason(const CameraInputs& inputs);
/// For the image sources: true when an image at rest can be used with the intrinsics; otherwise
/// counted (no camera info yet: inputs->without_intrinsics) or refused (another size than the
/// camera info's: kBadImage).
bool imageFitsIntrinsics(const CameraFrame& frame, CameraInputs* inputs, const RejectInput& reject);

/// `value` with `precision` decimals, for the pipeline's messages.
std::string fmt(double value, int precision = 2);

}  // namespace camera_imu_alignment
