// The joint estimate with camera links screened (camera_link_screening.h).
#include "camera_imu_alignment/estimation/camera_link_screening.h"

#include <algorithm>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

namespace camera_imu_alignment {
namespace {

/// The solve with link `j` measured as its alternative `a` instead, when that link then fits
/// (its chi-square below the outlier bound); of several such, the lowest total chi-square.
std::optional<std::pair<int, JointResult>> bestAlternative(const JointEstimator& estimator,
                                                           const JointProblem& problem,
                                                           std::size_t j,
                                                           const Eigen::Matrix3d& R_start,
                                                           JointProblem* swapped_problem) {
  std::optional<std::pair<int, JointResult>> best;
  const CameraLink& link = problem.camera_links[j];
  for (std::size_t a = 0; a < link.alternatives.size(); ++a) {
    JointProblem swapped = problem;
    CameraLink& measured = swapped.camera_links[j];
    measured.R_from_to = link.alternatives[a].R_from_to;
    measured.cov_rad2 = link.alternatives[a].cov_rad2;
    measured.alternatives.clear();  // chosen once: no going back and forth
    JointResult again = estimator.solve(swapped, R_start);
    if (!again.ok || again.camera_link_chi2.size() != swapped.camera_links.size() ||
        again.camera_link_chi2[j] >= kCameraLinkOutlierChi2) {
      continue;
    }
    if (!best || again.chi2 < best->second.chi2) {
      best.emplace(static_cast<int>(a), std::move(again));
      *swapped_problem = std::move(swapped);
    }
  }
  return best;
}

}  // namespace

JointResult solveScreeningCameraLinks(const JointEstimator& estimator, JointProblem problem,
                                      const Eigen::Matrix3d& R_start) {
  JointResult joint = estimator.solve(problem, R_start);
  const std::size_t links = problem.camera_links.size();
  const std::size_t max_left_out = links / 3;
  std::vector<int> caller_index(links);  // of each link still in `problem`
  std::iota(caller_index.begin(), caller_index.end(), 0);
  std::vector<std::pair<int, double>> left_out;  // caller's index, chi-square when left out
  std::vector<int> alternative_used(links, -1);  // caller's indices
  bool swapped_any = false;
  while (joint.ok && joint.camera_link_chi2.size() == problem.camera_links.size()) {
    const auto worst =
        std::max_element(joint.camera_link_chi2.begin(), joint.camera_link_chi2.end());
    if (worst == joint.camera_link_chi2.end() || *worst < kCameraLinkOutlierChi2) break;
    const auto j = worst - joint.camera_link_chi2.begin();
    // A link whose other solution fits is measured by it (each link's alternatives are tried
    // once: a swapped link has none left, so the loop ends).
    JointProblem swapped;
    if (auto alternative = bestAlternative(estimator, problem, j, joint.R_cam_imu, &swapped)) {
      alternative_used[caller_index[j]] = alternative->first;
      swapped_any = true;
      problem = std::move(swapped);
      joint = std::move(alternative->second);
      continue;
    }
    if (left_out.size() >= max_left_out) break;
    JointProblem without = problem;
    without.camera_links.erase(without.camera_links.begin() + j);
    JointResult again = estimator.solve(without, joint.R_cam_imu);
    if (!again.ok) break;  // the last usable estimate stands
    left_out.emplace_back(caller_index[j], *worst);
    caller_index.erase(caller_index.begin() + j);
    problem = std::move(without);
    joint = std::move(again);
  }
  if (swapped_any) joint.camera_link_alternative_used = alternative_used;
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
