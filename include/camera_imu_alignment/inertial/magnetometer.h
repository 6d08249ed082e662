// Magnetometer hygiene: unit check, hard/soft-iron correction, disturbance detection.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace camera_imu_alignment {

/// sensor_msgs/MagneticField is in tesla; the earth's field is 20-70 microtesla.
enum class FieldUnits {
  kTesla,           ///< norm within [min, max] microtesla: as specified
  kLooksLikeGauss,  ///< norm 1e4 x too large for tesla, i.e. within 0.2-0.7 (gauss sent as tesla)
  kLooksLikeMicrotesla,  ///< norm within 20-70 (microtesla sent as tesla)
  kOutOfRange,           ///< anything else (zero, disturbed, other unit)
};

/// Classifies a field norm (in the message's unit, nominally tesla). The range is that of a raw,
/// uncalibrated reading: the earth's 25-65 microtesla plus hard iron of up to tens of microtesla
/// either way (a 40 uT hard iron takes the norm down to a few uT at some orientations); gauss or
/// microtesla read as tesla are still two decades outside it.
FieldUnits classifyFieldUnits(double norm, double min_t = 1e-6, double max_t = 1e-3);
/// Message for a unit problem: "field norm 0.45 looks like gauss; sensor_msgs/MagneticField is in
/// tesla (set mag_scale ...)". The caller names the topic.
std::string describeFieldUnits(FieldUnits units, double norm);

/// Corrected field = soft_iron * (raw - hard_iron), in tesla, IMU frame.
struct MagnetometerCalibration {
  Eigen::Vector3d hard_iron_t = Eigen::Vector3d::Zero();
  Eigen::Matrix3d soft_iron = Eigen::Matrix3d::Identity();
  double scale = 1.0;  ///< applied to the raw value first (e.g. 1e-4 for gauss, 1e-6 for uT)
  Eigen::Vector3d apply(const Eigen::Vector3d& raw) const {
    return soft_iron * (scale * raw - hard_iron_t);
  }
};

/// How much the field direction wandered during a rest (deg): the RMS angle between the mean
/// directions of the rest's four consecutive quarters and the overall mean. Averaging makes it
/// insensitive to the sensor's noise (a steady field gives the per-sample noise / sqrt(N / 4),
/// whatever the noise's spectrum or sample-and-hold), while a magnet moving nearby shows up as
/// its swing. Zero for fewer than 8 samples. Samples in stamp order, tesla.
double fieldDirectionScatterDeg(const std::vector<Eigen::Vector3d>& fields_t);

struct DisturbanceSettings {
  double max_norm_change = 0.08;            ///< relative change of |B| against the reference
  double max_dip_change_deg = 3.0;          ///< change of the dip angle against the reference
  double max_within_segment_std_deg = 1.0;  ///< fieldDirectionScatterDeg inside a segment
};

/// Disturbance detection per stationary segment against a running reference of the field norm
/// and dip angle (the median of the undisturbed segments seen so far; the first segment sets it).
class MagneticDisturbanceDetector {
 public:
  explicit MagneticDisturbanceDetector(const DisturbanceSettings& settings = {});
  /// Checks one segment: its mean field norm (T), dip angle (deg, attitudeFromAccelMag) and the
  /// scatter of the field direction within it (deg). Returns true when disturbed, with the reason
  /// in `why`. Undisturbed segments update the reference.
  bool check(double field_norm_t, double dip_deg, double direction_scatter_deg, std::string* why);
  bool hasReference() const { return num_reference_ > 0; }
  double referenceNorm() const;
  double referenceDip() const;
  void reset();

 private:
  DisturbanceSettings settings_;
  std::vector<double> norms_, dips_;
  int num_reference_ = 0;
};

}  // namespace camera_imu_alignment
