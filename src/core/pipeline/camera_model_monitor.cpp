// CameraModelMonitor (camera_model_monitor.h).
#include "camera_model_monitor.h"

namespace camera_imu_alignment {

void CameraModelMonitor::addFrame(double stamp_s, const CameraModelFit& fit) {
  frames_.emplace_back(stamp_s, fit);
}

void CameraModelMonitor::addRefused(double stamp_s, const std::string& why) {
  refused_.emplace_back(stamp_s, why);
}

int CameraModelMonitor::refusedIn(double lo_s, double hi_s) const {
  int count = 0;
  for (const auto& r : refused_) count += r.first >= lo_s && r.first <= hi_s;
  return count;
}

std::string CameraModelMonitor::endRest(double lo_s, double hi_s, double end_s) {
  std::vector<CameraModelFit> inside;
  std::vector<std::pair<double, CameraModelFit>> later;
  for (const auto& f : frames_) {
    if (f.first >= lo_s && f.first <= hi_s) inside.push_back(f.second);
    if (f.first > end_s) later.push_back(f);
  }
  frames_.swap(later);
  if (const auto view = combineFrames(inside)) {
    if (views_.size() >= max_views_) views_.erase(views_.begin());
    views_.push_back(*view);
  }
  int refused = 0;
  std::string latest;
  std::vector<std::pair<double, std::string>> refused_later;
  for (const auto& r : refused_) {
    if (r.first >= lo_s && r.first <= hi_s) ++refused, latest = r.second;
    if (r.first > end_s) refused_later.push_back(r);
  }
  refused_.swap(refused_later);
  if (refused == 0) return "";
  return "the camera pose was refused in " + std::to_string(refused) + " of them (" + latest + ")";
}

CameraModelCheck CameraModelMonitor::check(double level, const CameraIntrinsics* intrinsics) const {
  return checkCameraModel(views_, level, intrinsics);
}

}  // namespace camera_imu_alignment
