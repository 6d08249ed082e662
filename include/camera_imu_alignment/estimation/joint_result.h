// What the joint maximum-likelihood estimate (estimation/joint_estimator.h) answers: R_cam_imu with
// its covariance, the IMU model at the estimate and the chi-square consistency figures;
// estimation/alignment_result.h puts it beside the pair solve as the window solve's answer.
// Frames and units as estimation/joint_types.h states them (camera axes, IMU = accelerometer axes,
// SI units).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace camera_imu_alignment {

/// Default significance level of the chi-square consistency test (the consistency_level setting,
/// online/online_types.h).
inline constexpr double kDefaultConsistencyLevel = 1e-3;
/// Residuals within this factor of their noise (JointResult::misfitRatio) are consistent whatever
/// the chi-square test's p-value: "good" up to it, "fair" up to kFairMisfitRatio, "poor" beyond.
inline constexpr double kConsistentMisfitRatio = 1.2;
inline constexpr double kFairMisfitRatio = 1.5;
/// "good", "fair" or "poor" (the bands above).
inline const char* misfitBand(double misfit_ratio) {
  if (misfit_ratio <= kConsistentMisfitRatio) return "good";
  return misfit_ratio <= kFairMisfitRatio ? "fair" : "poor";
}

enum class ImuMatrixModel {
  kEstimate,  ///< estimated, held by their priors (ImuModelPriors)
  kIdentity,  ///< held at I without uncertainty: a unit whose scale and axes are calibrated
  /// Both solved; T = I kept unless the likelihood ratio rejects it (chi2 of the identity model
  /// minus the estimated one's, chi-square with as many degrees of freedom as free entries of T,
  /// p below model_selection_level): the data's own evidence for scale and misalignment errors.
  kSelect
};

/// The measurement kinds whose noise the joint estimator learns from the recording (variance
/// components, JointSettings::learn_noise): the camera's orientation at the motion nodes, the
/// camera's position at the acceleration model's keyframes, the gyro's white noise (the relative
/// rotations it integrates), the accelerometer's white noise during motion (the acceleration
/// model's links) and both biases' random walks.
enum class NoiseKind {
  kCameraMotion,
  kCameraPosition,
  kGyroWhite,
  kAccelWhite,
  kGyroWalk,
  kAccelWalk
};
inline constexpr int kNoiseKinds = 6;
/// "camera_orientation", "camera_position", "gyro_noise", "accel_noise", "gyro_walk",
/// "accel_walk".
inline const char* toString(NoiseKind kind) {
  switch (kind) {
    case NoiseKind::kCameraMotion:
      return "camera_orientation";
    case NoiseKind::kCameraPosition:
      return "camera_position";
    case NoiseKind::kGyroWhite:
      return "gyro_noise";
    case NoiseKind::kAccelWhite:
      return "accel_noise";
    case NoiseKind::kGyroWalk:
      return "gyro_walk";
    case NoiseKind::kAccelWalk:
      break;
  }
  return "accel_walk";
}

/// Variance factors of the measurement kinds: the noise variance the recording shows over the
/// stated one (the datasheet, the driver's covariance or the settings'); 1 = as stated.
using NoiseFactors = std::array<double, kNoiseKinds>;
inline NoiseFactors unitNoiseFactors() { return {1.0, 1.0, 1.0, 1.0, 1.0, 1.0}; }

/// The noise as the recording shows it: per kind, the variance factor the estimate used, the
/// robust chi-square of that kind's residuals under it and their redundancy (residuals minus the
/// share of the parameters they determine, the trace of their hat matrix), whence the factor
/// (variance-component estimation: factor x chi2 / redundancy, iterated with the solve).
struct LearnedNoise {
  NoiseFactors variance_factor = unitNoiseFactors();
  std::array<double, kNoiseKinds> chi2{}, redundancy{};
  std::array<int, kNoiseKinds> residuals{};
  /// The kind had redundancy enough to learn its factor (else it kept the stated noise).
  std::array<bool, kNoiseKinds> learned{};
  /// The stated 1-sigma noise of each kind (0: the recording has none of it), in the kind's
  /// units: camera orientation rad (the median motion frame's, per axis), camera position m,
  /// gyro white noise rad/s/sqrt(Hz), accelerometer white noise m/s^2/sqrt(Hz), gyro bias walk
  /// rad/s/sqrt(s), accelerometer bias walk m/s^2/sqrt(s) (Kalibr's imu.yaml units).
  std::array<double, kNoiseKinds> stated{};
  /// The kind's noise as measured: stated x sigmaFactor (the stated value where not learned).
  double measured(NoiseKind kind) const {
    return stated[static_cast<size_t>(kind)] * sigmaFactor(kind);
  }
  bool settled = true;  ///< the factors changed by less than 10 % in the last pass
  int passes = 0;       ///< passes that updated a factor
  /// The 1-sigma noise factor of a kind: sqrt(variance_factor).
  double sigmaFactor(NoiseKind kind) const {
    return std::sqrt(variance_factor[static_cast<size_t>(kind)]);
  }
};

