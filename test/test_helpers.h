// Test helpers, the one home of what several tests need: random rotations, noise and rotation
// comparisons, independent of the library's own example generator and rotation math (tests build
// their truth themselves); the per-process temporary directory and text files; running a check as
// an unprivileged user. Running the tools:
// tool_runner.h; simulated runs through the pipeline: pipeline_simulation.h.
#pragma once

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>

#include "camera_imu_alignment/estimation/joint_result.h"
#include "camera_imu_alignment/solver/rotation_pair.h"

namespace camera_imu_alignment {
namespace test {

constexpr double kPiTest = 3.14159265358979323846;

/// The variance factor a joint estimate learned for the motion frames' camera orientation.
inline double cameraNoiseFactor(const JointResult& joint) {
  return joint.noise.variance_factor[static_cast<size_t>(NoiseKind::kCameraMotion)];
}
inline double toDeg(double rad) { return rad * 180.0 / kPiTest; }

/// Uniform random rotation (normalised Gaussian quaternion).
inline Eigen::Matrix3d randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  return q.normalized().toRotationMatrix();
}

inline Eigen::Vector3d randomUnitVector(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
}

/// Rotation by `angle` rad about `axis` (Eigen's AngleAxis, independent of the library's expSO3).
inline Eigen::Matrix3d axisAngle(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

/// Rotation vector uniformly distributed in the ball of radius `radius` (the paper's |v| < r
/// noise).
inline Eigen::Vector3d uniformBall(std::mt19937_64& rng, double radius) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(u(rng), u(rng), u(rng));
  } while (v.squaredNorm() > 1.0);
  return radius * v;
}

inline Eigen::Vector3d gaussianVector(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> g(0.0, sigma);
  return Eigen::Vector3d(g(rng), g(rng), g(rng));
}

inline Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& v) {
  const double a = v.norm();
  return a < 1e-15 ? Eigen::Matrix3d::Identity() : axisAngle(v / a, a);
}

/// Geodesic angle between two rotations (deg), via Eigen's AngleAxis.
inline double angleBetweenDeg(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& R2) {
  Eigen::AngleAxisd aa(Eigen::Matrix3d(R1.transpose() * R2));
  return toDeg(std::abs(aa.angle()));
}

/// Left error Log(R_est R_true^T) (rad, camera frame) via AngleAxis.
inline Eigen::Vector3d leftError(const Eigen::Matrix3d& R_est, const Eigen::Matrix3d& R_true) {
  Eigen::AngleAxisd aa(Eigen::Matrix3d(R_est * R_true.transpose()));
  return aa.axis() * aa.angle();
}

/// Noise-free pair for X from a given IMU rotation B.
inline RotationPair exactPair(const Eigen::Matrix3d& X, const Eigen::Matrix3d& B) {
  RotationPair p;
  p.B_imu = B;
  p.A_cam = X * B * X.transpose();
  return p;
}

/// J independent pairs with B uniformly random, and each side right-multiplied by Exp(v) with v
/// uniform in the ball of radius noise_rad (the paper's simulation).
inline RotationPairs paperPairs(std::mt19937_64& rng, const Eigen::Matrix3d& X, int J,
                                double noise_rad) {
  RotationPairs pairs;
  for (int j = 0; j < J; ++j) {
    RotationPair p = exactPair(X, randomRotation(rng));
    p.A_cam = p.A_cam * rotationFromVector(uniformBall(rng, noise_rad));
    p.B_imu = p.B_imu * rotationFromVector(uniformBall(rng, noise_rad));
    pairs.push_back(p);
  }
  return pairs;
}

/// A directory of this test process alone (other workspaces may run the same test at the same
/// time), removed at exit; ends with '/'.
inline const std::string& processTempDir() {
  struct TempDir {
    std::string path;
    TempDir() {
      std::string pattern = ::testing::TempDir() + "cia_test_XXXXXX";
      if (!mkdtemp(&pattern[0])) std::abort();
      path = pattern + "/";
    }
    ~TempDir() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const TempDir dir;
  return dir.path;
}

/// `name` in processTempDir().
inline std::string tempPath(const std::string& name) { return processTempDir() + name; }

/// The whole file (binary); "" when it cannot be read.
inline std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Writes `text` to tempPath(name) and returns that path.
inline std::string writeTempFile(const std::string& name, const std::string& text) {
  const std::string path = tempPath(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

/// Runs `body` as the unprivileged user nobody in a child process when we are root (root ignores
/// directory permissions), else directly. True when `body` returned true.
inline bool asUnprivilegedUser(const std::function<bool()>& body) {
  if (geteuid() != 0) return body();
  const pid_t child = fork();
  if (child == 0) {
    const bool ok = setgid(65534) == 0 && setuid(65534) == 0 && body();
    _exit(ok ? 0 : 1);
  }
  int status = 0;
  return child > 0 && waitpid(child, &status, 0) == child && WIFEXITED(status) &&
         WEXITSTATUS(status) == 0;
}

/// A folder the unprivileged user (asUnprivilegedUser) may enter and read but not write, under
/// /tmp (the per-process temporary folder is 0700: nobody could not reach it); removed by the
/// caller (chmod 0755 first).
inline std::string readOnlyFolder() {
  char pattern[] = "/tmp/cia_read_only_XXXXXX";
  if (!mkdtemp(pattern)) std::abort();
  chmod(pattern, 0555);
  return std::string(pattern) + "/";
}

#define EXPECT_ROTATION_NEAR_DEG(R1, R2, tol_deg) \
  EXPECT_LE(::camera_imu_alignment::test::angleBetweenDeg((R1), (R2)), (tol_deg))

}  // namespace test
}  // namespace camera_imu_alignment
