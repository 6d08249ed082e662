// The pipeline's window of stationary poses (stationary_window.h).
#include "camera_imu_alignment/pipeline/stationary_window.h"

#include <algorithm>
#include <map>
#include <utility>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

StationaryWindow::StationaryWindow(std::size_t max_poses)
    : max_poses_(std::max<std::size_t>(2, max_poses)) {}

bool StationaryWindow::add(Entry entry) {
  if (!isRotationMatrix(entry.pose.R_target_cam, 1e-6) ||
      !isRotationMatrix(entry.pose.R_world_imu, 1e-6)) {
    return false;
  }
  entries_.push_back(std::move(entry));
  while (entries_.size() > max_poses_) entries_.pop_front();
  return true;
}

void StationaryWindow::keepFrom(int pose_index) {
  while (!entries_.empty() && entries_.front().pose.index < pose_index) entries_.pop_front();
}

std::vector<StationaryPose> StationaryWindow::poses() const {
  std::vector<StationaryPose> out;
  out.reserve(entries_.size());
  for (const Entry& e : entries_) out.push_back(e.pose);
  return out;
}

PoseOrientation orientationOf(const StationaryPose& pose) {
  PoseOrientation o;
  o.stamp_s = 0.5 * (pose.start_s + pose.end_s);
  o.R_target_cam = pose.R_target_cam;
  o.R_world_imu = pose.R_world_imu;
  o.group = pose.group;
  o.camera_frame = pose.scene;
  return o;
}

std::vector<PoseOrientation> StationaryWindow::orientations() const {
  std::vector<PoseOrientation> out;
  out.reserve(entries_.size());
  for (const Entry& e : entries_) out.push_back(orientationOf(e.pose));
  return out;
}

RotationPairs StationaryWindow::pairs() const { return makeAllPairs(orientations()); }

JointProblem StationaryWindow::problem() const {
  JointProblem problem;
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    problem.poses.push_back(entries_[i].joint);
    const auto& gyro = entries_[i].gyro_from_previous;
    if (i == 0 || !gyro || gyro->stamps_s.size() < 2) continue;
    if (entries_[i - 1].joint.group != entries_[i].joint.group) continue;
    GyroSegment segment = *gyro;
    segment.from_pose = static_cast<int>(i) - 1;
    segment.to_pose = static_cast<int>(i);
    problem.segments.push_back(std::move(segment));
  }
  std::map<int, int> position;  // StationaryPose::index -> index in the window
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    position[entries_[i].pose.index] = static_cast<int>(i);
  }
  for (const Entry& entry : entries_) {
    for (CameraLink link : entry.camera_links) {
      const auto from = position.find(link.from_pose), to = position.find(link.to_pose);
      if (from == position.end() || to == position.end()) continue;  // left the window
      link.from_pose = from->second;
      link.to_pose = to->second;
      problem.camera_links.push_back(link);
    }
  }
  return problem;
}

}  // namespace camera_imu_alignment
