// Magnetometer unit check and disturbance detection against a running reference.
#include "camera_imu_alignment/inertial/magnetometer.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace camera_imu_alignment {

FieldUnits classifyFieldUnits(double norm, double min_t, double max_t) {
  if (!std::isfinite(norm) || norm <= 0.0) return FieldUnits::kOutOfRange;
  if (norm >= min_t && norm <= max_t) return FieldUnits::kTesla;
  // The same earth field expressed in gauss (1 G = 1e-4 T) or microtesla, read as tesla.
  if (norm >= min_t * 1e4 && norm <= max_t * 1e4) return FieldUnits::kLooksLikeGauss;
  if (norm >= min_t * 1e6 && norm <= max_t * 1e6) return FieldUnits::kLooksLikeMicrotesla;
  return FieldUnits::kOutOfRange;
}

std::string describeFieldUnits(FieldUnits units, double norm) {
  std::ostringstream out;
  out << "field norm " << norm;
  switch (units) {
    case FieldUnits::kTesla:
      out << " T is plausible";
      break;
    case FieldUnits::kLooksLikeGauss:
      out << " looks like gauss; sensor_msgs/MagneticField is in tesla (set mag_scale: 1e-4)";
      break;
    case FieldUnits::kLooksLikeMicrotesla:
      out << " looks like microtesla; sensor_msgs/MagneticField is in tesla (set mag_scale: 1e-6)";
      break;
    case FieldUnits::kOutOfRange:
      out << " is outside 1-1000 microtesla (the earth's field is 25-65 plus the sensor's hard "
             "iron): a wrong unit or a strong disturbance";
      break;
  }
  return out.str();
}

double fieldDirectionScatterDeg(const std::vector<Eigen::Vector3d>& fields_t) {
  constexpr std::size_t kParts = 4;
  if (fields_t.size() < 2 * kParts) return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& f : fields_t) mean += f;
  if (!(mean.norm() > 0.0) || !mean.allFinite()) return 0.0;
  double sum_sq = 0.0;
  for (std::size_t k = 0; k < kParts; ++k) {
    const std::size_t begin = k * fields_t.size() / kParts,
                      end = (k + 1) * fields_t.size() / kParts;
    Eigen::Vector3d part = Eigen::Vector3d::Zero();
    for (std::size_t i = begin; i < end; ++i) part += fields_t[i];
    sum_sq += std::pow(std::atan2(part.cross(mean).norm(), part.dot(mean)), 2);
  }
  return std::sqrt(sum_sq / kParts) * 180.0 / M_PI;
}

MagneticDisturbanceDetector::MagneticDisturbanceDetector(const DisturbanceSettings& settings)
    : settings_(settings) {}

namespace {
double median(std::vector<double> values) {
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  double m = values[mid];
  if (values.size() % 2 == 0) {
    m = 0.5 * (m + *std::max_element(values.begin(), values.begin() + mid));
  }
  return m;
}
}  // namespace

double MagneticDisturbanceDetector::referenceNorm() const {
  return norms_.empty() ? 0.0 : median(norms_);
}
double MagneticDisturbanceDetector::referenceDip() const {
  return dips_.empty() ? 0.0 : median(dips_);
}

bool MagneticDisturbanceDetector::check(double field_norm_t, double dip_deg,
                                        double direction_scatter_deg, std::string* why) {
  std::ostringstream reason;
  if (!std::isfinite(field_norm_t) || !std::isfinite(dip_deg) || field_norm_t <= 0.0) {
    reason << "field not finite";
  } else if (direction_scatter_deg > settings_.max_within_segment_std_deg) {
    reason << "field direction varied by " << direction_scatter_deg << " deg during the rest (max "
           << settings_.max_within_segment_std_deg << ")";
  } else if (hasReference()) {
    const double norm_change = std::abs(field_norm_t / referenceNorm() - 1.0);
    const double dip_change = std::abs(dip_deg - referenceDip());
    if (norm_change > settings_.max_norm_change) {
      reason << "field norm " << field_norm_t * 1e6 << " uT differs by " << norm_change * 100.0
             << " % from the reference " << referenceNorm() * 1e6 << " uT";
    } else if (dip_change > settings_.max_dip_change_deg) {
      reason << "dip angle " << dip_deg << " deg differs by " << dip_change
             << " deg from the reference " << referenceDip() << " deg";
    }
  }
  const std::string text = reason.str();
  if (!text.empty()) {
    if (why) *why = "disturbed: " + text;
    return true;
  }
  // Bounded memory: the reference is the median of the most recent undisturbed segments.
  constexpr std::size_t kMaxReference = 50;
  if (norms_.size() == kMaxReference) {
    norms_.erase(norms_.begin());
    dips_.erase(dips_.begin());
  }
  norms_.push_back(field_norm_t);
  dips_.push_back(dip_deg);
  num_reference_ = static_cast<int>(norms_.size());
  if (why) why->clear();
  return false;
}

void MagneticDisturbanceDetector::reset() {
  norms_.clear();
  dips_.clear();
  num_reference_ = 0;
}

}  // namespace camera_imu_alignment
