// The joint estimate with camera links screened (JointProblem::camera_links, the natural scene): a
// wrong rotation between two views (a near-planar view's two-fold ambiguity, repeated texture)
// stands out by its residual; the link with the largest whitened residual beyond the chi-square(3)
// tail at kCameraLinkOutlierChi2 is first measured by each of its other solutions
// (CameraLink::alternatives) and keeps the one under which it fits (the lowest chi-square; each
// link's alternatives are tried once); if none fits it is left out and the problem solved again,
// at most a third of the links. The result names the links left out
// (JointResult::camera_links_left_out) and the solutions taken (camera_link_alternative_used).
//
// Comparing two models of one problem (the mount-change test) each screened on its own, a link left
// out costs kCameraLinkOutlierChi2 and counts with its 3 residuals (trimmedChi2, trimmedDof): a
// model that explains a link the other had to leave out gains up to that much. Without it, the one-
// mount fit left out the natural-scene rotations that crossed a remount about the robot's vertical
// (the only measurements that showed it) and the change went unseen.
#pragma once

#include <Eigen/Core>

#include "camera_imu_alignment/estimation/joint_estimator.h"
#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {

/// Chi-square(3) upper-tail point at p = 1e-4: a camera link beyond it is an outlier.
constexpr double kCameraLinkOutlierChi2 = 21.108;

/// `estimator`'s solve of `problem` from R_start, screening its camera links as above.
JointResult solveScreeningCameraLinks(const JointEstimator& estimator, JointProblem problem,
                                      const Eigen::Matrix3d& R_start);

/// chi2 + kCameraLinkOutlierChi2 per link left out.
double trimmedChi2(const JointResult& result);
/// dof + 3 per link left out (the dof with every link counted).
int trimmedDof(const JointResult& result);

}  // namespace camera_imu_alignment
