#include "camera_imu_alignment/estimation/time_offset.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

constexpr double kStepS = 1e-3;
constexpr double kMinAngleRad = 0.5 * 3.14159265358979323846 / 180.0;
constexpr int kMinIntervals = 20;
/// Frames at exactly min_interval_s apart (up to the stamps' rounding) are an interval.
constexpr double kIntervalToleranceS = 1e-4;

/// Integral of the raw gyro from the first sample to t (rad), the rate interpolated linearly
/// between samples: prefix sums plus the partial trapezoid.
class GyroIntegral {
 public:
  explicit GyroIntegral(const GyroStream& gyro) : gyro_(gyro) {
    const size_t n = gyro.stamps_s.size();
    prefix_.assign(n, Eigen::Vector3d::Zero());
    for (size_t i = 1; i < n; ++i) {
      const double dt = gyro.stamps_s[i] - gyro.stamps_s[i - 1];
      prefix_[i] = prefix_[i - 1] + 0.5 * dt * (gyro.gyro_rad_s[i] + gyro.gyro_rad_s[i - 1]);
    }
  }
  bool covers(double t) const {
    return !gyro_.stamps_s.empty() && t >= gyro_.stamps_s.front() && t <= gyro_.stamps_s.back();
  }
  Eigen::Vector3d at(double t) const {
    const std::vector<double>& s = gyro_.stamps_s;
    size_t i = static_cast<size_t>(std::upper_bound(s.begin(), s.end(), t) - s.begin());
    if (i == 0) return prefix_[0];
    if (i >= s.size()) return prefix_.back();
    const double dt = t - s[i - 1];
    const double w = dt / (s[i] - s[i - 1]);
    const Eigen::Vector3d rate_t = (1.0 - w) * gyro_.gyro_rad_s[i - 1] + w * gyro_.gyro_rad_s[i];
    return prefix_[i - 1] + 0.5 * dt * (gyro_.gyro_rad_s[i - 1] + rate_t);
  }

 private:
  const GyroStream& gyro_;
  std::vector<Eigen::Vector3d> prefix_;
};

}  // namespace

double gyroNoiseDensityOf(const GyroStream& gyro) {
  return whiteNoiseDensityOf(gyro.stamps_s, gyro.gyro_rad_s);
}

double whiteNoiseDensityOf(const std::vector<double>& stamps_s,
                           const std::vector<Eigen::Vector3d>& values) {
  const size_t n = std::min(stamps_s.size(), values.size());
  if (n < 10) return 0.0;
  std::vector<double> absolute, intervals;
  for (size_t i = 1; i + 1 < n; ++i) {
    const Eigen::Vector3d second = values[i + 1] - 2.0 * values[i] + values[i - 1];
    for (int a = 0; a < 3; ++a) absolute.push_back(std::abs(second(a)));
    intervals.push_back(stamps_s[i + 1] - stamps_s[i]);
  }
  const auto median = [](std::vector<double>* v) {
    std::nth_element(v->begin(), v->begin() + v->size() / 2, v->end());
    return (*v)[v->size() / 2];
  };
  // |N(0, s^2)| has median 0.6745 s; the second difference has s^2 = 6 sigma^2.
  const double sigma = median(&absolute) / 0.6745 / std::sqrt(6.0);
  const double dt = median(&intervals);
  return dt > 0.0 ? sigma * std::sqrt(dt) : 0.0;
}

