// IMU side of the core: stationary detection, attitude at rest, gyro integration and magnetometer
// hygiene. Synthetic cases with exact answers, then the real BROAD recordings (CIA_REALDATA_DIR,
// skipped when absent) against their motion-capture reference and `moving` labels.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <iostream>
#include <random>

#include "broad_csv.h"
#include "camera_imu_alignment/inertial/imu_attitude.h"
#include "camera_imu_alignment/inertial/magnetometer.h"
#include "camera_imu_alignment/inertial/stationary_detector.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "synthetic_imu.h"
#include "test_helpers.h"

namespace camera_imu_alignment {
namespace {

const Eigen::Vector3d kUpSpecificForce(0.0, 0.0, 9.81);  // ENU, what an accelerometer at rest reads
const Eigen::Vector3d kEarthField(0.0, 22e-6, -42e-6);   // T, ENU (north and down)

Eigen::Matrix3d randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

// ------------------------------------------------------------------------------------------
// Attitude at rest
// ------------------------------------------------------------------------------------------

TEST(AttitudeFromAccelMag, ExactOnNoiseFreeVectorsAtAnyOrientation) {
  std::mt19937 rng(1);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Matrix3d R_world_imu = randomRotation(rng);
    const AttitudeFromVectors a = attitudeFromAccelMag(R_world_imu.transpose() * kUpSpecificForce,
                                                       R_world_imu.transpose() * kEarthField);
    ASSERT_TRUE(a.valid);
    EXPECT_LT(test::angleBetweenDeg(a.R_world_imu, R_world_imu), 1e-7);
    EXPECT_NEAR(a.dip_deg, rad2deg(std::atan2(42.0, 22.0)), 1e-7);
    EXPECT_NEAR(a.field_norm_t, kEarthField.norm(), 1e-15);
  }
}

TEST(AttitudeFromAccelMag, DisturbedFieldChangesTheHeadingOnlyAndDegenerateInputsAreInvalid) {
  std::mt19937 rng(2);
  const Eigen::Matrix3d R_world_imu = randomRotation(rng);
  const Eigen::Vector3d accel = R_world_imu.transpose() * kUpSpecificForce;
  const Eigen::Vector3d bad_field =
      R_world_imu.transpose() * (kEarthField + Eigen::Vector3d(15e-6, 0, 8e-6));
  const AttitudeFromVectors a = attitudeFromAccelMag(accel, bad_field);
  ASSERT_TRUE(a.valid);
  // Gravity is still exact: the up axis agrees; the error is a rotation about it.
  EXPECT_LT((a.R_world_imu * accel).normalized().cross(Eigen::Vector3d::UnitZ()).norm(), 1e-9);
  EXPECT_GT(test::angleBetweenDeg(a.R_world_imu, R_world_imu), 5.0);
  EXPECT_FALSE(attitudeFromAccelMag(accel, Eigen::Vector3d::Zero()).valid);
  EXPECT_FALSE(attitudeFromAccelMag(accel, 3e-5 * accel.normalized()).valid);  // parallel
  EXPECT_FALSE(attitudeFromAccelMag(Eigen::Vector3d(NAN, 0, 9.8), bad_field).valid);
}

TEST(AttitudeFromAccel, TiltExactHeadingFree) {
  std::mt19937 rng(3);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Matrix3d R_world_imu = randomRotation(rng);
    const Eigen::Matrix3d R = attitudeFromAccel(R_world_imu.transpose() * kUpSpecificForce);
    EXPECT_TRUE(isRotationMatrix(R));
    // Same up direction: R and the truth differ by a rotation about the world z axis only.
    const Eigen::Matrix3d D = R * R_world_imu.transpose();
    EXPECT_NEAR(D(2, 2), 1.0, 1e-12);
  }
}

// ------------------------------------------------------------------------------------------
// Gyro integration
// ------------------------------------------------------------------------------------------

std::vector<ImuSample> constantRate(const Eigen::Vector3d& rate, const Eigen::Vector3d& bias,
                                    double t0, double t1, double dt) {
  std::vector<ImuSample> out;
  for (double t = t0; t <= t1 + 1e-12; t += dt) out.push_back({t, rate + bias, kUpSpecificForce});
  return out;
}

