// Streaming stationary detection with O(1) work per sample: running sums over the sliding window
// and a count of samples whose gyro exceeds the threshold.
#include "camera_imu_alignment/stationary_detector.h"

#include <algorithm>
#include <cmath>

namespace camera_imu_alignment {

namespace {

struct WindowSample {
  ImuSample sample;
  double accel_norm_dev = 0.0;  ///< |accel| - g (m/s^2)
  bool gyro_over = false;       ///< bias-compensated gyro norm above the threshold
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
  Eigen::Vector3d accel_sum = Eigen::Vector3d::Zero();
  double dev_sum = 0.0, dev_sq_sum = 0.0;
  int num_over = 0;
  std::size_t updates_since_recompute = 0;
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  bool at_rest = false;
  SegmentAccumulator segment;
};

StationaryDetector::StationaryDetector(const StationaryDetectorSettings& settings)
    : settings_(settings), impl_(std::make_shared<Impl>()) {}

namespace {

bool gyroOver(const ImuSample& s, const Eigen::Vector3d& bias, double limit) {
  return (s.gyro_rad_s - bias).norm() > limit;
}

}  // namespace

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
      d.accel_sum.setZero();
      d.dev_sum = d.dev_sq_sum = 0.0;
      d.num_over = 0;
    }
  }
  WindowSample entry;
  entry.sample = sample;
  entry.accel_norm_dev = sample.accel_m_s2.norm() - settings_.gravity_m_s2;
  entry.gyro_over = gyroOver(sample, d.bias, settings_.max_gyro_rad_s);
  d.window.push_back(entry);
  d.pending.push_back(entry);
  d.accel_sum += sample.accel_m_s2;
  d.dev_sum += entry.accel_norm_dev;
  d.dev_sq_sum += entry.accel_norm_dev * entry.accel_norm_dev;
  d.num_over += entry.gyro_over;
  while (d.window.front().sample.stamp_s < sample.stamp_s - settings_.window_s) {
    const WindowSample& old = d.window.front();
    d.accel_sum -= old.sample.accel_m_s2;
    d.dev_sum -= old.accel_norm_dev;
    d.dev_sq_sum -= old.accel_norm_dev * old.accel_norm_dev;
    d.num_over -= old.gyro_over;
    d.window.pop_front();
  }
  // Running sums drift by rounding: recompute them once per window length of updates.
  if (++d.updates_since_recompute > d.window.size()) {
    d.accel_sum.setZero();
    d.dev_sum = d.dev_sq_sum = 0.0;
    for (const WindowSample& w : d.window) {
      d.accel_sum += w.sample.accel_m_s2;
      d.dev_sum += w.accel_norm_dev;
      d.dev_sq_sum += w.accel_norm_dev * w.accel_norm_dev;
    }
    d.updates_since_recompute = 0;
  }

  const double span = sample.stamp_s - d.window.front().sample.stamp_s;
  if (span < 0.9 * settings_.window_s) return emitted;  // window not filled yet
  const double n = static_cast<double>(d.window.size());
  const double mean_dev = d.dev_sum / n;
  const double accel_std = std::sqrt(std::max(0.0, d.dev_sq_sum / n - mean_dev * mean_dev));
  const double gravity_error = std::abs((d.accel_sum / n).norm() - settings_.gravity_m_s2);
  const bool rest = d.num_over == 0 && accel_std <= settings_.max_accel_std_m_s2 &&
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
  // The segment's mean gyro is the bias from now on; re-judge the samples in the window with it.
  d.bias = out.gyro_bias_rad_s;
  d.num_over = 0;
  for (WindowSample& w : d.window) {
    w.gyro_over = gyroOver(w.sample, d.bias, settings_.max_gyro_rad_s);
    d.num_over += w.gyro_over;
  }
  return out;
}

bool StationaryDetector::atRest() const { return impl_->at_rest; }

std::optional<double> StationaryDetector::restSince() const {
  if (!impl_->at_rest || !impl_->segment.active) return std::nullopt;
  return impl_->segment.rest_since_s;
}

void StationaryDetector::reset() { impl_ = std::make_shared<Impl>(); }

std::vector<StationarySegment> detectStationarySegments(const std::vector<ImuSample>& samples,
                                                        const StationaryDetectorSettings& settings) {
  StationaryDetector detector(settings);
  std::vector<StationarySegment> segments;
  for (const ImuSample& s : samples) {
    if (auto segment = detector.add(s)) segments.push_back(*segment);
  }
  if (auto segment = detector.flush()) segments.push_back(*segment);
  return segments;
}

}  // namespace camera_imu_alignment
