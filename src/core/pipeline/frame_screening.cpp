#include "camera_imu_alignment/pipeline/frame_screening.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace camera_imu_alignment {
namespace {

constexpr std::size_t kMinJudged = 10;
constexpr double kMadToSigma = 1.4826;  // MAD of a normal distribution = 0.6745 sigma

bool judged(const FrameFit& f) { return f.dof > 0; }
bool usable(const FrameFit& f) {
  return std::isfinite(f.reprojection_rms_px) && f.reprojection_rms_px > 0.0;
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

}  // namespace

FrameScreening screenFramesByReprojection(const std::vector<FrameFit>& frames, double k_sigma) {
  FrameScreening out;
  out.keep.assign(frames.size(), true);
  std::vector<double> logs;
  std::size_t judged_count = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (!judged(frames[k])) continue;
    ++judged_count;
    if (usable(frames[k])) {
      logs.push_back(std::log(frames[k].reprojection_rms_px));
    } else {
      out.keep[k] = false;  // no fit to use
      ++out.dropped;
    }
  }
  double worst_rms = 0.0;
  if (logs.size() >= kMinJudged && k_sigma > 0.0) {
    const double m = median(logs);
    std::vector<double> deviations;
    for (double x : logs) deviations.push_back(std::abs(x - m));
    out.typical_rms_px = std::exp(m);
    out.spread = kMadToSigma * median(deviations);
    for (std::size_t k = 0; k < frames.size(); ++k) {
      const FrameFit& f = frames[k];
      if (!judged(f) || !usable(f)) continue;
      const double noise_spread = 1.0 / std::sqrt(2.0 * f.dof);
      if (std::log(f.reprojection_rms_px) <= m + k_sigma * std::max(out.spread, noise_spread)) {
        continue;
      }
      out.keep[k] = false;
      ++out.dropped;
      worst_rms = std::max(worst_rms, f.reprojection_rms_px);
    }
  }
  if (out.dropped > 0) {
    char buffer[220];
    std::snprintf(buffer, sizeof(buffer),
                  "%d of %zu frames dropped: reprojection error far beyond the recording's "
                  "(typical %.3f px, worst dropped %.3f px) or no fit",
                  out.dropped, judged_count, out.typical_rms_px, worst_rms);
    out.note = buffer;
  }
  return out;
}

FrameScreening screenMotionFrames(std::vector<MotionFrame>* frames, double fallback_max_rms_px) {
  std::vector<FrameFit> fits;
  std::size_t judged_count = 0;
  for (const MotionFrame& frame : *frames) {
    fits.push_back({frame.reprojection_rms_px, frame.reprojection_dof});
    if (judged(fits.back())) ++judged_count;
  }
  FrameScreening out = screenFramesByReprojection(fits);
  if (judged_count > 0 && judged_count < kMinJudged) {
    out.keep.assign(fits.size(), true);
    out.dropped = 0;
    for (std::size_t k = 0; k < fits.size(); ++k) {
      if (judged(fits[k]) &&
          !(usable(fits[k]) && fits[k].reprojection_rms_px <= fallback_max_rms_px)) {
        out.keep[k] = false;
        ++out.dropped;
      }
    }
    out.note.clear();
    if (out.dropped > 0) {
      char buffer[200];
      std::snprintf(buffer, sizeof(buffer),
                    "%d of %zu frames dropped: reprojection above max_reprojection_rms_px (%.3g "
                    "px; too few frames to judge them by each other)",
                    out.dropped, judged_count, fallback_max_rms_px);
      out.note = buffer;
    }
  }
  std::vector<MotionFrame> kept;
  for (std::size_t k = 0; k < frames->size(); ++k) {
    if (out.keep[k]) kept.push_back((*frames)[k]);
  }
  *frames = std::move(kept);
  return out;
}

}  // namespace camera_imu_alignment
