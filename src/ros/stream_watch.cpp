// StreamWatch (stream_watch.h).
#include "camera_imu_alignment/ros/stream_watch.h"

#include <algorithm>

namespace camera_imu_alignment {

void StreamWatch::seen(InputStream stream, double now_s) {
  last_s_[static_cast<std::size_t>(stream)] = now_s;
  if (first_s_ < 0) first_s_ = now_s;
}

bool StreamWatch::everSeen(InputStream stream) const {
  return last_s_[static_cast<std::size_t>(stream)] >= 0;
}

bool StreamWatch::flowing(InputStream stream, double now_s) const {
  const double last = last_s_[static_cast<std::size_t>(stream)];
  return last >= 0 && now_s - last < silent_after_s_;
}

std::vector<InputStream> StreamWatch::silent(double now_s, bool magnetometer_expected) const {
  std::vector<InputStream> out;
  if (first_s_ < 0 || now_s - first_s_ < silent_after_s_) return out;
  const InputStream all[] = {InputStream::kImu, InputStream::kMagnetometer, InputStream::kImage,
                             InputStream::kCameraInfo, InputStream::kCameraPose};
  const bool any =
      std::any_of(std::begin(all), std::end(all), [&](InputStream s) { return flowing(s, now_s); });
  if (!any) return out;  // everything stopped (a bag ended): not a topic problem
  const bool pose_flows = flowing(InputStream::kCameraPose, now_s);
  const bool images_flow =
      flowing(InputStream::kImage, now_s) || flowing(InputStream::kCameraInfo, now_s);
  if (!flowing(InputStream::kImu, now_s)) out.push_back(InputStream::kImu);
  if (magnetometer_expected && !flowing(InputStream::kMagnetometer, now_s)) {
    out.push_back(InputStream::kMagnetometer);
  }
  if (!pose_flows) {
    if (!flowing(InputStream::kImage, now_s)) out.push_back(InputStream::kImage);
    if (!flowing(InputStream::kCameraInfo, now_s)) out.push_back(InputStream::kCameraInfo);
    if (!images_flow) out.push_back(InputStream::kCameraPose);
  }
  return out;
}

}  // namespace camera_imu_alignment
