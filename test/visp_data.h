// ViSP's Franka eye-in-hand data in CIA_REALDATA_DIR (README there): the 9 x 6 chessboard, the
// Realsense intrinsics ViSP states, the flange pose files and ViSP's own hand-eye estimate. Shared
// by the tests that read it (test_target_detection, test_visp_recording); each skips when the
// directory is absent. The including test defines CIA_REALDATA_DIR (test/CMakeLists.txt).
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/camera_model.h"
#include "camera_imu_alignment/vision/target_description.h"
#include "camera_imu_alignment/vision/target_detector.h"

namespace camera_imu_alignment {
namespace test {

inline std::string vispDir() { return std::string(CIA_REALDATA_DIR) + "/visp_franka_eye_in_hand"; }

/// chessboard-data.txt: 9 x 6 inner corners, 0.0236 m squares.
inline TargetDescription vispBoard() {
  TargetDescription board;
  board.type = TargetDescription::Type::kCheckerboard;
  board.cols = 9;
  board.rows = 6;
  board.row_spacing_m = board.col_spacing_m = 0.0236;
  return board;
}

/// franka_camera.xml: 640 x 480, px py u0 v0, no distortion. False (with `error`) if refused.
inline bool vispIntrinsics(CameraIntrinsics* intrinsics, std::string* error) {
  const double K[9] = {607.5931, 0, 323.4628, 0, 607.5750, 243.2553, 0, 0, 1};
  return CameraIntrinsics::fromCameraInfo(640, 480, K, "", {}, intrinsics, error);
}

/// A flange pose file (franka_pose_rPe_N.yaml: rows 6, data [[tx], [ty], [tz], [tux], [tuy],
/// [tuz]]) -> R_base_flange (p_base = R(theta u) p_flange + t); false when unreadable.
inline bool readVispFlangeRotation(const std::string& path, Eigen::Matrix3d* R) {
  try {
    const YAML::Node data = YAML::LoadFile(path)["data"];
    if (!data || data.size() != 6) return false;
    *R = expSO3(
        Eigen::Vector3d(data[3][0].as<double>(), data[4][0].as<double>(), data[5][0].as<double>()));
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

/// ViSP's board and intrinsics with the board found in each of the 8 images (franka_image-N.png).
struct VispViews {
  TargetDescription board = vispBoard();
  CameraIntrinsics intrinsics;
  std::vector<TargetObservation> observations;  ///< image N at N - 1
};

/// Loads the views; false (with `error`: the image or the setting) when an image is unreadable
/// or its board is not found.
inline bool loadVispViews(VispViews* views, std::string* error) {
  if (!vispIntrinsics(&views->intrinsics, error)) return false;
  const TargetDetector detector(views->board);
  for (int i = 1; i <= 8; ++i) {
    const std::string path = vispDir() + "/franka_image-" + std::to_string(i) + ".png";
    const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
    TargetObservation observation;
    if (image.empty() || !detector.detect(image, &observation)) {
      *error = path + ": " + (image.empty() ? "unreadable" : "board not found");
      return false;
    }
    views->observations.push_back(observation);
  }
  return true;
}

/// ViSP's published eMc rotation (p_flange = eMc p_cam) transposed: R_cam_imu with the flange as
/// the IMU.
inline Eigen::Matrix3d vispCameraImu() {
  Eigen::Matrix3d R_imu_cam;
  R_imu_cam << -0.0110121, -0.999915, 0.0069391, 0.999929, -0.0109794, 0.00473584, -0.00465925,
      0.00699075, 0.999965;
  return projectToSO3(R_imu_cam).transpose();
}

}  // namespace test
}  // namespace camera_imu_alignment
