// The joint estimate through the pipeline on simulated recordings of every IMU grade (Monte Carlo
// over seeds): accuracy against the simulated truth, the reported 1-sigma against the errors, and
// the pair estimate (`auto`) on the same recordings for comparison; `magnetometer` mode (the
// paper's sensors: camera, accelerometer and magnetometer, the iron self-calibrated) against the
// paper's pairs of accelerometer + magnetometer attitudes. Camera orientations are given
// (0.03 deg noise per frame at 15 Hz, as PnP on a good target), so no images are rendered.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "camera_imu_alignment/io/joint_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "pipeline_simulation.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

/// These tests judge consistency at 0.01, stricter than the gate's default consistency_level.
constexpr double kTestConsistencyLevel = 0.01;

namespace sim = simulation;

struct Outcome {
  int runs = 0, solved = 0, consistent = 0;  ///< consistent: chi-square p >= kTestConsistencyLevel
  int identity_matrices = 0;  ///< runs where model selection held T_g and T_a at identity
  int iron_estimated = 0;     ///< runs whose magnetometer was used with its hard iron estimated
  double sum_sq_deg = 0.0, max_deg = 0.0;
  double sum_sq_pairs_deg = 0.0;     ///< the pair solve of `compare_with`'s poses
  double sum_sq_compared_deg = 0.0;  ///< `compare_with`'s answer (its joint estimate, if any)
  std::vector<double> z;             ///< per-axis errors in units of the reported 1-sigma
  double rms() const { return solved ? std::sqrt(sum_sq_deg / solved) : NAN; }
  double rmsPairs() const { return solved ? std::sqrt(sum_sq_pairs_deg / solved) : NAN; }
  double rmsCompared() const { return solved ? std::sqrt(sum_sq_compared_deg / solved) : NAN; }
  double fractionWithin(double k) const {
    int n = 0;
    for (double v : z) n += std::abs(v) <= k;
    return z.empty() ? 0.0 : static_cast<double>(n) / z.size();
  }
};

/// The grade's priors for the joint estimate (a user sets them for the unit in
/// config/default.yaml).
using test::jointSettingsFor;

/// Changes to a scenario's recording and to the estimate's priors (0: as the scenario / grade).
struct Variant {
  double gyro_noise_density = 0.0;                        ///< rad/s/sqrt(Hz)
  double accel_random_walk = 0.0;                         ///< the simulated unit's (m/s^3/sqrt(Hz))
  double prior_accel_bias_walk = 0.0;                     ///< the estimate's prior (m/s^2/sqrt(s))
  ImuMatrixModel imu_matrices = ImuMatrixModel::kSelect;  ///< the default
  ImuOrientationSource source = ImuOrientationSource::kJoint;       ///< the estimate's mode
  ImuOrientationSource compare_with = ImuOrientationSource::kAuto;  ///< the pair estimate's
};