TEST(IntegrateGyro, ConstantRateGivesTheExponentialWithBiasRemovedAndEndsClipped) {
  const Eigen::Vector3d rate(0.3, -0.2, 0.5), bias(0.01, 0.02, -0.03);
  const auto samples = constantRate(rate, bias, 0.0, 3.0, 0.005);
  Eigen::Matrix3d R;
  ASSERT_TRUE(integrateGyro(samples, bias, 0.5, 2.0, &R));
  EXPECT_LT(test::angleBetweenDeg(R, expSO3(rate * 1.5)), 1e-9);
  // Times between samples: the ends are clipped exactly.
  ASSERT_TRUE(integrateGyro(samples, bias, 0.5012, 2.0031, &R));
  EXPECT_LT(test::angleBetweenDeg(R, expSO3(rate * (2.0031 - 0.5012))), 1e-9);
}

TEST(IntegrateGyro, TimeVaryingRateConvergesAtSecondOrder) {
  // Rotation about a fixed axis with rate w(t) = a t: angle a T^2 / 2, exact for the midpoint rule.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2).normalized();
  std::vector<ImuSample> samples;
  for (int i = 0; i <= 400; ++i) {
    const double t = i * 0.005;
    samples.push_back({t, 0.8 * t * axis, kUpSpecificForce});
  }
  Eigen::Matrix3d R;
  ASSERT_TRUE(integrateGyro(samples, Eigen::Vector3d::Zero(), 0.0, 2.0, &R));
  EXPECT_LT(test::angleBetweenDeg(R, expSO3(0.8 * 2.0 * 2.0 / 2.0 * axis)), 1e-9);
}

TEST(IntegrateGyro, GapsAndMissingCoverageFail) {
  auto samples = constantRate(Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d::Zero(), 0.0, 2.0, 0.005);
  std::vector<ImuSample> gapped;
  for (const auto& s : samples) {
    if (s.stamp_s < 0.9 || s.stamp_s > 1.2) gapped.push_back(s);
  }
  Eigen::Matrix3d R;
  EXPECT_FALSE(integrateGyro(gapped, Eigen::Vector3d::Zero(), 0.5, 1.5, &R, 0.1));
  EXPECT_TRUE(integrateGyro(gapped, Eigen::Vector3d::Zero(), 1.3, 1.9, &R, 0.1));
  EXPECT_FALSE(integrateGyro(samples, Eigen::Vector3d::Zero(), 1.0, 5.0, &R, 0.1));  // beyond data
  EXPECT_FALSE(integrateGyro({}, Eigen::Vector3d::Zero(), 0.0, 1.0, &R));
}

// ------------------------------------------------------------------------------------------
// Stationary detector, synthetic
// ------------------------------------------------------------------------------------------

/// Rest [0, 4) s, rotation about x at 0.5 rad/s for 2 s, rest [6, 10) s; white noise of the given
/// densities (per sample at 200 Hz) and a constant gyro bias.
std::vector<ImuSample> restMoveRest(double accel_sigma, double gyro_sigma,
                                    const Eigen::Vector3d& bias, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<ImuSample> out;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // R_world_imu
  const double dt = 0.005;
  for (int i = 0; i < 2000; ++i) {
    const double t = i * dt;
    const bool moving = t >= 4.0 && t < 6.0;
    // Smooth rate profile (sine bump) so that the accelerometer also sees the motion.
    const double w = moving ? 0.8 * std::sin(M_PI * (t - 4.0) / 2.0) : 0.0;  // 1 rad in all
    const Eigen::Vector3d rate(w, 0.0, 0.0);
    R = R * expSO3(rate * dt);
    Eigen::Vector3d accel = R.transpose() * kUpSpecificForce;
    if (moving) accel += Eigen::Vector3d(0.0, 0.3 * std::sin(3.0 * t), 0.0);  // hand shake
    out.push_back({t, rate + bias + gyro_sigma * Eigen::Vector3d(n(rng), n(rng), n(rng)),
                   accel + accel_sigma * Eigen::Vector3d(n(rng), n(rng), n(rng))});
  }
  return out;
}

