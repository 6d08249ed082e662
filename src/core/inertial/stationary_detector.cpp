// Streaming stationary detection with O(1) work per sample: running sums over the sliding window
// and over its second half (accelerometer, gyro, and the squared differences of successive samples
// that measure the sensor noise).
#include "camera_imu_alignment/inertial/stationary_detector.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace camera_imu_alignment {

namespace {

struct WindowSample {
  ImuSample sample;
  double accel_norm_dev = 0.0;  ///< |accel| - g (m/s^2)
  double gyro_sq = 0.0;         ///< |gyro|^2
  /// Squared differences to the previous sample (|accel|, accel vector, gyro vector); zero for the
  /// first sample after a (re)start, which `has_diff` marks.
  double accel_diff_sq = 0.0, accel_vector_diff_sq = 0.0, gyro_diff_sq = 0.0;
  bool has_diff = false;
};

/// Sums over the whole window; add() with sign -1 removes a sample, in O(1).
struct WindowSums {
  Eigen::Vector3d accel = Eigen::Vector3d::Zero(), gyro = Eigen::Vector3d::Zero();
  double dev = 0.0, dev_sq = 0.0, gyro_sq = 0.0;
  double accel_diff_sq = 0.0, accel_vector_diff_sq = 0.0, gyro_diff_sq = 0.0;
  int num_diff = 0;
  void add(const WindowSample& w, double sign) {
    accel += sign * w.sample.accel_m_s2;
    gyro += sign * w.sample.gyro_rad_s;
    dev += sign * w.accel_norm_dev;
    dev_sq += sign * w.accel_norm_dev * w.accel_norm_dev;
    gyro_sq += sign * w.gyro_sq;
    accel_diff_sq += sign * w.accel_diff_sq;
    accel_vector_diff_sq += sign * w.accel_vector_diff_sq;
    gyro_diff_sq += sign * w.gyro_diff_sq;
    num_diff += w.has_diff ? static_cast<int>(sign) : 0;
  }
};

/// Sums over the window's second half (the newest `n` samples).
struct HalfSums {
  Eigen::Vector3d accel = Eigen::Vector3d::Zero(), gyro = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  void add(const WindowSample& w, double sign) {
    accel += sign * w.sample.accel_m_s2;
    gyro += sign * w.sample.gyro_rad_s;
  }
};

/// Sums of the samples that become part of a segment.
struct SegmentAccumulator {
  bool active = false;
  double start_s = 0.0, end_s = 0.0;
  double rest_since_s = 0.0;  ///< raw start: first rest centre minus half a window
  Eigen::Vector3d accel_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_sum = Eigen::Vector3d::Zero();
  double norm_dev_sum = 0.0, norm_dev_sq_sum = 0.0, gyro_sq_sum = 0.0;
  int n = 0;
};

}  // namespace

struct StationaryDetector::Impl {
  std::deque<WindowSample> window;   ///< samples in [newest - window_s, newest]
  std::deque<WindowSample> pending;  ///< samples after the last decided centre
  WindowSums sums;
  HalfSums second_half;  ///< samples in (newest - window_s / 2, newest]
  std::size_t updates_since_recompute = 0;
  /// The previous segment's mean gyro: a hint for the next rest's bias.
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  bool bias_known = false;
  /// Quietest noise seen (the minimum over full windows of the successive-difference estimate):
  /// accelerometer norm (m/s^2), accelerometer and gyro vector magnitudes (RMS over the three
  /// axes; m/s^2, rad/s).
  double accel_noise_floor = std::numeric_limits<double>::infinity();
  double accel_vector_noise_floor = std::numeric_limits<double>::infinity();
  double gyro_noise_floor = std::numeric_limits<double>::infinity();
  /// The stretch of windows refused by the bias hint alone: centres (s) of its first and last.
  /// Interruptions shorter than a window (a noisy window) do not end it.
  std::optional<double> disputed_since;
  double disputed_until = 0.0;
  bool at_rest = false;
  SegmentAccumulator segment;

