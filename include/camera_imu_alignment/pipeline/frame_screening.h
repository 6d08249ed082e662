// Which camera frames during motion are fit for the joint estimate, judged against the recording
// itself rather than a threshold in pixels chosen for one camera (issue 25's "frames with motion
// blur or a poor PnP fit are dropped by their reprojection error and PnP covariance"). The
// pipeline's motion frames are judged so (screenMotionFrames, before the time offset's coarse
// value); the setting max_reprojection_rms_px applies to them only when too few frames are there
// to judge each other. Frames at rest keep it (vision/camera_pose.h).
//
// The rule works on x = log(r), r a frame's RMS reprojection error (px): a scale changes every x by
// the same amount, so a camera with 7x the pixel error gets the same decisions. With m the median
// of x over the frames and s = 1.4826 MAD(x) their robust spread, a frame is dropped when
//   x > m + k_sigma * max(s, 1 / sqrt(2 n)),
// n = 2 N - 6 its residual coordinates (N corners): 1 / sqrt(2 n) is the spread of log(r) from
// pixel noise alone (n r^2 / sigma^2 chi-square with n dof), so a frame with few corners is not
// judged beyond what its own noise allows. Why not a chi-square test of each frame against the
// median: rendered frames of one recording differ in error by 10x (distance, view angle, aliasing)
// and that test dropped a quarter of the sharp frames (test_frame_screening). The frames kept are
// weighted by their own PnP covariance (sigma^2 (J^T J)^-1 with sigma^2 from their residuals).
#pragma once

#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {

/// One frame's PnP fit: RMS reprojection error (px) over `dof` = 2 N - 6 residual coordinates.
/// dof <= 0: the frame has no fit to judge (a given orientation, camera_pose) and is kept.
struct FrameFit {
  double reprojection_rms_px = 0;
  int dof = 0;
};

struct FrameScreening {
  std::vector<bool> keep;     ///< per frame, same order
  int dropped = 0;            ///< frames dropped
  double typical_rms_px = 0;  ///< exp(median log r) over the judged frames (0: none judged)
  double spread = 0;          ///< s, the robust spread of log r
  std::string note;           ///< "" when nothing was dropped, else what and why
};

/// Judges `frames` against each other (k_sigma > 0). A fit that is not finite or not positive is
/// dropped. Fewer than 10 judged frames: all finite fits kept (no reliable median).
FrameScreening screenFramesByReprojection(const std::vector<FrameFit>& frames,
                                          double k_sigma = 4.0);

/// The motion frames of a window judged against each other (screenFramesByReprojection on their
/// MotionFrame::reprojection_rms_px and reprojection_dof); the dropped ones are erased. Where
/// fewer than 10 frames have a fit, those above `fallback_max_rms_px` (the setting
/// max_reprojection_rms_px) are dropped instead: no recording to judge them by.
FrameScreening screenMotionFrames(std::vector<MotionFrame>* frames, double fallback_max_rms_px);

}  // namespace camera_imu_alignment
