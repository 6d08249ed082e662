// ROS messages -> the core library's plain structs. The only place where sensor_msgs meet the
// core; used by calibrate_bag and the nodelet, so both feed the pipeline identically.
// Nothing here validates values (NaN, zero vectors, stamps): the pipeline does, and counts.
#pragma once

#include <geometry_msgs/Quaternion.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "camera_imu_alignment/inertial/inertial_samples.h"
#include "camera_imu_alignment/vision/camera_model.h"

namespace camera_imu_alignment {

/// Header stamp (s), gyro (rad/s), accelerometer (m/s^2), and the orientation when the message
/// carries one (orientation_covariance[0] != -1 and a non-zero quaternion).
ImuSample toImuSample(const sensor_msgs::Imu& msg);
/// Header stamp (s) and field (as sent; nominally tesla).
MagneticSample toMagneticSample(const sensor_msgs::MagneticField& msg);
/// K, D, distortion_model, size; false with `error` when unusable (zero K, wrong D length, ...).
bool toCameraIntrinsics(const sensor_msgs::CameraInfo& msg, CameraIntrinsics* intrinsics,
                        std::string* error);
/// Any image to grey through cv_bridge: every encoding of sensor_msgs/image_encodings with a colour
/// model (mono8/16, rgb/bgr(a)8/16, the Bayer patterns 8 and 16 bit, yuv422) and one-channel
/// generic ones (8UC1, 16UC1, 32FC1, ...), either byte order. Deeper than 8 bits is stretched by
/// the image's actual range (a 12-bit camera's mono16 up to 4095 becomes 0..255; 8-bit-range data
/// in a 16-bit type keeps its values; float images from darkest to brightest). False with `error`
/// for an unknown encoding, a multi-channel generic one (8UC3: no channel order) or when
/// step/size/data length disagree.
bool toMono8(const sensor_msgs::Image& msg, cv::Mat* mono8, std::string* error);
/// The rotation of a unit quaternion (norm within 1e-3 of 1, renormalised); nullopt for anything
/// else (NaN, zero, unnormalised), which callers count as non_finite.
std::optional<Eigen::Matrix3d> toRotation(const geometry_msgs::Quaternion& q);
/// A rotation matrix as a quaternion message.
geometry_msgs::Quaternion toQuaternionMsg(const Eigen::Matrix3d& R);
/// JPEG/PNG payload of a CompressedImage (any format cv::imdecode reads), decoded by cv_bridge and
/// made grey as toMono8(Image) does.
bool toMono8(const sensor_msgs::CompressedImage& msg, cv::Mat* mono8, std::string* error);

}  // namespace camera_imu_alignment
