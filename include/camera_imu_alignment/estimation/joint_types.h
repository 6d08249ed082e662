// Input, settings and result of the joint maximum-likelihood estimator (joint_estimator.h).
//
// Frames: W is gravity-aligned (z up, gravity (0, 0, -g)); its heading is a free gauge unless the
// magnetometer is used, then W's +y is magnetic north. The target frame is the calibration
// target's, the camera frame the image's optical frame, the IMU frame the accelerometer's (the gyro
// and magnetometer axes are modelled relative to it). R_a_b maps b-frame vectors into frame a.
//
// Sensor models (IMU frame; SI units: m/s^2, rad/s, tesla, seconds):
//   accelerometer at rest  a = T_a R_world_imu^T (0, 0, g) + b_a,k   (b_a per rest: it walks)
//   gyroscope              w = T_g w_true + b_g(t)
//   magnetometer           m = S_m R_world_imu^T m_world + h,  m_world = (0, |m| cos dip, -|m| sin
//   dip)
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/estimation/joint_result.h"

namespace camera_imu_alignment {

/// One stationary pose (a rest) with its averaged measurements.
struct JointPose {
  /// Gyro residuals only link consecutive poses of one group (e.g. one recording).
  int group = 0;
  double start_s = 0, end_s = 0;  ///< the rest (s)
  /// Camera in the target frame (PnP average). Without a target (camera_absolute false) the
  /// camera in a scene frame fixed in the world, e.g. the first rest's camera frame with the
  /// measured relative rotations (JointProblem::camera_links) chained onto it: a starting value.
  Eigen::Matrix3d R_target_cam = Eigen::Matrix3d::Identity();
  /// Covariance of R_target_cam (rad^2, camera axes, right perturbation R Exp(delta)); unused
  /// when camera_absolute is false.
  Eigen::Matrix3d cov_cam_rad2 = Eigen::Matrix3d::Zero();
  /// False: the camera's orientation is measured only relative to other poses' (the natural
  /// scene, JointProblem::camera_links); R_target_cam is then no measurement and gets no prior.
  bool camera_absolute = true;
  Eigen::Vector3d accel_mean_m_s2 = Eigen::Vector3d::Zero();  ///< IMU frame, mean over the rest
  Eigen::Matrix3d accel_mean_cov = Eigen::Matrix3d::Zero();   ///< (m/s^2)^2, scatter / N
  Eigen::Vector3d gyro_mean_rad_s = Eigen::Vector3d::Zero();  ///< raw mean gyro (= bias at rest)
  Eigen::Matrix3d gyro_mean_cov = Eigen::Matrix3d::Zero();    ///< (rad/s)^2, of that mean
  std::optional<Eigen::Vector3d> mag_mean_t;  ///< tesla, IMU frame; empty when unusable
  Eigen::Matrix3d mag_mean_cov = Eigen::Matrix3d::Zero();  ///< T^2, of that mean
  /// The field was flagged by a check on the raw field (its norm or dip against the other rests',
  /// inertial/magnetometer.h), which cannot tell a disturbance from uncalibrated iron (15 uT of
  /// hard iron changes the norm by a third with the orientation). The estimator tries such a
  /// field with the iron calibrated and keeps it when it fits (JointEstimator: screening).
  bool mag_flagged = false;
  /// False: not a rest but the camera's orientation at one instant of continuous motion (a node
  /// the estimator makes of JointProblem::motion_frames; start_s = end_s = its stamp, camera
  /// clock): no accelerometer, gyro-mean or magnetometer residual, only the camera prior and the
  /// gyro between it and its neighbours. Callers leave it true.
  bool at_rest = true;
};

/// The camera's orientation at a frame during motion (the target seen, or a camera_pose message).
struct MotionFrame {
  double stamp_s = 0;  ///< camera clock (s): t_imu = stamp_s + timeshift_cam_imu_s
  Eigen::Matrix3d R_target_cam = Eigen::Matrix3d::Identity();
  /// Covariance of R_target_cam (rad^2, camera axes, right perturbation), e.g. PnP's.
  Eigen::Matrix3d cov_cam_rad2 = Eigen::Matrix3d::Zero();
  /// The camera's centre in the target frame (m), when known (PnP, camera_pose): the positions
  /// the acceleration model needs (JointSettings::motion_accel_link_s).
  std::optional<Eigen::Vector3d> p_target_cam_m;
  /// The PnP fit it came from: RMS reprojection error (px) over reprojection_dof = 2 N - 6
  /// residual coordinates (N corners); dof 0 for a given orientation (camera_pose), which has no
  /// fit to judge (pipeline/frame_screening.h).
  double reprojection_rms_px = 0;
  int reprojection_dof = 0;
};

/// An unbroken stream of raw gyro samples (IMU clock, strictly increasing stamps, no gaps), with
/// the accelerometer's samples at the same stamps when given (empty: no acceleration model).
struct GyroStream {
  std::vector<double> stamps_s;
  std::vector<Eigen::Vector3d> gyro_rad_s;  ///< raw, gyro axes
  double noise_density_rad_s_sqrt_hz = 0;   ///< measured white noise (rad/s/sqrt(Hz))
  std::vector<Eigen::Vector3d>
      accel_m_s2;  ///< raw, IMU (accelerometer) axes; empty or one per stamp
  double accel_noise_density_m_s2_sqrt_hz = 0;  ///< measured white noise (m/s^2/sqrt(Hz))
};

/// The accelerometer during motion between two keyframes (set by the estimator): motion nodes
/// with a camera position about JointSettings::motion_accel_link_s apart, consecutive in a chain.
/// Each keyframe has the IMU's velocity and the camera centre's position as states, the position
/// measured by the camera; the accelerometer, rotated by the gyro from `from` and integrated once
/// and twice over the link, must give the change of velocity and of position (VIO's
/// preintegration), with gravity and the lever arm.
struct AccelLink {
  int from_pose = 0, to_pose = 0;  ///< keyframes (JointProblem::poses), from < to
  GyroStream samples;              ///< gyro and accelerometer over [from, to] and a margin
  /// The camera centre measured at the two keyframes (target frame, m).
  Eigen::Vector3d p_from_target_m = Eigen::Vector3d::Zero(),
                  p_to_target_m = Eigen::Vector3d::Zero();
  /// Start values of the velocity at the two keyframes (target frame, m/s): central differences
  /// of the chain's keyframe positions.
  Eigen::Vector3d v_from_target_m_s = Eigen::Vector3d::Zero(),
                  v_to_target_m_s = Eigen::Vector3d::Zero();
};

/// The camera's rotation between two poses measured without a target (vision/scene_rotation.h):
/// R_cam_from_cam_to maps the `to` pose's camera vectors into the `from` pose's camera frame.
struct CameraLink {
  int from_pose = 0, to_pose = 0;  ///< indices into JointProblem::poses, from != to
  Eigen::Matrix3d R_from_to = Eigen::Matrix3d::Identity();
  /// Covariance (rad^2, `to` camera axes, right perturbation R_from_to Exp(delta)).
  Eigen::Matrix3d cov_rad2 = Eigen::Matrix3d::Zero();
  /// Other rotations the views explain about as well (a near-planar view's second essential
  /// matrix; vision/scene_rotation.h), same frames: the screening (camera_link_screening.h) takes
  /// one in place of R_from_to when the IMU's measurements say so.
  struct Alternative {
    Eigen::Matrix3d R_from_to = Eigen::Matrix3d::Identity();
    Eigen::Matrix3d cov_rad2 = Eigen::Matrix3d::Zero();
  };
  std::vector<Alternative> alternatives;
  /// The spread between solutions the gyro's consensus could not choose between (rad^2, frames as
  /// cov_rad2; estimation/camera_link_consensus.h): already in cov_rad2 and the alternatives'
  /// covariances, and added to the covariance of the link fitted again.
  Eigen::Matrix3d undecided_rad2 = Eigen::Matrix3d::Zero();
};

/// Raw gyro samples from the end of rest `from_pose` to the start of rest `to_pose`. Sample i holds
/// over [stamps_s[i], stamps_s[i + 1]); the last one over the segment's median sample interval.
struct GyroSegment {
  int from_pose = 0, to_pose = 0;  ///< indices into JointProblem::poses, to_pose = from_pose + 1
  std::vector<double> stamps_s;    ///< strictly increasing (s)
  std::vector<Eigen::Vector3d> gyro_rad_s;  ///< raw, gyro axes
  double noise_density_rad_s_sqrt_hz = 0;   ///< measured white noise (rad/s/sqrt(Hz))
  /// Set by the estimator for the segments it makes around motion nodes (callers leave them):
  /// the samples are integrated over exactly [from, to] with the rate interpolated between
  /// samples (preintegrateGyroInterval), where an end at a motion node is that node's stamp
  /// shifted by the time offset (t_imu = t_cam + timeshift_cam_imu_s) and an end at a rest is the
  /// rest's end (from) or start (to).
  bool interval = false;
};

struct JointProblem {
  std::vector<JointPose> poses;
  std::vector<GyroSegment> segments;
  /// Relative camera rotations between poses whose camera_absolute is false (the natural scene).
  /// Such poses connected by links form a camera group whose rotation relative to the world is
  /// estimated from the IMU (the first group's when no pose has an absolute camera orientation:
  /// the world frame's gauge). A relative-only pose without a link (its links left the window)
  /// keeps its IMU measurements; its camera tells nothing.
  std::vector<CameraLink> camera_links;
  /// A mount change (the change-point model of mount_change.h): poses from this index on have
  /// their own R_cam_imu (JointResult::R_cam_imu_after_change), the IMU's parameters stay shared,
  /// and the gyro segment into this pose (the motion during which the mount moved) measures the
  /// IMU's turn from the first mount's orientation to the second's (the IMU turned so whenever the
  /// mount moved; a segment into a motion node there is left out). -1: one mount for all poses.
  int mount_change_pose = -1;
  /// The same for continuous motion: the first rest or motion node at or after this stamp (camera
  /// clock, as MotionFrame::stamp_s) has the second R_cam_imu, and the gyro into it is not used.
  /// NaN: none. Not together with mount_change_pose.
  double mount_change_stamp_s = std::numeric_limits<double>::quiet_NaN();

