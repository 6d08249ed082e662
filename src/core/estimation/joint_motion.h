// Continuous motion in the joint estimator (private to src/core/estimation): the motion frames of a
// JointProblem become nodes interleaved with the rests, linked by the gyro between neighbours.
#pragma once

#include <Eigen/Core>
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

/// An accelerometer link preintegrated at the gyro model and time offset of a pass, in the IMU
/// frame at its start. Index k = 0 is the change of velocity (weight 1), k = 1 the change of
/// position beyond the starting velocity (weight to - t): d0[k] = int w_k DeltaR(t) a(t) dt (raw
/// accelerometer), bias_jacobian[k] = int w_k DeltaR dt, per_entry[k](r, 3 s + u) = int w_k
/// DeltaR(t)(r, s) a_u(t) dt, so that int w_k DeltaR (T_a^-1 (a - b)) dt ~ d0[k] -
/// bias_jacobian[k] b - sum_su P_su per_entry[k](:, 3 s + u) with P = T_a - I (first order).
struct AccelLinkIntegral {
  Eigen::Vector3d d0[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  Eigen::Matrix3d bias_jacobian[2] = {Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  Eigen::Matrix<double, 3, 9> per_entry[2] = {Eigen::Matrix<double, 3, 9>::Zero(),
                                              Eigen::Matrix<double, 3, 9>::Zero()};
  double duration_s = 0;  ///< to - from
  /// d d0[k] / d theta, theta = [T_g row-major (9), gyro bias at the start (3), at the end (3)]
  /// (propagated with the integral, as VIO's preintegration does for the bias), and theta at which
  /// it was taken (T_g entries with I subtracted): the accelerometer's integral follows the gyro
  /// model within a pass.
  Eigen::Matrix<double, 3, 15> gyro_jacobian[2] = {Eigen::Matrix<double, 3, 15>::Zero(),
                                                   Eigen::Matrix<double, 3, 15>::Zero()};
  Eigen::Matrix<double, 15, 1> theta0_minus_identity = Eigen::Matrix<double, 15, 1>::Zero();
};

/// The link over [t_from_s, t_to_s] (IMU clock) under T_g and the gyro biases at its ends.
AccelLinkIntegral integrateAccelLink(const GyroStream& samples, double t_from_s, double t_to_s,
                                     const Eigen::Matrix3d& T_g, const Eigen::Vector3d& b_from,
                                     const Eigen::Vector3d& b_to);

/// Maps a result of the expanded problem back to the caller's rests (per-pose vectors, the poses
/// left out, the mount change); motion nodes are counted in motion_nodes.
void mapResultToCaller(const ExpandedProblem& expanded, JointResult* result);

}  // namespace joint
}  // namespace camera_imu_alignment