TEST(StationaryDetector, FindsBothRestsInsideTheTruthWithTheBias) {
  const Eigen::Vector3d bias(0.004, -0.006, 0.002);
  const auto segments = detectStationarySegments(restMoveRest(0.02, 0.003, bias, 4));
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_GE(segments[0].start_s, 0.0);
  EXPECT_LE(segments[0].end_s, 4.0);
  EXPECT_GE(segments[1].start_s, 6.0);
  EXPECT_LE(segments[1].end_s, 10.0);
  for (const auto& s : segments) {
    EXPECT_GT(s.duration(), 2.5);  // trimmed by about half a window at the motion end(s)
    EXPECT_LT((s.gyro_bias_rad_s - bias).norm(), 0.001);
    EXPECT_NEAR(s.mean_accel_m_s2.norm(), 9.81, 0.01);
  }
}

TEST(StationaryDetector, NoisyConsumerImuNeedsNoTuningButFixedLimitsWouldMissIt) {
  // Accelerometer 0.13 m/s^2 and gyro 0.01 rad/s per-axis noise per sample, bias 0.05 rad/s:
  // well above the fixed limits, found through the measured noise.
  const Eigen::Vector3d bias(0.03, -0.03, 0.025);
  const auto samples = restMoveRest(0.13, 0.01, bias, 5);
  const auto segments = detectStationarySegments(samples);
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_LE(segments[0].end_s, 4.0);
  EXPECT_GE(segments[1].start_s, 6.0);
  StationaryDetectorSettings fixed;
  fixed.noise_factor = 0.0;
  EXPECT_TRUE(detectStationarySegments(samples, fixed).empty());
}

TEST(StationaryDetector, GapEndsTheRestAndBadSamplesAreIgnored) {
  auto samples = restMoveRest(0.02, 0.003, Eigen::Vector3d::Zero(), 6);
  std::vector<ImuSample> edited;
  for (const auto& s : samples) {
    if (s.stamp_s >= 7.5 && s.stamp_s < 7.8) continue;  // 0.3 s gap in the second rest
    edited.push_back(s);
    if (std::abs(s.stamp_s - 2.0) < 1e-9) {
      edited.push_back({s.stamp_s + 0.001, Eigen::Vector3d(NAN, 0, 0), s.accel_m_s2});
      edited.push_back({s.stamp_s - 1.0, s.gyro_rad_s, s.accel_m_s2});  // backwards
    }
  }
  StationaryDetectorSettings settings;
  settings.min_duration_s = 1.0;
  const auto segments = detectStationarySegments(edited, settings);
  ASSERT_EQ(segments.size(), 2u);  // [0, 4) and [7.8, 10); [6, 7.5) minus the trims is too short
  EXPECT_LE(segments[0].end_s, 4.0);
  EXPECT_GE(segments[1].start_s, 7.8);
  for (const auto& s : segments) EXPECT_TRUE(s.mean_accel_m_s2.allFinite());
}

TEST(StationaryDetector, FindsEveryRestOfANoisyUnitWithA5DegPerSecondBiasTakenFromTheRest) {
  // Twelve poses held 3-5 s, joined by minimum-jerk moves of 2-3 s (20-120 deg about random axes,
  // about 0.2 m): every rest found once, none reported while moving, each with its own bias. The
  // first rest has no previous bias to go by.
  for (std::uint32_t seed : {21u, 22u, 23u}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::normal_distribution<double> normal(0.0, 1.0);
    test::SyntheticImu imu(test::noisyBiasedUnit(), randomRotation(rng), seed);
    for (int pose = 0; pose < 12; ++pose) {
      imu.rest(3.0 + 2.0 * uniform(rng));
      if (pose == 11) break;
      const Eigen::Vector3d axis =
          Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
      const Eigen::Vector3d displacement(0.2 * normal(rng), 0.2 * normal(rng), 0.1 * normal(rng));
      imu.move(deg2rad(20.0 + 100.0 * uniform(rng)) * axis, displacement, 2.0 + uniform(rng));
    }
    const auto segments = detectStationarySegments(imu.samples());
    const test::RestMatch m = test::matchRests(imu, segments);
    SCOPED_TRACE("seed " + std::to_string(seed));
    EXPECT_EQ(m.rests_found_once, 12);
    EXPECT_EQ(m.stray_segments, 0);
    EXPECT_GE(m.recall, 0.95);
    EXPECT_EQ(m.moving_detected_s, 0.0);
    ASSERT_FALSE(segments.empty());
    EXPECT_LE(segments[0].start_s, 0.5 + 0.01);  // the first rest from its first full window
    const double noise_rms = std::sqrt(3.0) * imu.unit().gyro_sigma_rad_s;
    for (const auto& s : segments) {
      // Mean of >= 400 samples: 0.003 rad/s per axis.
      EXPECT_LT((s.gyro_bias_rad_s - imu.unit().gyro_bias_rad_s).norm(), 0.015) << s.start_s;
      EXPECT_NEAR(s.gyro_std_rad_s, noise_rms, 0.1 * noise_rms) << s.start_s;
    }
  }
}

