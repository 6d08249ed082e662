// Streaming stationary detection with O(1) work per sample: running sums over the sliding window
// (accelerometer norm, gyro, and the squared differences of successive samples that measure the
// sensor noise).
#include "camera_imu_alignment/inertial/stationary_detector.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace camera_imu_alignment {

namespace {

struct WindowSample {
  ImuSample sample;
  double accel_norm_dev = 0.0;  ///< |accel| - g (m/s^2)
  double gyro_sq = 0.0;         ///< |gyro|^2
  /// Squared differences to the previous sample (|accel| and gyro vector); zero for the first
  /// sample after a (re)start, which `has_diff` marks.
  double accel_diff_sq = 0.0, gyro_diff_sq = 0.0;
  bool has_diff = false;
};

/// Window sums; add() / remove() keep them in O(1).
struct WindowSums {
  Eigen::Vector3d accel = Eigen::Vector3d::Zero(), gyro = Eigen::Vector3d::Zero();
  double dev = 0.0, dev_sq = 0.0, gyro_sq = 0.0, accel_diff_sq = 0.0, gyro_diff_sq = 0.0;
  int num_diff = 0;
  void add(const WindowSample& w, double sign) {
    accel += sign * w.sample.accel_m_s2;
    gyro += sign * w.sample.gyro_rad_s;
    dev += sign * w.accel_norm_dev;
    dev_sq += sign * w.accel_norm_dev * w.accel_norm_dev;
    gyro_sq += sign * w.gyro_sq;
    accel_diff_sq += sign * w.accel_diff_sq;
    gyro_diff_sq += sign * w.gyro_diff_sq;
    num_diff += w.has_diff ? static_cast<int>(sign) : 0;
  }
};

/// Sums of the samples that become part of a segment.
struct SegmentAccumulator {
  bool active = false;
  double start_s = 0.0, end_s = 0.0;
  double rest_since_s = 0.0;  ///< raw start: first rest centre minus half a window
  Eigen::Vector3d accel_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_sum = Eigen::Vector3d::Zero();
  double norm_dev_sum = 0.0, norm_dev_sq_sum = 0.0;
  double gyro_norm_max = 0.0;
  int n = 0;
};

}  // namespace

struct StationaryDetector::Impl {
  std::deque<WindowSample> window;   ///< samples in [newest - window_s, newest]
  std::deque<WindowSample> pending;  ///< samples after the last decided centre
  WindowSums sums;
  std::size_t updates_since_recompute = 0;
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  bool bias_known = false;  ///< a segment has set `bias`
  /// Quietest noise seen (the minimum over full windows of the successive-difference estimate):
  /// accelerometer norm (m/s^2) and gyro vector magnitude (rad/s, RMS over the three axes).
  double accel_noise_floor = std::numeric_limits<double>::infinity();
  double gyro_noise_floor = std::numeric_limits<double>::infinity();
  bool at_rest = false;
  SegmentAccumulator segment;
};

StationaryDetector::StationaryDetector(const StationaryDetectorSettings& settings)
    : settings_(settings), impl_(std::make_shared<Impl>()) {}

