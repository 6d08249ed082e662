// Rejection reasons and their counts.
#include "camera_imu_alignment/pipeline/input_rejections.h"

#include <iomanip>
#include <sstream>

namespace camera_imu_alignment {

std::string formatStamp(double stamp_s) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(6) << stamp_s;  // a double holds ~0.2 us at 1.7e9 s
  std::string text = out.str();
  const std::size_t point = text.find('.');
  if (point == std::string::npos) return text;  // inf, nan
  std::size_t end = text.find_last_not_of('0');
  if (end == point) ++end;  // keep one decimal: "12.0"
  return text.substr(0, end + 1);
}

const char* toString(RejectReason reason) {
  switch (reason) {
    case RejectReason::kNonFinite:
      return "non_finite";
    case RejectReason::kZeroVector:
      return "zero_vector";
    case RejectReason::kStampBackwards:
      return "stamp_backwards";
    case RejectReason::kDuplicateStamp:
      return "duplicate_stamp";
    case RejectReason::kMissingStamp:
      return "missing_stamp";
    case RejectReason::kMagneticUnits:
      return "magnetic_units";
    case RejectReason::kBadImage:
      return "bad_image";
    case RejectReason::kBadCameraInfo:
      return "bad_camera_info";
    case RejectReason::kTargetNotFound:
      return "target_not_found";
    case RejectReason::kPoseRejected:
      return "pose_rejected";
    case RejectReason::kMixedCameraSource:
      return "mixed_camera_source";
    case RejectReason::kCount:
      break;
  }
  return "unknown";
}

const char* toString(InputStream stream) {
  switch (stream) {
    case InputStream::kImu:
      return "imu";
    case InputStream::kMagnetometer:
      return "mag";
    case InputStream::kImage:
      return "image";
    case InputStream::kCameraInfo:
      return "camera_info";
    case InputStream::kCameraPose:
      return "camera_pose";
  }
  return "unknown";
}

std::uint64_t RejectionCounts::total() const {
  std::uint64_t sum = 0;
  for (const std::uint64_t n : counts_) sum += n;
  return sum;
}

std::string RejectionCounts::summary() const {
  std::ostringstream out;
  bool first = true;
  for (std::size_t i = 0; i < counts_.size(); ++i) {
    if (counts_[i] == 0) continue;
    if (!first) out << ", ";
    out << toString(static_cast<RejectReason>(i)) << ": " << counts_[i];
    first = false;
  }
  return first ? "none" : out.str();
}

}  // namespace camera_imu_alignment