/// One reported parameter block.
struct EstimatedValue {
  std::string name;       ///< e.g. "gyro_matrix_column_x", "accel_bias_m_s2"
  Eigen::VectorXd value;  ///< in the block's units
  Eigen::VectorXd sigma;  ///< 1-sigma: posterior when estimated, the prior's when held
  bool estimated = false;
};

/// The IMU model at the estimate. Sigmas are 1-sigma (posterior, or the prior's when held).
struct ImuIntrinsics {
  Eigen::Matrix3d gyro_matrix = Eigen::Matrix3d::Identity();  ///< T_g
  Eigen::Matrix3d gyro_matrix_sigma = Eigen::Matrix3d::Zero();
  std::array<bool, 3> gyro_matrix_column_estimated = {false, false, false};  ///< per gyro axis
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();  ///< at the first pose with gyro data
  Eigen::Vector3d gyro_bias_sigma_rad_s = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> gyro_bias_per_pose_rad_s;  ///< per pose (the rest mean if unused)
  Eigen::Matrix3d accel_matrix = Eigen::Matrix3d::Identity();  ///< T_a
  Eigen::Matrix3d accel_matrix_sigma = Eigen::Matrix3d::Zero();
  bool accel_matrix_estimated = false;
  Eigen::Vector3d accel_bias_m_s2 = Eigen::Vector3d::Zero();  ///< b_a at the first pose
  Eigen::Vector3d accel_bias_sigma_m_s2 = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> accel_bias_per_pose_m_s2;  ///< b_a per pose (it walks)
  bool accel_bias_estimated = false;
  Eigen::Matrix3d soft_iron = Eigen::Matrix3d::Identity();  ///< S_m
  Eigen::Matrix3d soft_iron_sigma = Eigen::Matrix3d::Zero();
  bool soft_iron_estimated = false;
  Eigen::Vector3d hard_iron_t = Eigen::Vector3d::Zero();
  Eigen::Vector3d hard_iron_sigma_t = Eigen::Vector3d::Zero();
  bool hard_iron_estimated = false;
  bool magnetometer_used = false;
  double magnetic_field_t = 0;  ///< |m_world| (T), when the magnetometer is used
  double magnetic_dip_rad = 0;  ///< dip (rad, positive downwards), when used
};

/// What the report shows of the continuous motion (calibration_report.h), computed once where the
/// data are: the per-node residuals by the estimator, the rest by the pipeline from the motion
/// frames and the raw gyro it solved on (calibration_pipeline.h). Empty without motion nodes.
struct MotionFigures {
  /// Per motion node in time order: its stamp (s, camera clock) and its RMS whitened residual
  /// (sigma units, as pose_residual_norm: its camera prior and half of each adjacent gyro and
  /// accelerometer link; about 1 where the camera and the gyro agree within their noise).
  std::vector<double> node_stamps_s;
  std::vector<double> node_residual_sigma;
  /// Per motion node (same order): its camera correction at the estimate, as
  /// JointResult::camera_residual_rad (rad, camera axes). A mount change during the motion shows
  /// as a step in it (mount_change.h).
  std::vector<Eigen::Vector3d> node_camera_residual_rad;
  /// The coarse time offset's fit (coarseTimeshift, estimation/time_offset.h): candidate
  /// timeshift_cam_imu_s (s, ascending, evenly spaced) and at each the RMS difference (rad) of the
  /// camera's and the gyro's angles per frame interval.
  std::vector<double> timeshift_candidates_s;
  std::vector<double> timeshift_rms_difference_rad;
  double coarse_timeshift_s = 0;  ///< the coarse value (the curve's interpolated minimum, s)
  /// Rotation the motion frames carried about the camera x, y, z axes (rad): the sum over
  /// consecutive frames of |Log(R_target_cam_k^T R_target_cam_k+1)| per component
  /// (motionExcitation, estimation/time_offset.h). Near 0 about an axis the motion never turned.
  Eigen::Vector3d excitation_rad = Eigen::Vector3d::Zero();
  double excitation_duration_s = 0;  ///< the frame intervals summed (s)
  /// Motion frames dropped for a reprojection error far beyond the recording's own
  /// (pipeline/frame_screening.h).
  int frames_dropped = 0;
};

