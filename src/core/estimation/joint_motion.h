// Continuous motion in the joint estimator (private to src/core/estimation): the motion frames of a
// JointProblem become nodes interleaved with the rests, linked by the gyro between neighbours.
#pragma once

#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_types.h"

namespace camera_imu_alignment {
namespace joint {

/// A problem with its motion frames turned into nodes (JointPose::at_rest false; start_s = end_s =
/// the frame's stamp shifted by timeshift_initial_s, i.e. on the IMU clock at the initial offset),
/// ordered in time with the rests, and gyro segments between neighbours (GyroSegment::interval
/// where a node is an end). Rest-to-rest segments without nodes between them are the caller's.
struct ExpandedProblem {
  JointProblem problem;
  std::vector<int> caller_pose;    ///< per pose of `problem`: the caller's rest index, -1: a node
  std::vector<int> expanded_pose;  ///< per caller rest: its index in `problem`
  int motion_nodes = 0;
};

/// Empty when the motion input is usable, else the reason (names the frame or sample).
std::string validateMotion(const JointProblem& problem);

/// The expanded problem (a copy of `problem` when it has no motion frames).
ExpandedProblem expandMotion(const JointProblem& problem, const JointSettings& settings);

/// Maps a result of the expanded problem back to the caller's rests (per-pose vectors, the poses
/// left out, the mount change); motion nodes are counted in motion_nodes.
void mapResultToCaller(const ExpandedProblem& expanded, JointResult* result);

/// Motion frames' covariance re-weighting (JointEstimator::solve): their covariance is scaled by
/// chi2/dof, first when it exceeds kMotionReweightAbove, then while it exceeds
/// kMotionReweightSettled, in at most kMaxMotionReweights more solves.
constexpr double kMotionReweightAbove = 2.0;
constexpr double kMotionReweightSettled = 1.1;
constexpr int kMaxMotionReweights = 4;

}  // namespace joint
}  // namespace camera_imu_alignment