TimeshiftSearch coarseTimeshift(const std::vector<MotionFrame>& frames, const GyroStream& gyro,
                                double range_s, double max_interval_s) {
  TimeshiftSearch out;
  struct Interval {
    double from, to, angle;
  };
  std::vector<Interval> intervals;
  int turning = 0;
  for (size_t k = 0; k + 1 < frames.size(); ++k) {
    const double dt = frames[k + 1].stamp_s - frames[k].stamp_s;
    if (!(dt > 0.0) || dt > max_interval_s) continue;
    const double angle =
        logSO3(frames[k].R_target_cam.transpose() * frames[k + 1].R_target_cam).norm();
    intervals.push_back({frames[k].stamp_s, frames[k + 1].stamp_s, angle});
    turning += angle > kMinAngleRad;
  }
  if (turning < kMinIntervals || gyro.stamps_s.size() < 2) {
    out.message = "too little motion to find the camera-IMU time offset (" +
                  std::to_string(turning) + " frame intervals turn by more than 0.5 deg, " +
                  std::to_string(kMinIntervals) + " needed)";
    return out;
  }
  const GyroIntegral integral(gyro);
  const int steps = static_cast<int>(std::ceil(range_s / kStepS));
  std::vector<double> cost(2 * steps + 1, std::numeric_limits<double>::infinity());
  // Only the intervals the gyro covers at every candidate: each candidate compares the same set.
  std::vector<Interval> usable;
  for (const Interval& interval : intervals) {
    if (integral.covers(interval.from - range_s) && integral.covers(interval.to + range_s)) {
      usable.push_back(interval);
    }
  }
  if (static_cast<int>(usable.size()) < kMinIntervals) {
    out.message =
        "the gyro does not cover the camera frames within the time offset search range "
        "(+-" +
        std::to_string(range_s) + " s)";
    return out;
  }
  for (int i = 0; i <= 2 * steps; ++i) {
    const double shift = (i - steps) * kStepS;
    double sum = 0.0;
    for (const Interval& interval : usable) {
      const double gyro_angle =
          (integral.at(interval.to + shift) - integral.at(interval.from + shift)).norm();
      sum += (gyro_angle - interval.angle) * (gyro_angle - interval.angle);
    }
    cost[i] = sum;
  }
  const int best = static_cast<int>(std::min_element(cost.begin(), cost.end()) - cost.begin());
  out.intervals = static_cast<int>(usable.size());
  for (int i = 0; i <= 2 * steps; ++i) {
    out.candidates_s.push_back((i - steps) * kStepS);
    out.rms_difference_rad.push_back(std::sqrt(cost[i] / static_cast<double>(usable.size())));
  }
  if (best == 0 || best == 2 * steps) {
    char buffer[200];
    std::snprintf(buffer, sizeof(buffer),
                  "the camera-IMU time offset is beyond the search range of +-%.3f s (the best "
                  "fit is at its end, %+.3f s): widen the range or check the clocks",
                  range_s, (best - steps) * kStepS);
    out.message = buffer;
    return out;
  }
  // Parabola through the best and its neighbours.
  const double a = cost[best - 1], b = cost[best], c = cost[best + 1];
  const double curvature = a - 2.0 * b + c;
  const double offset = curvature > 0.0 ? 0.5 * (a - c) / curvature : 0.0;
  out.timeshift_cam_imu_s = (best - steps + std::clamp(offset, -0.5, 0.5)) * kStepS;
  out.rms_angle_difference_rad = std::sqrt(b / static_cast<double>(usable.size()));
  out.ok = true;
  return out;
}

MotionExcitation motionExcitation(const std::vector<MotionFrame>& frames, double min_interval_s,
                                  double max_interval_s) {
  MotionExcitation out;
  size_t from = 0;
  for (size_t k = 1; k < frames.size(); ++k) {
    const double dt = frames[k].stamp_s - frames[from].stamp_s;
    if (dt < min_interval_s - kIntervalToleranceS) continue;
    if (dt <= max_interval_s) {
      const Eigen::Vector3d turn =
          logSO3(frames[from].R_target_cam.transpose() * frames[k].R_target_cam);
      if (turn.allFinite()) {
        out.about_cam_rad += turn.cwiseAbs();
        out.duration_s += dt;
      }
    }
    from = k;
  }
  return out;
}

}  // namespace camera_imu_alignment