struct JointResult {
  bool ok = false;
  std::string message;  ///< why not, when !ok; a summary otherwise
  Eigen::Matrix3d R_cam_imu = Eigen::Matrix3d::Identity();
  /// Covariance of the left perturbation R_cam_imu <- Exp(e) R_cam_imu (rad^2, camera axes),
  /// scaled by chi2 / dof when that is > 1 (covariance_scale).
  Eigen::Matrix3d covariance_rad2 = Eigen::Matrix3d::Zero();
  Eigen::Vector3d std_dev_deg = Eigen::Vector3d::Zero();  ///< camera x, y, z axes
  double covariance_scale = 1.0;  ///< chi2 / dof applied to every covariance (1 when <= 1)
  /// The noise of each measurement kind as the recording shows it (JointSettings::learn_noise);
  /// every covariance and chi-square of this result is under it.
  LearnedNoise noise;
  /// With JointProblem::mount_change_pose: R_cam_imu of the poses from that index on (R_cam_imu
  /// is then the earlier poses').
  std::optional<Eigen::Matrix3d> R_cam_imu_after_change;
  Eigen::Matrix3d R_world_target =
      Eigen::Matrix3d::Identity();  ///< W's yaw: gauge w/o magnetometer
  ImuIntrinsics intrinsics;
  std::vector<EstimatedValue> parameters;  ///< every IMU parameter block, estimated or held
  /// Consistency: chi2 = sum of squared whitened residuals (priors included, no robust loss),
  /// dof = residuals - free parameters, p-value of chi2 given dof.
  double chi2 = 0;
  int dof = 0;
  double chi2_p_value = 1;
  /// The level the consistency verdict is judged at: the online calibrator stamps its
  /// consistency_level setting here when its gate judges the estimate, so that the result YAML, the
  /// report and the status print the gate's verdict (consistent()), never one of their own.
  double consistency_level = kDefaultConsistencyLevel;
  /// The residuals' size against their noise (learned where the recording allows): sqrt(chi2 /
  /// dof), about 1 when the model holds. The effect size the consistency verdict reads.
  double misfitRatio() const { return dof > 0 ? std::sqrt(std::max(0.0, chi2) / dof) : 0.0; }
  /// The consistency verdict: ok, and the chi-square test passes (chi2_p_value >=
  /// consistency_level) or the misfit is within kConsistentMisfitRatio (with thousands of degrees
  /// of freedom the test rejects a misfit that moves nothing: the effect size decides then).
  bool consistent() const {
    return ok && (chi2_p_value >= consistency_level || misfitRatio() <= kConsistentMisfitRatio);
  }
  /// Per pose: RMS whitened residual (sigma units) over its camera, accelerometer, magnetometer and
  /// gyro-bias residuals and half of each adjacent gyro residual.
  std::vector<double> pose_residual_norm;
  /// Per pose: the magnetometer residual's squared whitened norm (chi-square with 3 dof when the
  /// model holds; robust loss not applied), 0 where the field is not used.
  std::vector<double> mag_residual_chi2;
  /// Per pose: the camera's correction at the estimate, R_target_cam_measured^T R_target_cam_fit
  /// as a rotation vector (rad, camera axes); zero for a pose without an absolute camera
  /// orientation (the natural scene). Motion nodes': MotionFigures::node_camera_residual_rad.
  std::vector<Eigen::Vector3d> camera_residual_rad;
  /// Per pose: the camera's orientation at the estimate, R_target_cam Exp(correction) (target or
  /// natural-scene frame; the measured one where the camera's correction was not estimated):
  /// (fit_from)^T fit_to is the estimate's rotation of a camera link, left out or not.
  std::vector<Eigen::Matrix3d> camera_orientation_fit;
  /// Camera links (indices into JointProblem::camera_links) whose rotation the pipeline fitted
  /// again from the views with the rotation held near this estimate's (natural scene: a moved
  /// object in view; pipeline/calibration_pipeline.h, WindowSnapshot::scene_link_refit). Sorted.
  std::vector<int> camera_links_refitted;
  /// Of camera_links_refitted, those fitted as two motions sharing the rotation (an object moved
  /// between the views: SceneRotation::second_motion_inliers > 0). Sorted.
  std::vector<int> camera_links_second_motion;
  /// Isotropic variance added to every rest's camera covariance (rad^2 per axis) because the
  /// rests' camera residuals exceeded their covariances (JointSettings::camera_excess_level): the
  /// camera's noise as the recording shows it. 0 when not.
  double camera_excess_variance_rad2 = 0;
  /// Per JointProblem::camera_links entry: its residual's squared whitened norm (chi-square with 3
  /// dof when the model holds; robust loss not applied). For a link left out (below), its value in
  /// the solve that left it out.
  std::vector<double> camera_link_chi2;
  /// Per JointProblem::camera_links entry: its residual Log(R_measured^T R_fit) (rad, `to`
  /// camera axes), zero for a link left out.
  std::vector<Eigen::Vector3d> camera_link_residual_rad;
  /// Isotropic variance added to every camera link's covariance (rad^2 per axis) because the
  /// links' residuals exceeded their covariances (JointSettings::camera_excess_level): the
  /// natural scene's rotations as the recording shows them. 0 when not.
  double camera_link_excess_variance_rad2 = 0;
  /// Camera links (indices into JointProblem::camera_links) this estimate left out as outliers
  /// (the pipeline's screening of natural-scene rotations): a comparison of models on the same
  /// measurements (the mount-change test) leaves them out too. Sorted.
  std::vector<int> camera_links_left_out;
  /// Per JointProblem::camera_links entry (empty when the problem has none or none was screened):
  /// -1 where the link's measured rotation was used, else the index into its alternatives of the
  /// rotation the screening took instead.
  std::vector<int> camera_link_alternative_used;
  /// Poses whose field was left out as disturbed: it did not fit the calibrated iron and field.
  std::vector<int> mag_poses_left_out;
  /// The camera-IMU time offset (Kalibr's timeshift_cam_imu: t_imu = t_cam + timeshift; s) and
  /// its 1-sigma, estimated with motion nodes (timeshift_estimated); else 0 and not estimated.
  double timeshift_cam_imu_s = 0;
  double timeshift_sigma_s = 0;
  bool timeshift_estimated = false;
  /// The IMU's position in the camera frame (m): T_cam_imu's translation (p_cam = R_cam_imu p_imu
  /// + p_cam_imu_m), from the acceleration model during motion (AccelLink: the camera's positions
  /// and the accelerometer); lever_arm_in_model false (and zeros) without it.
  Eigen::Vector3d p_cam_imu_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_cam_imu_sigma_m = Eigen::Vector3d::Zero();  ///< 1-sigma per camera axis (m)
  bool lever_arm_in_model = false;
  /// Determined by the data: every axis' 1-sigma well below its prior (lever_arm_prior_m); else
  /// the value rests on the prior (zero) and is not a measurement.
  bool lever_arm_measured = false;
  int motion_nodes = 0;      ///< motion nodes used (JointProblem::motion_frames)
  MotionFigures motion;      ///< the motion's figures for the report
  int rests_used = 0;        ///< rests used (JointProblem::poses)
  int iterations = 0;        ///< Levenberg-Marquardt iterations over all passes
  int relinearisations = 0;  ///< gyro preintegration passes
  /// The model of T_g and T_a this result is of: kEstimate or kIdentity (kSelect chooses one).
  ImuMatrixModel imu_matrices = ImuMatrixModel::kEstimate;
  double solve_time_s = 0;
  std::vector<std::string> notes;  ///< what was not estimated and why, what to rotate about
  /// Unit vector (IMU frame): the rotation axis that would add the most information.
  Eigen::Vector3d suggested_rotation_axis_imu = Eigen::Vector3d::UnitX();
};

}  // namespace camera_imu_alignment
