// The joint estimate with camera links screened (camera_link_screening.h).
#include "camera_imu_alignment/estimation/camera_link_screening.h"

#include <algorithm>
#include <numeric>
#include <utility>
#include <vector>

namespace camera_imu_alignment {

JointResult solveScreeningCameraLinks(const JointEstimator& estimator, JointProblem problem,
                                      const Eigen::Matrix3d& R_start) {
  JointResult joint = estimator.solve(problem, R_start);
  const std::size_t links = problem.camera_links.size();
  const std::size_t max_left_out = links / 3;
  std::vector<int> caller_index(links);  // of each link still in `problem`
  std::iota(caller_index.begin(), caller_index.end(), 0);
  std::vector<std::pair<int, double>> left_out;  // caller's index, chi-square when left out
  while (joint.ok && left_out.size() < max_left_out &&
         joint.camera_link_chi2.size() == problem.camera_links.size()) {
    const auto worst =
        std::max_element(joint.camera_link_chi2.begin(), joint.camera_link_chi2.end());
    if (worst == joint.camera_link_chi2.end() || *worst < kCameraLinkOutlierChi2) break;
    const auto j = worst - joint.camera_link_chi2.begin();
    JointProblem without = problem;
    without.camera_links.erase(without.camera_links.begin() + j);
    JointResult again = estimator.solve(without, joint.R_cam_imu);
    if (!again.ok) break;  // the last usable estimate stands
    left_out.emplace_back(caller_index[j], *worst);
    caller_index.erase(caller_index.begin() + j);
    problem = std::move(without);
    joint = std::move(again);
  }
  if (left_out.empty() || joint.camera_link_chi2.size() != caller_index.size()) return joint;
  // In the caller's indices; a link left out keeps its chi-square of the solve that left it out.
  std::vector<double> chi2(links, 0.0);
  for (std::size_t i = 0; i < caller_index.size(); ++i) {
    chi2[caller_index[i]] = joint.camera_link_chi2[i];
  }
  for (const auto& [index, value] : left_out) {
    chi2[index] = value;
    joint.camera_links_left_out.push_back(index);
  }
  std::sort(joint.camera_links_left_out.begin(), joint.camera_links_left_out.end());
  joint.camera_link_chi2 = std::move(chi2);
  return joint;
}

double trimmedChi2(const JointResult& result) {
  return result.chi2 +
         kCameraLinkOutlierChi2 * static_cast<double>(result.camera_links_left_out.size());
}

int trimmedDof(const JointResult& result) {
  return result.dof + 3 * static_cast<int>(result.camera_links_left_out.size());
}

}  // namespace camera_imu_alignment
