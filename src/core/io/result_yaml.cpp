#include "camera_imu_alignment/io/result_yaml.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

#include "camera_imu_alignment/io/atomic_file.h"
#include "camera_imu_alignment/io/csv_io.h"
#include "camera_imu_alignment/io/joint_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"

namespace camera_imu_alignment {
namespace {

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

/// R_cam_imu's quaternion and matrix (9 digits) of one file agree to about 1e-7 deg; a matrix
/// typed with 4 decimals to about 0.01 deg. Further apart, one of them was edited.
constexpr double kQuaternionMatrixToleranceDeg = 0.02;

std::string row(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out << std::setprecision(9) << "[" << v(0) << ", " << v(1) << ", " << v(2) << "]";
  return out.str();
}

std::string quaternionXyzw(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // canonical sign; q and -q are the same rotation
  std::ostringstream out;
  out << std::setprecision(12) << "[" << q.x() << ", " << q.y() << ", " << q.z() << ", " << q.w()
      << "]";
  return out.str();
}

void writeRotation(std::ostream& out, const std::string& name, const std::string& comment,
                   const Eigen::Matrix3d& R) {
  out << name << ":  # " << comment << "\n";
  out << "  quaternion_xyzw: " << quaternionXyzw(R) << "\n";
  out << "  matrix: [" << row(R.row(0)) << ", " << row(R.row(1)) << ", " << row(R.row(2)) << "]\n";
}

}  // namespace

std::string translationNotMeasuredReason(const AlignmentResult& r) {
  const char* keep = ": keep your measured translation";
  if (!r.joint || !r.joint->ok) return std::string("not measured (no joint estimate)") + keep;
  const JointResult& j = *r.joint;
  if (j.lever_arm_measured) return "";
  if (j.motion_nodes == 0) {
    return std::string(
               "not measured: rests only (the lever arm needs the camera's positions "
               "during motion)") +
           keep;
  }
  if (!j.lever_arm_in_model) {
    return std::string(
               "not measured: no camera positions during the motion (or "
               "motion_accel_link_s 0)") +
           keep;
  }
  std::ostringstream out;
  out << std::setprecision(2) << "not determined by the motion (1-sigma " << j.p_cam_imu_sigma_m(0)
      << ", " << j.p_cam_imu_sigma_m(1) << ", " << j.p_cam_imu_sigma_m(2) << " m, near its prior)"
      << keep;
  return out.str();
}

std::string resultToYaml(const AlignmentResult& r, const ResultMetadata& meta) {
  const Eigen::Matrix3d& R = r.R_cam_imu;
  const SolutionQuality& q = r.quality;
  std::ostringstream out;
  out << std::setprecision(6);
  out << "camera_frame: " << quoted(meta.camera_frame) << "  # the camera's tf frame\n";
  out << "imu_frame: " << quoted(meta.imu_frame) << "  # the IMU's tf frame\n";
  if (meta.verdict) {
    out << "verdict:  # the quality gates' verdict it was written under\n";
    out << "  passed: " << (meta.verdict->passed ? "true" : "false") << "\n";
    out << "  forced: " << (meta.verdict->forced ? "true" : "false")
        << "  # written on request (calibrate_bag --force, ~calibrate force) although it failed\n";
    out << "  text: " << quoted(meta.verdict->text) << "\n";
  }
  writeRotation(out, "R_cam_imu", "p_cam = R_cam_imu * p_imu", R);
  // The translation where the motion measured it (the translation block says whether).
  const bool measured = r.joint && r.joint->ok && r.joint->lever_arm_measured;
  const Eigen::Vector3d t = measured ? r.joint->p_cam_imu_m : Eigen::Vector3d::Zero();
  out << "T_cam_imu:  # Kalibr camchain-imucam convention; translation: see the translation "
         "block\n";
  for (int i = 0; i < 3; ++i) {
    out << "  - [" << std::setprecision(9) << R(i, 0) << ", " << R(i, 1) << ", " << R(i, 2) << ", "
        << (measured ? t(i) : 0.0) << "]\n";
  }
  out << "  - [0.0, 0.0, 0.0, 1.0]\n" << std::setprecision(6);
  out << "translation:  # T_cam_imu's: the IMU's position in the camera frame (m)\n";
  out << "  measured: " << (measured ? "true" : "false") << "\n";
  if (measured) {
    out << std::setprecision(9) << "  p_cam_imu_m: " << row(t) << "\n"
        << "  sigma_m: " << row(r.joint->p_cam_imu_sigma_m) << "  # 1-sigma per camera axis\n"
        << std::setprecision(6)
        << "  source: \"the accelerometer during motion against the camera's positions\"\n";
  } else {
    out << "  source: " << quoted(translationNotMeasuredReason(r)) << "\n";
  }
  if (r.joint && r.joint->ok && r.joint->timeshift_estimated) {
    out << std::setprecision(9) << "timeshift_cam_imu_s: " << r.joint->timeshift_cam_imu_s
        << "  # Kalibr's timeshift_cam_imu: t_imu = t_cam + timeshift_cam_imu_s\n"
        << "timeshift_cam_imu_sigma_s: " << r.joint->timeshift_sigma_s << "  # 1-sigma\n"
        << std::setprecision(6);
  }
  writeRotation(out, "R_imu_cam", "p_imu = R_imu_cam * p_cam (OpenVINS / VINS-Mono direction)",
                R.transpose());
  out << "quality:\n";
  out << "  observable: " << (q.observable ? "true" : "false") << "\n";
  out << "  num_poses: " << meta.num_poses << "\n";
  out << "  num_pairs: " << q.num_pairs << "\n";
  out << "  num_inliers: " << q.num_inliers << "\n";
  out << "  residual_rms_deg: " << q.residual_rms_deg << "\n";
  out << "  std_dev_deg: " << row(q.std_dev_deg) << "  # 1-sigma about the camera x, y, z axes\n";
  out << "  iterations: " << r.iterations << "\n";
  out << "  converged: " << (r.converged ? "true" : "false") << "\n";
  out << "  observability: " << q.observability << "  # 0 single axis .. 1 all axes evenly\n";
  out << "  weakest_excitation_deg: " << q.weakest_excitation_deg << "\n";
  out << "  weak_axis_cam: " << row(q.weak_axis_cam) << "  # least-constrained direction\n";
  out << "  excite_axis_cam: " << row(q.excite_axis_cam) << "  # rotate about this to improve\n";
  out << "  message: " << quoted(r.message) << "\n";
  out << "  pair_residuals_deg: [";
  for (size_t j = 0; j < q.pairs.size(); ++j) out << (j ? ", " : "") << q.pairs[j].residual_deg;
  out << "]\n";
  out << "  rejected_pairs:";
  bool any_rejected = false;
  for (size_t j = 0; j < q.pairs.size(); ++j) {
    if (q.pairs[j].inlier) continue;
    out << "\n    - {index: " << j << ", reason: " << quoted(q.pairs[j].rejection) << "}";
    any_rejected = true;
  }
  out << (any_rejected ? "\n" : " []\n");
  out << "solver:\n";
  out << "  method: " << toString(r.method) << "\n";
  out << "  start: " << r.start << "\n";
  out << "  two_step:  # the paper's iteration, run at every solve\n";
  out << "    converged: " << (r.two_step.converged ? "true" : "false") << "\n";
  out << "    iterations: " << r.two_step.iterations << "\n";
  out << "    R_cam_imu_left_quaternion_xyzw: " << quaternionXyzw(r.two_step.R_cam_imu_left)
      << "\n";
  out << "    R_cam_imu_right_quaternion_xyzw: " << quaternionXyzw(r.two_step.R_cam_imu_right)
      << "\n";
  out << "    difference_to_result_deg: " << rad2deg(geodesicDistance(r.two_step.R_cam_imu_left, R))
      << "\n";
  if (r.joint) out << jointToYaml(*r.joint);
  return out.str();
}

void writeResultYaml(const std::string& path, const AlignmentResult& result,
                     const ResultMetadata& meta) {
  // A failed write (disk full, no permission) leaves the previous calibration as it was.
  writeFileAtomically(path, resultToYaml(result, meta));
}

StoredCalibration readResultYaml(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path + ": cannot open file");
  } catch (const YAML::Exception& e) {
    throw InputError(path + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  StoredCalibration stored;
  try {
    if (root["camera_frame"]) stored.camera_frame = root["camera_frame"].as<std::string>();
    if (root["imu_frame"]) stored.imu_frame = root["imu_frame"].as<std::string>();
    const YAML::Node rot = root["R_cam_imu"];
    if (!rot) throw InputError(path + ": no R_cam_imu key");
    std::optional<Eigen::Matrix3d> from_quaternion, from_matrix;
    if (rot["quaternion_xyzw"]) {
      const auto v = rot["quaternion_xyzw"].as<std::vector<double>>();
      if (v.size() != 4) throw InputError(path + ": R_cam_imu.quaternion_xyzw needs 4 numbers");
      Eigen::Quaterniond q(v[3], v[0], v[1], v[2]);
      if (!q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > kQuaternionNormTolerance) {
        throw InputError(path + ": R_cam_imu.quaternion_xyzw is not a unit quaternion");
      }
      from_quaternion = q.normalized().toRotationMatrix();
    }
    if (rot["matrix"]) {
      const auto m = rot["matrix"].as<std::vector<std::vector<double>>>();
      if (m.size() != 3) throw InputError(path + ": R_cam_imu.matrix needs 3 rows");
      Eigen::Matrix3d R;
      for (int i = 0; i < 3; ++i) {
        if (m[i].size() != 3) throw InputError(path + ": R_cam_imu.matrix needs 3 columns");
        for (int k = 0; k < 3; ++k) R(i, k) = m[i][k];
      }
      if (!isRotationMatrix(R, 1e-4)) {
        throw InputError(path + ": R_cam_imu.matrix is not a rotation matrix");
      }
      from_matrix = projectToSO3(R);
    }
    if (!from_quaternion && !from_matrix) {
      throw InputError(path + ": R_cam_imu has neither quaternion_xyzw nor matrix");
    }
    // Both written (as this package writes them): a hand edit of one of them is not read silently.
    if (from_quaternion && from_matrix) {
      const double apart_deg = rad2deg(geodesicDistance(*from_quaternion, *from_matrix));
      if (apart_deg > kQuaternionMatrixToleranceDeg) {
        std::ostringstream out;
        out << path << ": R_cam_imu.quaternion_xyzw and R_cam_imu.matrix are " << apart_deg
            << " deg apart (one was edited?): make them agree, or delete one of them";
        throw InputError(out.str());
      }
    }
    stored.R_cam_imu = from_quaternion ? *from_quaternion : *from_matrix;
    const YAML::Node quality = root["quality"];
    if (quality && quality["std_dev_deg"]) {
      const auto v = quality["std_dev_deg"].as<std::vector<double>>();
      if (v.size() == 3 && std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) &&
          v[0] >= 0 && v[1] >= 0 && v[2] >= 0) {
        stored.std_dev_deg = Eigen::Vector3d(v[0], v[1], v[2]);
      }
    }
    if (quality && quality["num_poses"]) stored.num_poses = quality["num_poses"].as<int>();
    const YAML::Node verdict = root["verdict"];
    if (verdict) {
      if (!verdict.IsMap() || !verdict["passed"]) {
        throw InputError(path + ": verdict needs the key passed (true or false)");
      }
      ResultVerdict v;
      v.passed = verdict["passed"].as<bool>();
      if (verdict["forced"]) v.forced = verdict["forced"].as<bool>();
      if (verdict["text"]) v.text = verdict["text"].as<std::string>();
      stored.verdict = v;
    }
  } catch (const YAML::Exception& e) {
    throw InputError(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  return stored;
}

std::string failedVerdictNote(const StoredCalibration& stored, const std::string& path) {
  if (!stored.verdict || stored.verdict->passed) return "";
  std::string why = stored.verdict->text;
  if (why.rfind("FAILED: ", 0) == 0) why.erase(0, 8);
  return path + " holds an estimate that FAILED its quality gates" +
         (stored.verdict->forced ? std::string(", written on request (force)") : std::string()) +
         (why.empty() ? std::string() : ": " + why);
}

std::optional<StoredCalibration> loadSavedCalibration(const std::string& path,
                                                      std::string* warning) {
  warning->clear();
  std::error_code ec;
  if (path.empty() || !std::filesystem::exists(path, ec)) return std::nullopt;
  try {
    return readResultYaml(path);
  } catch (const std::exception& e) {
    const std::string aside = path + ".bad";
    std::filesystem::rename(path, aside, ec);
    *warning = std::string(e.what()) + (ec ? "; could not move it aside: " + ec.message()
                                           : "; moved aside to " + aside + ", starting fresh");
    return std::nullopt;
  }
}

}  // namespace camera_imu_alignment