TEST(StationaryDetector, NoRestDuringSlowConstantRotations) {
  // A constant rotation has the gyro mean and scatter of a rest. Across gravity it turns the
  // accelerometer; about gravity only the previous rest's bias tells it apart.
  const Eigen::Vector3d axes[] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                  Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, 1, 1)};
  std::uint32_t seed = 30;
  for (const Eigen::Vector3d& axis : axes) {
    for (double rate_deg_s : {3.0, 6.0, 12.0}) {
      SCOPED_TRACE("axis " + std::to_string(axis.x()) + " " + std::to_string(axis.y()) + " " +
                   std::to_string(axis.z()) + ", " + std::to_string(rate_deg_s) + " deg/s");
      std::mt19937 rng(++seed);
      test::SyntheticImu imu(test::noisyBiasedUnit(), randomRotation(rng), seed);
      imu.rest(4.0);
      imu.spin(axis, deg2rad(rate_deg_s), 1.0, 8.0, 1.0);
      imu.rest(4.0);
      const auto segments = detectStationarySegments(imu.samples());
      const test::RestMatch m = test::matchRests(imu, segments);
      EXPECT_EQ(m.spinning_detected_s, 0.0);
      EXPECT_EQ(m.rests_found_once, 2);
      // Only the two rests; their ends may reach into the 1-s ramps, where the rate (< 2 deg/s)
      // is within this gyro's noise.
      EXPECT_EQ(segments.size(), 2u);
    }
  }
  // Spinning from the start, no bias known yet: the accelerometer alone refuses rotations with
  // more than 1.5 deg/s across gravity for this accelerometer (1 deg/s for a quiet one); here 3
  // deg/s about axes 55 degrees or more from it.
  for (const Eigen::Vector3d& axis : {axes[0], axes[1], axes[3]}) {
    for (double rate_deg_s : {3.0, 6.0}) {
      std::mt19937 rng(++seed);
      test::SyntheticImu imu(test::noisyBiasedUnit(), randomRotation(rng), seed);
      imu.spin(axis, deg2rad(rate_deg_s), 0.0, 8.0, 1.0);
      imu.rest(4.0);
      const test::RestMatch m = test::matchRests(imu, detectStationarySegments(imu.samples()));
      EXPECT_EQ(m.spinning_detected_s, 0.0) << rate_deg_s << " deg/s";
      EXPECT_EQ(m.rests_found_once, 1) << rate_deg_s << " deg/s";
    }
  }
}

TEST(StationaryDetector, ThePreviousBiasIsAHintNotARequirement) {
  // The bias steps by 0.05 rad/s about gravity and 0.09 across it between two rests (a warm-up):
  // the accelerometer shows the rest still, and a rotation more than twice its turn-rate limit
  // across gravity (0.05 rad/s for this accelerometer) would have turned it: the step is the
  // bias's, and the rest is taken.
  test::ImuUnit unit = test::noisyBiasedUnit();
  unit.gyro_bias_rad_s = Eigen::Vector3d(0.01, -0.02, 0.01);  // within the old first-rest limit
  const Eigen::Matrix3d R_world_imu = Eigen::Matrix3d::Identity();  // up = IMU z
  {
    test::SyntheticImu imu(unit, R_world_imu, 40);
    imu.rest(4.0);
    imu.move(deg2rad(90.0) * Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero(), 2.0);
    // IMU -x is now up.
    imu.unit().gyro_bias_rad_s += Eigen::Vector3d(0.05, 0.09, 0.0);
    imu.rest(4.0);
    const auto segments = detectStationarySegments(imu.samples());
    const test::RestMatch m = test::matchRests(imu, segments);
    EXPECT_EQ(m.rests_found_once, 2);
    EXPECT_EQ(segments.size(), 2u);
    if (segments.size() == 2u) {
      EXPECT_LT((segments[1].gyro_bias_rad_s - imu.unit().gyro_bias_rad_s).norm(), 0.015);
    }
  }
  {
    // A step about gravity only, the next rests at the same tilt (turns about the vertical): the
    // first rest after it looks like a rotation about gravity and is lost, but a wrong hint does
    // not refuse every later rest.
    test::SyntheticImu imu(unit, R_world_imu, 41);
    imu.rest(4.0);
    imu.move(deg2rad(60.0) * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0.2, 0, 0), 2.0);
    imu.unit().gyro_bias_rad_s.z() += 0.05;
    for (int k = 0; k < 3; ++k) {
      imu.rest(4.0);
      imu.move(deg2rad(-40.0) * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0.2, 0), 2.0);
    }
    imu.rest(4.0);
    const test::RestMatch m = test::matchRests(imu, detectStationarySegments(imu.samples()));
    EXPECT_GE(m.rests_found_once, 4);  // of 5
    EXPECT_EQ(m.stray_segments, 0);
  }
}