Outcome monteCarlo(const std::string& scenario, int seeds, const Variant& variant = {}) {
  Outcome out;
  for (int k = 0; k < seeds; ++k) {
    sim::SimulationConfig c;
    c.seed = 1 + k;
    EXPECT_TRUE(sim::applyScenario(scenario, &c)) << scenario;
    if (variant.gyro_noise_density > 0.0) {
      c.imu_noise.gyroscope_noise_density = variant.gyro_noise_density;
    }
    if (variant.accel_random_walk > 0.0) {
      c.imu_noise.accelerometer_random_walk = variant.accel_random_walk;
    }
    c.camera_rate_hz = 1.0;  // frames are given by the harness, not rendered
    const sim::SimulationRun run(c);
    PipelineSettings settings;
    settings.joint = jointSettingsFor(c);
    settings.joint.imu_matrices = variant.imu_matrices;
    settings.imu_orientation = variant.source;
    if (variant.prior_accel_bias_walk > 0.0) {
      settings.joint.priors.accel_bias_walk_m_s2_sqrt_s = variant.prior_accel_bias_walk;
    }
    const auto pipeline = test::feedWithoutImages(run, settings, 0.03, false, 100 + c.seed);
    ++out.runs;
    const AlignmentResult r = test::solveFinalWindow(*pipeline);
    if (!r.joint || !r.joint->ok) {
      ADD_FAILURE() << scenario << " seed " << c.seed << ": "
                    << (r.joint ? r.joint->message : r.message);
      continue;
    }
    ++out.solved;
    out.consistent += r.joint->chi2_p_value >= kTestConsistencyLevel;
    out.identity_matrices += r.joint->intrinsics.gyro_matrix_sigma.isZero();
    out.iron_estimated += r.joint->intrinsics.hard_iron_estimated;
    const Eigen::Matrix3d R_true = run.trajectory.R_cam_imu_final();
    const Eigen::Vector3d e = test::leftError(r.R_cam_imu, R_true);
    const double e_deg = rad2deg(e.norm());
    out.sum_sq_deg += e_deg * e_deg;
    out.max_deg = std::max(out.max_deg, e_deg);
    // The same poses in the mode compared with: its answer and its pair solve (the gyro chain,
    // or the paper's accel + mag).
    PipelineSettings compared = settings;
    compared.imu_orientation = variant.compare_with;
    const auto other = test::feedWithoutImages(run, compared, 0.03, false, 100 + c.seed);
    const double compared_deg =
        rad2deg(geodesicDistance(test::solveFinalWindow(*other).R_cam_imu, R_true));
    out.sum_sq_compared_deg += compared_deg * compared_deg;
    const double pair_deg = rad2deg(geodesicDistance(
        solveAlignment(other->snapshot().pairs, compared.solver).R_cam_imu, R_true));
    out.sum_sq_pairs_deg += pair_deg * pair_deg;
    // Per-axis normalised errors: the joint covariance is about the camera axes.
    const Eigen::Matrix3d& P = r.joint->covariance_rad2;
    for (int a = 0; a < 3; ++a) out.z.push_back(e(a) / std::sqrt(P(a, a)));
  }
  std::printf(
      "%-16s %-12s %2d/%2d solved  RMS %.4f deg  max %.4f deg  (%s: RMS %.4f, its pairs %.4f)  "
      "within 1 sigma %.2f, 3 sigma %.3f, consistent %d, T = I in %d, iron estimated in %d\n",
      scenario.c_str(), toString(variant.source), out.solved, out.runs, out.rms(), out.max_deg,
      toString(variant.compare_with), out.rmsCompared(), out.rmsPairs(), out.fractionWithin(1.0),
      out.fractionWithin(3.0), out.consistent, out.identity_matrices, out.iron_estimated);
  return out;
}

/// Honest 1-sigma: about 68% of the per-axis errors within 1 sigma, nearly all within 3.
void expectHonestSigma(const Outcome& o, double max_within_one_sigma = 0.9) {
  EXPECT_GE(o.fractionWithin(1.0), 0.5);
  EXPECT_LE(o.fractionWithin(1.0), max_within_one_sigma);
  EXPECT_GE(o.fractionWithin(3.0), 0.95);
}

// With T_g and T_a held at identity the estimate of an ideal unit rests on the camera, whose
// per-pose floor (0.01 deg, pose_assembly.cpp: what the frames' scatter cannot show) equals this
// harness's per-pose noise (0.03 deg / sqrt(10 frames)): its 1-sigma is ~1.4x the error's
// (measured 0.92 within 1 sigma; 0.80 with a 0.001 deg floor). Pessimistic, never over-confident.
constexpr double kIdealGradeWithinOneSigma = 0.95;

/// Model selection (imu_matrices: select, the default) holds the ideal unit's T_g and T_a at
/// identity: 0.013 deg RMS where estimating them with the consumer priors gave 0.044 (and the gyro
/// chain's pairs 0.029).
TEST(JointPipeline, IdealGrade) {
  const Outcome o = monteCarlo("nominal", 20);
  EXPECT_EQ(o.solved, o.runs);
  EXPECT_LE(o.rms(), 0.02);
  EXPECT_GE(o.identity_matrices, o.solved - 2);
  expectHonestSigma(o, kIdealGradeWithinOneSigma);
  Variant estimate;
  estimate.imu_matrices = ImuMatrixModel::kEstimate;
  const Outcome estimated = monteCarlo("nominal", 20, estimate);
  EXPECT_LE(estimated.rms(), 0.06);
  EXPECT_LT(o.rms(), 0.5 * estimated.rms());
  expectHonestSigma(estimated);
}

