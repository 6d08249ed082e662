#include "camera_imu_alignment/ros/broadcast_gate.h"

#include <sstream>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

GateOutcome judgeEstimate(const AlignmentResult& r, std::size_t window_poses,
                          const WrapperSettings& settings,
                          const std::optional<PublishedEstimate>& published, bool after_remount) {
  GateOutcome out;
  std::ostringstream why;
  why.precision(3);
  const double sigma = r.quality.std_dev_deg.maxCoeff();
  if (r.status != SolveStatus::kOk) {
    why << r.message;
  } else if (!r.R_cam_imu.allFinite() || !r.quality.std_dev_deg.allFinite()) {
    why << "estimate or 1-sigma not finite";  // never reaches the tf or a file
  } else if (window_poses < static_cast<std::size_t>(settings.min_poses)) {
    why << window_poses << " poses in the window, min_poses is " << settings.min_poses;
  } else if (!(r.quality.residual_rms_deg <= settings.max_residual_deg)) {
    why << "residual RMS " << r.quality.residual_rms_deg << " deg > max_residual_deg "
        << settings.max_residual_deg;
  } else if (!(sigma <= settings.max_std_dev_deg)) {
    why << "1-sigma " << sigma << " deg > max_std_dev_deg " << settings.max_std_dev_deg
        << ": more poses, rotated about other axes";
  } else if (published && !after_remount && sigma > published->max_std_dev_deg) {
    out.decision = GateDecision::kKeep;
    why << "1-sigma " << sigma << " deg is larger than the broadcast estimate's "
        << published->max_std_dev_deg << " deg: kept back (no silent regression)";
  } else if (published && rad2deg(rotationAngle(published->R_cam_imu.transpose() * r.R_cam_imu)) <=
                              settings.min_change_deg) {
    out.decision = GateDecision::kKeep;
    why << "within min_change_deg " << settings.min_change_deg << " of the broadcast estimate";
  } else {
    out.decision = GateDecision::kBroadcast;
  }
  out.why = why.str();
  return out;
}

}  // namespace camera_imu_alignment
