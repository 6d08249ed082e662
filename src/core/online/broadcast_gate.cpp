// The quality gates (broadcast_gate.h).
#include "camera_imu_alignment/online/broadcast_gate.h"

#include <Eigen/LU>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

const char* toString(GateDecision decision) {
  switch (decision) {
    case GateDecision::kReject:
      return "reject";
    case GateDecision::kKeep:
      return "keep";
    case GateDecision::kBroadcast:
      return "broadcast";
  }
  return "?";
}

namespace {

/// The difference between a joint estimate and a current calibration: its rotation vector
/// (rad, camera axes), and its chi-square (3 dof) under the estimate's covariance plus the current
/// one's when it has one; nullopt without a joint estimate or a usable covariance.
struct Difference {
  Eigen::Vector3d rotation_rad;
  double chi2 = 0;
  double p_value = 1;
};

std::optional<Difference> differenceOf(const AlignmentResult& estimate,
                                       const BroadcastEstimate& current) {
  if (!estimate.joint || !estimate.joint->ok) return std::nullopt;
  Eigen::Matrix3d covariance = estimate.joint->covariance_rad2;
  if (current.covariance_rad2) covariance += *current.covariance_rad2;
  if (!covariance.allFinite() || !(covariance.determinant() > 0.0)) return std::nullopt;
  Difference d;
  d.rotation_rad = logSO3(estimate.R_cam_imu * current.R_cam_imu.transpose());
  d.chi2 = d.rotation_rad.dot(covariance.inverse() * d.rotation_rad);
  if (!std::isfinite(d.chi2)) return std::nullopt;
  d.p_value = boost::math::cdf(boost::math::complement(boost::math::chi_squared(3.0), d.chi2));
  return d;
}

/// Camera orientations during motion behind an estimate (0 without the joint estimate's motion).
int motionNodesOf(const AlignmentResult& r) {
  return r.joint && r.joint->ok ? std::max(0, r.joint->motion_nodes) : 0;
}
int motionNodesOf(const std::optional<AlignmentResult>& r) { return r ? motionNodesOf(*r) : 0; }

/// "12 poses", "302 camera orientations during motion" or both.
std::string dataText(std::size_t poses, int motion_nodes) {
  std::string out;
  if (poses > 0 || motion_nodes == 0) out = std::to_string(poses) + " poses";
  if (motion_nodes > 0) {
    out += (out.empty() ? "" : " and ") + std::to_string(motion_nodes) +
           " camera orientations during motion";
  }
  return out;
}

}  // namespace

bool enoughMotion(const JointResult& joint, const OnlineSettings& settings) {
  const MotionFigures& m = joint.motion;
  return joint.motion_nodes > 0 && m.excitation_duration_s >= settings.min_motion_s &&
         rad2deg(m.excitation_rad.minCoeff()) >= settings.min_motion_rotation_deg;
}

std::string unexcitedAxes(const MotionFigures& motion, const OnlineSettings& settings) {
  std::vector<std::string> axes;
  for (int i = 0; i < 3; ++i) {
    if (!(rad2deg(motion.excitation_rad(i)) >= settings.min_motion_rotation_deg)) {
      axes.push_back(std::string("camera ") + "xyz"[i]);
    }
  }
  std::string out;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    out += (k == 0 ? "" : k + 1 == axes.size() ? " and " : ", ") + axes[k];
  }
  return out;
}

double differenceSignificance(const AlignmentResult& result, const BroadcastEstimate& broadcast) {
  if (!broadcast.covariance_rad2) return 1.0;
  const std::optional<Difference> d = differenceOf(result, broadcast);
  return d ? d->p_value : 1.0;
}

std::optional<CalibrationCheck> checkCalibration(const AlignmentResult& estimate,
                                                 const BroadcastEstimate& current,
                                                 double consistency_level) {
  if (estimate.status != SolveStatus::kOk) return std::nullopt;
  const std::optional<Difference> d = differenceOf(estimate, current);
  if (!d) return std::nullopt;
  CalibrationCheck check;
  check.error_deg = rad2deg(d->rotation_rad.norm());
  check.chi2 = d->chi2;
  check.sigmas = std::sqrt(check.chi2);
  check.p_value = d->p_value;
  check.consistent = check.p_value >= consistency_level;
  std::ostringstream text;
  text.precision(3);
  text << "the current calibration is " << check.error_deg << " deg (" << check.sigmas
       << " sigma) from the new estimate: chi2 " << check.chi2 << " (3 dof), p " << check.p_value
       << (check.consistent ? " >= " : " < ") << "consistency_level " << consistency_level << ": "
       << (check.consistent ? "still right" : "NOT consistent with the new poses: recalibrate");
  check.text = text.str();
  return check;
}