TEST(JointPipeline, ConsumerGradeWithSystematicErrors) {
  const Outcome o = monteCarlo("consumer", 20);
  EXPECT_EQ(o.solved, o.runs);
  EXPECT_LE(o.rms(), 0.10);
  EXPECT_EQ(o.identity_matrices, 0);  // their scale errors are always detected
  expectHonestSigma(o);
}

// With the motion between the rests (motion nodes, issue 25) the tactical unit's estimate rests
// mostly on the camera orientations during motion, which this harness gives as camera_pose-style
// orientations with 0.03 deg of noise while the pipeline, which cannot know it, assumes 0.05
// (kGivenOrientationSigmaDeg): its 1-sigma is conservative, 56 of 60 axes within 1 sigma
// (0.0192 deg RMS, max 0.059; rests only: 0.0190, max 0.037). Measuring a given orientation's
// noise from the rests' scatter made the joint estimates inconsistent in 6 of 20 consumer runs,
// so the assumption stays and the bound allows it.
TEST(JointPipeline, TacticalGrade) {
  const Outcome o = monteCarlo("tactical", 20);
  EXPECT_EQ(o.solved, o.runs);
  EXPECT_LE(o.rms(), 0.06);
  EXPECT_EQ(o.identity_matrices, 0);  // their scale errors are always detected
  expectHonestSigma(o, 0.95);
}

/// A noisy MEMS gyro on a vibrating mount (0.004 rad/s/sqrt(Hz), 20x the ideal grade's): the gyro
/// chain's random walk made the pair estimate 2-10x worse than the paper's accel + mag attitude.
TEST(JointPipeline, NoisyGyroIsNeverWorseThanAccelerometerAndMagnetometer) {
  Variant noisy_gyro;
  noisy_gyro.gyro_noise_density = 0.004;
  noisy_gyro.compare_with = ImuOrientationSource::kMagnetometer;
  const Outcome o = monteCarlo("nominal", 20, noisy_gyro);
  EXPECT_EQ(o.solved, o.runs);
  EXPECT_LE(o.rms(), 0.10);
  // Never worse than the paper's accel + mag pairs, nor (within 10 %: 0.025 against 0.026 deg RMS)
  // than the joint estimate of `magnetometer` mode, which calibrates them and leaves the gyro out.
  EXPECT_LE(o.rms(), o.rmsPairs());
  EXPECT_LE(o.rms(), 1.1 * o.rmsCompared());
  expectHonestSigma(o, kIdealGradeWithinOneSigma);
}

/// The noisy grade (MPU-6050 class on a vibrating mount: gyro bias 3 deg/s, accelerometer bias
/// 0.6 m/s^2 and scale 3 %, hard iron 40 uT): every rest found, calibrated, the 1-sigma covers the
/// error. 0.34 deg RMS before its magnetometer was used (the raw field check flagged most rests,
/// and samples below 15 uT were refused); 0.23 with the iron calibrated.
TEST(JointPipeline, NoisyConsumerGrade) {
  const Outcome o = monteCarlo("noisy_consumer", 20);
  EXPECT_EQ(o.solved, o.runs);
  EXPECT_LE(o.rms(), 0.3);
  EXPECT_EQ(o.identity_matrices, 0);  // their scale errors are always detected
  expectHonestSigma(o);
}