// ------------------------------------------------------------------------------------------
// Magnetometer hygiene
// ------------------------------------------------------------------------------------------

TEST(Magnetometer, UnitsAreClassifiedAndTheMessageNamesTheFix) {
  EXPECT_EQ(classifyFieldUnits(48e-6), FieldUnits::kTesla);
  EXPECT_EQ(classifyFieldUnits(0.48), FieldUnits::kLooksLikeGauss);
  EXPECT_EQ(classifyFieldUnits(48.0), FieldUnits::kLooksLikeMicrotesla);
  EXPECT_EQ(classifyFieldUnits(0.0), FieldUnits::kOutOfRange);
  EXPECT_EQ(classifyFieldUnits(NAN), FieldUnits::kOutOfRange);
  EXPECT_EQ(classifyFieldUnits(3e-3), FieldUnits::kOutOfRange);
  const std::string gauss = describeFieldUnits(FieldUnits::kLooksLikeGauss, 0.48);
  EXPECT_NE(gauss.find("gauss"), std::string::npos) << gauss;
  EXPECT_NE(gauss.find("mag_scale"), std::string::npos) << gauss;
  const std::string micro = describeFieldUnits(FieldUnits::kLooksLikeMicrotesla, 48);
  EXPECT_NE(micro.find("1e-6"), std::string::npos) << micro;
}

TEST(Magnetometer, CalibrationAppliesScaleHardAndSoftIron) {
  MagnetometerCalibration c;
  c.scale = 1e-6;
  c.hard_iron_t = Eigen::Vector3d(1e-6, 0, 0);
  c.soft_iron = Eigen::Vector3d(2, 1, 1).asDiagonal();
  EXPECT_TRUE(c.apply(Eigen::Vector3d(11, 20, 30)).isApprox(Eigen::Vector3d(20e-6, 20e-6, 30e-6)));
}

TEST(Magnetometer, DirectionScatterIgnoresWhiteNoiseAndSeesAWanderingField) {
  std::mt19937 rng(8);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Eigen::Vector3d> steady, wandering;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d noise = 1e-6 * Eigen::Vector3d(n(rng), n(rng), n(rng));  // ~1.3 deg
    steady.push_back(kEarthField + noise);
    // A magnet swinging slowly: +-4 deg about x over the rest.
    const double swing = deg2rad(4.0) * std::sin(2.0 * M_PI * i / 400.0);
    wandering.push_back(expSO3(Eigen::Vector3d(swing, 0, 0)) * kEarthField + noise);
  }
  EXPECT_LT(fieldDirectionScatterDeg(steady), 0.3);  // 1.3 deg / sqrt(100) per quarter
  // Quarter means of a full sine period: +-(2 / pi) x 4 deg each.
  EXPECT_NEAR(fieldDirectionScatterDeg(wandering), 8.0 / M_PI, 0.3);
  EXPECT_EQ(fieldDirectionScatterDeg({kEarthField}), 0.0);
}