  void clearWindow() {
    window.clear();
    pending.clear();
    sums = WindowSums();
    second_half = HalfSums();
  }
  /// Adds the newest sample to the sums and drops what left the window or its second half.
  void slide(const WindowSample& entry, double window_s);
  enum class Verdict { kMoving, kRest, kRefusedByHint };
  /// The rest decision for the window as it stands (full window).
  Verdict judgeWindow(const StationaryDetectorSettings& settings);
  /// Applies the verdict of the window centred on `centre_s` to the bias hint's bookkeeping;
  /// `stream_broken`: a gap, the stretch ends now.
  void trackDispute(Verdict verdict, double centre_s, bool stream_broken,
                    const StationaryDetectorSettings& settings);
};

void StationaryDetector::Impl::slide(const WindowSample& entry, double window_s) {
  window.push_back(entry);
  pending.push_back(entry);
  sums.add(entry, 1.0);
  second_half.add(entry, 1.0);
  ++second_half.n;
  const double newest = entry.sample.stamp_s;
  while (window.front().sample.stamp_s < newest - window_s) {
    sums.add(window.front(), -1.0);
    window.pop_front();
  }
  second_half.n = std::min(second_half.n, window.size());
  while (second_half.n > 1 &&
         window[window.size() - second_half.n].sample.stamp_s <= newest - 0.5 * window_s) {
    second_half.add(window[window.size() - second_half.n], -1.0);
    --second_half.n;
  }
  // Running sums drift by rounding: recompute them once per window length of updates.
  if (++updates_since_recompute > window.size()) {
    sums = WindowSums();
    for (const WindowSample& w : window) sums.add(w, 1.0);
    const std::size_t n = second_half.n;
    second_half = HalfSums();
    second_half.n = n;
    for (std::size_t i = window.size() - n; i < window.size(); ++i) second_half.add(window[i], 1.0);
    updates_since_recompute = 0;
  }
}

StationaryDetector::Impl::Verdict StationaryDetector::Impl::judgeWindow(
    const StationaryDetectorSettings& settings) {
  const WindowSums& w = sums;
  const double n = static_cast<double>(window.size());
  const double n2 = static_cast<double>(second_half.n), n1 = n - n2;
  if (n1 < 1.0) return Verdict::kMoving;
  // White noise: successive differences have twice the variance of the samples, motion (smooth
  // at IMU rates) adds little to them. The quietest window so far gives the sensor's noise.
  if (w.num_diff > 0) {
    const double twice_n = 2.0 * w.num_diff;
    accel_noise_floor = std::min(accel_noise_floor, std::sqrt(w.accel_diff_sq / twice_n));
    accel_vector_noise_floor =
        std::min(accel_vector_noise_floor, std::sqrt(w.accel_vector_diff_sq / twice_n));
    gyro_noise_floor = std::min(gyro_noise_floor, std::sqrt(w.gyro_diff_sq / twice_n));
  }
  const double k = settings.noise_factor;
  // Scatter.
  const double mean_dev = w.dev / n;
  const double accel_std = std::sqrt(std::max(0.0, w.dev_sq / n - mean_dev * mean_dev));
  const Eigen::Vector3d gyro_mean = w.gyro / n;
  const double gyro_std = std::sqrt(std::max(0.0, w.gyro_sq / n - gyro_mean.squaredNorm()));
  if (accel_std > std::max(settings.max_accel_std_m_s2, k * accel_noise_floor) ||
      gyro_std > std::max(settings.max_gyro_std_rad_s, k * gyro_noise_floor)) {
    return Verdict::kMoving;
  }
  const Eigen::Vector3d accel_mean = w.accel / n;
  const double accel_norm = accel_mean.norm();
  if (!(std::abs(accel_norm - settings.gravity_m_s2) <= settings.max_gravity_error_m_s2)) {
    return Verdict::kMoving;
  }
  // Change between the halves. A difference of two means of white noise has the per-axis std
  // sigma x sqrt(1/n1 + 1/n2); the noise floors are magnitudes over three axes.
  const double kc = settings.change_noise_factor;
  const double halves = std::sqrt(1.0 / n1 + 1.0 / n2);
  const Eigen::Vector3d gyro_second = second_half.gyro / n2;
  const Eigen::Vector3d gyro_first = (w.gyro - second_half.gyro) / n1;
  const double gyro_axis_noise = gyro_noise_floor / std::sqrt(3.0);
  auto gyroChanged = [&](const Eigen::Vector3d& change, double noise_scale) {
    return change.norm() >
           std::max(settings.max_gyro_change_rad_s, kc * gyro_axis_noise * noise_scale);
  };
  if (gyroChanged(gyro_second - gyro_first, halves)) return Verdict::kMoving;
  // Change against the rest in progress: a slow ramp into a constant rotation moves the window's
  // mean away from the bias step by step, too little between the halves.
  if (segment.active && segment.n > 0) {
    const double m = static_cast<double>(segment.n);
    if (gyroChanged(gyro_mean - segment.gyro_sum / m, std::sqrt(1.0 / n + 1.0 / m))) {
      return Verdict::kMoving;
    }
  }
  const Eigen::Vector3d accel_second = second_half.accel / n2;
  const Eigen::Vector3d accel_first = (w.accel - second_half.accel) / n1;
  const double apart_s = 0.5 * (window.back().sample.stamp_s - window.front().sample.stamp_s);
  const double turn_rad = std::atan2(accel_first.cross(accel_second).norm(),
                                     std::max(0.0, accel_first.dot(accel_second)));
  const double turn_limit =
      std::max(settings.max_gravity_turn_rate_rad_s,
               kc * accel_vector_noise_floor / std::sqrt(3.0) * halves / (accel_norm * apart_s));
  if (!(turn_rad <= turn_limit * apart_s)) return Verdict::kMoving;
  // Bias: plausible, and about gravity as the previous rest's unless the bias evidently changed.
  if (gyro_mean.norm() > settings.max_gyro_bias_rad_s) return Verdict::kMoving;
  if (bias_known) {
    const Eigen::Vector3d up = accel_mean / accel_norm;
    const Eigen::Vector3d difference = gyro_mean - bias;
    const double about_gravity = difference.dot(up);
    const double across_gravity = (difference - about_gravity * up).norm();
    if (std::abs(about_gravity) > settings.max_rate_about_gravity_rad_s &&
        across_gravity <= 2.0 * turn_limit) {
      return Verdict::kRefusedByHint;
    }
  }
  return Verdict::kRest;
}