  /// Continuous motion (no rests needed): the camera's orientation at the frames outside the rests
  /// (stamp order) and the raw gyro over them (covering every frame's stamp plus the time offset).
  /// The estimator takes nodes from the frames (JointSettings::motion_node_spacing_s) and links
  /// consecutive nodes and rests by the gyro between them (the segment between two rests with
  /// nodes in between is then replaced by the chain through the nodes). The accelerometer is not
  /// used during motion (it measures gravity plus the rig's acceleration).
  std::vector<MotionFrame> motion_frames;
  GyroStream motion_gyro;
  /// The camera-IMU time offset, Kalibr's timeshift_cam_imu (t_imu = t_cam + timeshift; s):
  /// estimated with the motion nodes, from this initial value (e.g. coarseTimeshift,
  /// motion_pairs.h) under a Gaussian prior of this 1-sigma (s). Unused without motion frames.
  double timeshift_initial_s = 0;
  double timeshift_prior_sigma_s = 0.05;
  /// Set by the estimator from motion_frames with positions and motion_gyro's accelerometer
  /// (callers leave it empty).
  std::vector<AccelLink> accel_links;
  /// The noise of each learned kind (NoiseKind) relative to the stated one that the problem is
  /// solved under: the estimator's start, and what it learned (JointResult::noise) when a caller
  /// solves a variant of the same recording (the mount-change fits). Callers leave it at 1.
  NoiseFactors noise = unitNoiseFactors();
};

/// 1-sigma of the Gaussian priors on the IMU parameters (mean: the ideal sensor, T = I, bias 0).
/// Defaults: a consumer MEMS unit (gyro sensitivity 1.5 %, cross-axis 1 %, accelerometer scale 1 %
/// and bias 0.2 m/s^2, hard iron 15 uT, soft iron 5 %). Both biases are per pose: the walks link
/// each pose's bias to the previous pose's (sigma = walk x sqrt(dt), dt the time between the
/// rests' centres), and accel_bias_m_s2 holds the first pose's.
struct ImuModelPriors {
  double gyro_scale = 0.015;                  ///< diagonal of T_g - I (dimensionless)
  double gyro_cross_axis = 0.01;              ///< off-diagonal of T_g (misalignment + cross-axis)
  double gyro_bias_walk_rad_s_sqrt_s = 1e-4;  ///< bias random walk (rad/s/sqrt(s))
  double accel_scale = 0.01;                  ///< diagonal of T_a - I
  double accel_cross_axis = 0.01;             ///< off-diagonal parameters of T_a
  double accel_bias_m_s2 = 0.2;               ///< each axis of b_a (at the first pose)
  /// Accelerometer bias random walk (m/s^2/sqrt(s) = m/s^3/sqrt(Hz), Kalibr's
  /// accelerometer_random_walk). Consumer datasheets (ICM-20948, BMI088) state none; 1e-3 is about
  /// 1.7x the simulator's consumer grade (6e-4) and 2.3x its ideal grade (4.33e-4): the margin
  /// the gyro's walk prior has too (1e-4 against 4e-5).
  double accel_bias_walk_m_s2_sqrt_s = 1e-3;
  double soft_iron_scale = 0.05;  ///< diagonal of S_m - I
  double soft_iron_cross = 0.05;  ///< off-diagonal of S_m (symmetric)
  double hard_iron_t = 15e-6;     ///< each axis of h (T)
};

enum class RobustLossKind { kNone, kHuber, kCauchy };
enum class MagnetometerUse {
  kAuto,  ///< use it when enough poses have a usable field (JointSettings::min_mag_poses_hard_iron)
  kOn,    ///< use every usable pose's field, even with the iron held at its prior
  kOff
};
/// Shape of T_a - I; both leave no rotation (the accelerometer's axes define the IMU frame).
enum class AccelMatrixForm {
  kLowerTriangular,  ///< [[sx,0,0],[kyx,sy,0],[kzx,kzy,sz]]: x axis exact, y in the x-y plane
  kSymmetric         ///< symmetric (polar decomposition without its rotation)
};

/// What is done with the gyro and accelerometer matrices T_g and T_a.

/// 'select', 'estimate', 'identity' (the configuration's words).
const char* toString(ImuMatrixModel model);
/// False (model unchanged) for an unknown word.
bool parseImuMatrixModel(const std::string& text, ImuMatrixModel* model);

struct JointSettings {
  ImuModelPriors priors;
  AccelMatrixForm accel_matrix_form = AccelMatrixForm::kLowerTriangular;
  ImuMatrixModel imu_matrices = ImuMatrixModel::kSelect;
  double model_selection_level = 0.01;  ///< for ImuMatrixModel::kSelect, in (0, 1)
  /// Robust loss on the camera, accelerometer, magnetometer and gyro residual blocks; the scale is
  /// in sigma units of the whitened block (|r| below it is unaffected by Huber).
  RobustLossKind robust_loss = RobustLossKind::kHuber;
  double robust_loss_scale = 4.0;
  int max_iterations = 50;       ///< Levenberg-Marquardt iterations per solve
  int max_relinearisations = 5;  ///< gyro preintegration passes (outer loop), >= 2
  /// Ceres threads per solve (residual and Jacobian evaluation; the same estimate with any
  /// count). 1 in the nodelet, which leaves the other core to its callbacks; calibrate_bag uses
  /// the machine's cores (up to 2). Not a setting key.
  int solver_threads = 1;
  MagnetometerUse use_magnetometer = MagnetometerUse::kAuto;
  /// Local gravity (m/s^2) of the accelerometer model. The pipeline sets it from the setting
  /// gravity_m_s2 (jointSettingsOf in calibration_pipeline.h), as the stationary detector's.
  double gravity_m_s2 = 9.81;
  /// The estimate is refused (ok = false, "R_cam_imu is not determined") when its 1-sigma about a
  /// camera axis exceeds this (deg): the poses do not determine R_cam_imu (e.g. no rotation
  /// between them). Not a setting key; far above the broadcast gate (the key max_std_dev_deg).
  double undetermined_std_dev_deg = 10.0;
  /// False: the fit alone (R_cam_imu, R_cam_imu_after_change, chi2, dof, p-value, per-pose
  /// residuals); no covariance (zero 1-sigma), no IMU parameters. For callers that compare fits
  /// (the mount-change test needs its chi-square drops only; the covariance is about a tenth of
  /// a solve, and with one pose after a split and no magnetometer the second mount's rotation
  /// about that pose's gravity is determined by nothing but a weak prior).
  bool compute_covariance = true;
  /// Learn the noise of each measurement kind (NoiseKind) from the recording: its variance
  /// factor estimated from its residuals' chi-square and redundancy and the window solved again
  /// until the factors settle (variance-component estimation, JointResult::noise). A kind with
  /// less redundancy than kMinNoiseRedundancy keeps the stated noise. Only with
  /// compute_covariance (fits compared with each other keep the problem's JointProblem::noise).
  bool learn_noise = true;