TEST(Magnetometer, DisturbanceAgainstTheRunningReference) {
  MagneticDisturbanceDetector d;
  std::string why;
  EXPECT_FALSE(d.check(48e-6, 62.0, 0.2, &why));  // first: sets the reference
  EXPECT_FALSE(d.check(48.5e-6, 62.5, 0.2, &why)) << why;
  EXPECT_TRUE(d.check(56e-6, 62.0, 0.2, &why));  // +16 % norm
  EXPECT_NE(why.find("norm"), std::string::npos) << why;
  EXPECT_TRUE(d.check(48e-6, 70.0, 0.2, &why));  // dip
  EXPECT_NE(why.find("dip"), std::string::npos) << why;
  EXPECT_TRUE(d.check(48e-6, 62.0, 3.0, &why));  // field direction moving during the rest
  EXPECT_TRUE(d.check(NAN, 62.0, 0.2, &why));
  // Disturbed segments never move the reference.
  EXPECT_NEAR(d.referenceDip(), 62.25, 1e-9);
}

// ------------------------------------------------------------------------------------------
// BROAD (real myon IMU at 285.7 Hz with optical reference), skipped when absent
// ------------------------------------------------------------------------------------------

struct Score {
  double precision = 0.0, recall = 0.0;
};

/// Per-sample precision (samples inside detected segments that the authors label at rest) and
/// recall (samples of the authors' rests long enough to be poses that are inside a segment; half a
/// window at each end of a rest cannot be, by design, and is not counted).
Score scoreDetector(const test::BroadRecording& rec, const std::vector<StationarySegment>& segs,
                    const StationaryDetectorSettings& settings) {
  std::vector<char> detected(rec.size(), 0);
  std::size_t k = 0;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const double t = rec.imu[i].stamp_s;
    while (k < segs.size() && segs[k].end_s < t) ++k;
    detected[i] = k < segs.size() && t >= segs[k].start_s;
  }
  double true_pos = 0, detected_n = 0, rest_n = 0, rest_hit = 0;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    detected_n += detected[i];
    true_pos += detected[i] && rec.moving[i] == 0;
  }
  for (const auto& [begin, end] : test::broadRests(rec)) {
    const double t0 = rec.imu[begin].stamp_s + 0.5 * settings.window_s;
    const double t1 = rec.imu[end - 1].stamp_s - 0.5 * settings.window_s;
    if (t1 - t0 < settings.min_duration_s) continue;
    for (std::size_t i = begin; i < end; ++i) {
      const double t = rec.imu[i].stamp_s;
      if (t < t0 || t > t1) continue;
      ++rest_n;
      rest_hit += detected[i];
    }
  }
  return {detected_n > 0 ? true_pos / detected_n : 0.0, rest_n > 0 ? rest_hit / rest_n : 0.0};
}

class Broad : public ::testing::TestWithParam<const char*> {};

