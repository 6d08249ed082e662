// solve_rotation: R_cam_imu from a pairs or poses CSV file (formats: doc/CONVENTIONS.md).
// Exit codes: 0 success; 2 bad input or usage; 3 not enough information (not observable).
#include <Eigen/Geometry>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "camera_imu_alignment/io/csv_io.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/solver/alignment_solver.h"
#include "camera_imu_alignment/solver/pose_window.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "cli_args.h"

namespace cia = camera_imu_alignment;

namespace {

using cia::kExitBadInput;
using cia::kExitNotEnoughInformation;
using cia::kExitOk;

const char* kUsage =
    "usage: solve_rotation (--pairs FILE.csv | --poses FILE.csv) [--method optimal|two_step]\n"
    "                      [--max-iterations N] [--output FILE.yaml] [--truth TRUTH.yaml]\n"
    "                      [--max-poses N] [--camera-frame NAME] [--imu-frame NAME]\n"
    "  --pairs FILE.csv     relative rotations qa_w..qa_z (camera A), qb_w..qb_z (IMU B)\n"
    "  --poses FILE.csv     stationary poses: stamp, cam_qw..cam_qz (q_target_cam),\n"
    "                       imu_qw..imu_qz (q_world_imu); all pairs of the poses are used\n"
    "  --method M           optimal (default: robust least squares on SO(3) started from the\n"
    "                       paper's two-step) or two_step (the paper's iteration alone)\n"
    "  --max-iterations N   iteration limit of the selected method (default 100 Gauss-Newton\n"
    "                       iterations per stage; 1000 for two_step)\n"
    "  --output FILE.yaml   write the result YAML there (default: standard output)\n"
    "  --truth TRUTH.yaml   a YAML with R_cam_imu to compare with (prints the error)\n"
    "  --max-poses N        use at most the last N poses (default 100)\n"
    "exit codes: 0 success, 2 bad input or usage, 3 not enough information: not observable (the\n"
    "message names the axis to rotate about), or the two-step settled on a rotation that does not\n"
    "fit the data\n"
    "file formats, frames and quaternion order: see doc/CONVENTIONS.md in the package\n";

void printSummary(const cia::PairSolveResult& r) {
  const Eigen::Matrix3d& R = r.R_cam_imu;
  Eigen::Quaterniond q(R);
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  std::cerr << std::fixed << std::setprecision(4);
  std::cerr << "R_cam_imu (p_cam = R_cam_imu * p_imu), method " << cia::toString(r.method) << ":\n"
            << "  quaternion xyzw: [" << q.x() << ", " << q.y() << ", " << q.z() << ", " << q.w()
            << "]\n"
            << "  " << cia::rollPitchYawText(R, 4) << "\n"
            << "  1-sigma about camera x/y/z (deg): [" << r.quality.std_dev_deg.transpose() << "]\n"
            << "  residual RMS (deg): " << r.quality.residual_rms_deg << ", inliers "
            << r.quality.num_inliers << "/" << r.quality.num_pairs << ", iterations "
            << r.iterations << (r.converged ? "" : " (not converged)") << "\n"
            << (r.method == cia::SolverMethod::kOptimal
                    ? "  the paper's two-step as the optimal estimator's start (at most its "
                      "start iterations; start used: " +
                          r.start + "): "
                    : "  paper's two-step: ")
            << (r.two_step.converged ? "converged in " : "stopped without converging after ")
            << r.two_step.iterations << " iterations, "
            << cia::rad2deg(cia::geodesicDistance(r.two_step.R_cam_imu_left, R))
            << " deg from this result\n";
}

int run(int argc, char** argv) {
  const cia::CliArgs args(argc, argv,
                          {"--pairs", "--poses", "--method", "--max-iterations", "--output",
                           "--truth", "--max-poses", "--camera-frame", "--imu-frame"},
                          {"--help", "-h"});
  if (args.has("--help") || args.has("-h")) {
    std::cout << kUsage;
    return kExitOk;
  }
  if (args.has("--pairs") == args.has("--poses")) {
    throw cia::UsageError("give exactly one of --pairs FILE.csv or --poses FILE.csv");
  }
  cia::SolverOptions options;
  if (args.has("--method") && !cia::parseSolverMethod(args.get("--method"), &options.method)) {
    throw cia::UsageError("--method must be optimal or two_step, got '" + args.get("--method") +
                          "'");
  }
  if (args.has("--max-iterations")) {
    const int n = static_cast<int>(args.getInt("--max-iterations", 100, 1, 1000000));
    options.optimal.max_iterations = n;
    options.two_step.max_iterations = n;
  }
  const long max_poses = args.getInt("--max-poses", 100, 2, 2000);
  std::optional<cia::StoredCalibration> truth;
  if (args.has("--truth")) truth = cia::readResultYaml(args.get("--truth"));

  cia::RotationPairs pairs;
  cia::ResultMetadata meta;
  meta.camera_frame = args.get("--camera-frame", meta.camera_frame);
  meta.imu_frame = args.get("--imu-frame", meta.imu_frame);
  if (args.has("--pairs")) {
    pairs = cia::readPairsCsv(args.get("--pairs"));
  } else {
    std::vector<cia::PoseOrientation> poses = cia::readPosesCsv(args.get("--poses"));
    if (static_cast<long>(poses.size()) > max_poses) {
      std::cerr << "warning: " << args.get("--poses") << " has " << poses.size()
                << " poses; using the last " << max_poses << " (--max-poses)\n";
      poses.erase(poses.begin(), poses.end() - max_poses);
    }
    meta.num_poses = static_cast<int>(poses.size());
    pairs = cia::makeAllPairs(poses);
    if (pairs.empty()) {
      std::cerr << "not enough information: " << args.get("--poses")
                << " has a single pose; record at least 3 poses rotated about two different axes\n";
      return kExitNotEnoughInformation;
    }
  }

  const cia::PairSolveResult result = cia::solveAlignment(pairs, options);
  if (result.status == cia::SolveStatus::kBadInput) {
    std::cerr << "error: " << result.message << "\n";
    return kExitBadInput;
  }
  if (args.has("--output")) {
    cia::writeResultYaml(args.get("--output"), result, meta);
  } else {
    std::cout << cia::resultToYaml(result, meta);
  }
  printSummary(result);
  if (truth) {
    const double err = cia::rad2deg(cia::geodesicDistance(result.R_cam_imu, truth->R_cam_imu));
    // The paper's two-step run alone (the optimal estimator's start stops after a few
    // iterations, so its value is not the two-step's answer).
    cia::SolverOptions alone = options;
    alone.method = cia::SolverMethod::kTwoStep;
    const cia::PairSolveResult two_step =
        options.method == cia::SolverMethod::kTwoStep ? result : cia::solveAlignment(pairs, alone);
    const double err_two_step =
        cia::rad2deg(cia::geodesicDistance(two_step.R_cam_imu, truth->R_cam_imu));
    std::cerr << "  error to the truth in " << args.get("--truth") << ": " << err
              << " deg (the paper's two-step alone: " << err_two_step << " deg, "
              << (two_step.two_step.converged ? "converged in " : "not converged after ")
              << two_step.two_step.iterations << " iterations)\n";
  }
  if (result.status == cia::SolveStatus::kNotObservable ||
      result.status == cia::SolveStatus::kPoorFit) {
    std::cerr << result.message << "\n";
    return kExitNotEnoughInformation;
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const cia::UsageError& e) {
    std::cerr << "solve_rotation: " << e.what() << "\n" << kUsage;
    return kExitBadInput;
  } catch (const cia::InputError& e) {
    std::cerr << "solve_rotation: bad input: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "solve_rotation: error: " << e.what() << "\n";
    return kExitBadInput;
  }
}