std::optional<StationarySegment> StationaryDetector::add(const ImuSample& sample) {
  Impl& d = *impl_;
  if (!std::isfinite(sample.stamp_s) || !sample.gyro_rad_s.allFinite() ||
      !sample.accel_m_s2.allFinite()) {
    return std::nullopt;  // the pipeline rejects these before; never let them into the sums
  }
  std::optional<StationarySegment> emitted;
  if (!d.window.empty()) {
    const double gap = sample.stamp_s - d.window.back().sample.stamp_s;
    if (gap <= 0.0) return std::nullopt;  // not in stamp order
    if (gap > settings_.max_gap_s) {
      // Unknown motion in the gap: the rest in progress ends, the window starts over.
      emitted = flush();
      d.window.clear();
      d.pending.clear();
      d.sums = WindowSums();
    }
  }
  WindowSample entry;
  entry.sample = sample;
  entry.accel_norm_dev = sample.accel_m_s2.norm() - settings_.gravity_m_s2;
  entry.gyro_sq = sample.gyro_rad_s.squaredNorm();
  if (!d.window.empty()) {
    const WindowSample& previous = d.window.back();
    const double da = entry.accel_norm_dev - previous.accel_norm_dev;
    entry.accel_diff_sq = da * da;
    entry.gyro_diff_sq = (sample.gyro_rad_s - previous.sample.gyro_rad_s).squaredNorm();
    entry.has_diff = true;
  }
  d.window.push_back(entry);
  d.pending.push_back(entry);
  d.sums.add(entry, 1.0);
  while (d.window.front().sample.stamp_s < sample.stamp_s - settings_.window_s) {
    d.sums.add(d.window.front(), -1.0);
    d.window.pop_front();
  }
  // Running sums drift by rounding: recompute them once per window length of updates.
  if (++d.updates_since_recompute > d.window.size()) {
    d.sums = WindowSums();
    for (const WindowSample& w : d.window) d.sums.add(w, 1.0);
    d.updates_since_recompute = 0;
  }

  const double span = sample.stamp_s - d.window.front().sample.stamp_s;
  if (span < 0.9 * settings_.window_s) return emitted;  // window not filled yet
  const WindowSums& w = d.sums;
  const double n = static_cast<double>(d.window.size());
  const double mean_dev = w.dev / n;
  const double accel_std = std::sqrt(std::max(0.0, w.dev_sq / n - mean_dev * mean_dev));
  const double gravity_error = std::abs((w.accel / n).norm() - settings_.gravity_m_s2);
  const Eigen::Vector3d gyro_mean = w.gyro / n;
  const double gyro_std = std::sqrt(std::max(0.0, w.gyro_sq / n - gyro_mean.squaredNorm()));
  // White noise: successive differences have twice the variance of the samples, motion (smooth
  // at IMU rates) adds little to them. The quietest window so far gives the sensor's noise.
  if (w.num_diff > 0) {
    d.accel_noise_floor =
        std::min(d.accel_noise_floor, std::sqrt(w.accel_diff_sq / (2.0 * w.num_diff)));
    d.gyro_noise_floor =
        std::min(d.gyro_noise_floor, std::sqrt(w.gyro_diff_sq / (2.0 * w.num_diff)));
  }
  const double k = settings_.noise_factor;
  const double accel_limit = std::max(settings_.max_accel_std_m_s2, k * d.accel_noise_floor);
  const double gyro_std_limit = std::max(settings_.max_gyro_std_rad_s, k * d.gyro_noise_floor);
  // Bias-compensated mean rate (the bias is zero until the first segment, hence its own limit).
  const double gyro_mean_limit =
      d.bias_known ? settings_.max_gyro_rad_s : settings_.max_initial_gyro_bias_rad_s;
  const bool rest = accel_std <= accel_limit && gyro_std <= gyro_std_limit &&
                    (gyro_mean - d.bias).norm() <= gyro_mean_limit &&
                    gravity_error <= settings_.max_gravity_error_m_s2;
  const double centre = 0.5 * (d.window.front().sample.stamp_s + sample.stamp_s);
  d.at_rest = rest;

  SegmentAccumulator& seg = d.segment;
  if (rest && !seg.active) {
    seg = SegmentAccumulator();
    seg.active = true;
    seg.start_s = centre;
    seg.rest_since_s = centre - 0.5 * settings_.window_s;
  }
  // Samples up to the centre are decided: they belong to the segment when the centre is at rest.
  while (!d.pending.empty() && d.pending.front().sample.stamp_s <= centre) {
    const WindowSample& p = d.pending.front();
    if (rest && p.sample.stamp_s >= seg.start_s) {
      seg.accel_sum += p.sample.accel_m_s2;
      seg.gyro_sum += p.sample.gyro_rad_s;
      seg.norm_dev_sum += p.accel_norm_dev;
      seg.norm_dev_sq_sum += p.accel_norm_dev * p.accel_norm_dev;
      seg.gyro_norm_max = std::max(seg.gyro_norm_max, (p.sample.gyro_rad_s - d.bias).norm());
      seg.end_s = p.sample.stamp_s;
      ++seg.n;
    }
    d.pending.pop_front();
  }
  if (!rest && seg.active) {
    auto ended = flush();
    if (ended) emitted = ended;
  }
  return emitted;
}

std::optional<StationarySegment> StationaryDetector::flush() {
  Impl& d = *impl_;
  SegmentAccumulator seg = d.segment;
  d.segment = SegmentAccumulator();
  d.at_rest = false;
  if (!seg.active || seg.n < 2) return std::nullopt;
  StationarySegment out;
  out.start_s = seg.start_s;
  out.end_s = seg.end_s;
  out.num_samples = seg.n;
  out.mean_accel_m_s2 = seg.accel_sum / seg.n;
  out.gyro_bias_rad_s = seg.gyro_sum / seg.n;
  const double mean_dev = seg.norm_dev_sum / seg.n;
  out.accel_norm_std_m_s2 =
      std::sqrt(std::max(0.0, seg.norm_dev_sq_sum / seg.n - mean_dev * mean_dev));
  out.gyro_norm_max_rad_s = seg.gyro_norm_max;
  if (out.duration() < settings_.min_duration_s) return std::nullopt;
  // The segment's mean gyro is the bias from now on.
  d.bias = out.gyro_bias_rad_s;
  d.bias_known = true;
  return out;
}

bool StationaryDetector::atRest() const { return impl_->at_rest; }

std::optional<double> StationaryDetector::restSince() const {
  if (!impl_->at_rest || !impl_->segment.active) return std::nullopt;
  return impl_->segment.rest_since_s;
}

void StationaryDetector::reset() { impl_ = std::make_shared<Impl>(); }

std::vector<StationarySegment> detectStationarySegments(
    const std::vector<ImuSample>& samples, const StationaryDetectorSettings& settings) {
  StationaryDetector detector(settings);
  std::vector<StationarySegment> segments;
  for (const ImuSample& s : samples) {
    if (auto segment = detector.add(s)) segments.push_back(*segment);
  }
  if (auto segment = detector.flush()) segments.push_back(*segment);
  return segments;
}

}  // namespace camera_imu_alignment