/// An accelerometer whose bias walks (2e-3 m/s^3/sqrt(Hz), the noisy grade's, 4.6x the ideal
/// grade's): over the 80 s recording it moves by ~0.02 m/s^2 per axis, ~20x a rest mean's noise.
/// Modelled as one constant (a walk prior of 1e-8, the estimator before the walk model), it was
/// 0.19-0.20 deg RMS with 7-10 % of the errors beyond 3 sigma; with the bias per rest and its
/// walk, 0.077 deg with all within 3 sigma and the chi-square consistent (T_g and T_a estimated;
/// with the model selection, which holds them at identity here, 0.014 against 0.188 deg).
TEST(JointPipeline, WalkingAccelerometerBiasIsModelled) {
  Variant walking;
  walking.accel_random_walk = 2e-3;
  walking.imu_matrices = ImuMatrixModel::kEstimate;
  const Outcome o = monteCarlo("nominal", 20, walking);
  EXPECT_EQ(o.solved, o.runs);
  EXPECT_LE(o.rms(), 0.11);
  expectHonestSigma(o);
  EXPECT_GE(o.consistent, o.solved - 1);
  // The same recordings with the bias held constant: the scenario does exercise the walk.
  walking.prior_accel_bias_walk = 1e-8;
  const Outcome constant = monteCarlo("nominal", 20, walking);
  EXPECT_GT(constant.rms(), 1.5 * o.rms());
}

/// `imu_orientation: magnetometer`, the paper's sensors: the IMU orientation from gravity and the
/// magnetic field, the gyro left out. The joint estimate over the camera, the accelerometer and the
/// magnetometer calibrates the hard and soft iron and the accelerometer's bias and matrix from the
/// poses themselves; the paper's pairs of raw accelerometer + magnetometer attitudes on the same
/// consumer units (hard iron 15 uT, soft iron 5 %) are degrees off.
TEST(JointPipeline, MagnetometerModeSelfCalibratesTheIron) {
  Variant paper;
  paper.source = ImuOrientationSource::kMagnetometer;
  paper.compare_with = ImuOrientationSource::kMagnetometer;
  const Outcome o = monteCarlo("consumer", 20, paper);
  EXPECT_EQ(o.solved, o.runs);
  EXPECT_LE(o.rms(), 0.3);
  EXPECT_GT(o.rmsPairs(), 3.0 * o.rms());  // the recordings do carry the iron
  expectHonestSigma(o);
  EXPECT_EQ(o.iron_estimated, o.solved);
  // The other grades (the ideal one has no iron), the 1-sigma honest. The noisy grade (40 uT hard
  // iron, the raw field below 15 uT at some orientations) is limited by its accelerometer noise.
  for (const char* scenario : {"nominal", "tactical", "noisy_consumer"}) {
    const Outcome grade = monteCarlo(scenario, 20, paper);
    EXPECT_EQ(grade.solved, grade.runs) << scenario;
    EXPECT_LE(grade.rms(), 0.3) << scenario;
    EXPECT_GE(grade.fractionWithin(3.0), 0.95) << scenario;
    EXPECT_EQ(grade.iron_estimated, grade.solved) << scenario;
  }
}

/// A consumer unit (15 uT hard iron) whose rests 2 and 5 sit in an extra 25 uT field: the raw
/// field check cannot tell the iron from the disturbance and flags most rests; with the iron
/// calibrated every undisturbed rest's field is used, and the two disturbed ones are left out.
TEST(JointPipeline, DisturbedFieldsAreLeftOutOnceTheIronIsCalibrated) {
  int exact = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    sim::SimulationConfig c;
    c.seed = seed;
    ASSERT_TRUE(sim::applyScenario("consumer", &c));
    c.mag_disturbance_poses = {2, 5};
    c.camera_rate_hz = 1.0;
    const sim::SimulationRun run(c);
    PipelineSettings settings;
    settings.joint = jointSettingsFor(c);
    settings.imu_orientation = ImuOrientationSource::kMagnetometer;
    const auto pipeline = test::feedWithoutImages(run, settings, 0.03, false, 100 + c.seed);
    const AlignmentResult r = test::solveFinalWindow(*pipeline);
    ASSERT_TRUE(r.joint && r.joint->ok) << seed << ": " << r.message;
    const ImuIntrinsics& in = r.joint->intrinsics;
    ASSERT_TRUE(in.magnetometer_used && in.hard_iron_estimated) << seed << ": " << r.message;
    const std::vector<int>& left_out = r.joint->mag_poses_left_out;
    EXPECT_TRUE(std::find(left_out.begin(), left_out.end(), 2) != left_out.end()) << seed;
    EXPECT_TRUE(std::find(left_out.begin(), left_out.end(), 5) != left_out.end()) << seed;
    EXPECT_LE(left_out.size(), 3u) << seed;  // at most one good rest lost
    exact += left_out.size() == 2u;
    // The hard iron against the simulated unit's, within 3 sigma per axis.
    const Eigen::Vector3d h_error = in.hard_iron_t - run.imu_errors.mag_hard_iron;
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(std::abs(h_error(a)), 3.0 * in.hard_iron_sigma_t(a) + 1e-8)
          << seed << " axis " << a;
    }
    EXPECT_LT(rad2deg(geodesicDistance(r.R_cam_imu, run.trajectory.R_cam_imu_final())), 0.15)
        << seed;
  }
  EXPECT_GE(exact, 4);
}