std::string broadcastWarning(const std::optional<CalibrationCheck>& check, bool latest_is_broadcast,
                             const std::string& gate_why) {
  if (!check || latest_is_broadcast) return "";
  if (check->consistent && !(check->sigmas > kBroadcastWarningSigmas)) return "";
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer),
                "the broadcast tf is %.2f deg (%.1f sigma) from the latest estimate, which the "
                "gates kept back: ",
                check->error_deg, check->sigmas);
  return buffer + (gate_why.empty() ? std::string("no reason given") : gate_why);
}

GateOutcome judgeEstimate(const AlignmentResult& r, std::size_t window_poses,
                          const OnlineSettings& settings,
                          const std::optional<BroadcastEstimate>& broadcast, bool fresh_start) {
  GateOutcome out;
  std::ostringstream why;
  why.precision(3);
  const double sigma = r.quality.std_dev_deg.maxCoeff();
  const bool joint = r.joint.has_value();
  if (joint) {  // the result's own rule (JointResult::consistent) at the gate's level
    JointResult judged = *r.joint;
    judged.consistency_level = settings.consistency_level;
    out.consistent = judged.consistent();
  }
  out.determined = r.status == SolveStatus::kOk && r.R_cam_imu.allFinite() &&
                   r.quality.std_dev_deg.allFinite() && sigma <= settings.max_std_dev_deg;
  if (r.status != SolveStatus::kOk) {
    why << r.message;
  } else if (!r.R_cam_imu.allFinite() || !r.quality.std_dev_deg.allFinite()) {
    why << "estimate or 1-sigma not finite";  // never reaches the tf or a file
  } else if (window_poses < static_cast<std::size_t>(settings.min_poses) &&
             !(joint && enoughMotion(*r.joint, settings))) {
    out.enough_data = false;
    why << window_poses << " poses in the window, min_poses is " << settings.min_poses;
    if (joint && r.joint->motion_nodes > 0) {
      const MotionFigures& m = r.joint->motion;
      why << "; motion " << m.excitation_duration_s << " s (min_motion_s " << settings.min_motion_s
          << "), rotation about camera x, y, z " << rad2deg(m.excitation_rad(0)) << ", "
          << rad2deg(m.excitation_rad(1)) << ", " << rad2deg(m.excitation_rad(2))
          << " deg (min_motion_rotation_deg " << settings.min_motion_rotation_deg << ")";
    }
  } else if (joint && !r.joint->ok) {
    why << "the joint estimate failed: " << r.joint->message;
  } else if (joint && !out.consistent) {
    why << "the data do not fit one mount: the residuals are " << r.joint->misfitRatio()
        << "x their measured noise (" << misfitBand(r.joint->misfitRatio()) << "; consistent up to "
        << kConsistentMisfitRatio << "x), chi2/dof "
        << (r.joint->dof > 0 ? r.joint->chi2 / r.joint->dof : 0.0) << ", p "
        << r.joint->chi2_p_value << " < consistency_level " << settings.consistency_level
        << " (a bad pose, a mount that moved, or IMU errors beyond the imu_prior_* values)";
  } else if (!joint && !(r.quality.residual_rms_deg <= settings.max_residual_deg)) {
    why << "residual RMS " << r.quality.residual_rms_deg << " deg > max_residual_deg "
        << settings.max_residual_deg;
  } else if (!out.determined) {
    why << "1-sigma " << sigma << " deg > max_std_dev_deg " << settings.max_std_dev_deg
        << ": more poses, rotated about other axes";
  } else if (broadcast && !fresh_start && sigma > broadcast->maxStdDevDeg() &&
             window_poses <= static_cast<std::size_t>(broadcast->poses) &&
             motionNodesOf(r) <= motionNodesOf(broadcast->result) &&
             differenceSignificance(r, *broadcast) >= settings.remount.level) {
    out.decision = GateDecision::kKeep;
    why << "1-sigma " << sigma << " deg from " << dataText(window_poses, motionNodesOf(r))
        << " is larger than the broadcast estimate's " << broadcast->maxStdDevDeg() << " deg from "
        << dataText(static_cast<std::size_t>(std::max(0, broadcast->poses)),
                    motionNodesOf(broadcast->result))
        << ": kept back (no silent regression)";
  } else if (broadcast && rad2deg(rotationAngle(broadcast->R_cam_imu.transpose() * r.R_cam_imu)) <=
                              settings.min_change_deg) {
    out.decision = GateDecision::kKeep;
    out.refines_broadcast = sigma < broadcast->maxStdDevDeg();
    why << "within min_change_deg " << settings.min_change_deg << " of the broadcast estimate";
    if (out.refines_broadcast) {
      why << " (its 1-sigma " << sigma << " deg from " << window_poses
          << " poses becomes the broadcast estimate's)";
    }
  } else {
    out.decision = GateDecision::kBroadcast;
  }
  out.why = why.str();
  return out;
}

}  // namespace camera_imu_alignment