void StationaryDetector::Impl::trackDispute(Verdict verdict, double centre_s, bool stream_broken,
                                            const StationaryDetectorSettings& settings) {
  if (verdict == Verdict::kRefusedByHint) {
    if (!disputed_since) disputed_since = centre_s;
    disputed_until = centre_s;
    return;
  }
  if (!disputed_since || (!stream_broken && centre_s - disputed_until <= settings.window_s)) return;
  // A stretch as long as a segment that only the hint refused: either a rotation about gravity
  // (the hint right) or a rest (the hint came from such a rotation, or the bias drifted about
  // gravity). The next rest is taken on its own, so that a wrong hint cannot refuse every later
  // rest at this tilt.
  if (disputed_until - *disputed_since >= settings.min_duration_s) bias_known = false;
  disputed_since.reset();
}

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
      d.clearWindow();
      d.trackDispute(Impl::Verdict::kMoving, sample.stamp_s, true, settings_);
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
    entry.accel_vector_diff_sq = (sample.accel_m_s2 - previous.sample.accel_m_s2).squaredNorm();
    entry.gyro_diff_sq = (sample.gyro_rad_s - previous.sample.gyro_rad_s).squaredNorm();
    entry.has_diff = true;
  }
  d.slide(entry, settings_.window_s);

  const double span = sample.stamp_s - d.window.front().sample.stamp_s;
  if (span < 0.9 * settings_.window_s) return emitted;  // window not filled yet
  const double centre = 0.5 * (d.window.front().sample.stamp_s + sample.stamp_s);
  const Impl::Verdict verdict = d.judgeWindow(settings_);
  d.trackDispute(verdict, centre, false, settings_);
  const bool rest = verdict == Impl::Verdict::kRest;
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
      seg.gyro_sq_sum += p.gyro_sq;
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
  out.gyro_std_rad_s =
      std::sqrt(std::max(0.0, seg.gyro_sq_sum / seg.n - out.gyro_bias_rad_s.squaredNorm()));
  if (out.duration() < settings_.min_duration_s) return std::nullopt;
  // The segment's mean gyro is the bias hint from now on.
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