  // What the data determine. Every parameter is estimated with its prior: no geometric rule (of
  // rotation angles, gravity or field directions) decides what is estimated. A parameter the poses
  // carry little information about (posterior 1-sigma above kInformedFraction of its prior's on
  // some entry, joint_observability.h) stays near its prior mean, its prior uncertainty carried
  // into every covariance so that the 1-sigma of R_cam_imu still covers it; it is reported as not
  // estimated, with a note. With pin_unexcited_parameters such a parameter is instead held
  // constant at its prior mean (SetParameterBlockConstant; decided by a first solve) and the
  // covariances ignore its uncertainty.
  bool pin_unexcited_parameters = false;
  /// MagnetometerUse::kAuto uses the magnetometer when at least this many poses have a usable
  /// field (the hard iron, 3 unknowns, then has more field directions than unknowns).
  int min_mag_poses_hard_iron = 4;

  /// The camera's noise as the recording shows it. Real PnP has errors the pixel-noise
  /// covariance does not describe (lens model, board flatness, the IMU's own reference); when the
  /// rests' camera residuals fail their chi-square test at this level (3 dof per rest) and the
  /// median rest is off too (a misfit of most poses, not of a remounted or bad few), an isotropic
  /// variance is added to every rest's camera covariance, found so that the median rest's camera
  /// chi-square is chi-square(3)'s median, and the window solved again
  /// (JointResult::camera_excess_variance_rad2). 0: never. Only with compute_covariance (a full
  /// solve); fits compared with each other (the mount-change test) keep one noise model.
  double camera_excess_level = 1e-3;

