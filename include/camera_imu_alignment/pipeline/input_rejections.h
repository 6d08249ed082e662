// Why an input (IMU or magnetometer sample, image, camera info, camera pose) was refused on its
// way into the pipeline, which stream it came from, and the per-reason counts. Every refusal is
// counted and reported, never propagated.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace camera_imu_alignment {

/// Why an input sample or frame was rejected. Every rejection is counted, never propagated.
enum class RejectReason {
  kNonFinite,       ///< NaN or Inf in a value or the stamp
  kZeroVector,      ///< accelerometer or magnetometer norm (near) zero
  kStampBackwards,  ///< stamp earlier than the previous sample of the same stream
  kDuplicateStamp,  ///< stamp equal to the previous sample of the same stream
  kMissingStamp,    ///< header stamp zero: the driver never set it (ROS messages only)
  kMagneticUnits,   ///< field norm far outside 20-70 microtesla (gauss or microtesla sent as T?)
  kBadImage,        ///< empty image, unsupported encoding, size differs from the camera info
  kBadCameraInfo,   ///< zero/non-finite K, D of a wrong length, unknown distortion model
  kTargetNotFound,  ///< no (or too little of the) target detected in a frame at rest
  kPoseRejected,    ///< PnP failed, reprojection error too high or ambiguous planar solution
  /// A camera frame of the other stream than the one whose first frame chose the camera source
  /// (camera poses after images, or images after camera poses): one pipeline takes one
  kMixedCameraSource,
  kCount  ///< number of reasons (not a reason)
};

/// Which input a rejected item came from; the nodelet names the topic, calibrate_bag the bag topic.
enum class InputStream { kImu, kMagnetometer, kImage, kCameraInfo, kCameraPose };

/// "imu", "mag", "image", "camera_info", "camera_pose".
const char* toString(InputStream stream);

/// Short snake_case name of a reason ("non_finite", "stamp_backwards", ...), for logs and reports.
const char* toString(RejectReason reason);

/// A stamp (s) in full for messages, to the microsecond without trailing zeros: "1700000001.5",
/// "1700000001.000123", never "1.7e+09".
std::string formatStamp(double stamp_s);

/// Counts of rejected inputs by reason.
class RejectionCounts {
 public:
  void add(RejectReason reason, std::uint64_t n = 1) { counts_[index(reason)] += n; }
  std::uint64_t count(RejectReason reason) const { return counts_[index(reason)]; }
  std::uint64_t total() const;
  /// "non_finite: 3, stamp_backwards: 1" (reasons with a zero count left out), or "none".
  std::string summary() const;
  void clear() { counts_.fill(0); }

 private:
  static std::size_t index(RejectReason reason) { return static_cast<std::size_t>(reason); }
  std::array<std::uint64_t, static_cast<std::size_t>(RejectReason::kCount)> counts_{};
};

}  // namespace camera_imu_alignment
