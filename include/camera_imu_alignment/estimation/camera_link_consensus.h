// Which of a camera link's solutions the gyro agrees with, before the joint estimate.
//
// A near-planar view gives two essential matrices that explain its matches about equally
// (CameraLink::alternatives); on the simulator's hand-held room a third of the links took the
// wrong one, 0.3-6 deg off with a 1-sigma of hundredths of a degree, too many for the joint
// estimate's one-at-a-time screening to find from a start they had already pulled away.
//
// Between two rests of one gyro chain the IMU's rotation theta_imu (rotation vector, IMU axes,
// from the gyro integrated with the rests' mean rates as biases, T_g = I) and the camera's
// (phi, camera axes) satisfy phi = R_cam_imu T theta_imu to first order, where T absorbs the
// gyro's scale and cross-axis errors. So a linear map M (3 x 3) takes every link's IMU rotation
// vector onto one of its camera solutions:
//  1. RANSAC over two links and one solution of each: R_cam_imu from their rotation vectors (axes
//     and angles), the links whose nearest solution lies within a loose gate (the uncalibrated
//     gyro: kLooseGateRel of the angle plus kLooseGateDeg) counted;
//  2. M fitted by least squares to the consensus links' nearest solutions, their residual's robust
//     scale measured, and the nearest solutions chosen again (three rounds);
//  3. a link is given its other solution when that one lies within kSwapSigmas of the scale and
//     the measured one beyond it. When the other solution is the nearer but the measured one also
//     lies within, the gyro leans to the other without telling them apart: the link's covariance
//     is widened to span both (CameraLink::undecided_rad2). Measured on the simulated hand-held
//     room with the fast feature profile (seed 109): two links held the wrong one of two
//     solutions 0.08 and 0.24 deg apart at a 1-sigma of 0.001-0.002 deg, and the joint estimate
//     bent the IMU's states to fit them (chi2/dof 1.69, inconsistent).
// Links across gyro chains, windows with fewer than kMinConsensusLinks links in one chain, or no
// consensus of them, are left as they are (the joint estimate's screening still judges them).
#pragma once

#include <vector>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {

/// What the consensus found.
struct CameraLinkConsensus {
  int links_judged = 0;  ///< links within one gyro chain with an IMU rotation
  int consensus = 0;     ///< of them, within the final gate on their nearest solution
  /// Per JointProblem::camera_links entry: -1 where the measured rotation stays, else the index
  /// into the entry's alternatives of the solution it now holds (the measured one took that
  /// place among its alternatives).
  std::vector<int> alternative_used;
  double residual_scale_deg = 0;  ///< robust scale of the consensus links' residuals (deg)
  int undecided = 0;  ///< links whose covariance was widened to span their undecided solutions
};

/// Chooses each camera link's solution as above, in place: a link given its other solution holds
/// it as R_from_to / cov_rad2 and the measured one in its place among the alternatives.
CameraLinkConsensus chooseCameraLinkSolutions(JointProblem* problem);

}  // namespace camera_imu_alignment