  // Noise floors (added in quadrature to the given covariances; 1-sigma).
  double accel_mean_sigma_floor_m_s2 = 5e-4;
  double gyro_mean_sigma_floor_rad_s = 1e-5;
  double mag_mean_sigma_floor_t = 5e-8;
  double camera_sigma_floor_rad = 1e-5;
  double gyro_integration_sigma_floor_rad = 1e-5;

  /// Motion nodes (JointProblem::motion_frames): consecutive nodes are at least this far apart
  /// (s). Shorter intervals add nodes (parameters) whose rotation is barely above the camera's
  /// noise; longer ones leave frames unused.
  double motion_node_spacing_s = 0.1;
  /// Motion nodes further than this (s) from the next node or rest are linked to it only when
  /// the gyro covers the gap: beyond it the chain breaks (the target was out of view).
  double motion_max_link_s = 2.0;
  /// The acceleration model (AccelLink): keyframes about this far apart (s), the accelerometer
  /// between them against their velocity and position; 0: the accelerometer is used at rests only.
  double motion_accel_link_s = 1.0;
  /// 1-sigma (m) of each axis of a camera position (PnP, camera_pose) in the acceleration model.
  double camera_position_sigma_m = 1e-3;
  /// 1-sigma (m) of the prior on each axis of the IMU's position in the camera frame (the lever
  /// arm the acceleration model needs; estimated with it).
  double lever_arm_prior_m = 0.2;
};

}  // namespace camera_imu_alignment
