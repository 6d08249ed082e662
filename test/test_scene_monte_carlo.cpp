// Calibration without a board, Monte Carlo (issue 26's targets; labelled statistical): 8 seeds
// (CIA_SCENE_SEEDS=20: the size, BENCHMARKS.md) of the simulator's room scenarios with a
// consumer IMU (scene_sessions.h): RMS error, answers (the chi-square test passing), and the
// reported 1-sigma covering the errors whenever it passes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "scene_sessions.h"

namespace camera_imu_alignment {
namespace {

/// Seeds per scene unless CIA_SCENE_SEEDS says (the Monte Carlo size, 20, in
/// BENCHMARKS.md: about 5 min for both scenes).
constexpr int kDefaultSeeds = 8;

struct Statistics {
  std::vector<double> error_deg;        ///< of the consistent estimates
  std::vector<double> board_error_deg;  ///< the same seeds with a board at every rest
  int consistent = 0, within_3_sigma = 0, seeds = 0;
};

Statistics runSeeds(const std::string& scenario) {
  Statistics s;
  const int seeds = test::sceneSeedCount(kDefaultSeeds);
  for (int k = 0; k < seeds; ++k) {
    const test::SceneOutcome o = test::runScene(scenario, 100 + k);
    ++s.seeds;
    s.board_error_deg.push_back(o.board_error_deg);
    if (!o.consistent) continue;
    ++s.consistent;
    s.error_deg.push_back(o.error_deg);
    s.within_3_sigma += o.error_deg < 3.0 * o.sigma_norm_deg;
  }
  double sum = 0;
  for (double e : s.error_deg) sum += e * e;
  double board_sum = 0;
  for (double e : s.board_error_deg) board_sum += e * e;
  std::printf(
      "%s, %d seeds: %d consistent, RMS %.4f deg over them, %d within 3 sigma; a board at every "
      "rest: RMS %.4f deg\n",
      scenario.c_str(), s.seeds, s.consistent,
      s.error_deg.empty() ? 0.0 : std::sqrt(sum / s.error_deg.size()), s.within_3_sigma,
      std::sqrt(board_sum / s.board_error_deg.size()));
  return s;
}

double rms(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x * x;
  return v.empty() ? 0.0 : std::sqrt(sum / v.size());
}

// The target is 0.10 deg RMS, not met: measured 0.175 (20/20 consistent, all within 3
// sigma, 1-sigma norms about 0.2 deg: the robot turns mostly about the vertical, tilted 5-20 deg;
// 2026-11-27), and 0.1747 with the links fitted again with the rotation held (sixth session), where
// a board at every stop gives 0.189 deg on the same motions. Asserted: honesty, and the measured
// level with a margin.
TEST(SceneMonteCarlo, RobotStopsConsumer) {
  const Statistics s = runSeeds("room_robot");
  EXPECT_GE(s.consistent, s.seeds * 9 / 10);
  EXPECT_EQ(s.within_3_sigma, s.consistent);
  EXPECT_LE(rms(s.error_deg), 0.25);
}

// The target: 0.08 deg RMS and at most 1.5x the board's error on the same motion, honest.
// Measured (2026-11-27, fifth session): 20 of 20 consistent at 0.0625 deg RMS, all within 3 sigma;
// a board at every rest (scene_sessions.h) 0.0652 deg (before the near-planar views' other
// solutions and the gyro's consensus: 8 of 20 answered, the other 12 failed the chi-square test).
// Sixth session, the links fitted again with the rotation held near the estimate's: 20 of 20 at
// 0.0571 deg.
TEST(SceneMonteCarlo, HandHeldConsumer) {
  const Statistics s = runSeeds("room_handheld");
  EXPECT_GE(s.consistent, s.seeds * 9 / 10);
  EXPECT_EQ(s.within_3_sigma, s.consistent);
  EXPECT_LE(rms(s.error_deg), 0.08);
  EXPECT_LE(rms(s.error_deg), 1.5 * rms(s.board_error_deg));
}

}  // namespace
}  // namespace camera_imu_alignment
