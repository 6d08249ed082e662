// generate_example: stationary poses of a simulated camera + IMU rig with a known R_cam_imu
// (poses CSV, optional pairs CSV, truth YAML). The demo's built-in data.
#include <Eigen/Geometry>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "camera_imu_alignment/io/csv_io.h"
#include "camera_imu_alignment/solver/example_data.h"
#include "camera_imu_alignment/solver/pose_window.h"
#include "cli_args.h"

namespace cia = camera_imu_alignment;

namespace {

const char* kUsage =
    "usage: generate_example --poses-out POSES.csv --truth-out TRUTH.yaml [--pairs-out PAIRS.csv]\n"
    "                        [--seed N] [--num-poses N] [--camera-noise-deg X] [--imu-noise-deg "
    "X]\n"
    "  Writes stationary poses (q_target_cam, q_world_imu) of a rig with a random R_cam_imu, and "
    "the\n"
    "  truth. Noise is Gaussian per axis (defaults 0.1 deg camera, 0.5 deg IMU); 12 poses.\n";

void writeTruth(const std::string& path, const cia::ExampleData& data,
                const cia::ExampleOptions& o) {
  Eigen::Quaterniond q(data.R_cam_imu);
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  std::ofstream out(path);
  if (!out) throw cia::InputError(path + ": cannot write file");
  out << std::setprecision(15);
  out << "# Ground truth of generate_example\ncamera_frame: camera_optical_frame\nimu_frame: "
         "imu_link\n"
      << "R_cam_imu:  # p_cam = R_cam_imu * p_imu\n"
      << "  quaternion_xyzw: [" << q.x() << ", " << q.y() << ", " << q.z() << ", " << q.w() << "]\n"
      << "  matrix: [";
  for (int i = 0; i < 3; ++i) {
    out << (i ? ", " : "") << "[" << data.R_cam_imu(i, 0) << ", " << data.R_cam_imu(i, 1) << ", "
        << data.R_cam_imu(i, 2) << "]";
  }
  out << "]\nseed: " << o.seed << "\nnum_poses: " << o.num_poses
      << "\ncamera_noise_deg: " << o.camera_noise_deg << "\nimu_noise_deg: " << o.imu_noise_deg
      << "\n";
  if (!out) throw cia::InputError(path + ": write error");
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const cia::CliArgs args(argc, argv,
                            {"--poses-out", "--truth-out", "--pairs-out", "--seed", "--num-poses",
                             "--camera-noise-deg", "--imu-noise-deg"},
                            {"--help", "-h"});
    if (args.has("--help") || args.has("-h")) {
      std::cout << kUsage;
      return 0;
    }
    if (!args.has("--poses-out") || !args.has("--truth-out")) {
      throw cia::UsageError("--poses-out and --truth-out are required");
    }
    cia::ExampleOptions o;
    o.seed = static_cast<unsigned int>(args.getInt("--seed", o.seed, 0, 4294967295L));
    o.num_poses = static_cast<int>(args.getInt("--num-poses", o.num_poses, 2, 2000));
    o.camera_noise_deg = args.getDouble("--camera-noise-deg", o.camera_noise_deg, 0.0, 30.0);
    o.imu_noise_deg = args.getDouble("--imu-noise-deg", o.imu_noise_deg, 0.0, 30.0);
    const cia::ExampleData data = cia::generateExample(o);
    cia::writePosesCsv(args.get("--poses-out"), data.poses);
    if (args.has("--pairs-out"))
      cia::writePairsCsv(args.get("--pairs-out"), cia::makeAllPairs(data.poses));
    writeTruth(args.get("--truth-out"), data, o);
    return 0;
  } catch (const cia::UsageError& e) {
    std::cerr << "generate_example: " << e.what() << "\n" << kUsage;
    return cia::kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "generate_example: " << e.what() << "\n";
    return cia::kExitBadInput;
  }
}