TEST_P(Broad, DetectorAgreesWithTheAuthorsLabelsAndAttitudeWithTheReference) {
  const auto rec = test::loadBroad(GetParam());
  if (!rec) GTEST_SKIP() << test::broadPath(GetParam()) << " not found";
  const StationaryDetectorSettings settings;
  const auto segments = detectStationarySegments(rec->imu, settings);
  ASSERT_GE(segments.size(), 3u);
  const Score score = scoreDetector(*rec, segments, settings);
  std::cout << GetParam() << ": " << segments.size() << " segments, precision " << score.precision
            << ", recall " << score.recall << "\n";
  RecordProperty("precision", std::to_string(score.precision));
  RecordProperty("recall", std::to_string(score.recall));
  EXPECT_GE(score.precision, 0.99);
  EXPECT_GE(score.recall, 0.97);

  // Attitude at each rest against the motion-capture reference. Their heading origins differ by a
  // constant (magnetic north vs. the capture room), so compare rotations between rests, and the
  // tilt directly.
  std::vector<Eigen::Matrix3d> ours, ref;
  for (const auto& s : segments) {
    Eigen::Vector3d field = Eigen::Vector3d::Zero();
    std::size_t begin = 0, end = 0;
    for (std::size_t i = 0; i < rec->size(); ++i) {
      const double t = rec->imu[i].stamp_s;
      if (t < s.start_s) begin = i + 1;
      if (t <= s.end_s) end = i + 1;
    }
    for (std::size_t i = begin; i < end; ++i) field += rec->mag[i].field_t;
    Eigen::Matrix3d R_ref;
    if (end <= begin || !test::meanReference(*rec, begin, end, &R_ref)) continue;
    const AttitudeFromVectors a = attitudeFromAccelMag(s.mean_accel_m_s2, field / (end - begin));
    ASSERT_TRUE(a.valid);
    ours.push_back(a.R_world_imu);
    ref.push_back(R_ref);
    const Eigen::Vector3d up_ours = a.R_world_imu.transpose().col(2);
    const Eigen::Vector3d up_ref = R_ref.transpose().col(2);
    EXPECT_LT(rad2deg(std::acos(std::min(1.0, up_ours.dot(up_ref)))), 1.0)
        << "tilt, rest at " << s.start_s;
  }
  ASSERT_GE(ours.size(), 3u);
  double worst = 0.0;
  for (std::size_t k = 1; k < ours.size(); ++k) {
    const Eigen::Matrix3d B_ours = ours[0].transpose() * ours[k];
    const Eigen::Matrix3d B_ref = ref[0].transpose() * ref[k];
    worst = std::max(worst, test::angleBetweenDeg(B_ours, B_ref));
  }
  std::cout << GetParam() << ": worst relative attitude error " << worst << " deg over "
            << ours.size() << " rests\n";
  EXPECT_LT(worst, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Trials, Broad,
                         ::testing::Values("04_undisturbed_slow_rotation_with_breaks_A.csv",
                                           "08_undisturbed_fast_rotation_with_breaks_A.csv"));

TEST(BroadTrial30, MagnetMovedNearTheRestingImuIsFlagged) {
  const auto rec = test::loadBroad("30_disturbed_stationary_magnet_C.csv");
  if (!rec) GTEST_SKIP() << "BROAD trial 30 not found";
  // The IMU rests throughout while a magnet moves near it: judge 2-s blocks like rests.
  MagneticDisturbanceDetector detector;
  int disturbed_blocks = 0, flagged_disturbed = 0, quiet_blocks = 0, flagged_quiet = 0;
  const double block_s = 2.0;
  std::size_t begin = 0;
  while (begin < rec->size()) {
    std::size_t end = begin;
    while (end < rec->size() && rec->imu[end].stamp_s < rec->imu[begin].stamp_s + block_s) ++end;
    Eigen::Vector3d accel = Eigen::Vector3d::Zero(), field = Eigen::Vector3d::Zero();
    int moving = 0;
    for (std::size_t i = begin; i < end; ++i) {
      accel += rec->imu[i].accel_m_s2;
      field += rec->mag[i].field_t;
      moving += rec->moving[i];
    }
    const double n = static_cast<double>(end - begin);
    accel /= n, field /= n;
    std::vector<Eigen::Vector3d> fields;
    for (std::size_t i = begin; i < end; ++i) fields.push_back(rec->mag[i].field_t);
    const AttitudeFromVectors a = attitudeFromAccelMag(accel, field);
    std::string why;
    const bool flagged =
        detector.check(a.field_norm_t, a.dip_deg, fieldDirectionScatterDeg(fields), &why);
    if (moving == 0) {
      ++quiet_blocks, flagged_quiet += flagged;
    } else if (moving == static_cast<int>(end - begin)) {
      ++disturbed_blocks, flagged_disturbed += flagged;
    }
    begin = end;
  }
  std::cout << "BROAD 30: " << flagged_disturbed << "/" << disturbed_blocks
            << " disturbed blocks flagged, " << flagged_quiet << "/" << quiet_blocks
            << " quiet blocks flagged\n";
  ASSERT_GT(disturbed_blocks, 10);
  EXPECT_GE(flagged_disturbed, 0.8 * disturbed_blocks);
  EXPECT_LE(flagged_quiet, 0.2 * quiet_blocks);

  // As the pipeline sees it: one long rest over the whole trial, its field direction wandering.
  Eigen::Vector3d accel = Eigen::Vector3d::Zero(), field = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> fields;
  for (std::size_t i = 0; i < rec->size(); ++i) {
    accel += rec->imu[i].accel_m_s2;
    field += rec->mag[i].field_t;
    fields.push_back(rec->mag[i].field_t);
  }
  const AttitudeFromVectors a = attitudeFromAccelMag(accel, field);
  MagneticDisturbanceDetector whole;
  std::string why;
  EXPECT_TRUE(whole.check(a.field_norm_t, a.dip_deg, fieldDirectionScatterDeg(fields), &why));
  EXPECT_NE(why.find("direction varied"), std::string::npos) << why;
}

}  // namespace
}  // namespace camera_imu_alignment
