// Number formatting shared by the summary (calibration_summary.cpp) and the PNG report
// (calibration_report.cpp). Private to the io room; not installed.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "camera_imu_alignment/estimation/alignment_result.h"

namespace camera_imu_alignment {
namespace report_text {

/// Significant digits of exported numbers: a rotation entry (|x| <= 1) round-trips to 5e-10.
inline constexpr int kExportDigits = 9;

// --- Text helpers

/// `value` with `decimals` fixed decimals, or "n/a" when not finite.
inline std::string fixed(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  std::ostringstream out;
  out << std::fixed << std::setprecision(decimals) << value;
  return out.str();
}

/// `value` with kExportDigits significant digits (for files other tools read back), always as a
/// floating-point literal ("1.0", not "1").
inline std::string exact(double value) {
  std::ostringstream out;
  out << std::setprecision(kExportDigits) << value;
  std::string text = out.str();
  if (text.find_first_of(".eEni") == std::string::npos) text += ".0";
  return text;
}

inline std::string fixedList(const Eigen::Vector3d& v, int decimals) {
  return "[" + fixed(v(0), decimals) + ", " + fixed(v(1), decimals) + ", " + fixed(v(2), decimals) +
         "]";
}

/// q_cam_imu with w >= 0 (q and -q are the same rotation).
inline Eigen::Quaterniond canonicalQuaternion(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return q;
}

/// True when the result is not observable and names a weak axis (not for bad input).
inline bool hasAxisAdvice(const AlignmentResult& r) {
  const SolutionQuality& q = r.quality;
  return !q.observable && r.status != SolveStatus::kBadInput && q.weak_axis_cam.allFinite() &&
         q.excite_axis_cam.allFinite() && q.weak_axis_cam.norm() > 0.0;
}

}  // namespace report_text
}  // namespace camera_imu_alignment