/// The setting gravity_m_s2 reaches the joint estimate's accelerometer model, not only the
/// stationary detector: a tactical unit recorded where g = 9.78 m/s^2 and solved with
/// gravity_m_s2: 9.78 is as accurate as at 9.81, and its estimated accelerometer scale is the
/// unit's (mean diagonal of T_a against the simulated one). The control solves the same recording
/// with the default 9.81: the 0.3 % difference then goes into T_a, which is what the joint model
/// did with any gravity_m_s2 before.
TEST(JointPipeline, LocalGravityReachesTheJointEstimate) {
  double sum_sq_local_deg = 0.0, sum_sq_standard_deg = 0.0;
  const int seeds = 3;
  for (int seed = 1; seed <= seeds; ++seed) {
    auto solve = [&](double g_world, double g_setting, double* error_deg, double* scale_error) {
      sim::SimulationConfig c;
      c.seed = seed;
      EXPECT_TRUE(sim::applyScenario("tactical", &c));
      c.gravity_world = Eigen::Vector3d(0.0, 0.0, -g_world);
      c.camera_rate_hz = 1.0;  // frames are given by the harness, not rendered
      const sim::SimulationRun run(c);
      PipelineSettings settings;
      settings.joint = jointSettingsFor(c);
      settings.stationary.gravity_m_s2 = g_setting;
      const auto pipeline = test::feedWithoutImages(run, settings, 0.03, false, 100 + c.seed);
      const AlignmentResult r = test::solveFinalWindow(*pipeline);
      ASSERT_TRUE(r.joint && r.joint->ok) << seed << ": " << r.message;
      ASSERT_TRUE(r.joint->intrinsics.accel_matrix_estimated) << seed;
      *error_deg = rad2deg(geodesicDistance(r.R_cam_imu, run.trajectory.R_cam_imu_final()));
      *scale_error =
          (r.joint->intrinsics.accel_matrix.diagonal() - run.imu_errors.T_a.diagonal()).mean();
    };
    double local_deg = 0.0, local_scale = 0.0;
    solve(9.78, 9.78, &local_deg, &local_scale);
    double standard_deg = 0.0, standard_scale = 0.0;
    solve(9.81, 9.81, &standard_deg, &standard_scale);
    double control_deg = 0.0, control_scale = 0.0;
    solve(9.78, 9.81, &control_deg, &control_scale);
    std::printf(
        "seed %d: g 9.78 error %.4f deg, T_a scale error %+.5f; g 9.81: %.4f deg, %+.5f; "
        "g 9.78 solved with 9.81: %.4f deg, %+.5f\n",
        seed, local_deg, local_scale, standard_deg, standard_scale, control_deg, control_scale);
    EXPECT_LT(std::abs(local_scale), 0.001) << seed;  // the unit's scale, not 9.78 / 9.81 - 1
    EXPECT_LT(std::abs(standard_scale), 0.001) << seed;
    EXPECT_GT(std::abs(control_scale), 0.002) << seed;  // the test sees a gravity not passed on
    sum_sq_local_deg += local_deg * local_deg;
    sum_sq_standard_deg += standard_deg * standard_deg;
  }
  const double rms_local = std::sqrt(sum_sq_local_deg / seeds);
  const double rms_standard = std::sqrt(sum_sq_standard_deg / seeds);
  EXPECT_LE(rms_local, 1.5 * rms_standard + 0.01) << rms_local << " vs " << rms_standard;
  EXPECT_LE(rms_local, 0.06);
}

