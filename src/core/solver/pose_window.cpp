#include "camera_imu_alignment/solver/pose_window.h"

#include <algorithm>

#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {

RotationPairs makeAllPairs(const std::vector<PoseOrientation>& poses) {
  RotationPairs pairs;
  const int P = static_cast<int>(poses.size());
  pairs.reserve(static_cast<size_t>(P) * (P > 0 ? P - 1 : 0) / 2);
  for (int k = 0; k < P; ++k) {
    for (int t = k + 1; t < P; ++t) {
      if (poses[k].group != poses[t].group || poses[k].camera_frame != poses[t].camera_frame) {
        continue;
      }
      RotationPair pair;
      pair.A_cam = poses[k].R_target_cam.transpose() * poses[t].R_target_cam;
      pair.B_imu = poses[k].R_world_imu.transpose() * poses[t].R_world_imu;
      pair.pose_k = k;
      pair.pose_t = t;
      pairs.push_back(pair);
    }
  }
  return pairs;
}

}  // namespace camera_imu_alignment