/// Passes everything on to a pipeline except the camera frames while the rig holds `pose`: the
/// board out of view for one hold (a capture not armed, frames rejected).
class DropHold : public SampleSink {
 public:
  DropHold(const sim::SimulationRun& run, int pose, CalibrationPipeline* pipeline)
      : run_(run), pose_(pose), pipeline_(pipeline) {}
  void addImu(const ImuSample& s) override { pipeline_->addImu(s); }
  void addMagnetic(const MagneticSample& s) override { pipeline_->addMagnetic(s); }
  bool setCameraIntrinsics(const CameraIntrinsics& i) override {
    return pipeline_->setCameraIntrinsics(i);
  }
  void addFrame(const CameraFrame& frame) override {
    if (run_.trajectory.at(frame.stamp_s).pose != pose_) pipeline_->addFrame(frame);
  }
  void rejectInput(RejectReason reason, InputStream stream, const std::string& detail) override {
    pipeline_->rejectInput(reason, stream, detail);
  }
  ImuOrientationSource imuOrientationSource() const override {
    return pipeline_->imuOrientationSource();
  }

 private:
  const sim::SimulationRun& run_;
  int pose_;
  CalibrationPipeline* pipeline_;
};

/// One hold without camera frames: that rest becomes no pose, and the gyro from the pose before it
/// to the pose after it runs through it. Its own samples were once appended to the pending gyro
/// segment on top of the motion's (the rest's first sample twice, then its last one again with the
/// next motion): "gyro segment 3: stamps are not strictly increasing", and every later solve of the
/// window failed.
TEST(JointPipeline, AHoldWithoutCameraFramesIsBridgedByTheGyro) {
  sim::SimulationConfig c;
  c.seed = 3;
  ASSERT_TRUE(sim::applyScenario("nominal", &c));
  c.camera_rate_hz = 1.0;
  const sim::SimulationRun run(c);
  PipelineSettings settings;
  settings.joint = jointSettingsFor(c);
  int rejected = 0;
  PipelineCallbacks callbacks;
  callbacks.on_pose_rejected = [&rejected](const RejectedPose&) { ++rejected; };
  CalibrationPipeline pipeline(parseTargetYaml(sim::targetYaml(c.target), "target"), settings,
                               callbacks);
  DropHold sink(run, 3, &pipeline);
  test::feedSinkWithoutImages(run, &sink, 0.03, false, 103);
  pipeline.finish();
  EXPECT_GE(rejected, 1);
  const AlignmentResult r = test::solveFinalWindow(pipeline);
  ASSERT_TRUE(r.joint.has_value()) << r.message;
  ASSERT_TRUE(r.joint->ok) << r.joint->message;
  // Every gyro segment's stamps strictly increasing, and one of them spans the dropped hold.
  const JointProblem problem = pipeline.snapshot().joint;
  const sim::StationaryPose& dropped = run.trajectory.poses().at(3);
  bool bridged = false;
  for (const GyroSegment& g : problem.segments) {
    for (std::size_t i = 1; i < g.stamps_s.size(); ++i) {
      ASSERT_GT(g.stamps_s[i], g.stamps_s[i - 1]) << "sample " << i;
    }
    bridged |= !g.stamps_s.empty() && g.stamps_s.front() < dropped.start_s &&
               g.stamps_s.back() > dropped.end_s;
  }
  EXPECT_TRUE(bridged);
  EXPECT_LT(rad2deg(geodesicDistance(r.R_cam_imu, run.trajectory.R_cam_imu_final())), 0.05);
}

}  // namespace
}  // namespace camera_imu_alignment
