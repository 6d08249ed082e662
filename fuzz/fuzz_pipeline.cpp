// libFuzzer: the product's input path, ROS messages -> MessageInput -> OnlineCalibrator (solving
// on the caller's thread, as calibrate_bag does). The input is read as a stream of records: a type
// byte, a stamp and the message's fields taken raw from the bytes (NaN, Inf, huge and denormal
// values included): Imu (with or without an orientation), MagneticField, a given camera pose
// (PoseStamped), Image (small, any encoding name, data possibly short), CompressedImage (bytes
// decoded by OpenCV) and CameraInfo (any K, D length and distortion model). Nothing may crash or
// hang; every estimate and what is broadcast must be finite.
#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>
#include <sensor_msgs/image_encodings.h>

#include <cstdint>
#include <cstring>
#include <string>

#include "camera_imu_alignment/online/online_calibrator.h"
#include "camera_imu_alignment/ros/message_input.h"
#include "camera_imu_alignment/vision/target_description.h"

namespace cia = camera_imu_alignment;

namespace {

struct Reader {
  const std::uint8_t* data;
  std::size_t size, pos = 0;
  bool more() const { return pos < size; }
  std::uint8_t byte() { return pos < size ? data[pos++] : 0; }
  std::uint32_t u32() {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | byte();
    return v;
  }
  double number() {
    double v = 0.0;
    if (pos + sizeof(double) <= size) std::memcpy(&v, data + pos, sizeof(double));
    pos += sizeof(double);
    return v;
  }
  /// Up to `max` raw bytes (fewer at the end of the input).
  std::vector<std::uint8_t> bytes(std::size_t max) {
    const std::size_t n = std::min<std::size_t>(byte() % (max + 1), size - std::min(pos, size));
    std::vector<std::uint8_t> out(data + pos, data + pos + n);
    pos += n;
    return out;
  }
  /// A header: a stamp (seconds from the byte stream, possibly zero) and a frame id from a list.
  std_msgs::Header header() {
    static const char* const kFrames[] = {"imu", "/imu", "mag", "", "camera"};
    std_msgs::Header h;
    h.stamp.sec = u32() % 100000;  // within a day: stamps near each other happen
    h.stamp.nsec = u32() % 1000000000u;
    h.frame_id = kFrames[byte() % 5];
    return h;
  }
};

template <typename Vector>
void fill(Reader& in, Vector* v) {
  v->x = in.number();
  v->y = in.number();
  v->z = in.number();
}

void fillQuaternion(Reader& in, geometry_msgs::Quaternion* q) {
  q->x = in.number();
  q->y = in.number();
  q->z = in.number();
  q->w = in.number();
}

void checkFinite(const cia::AlignmentResult& result) {
  if (result.status == cia::SolveStatus::kOk && !result.R_cam_imu.allFinite()) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const cia::TargetDescription target = cia::parseTargetYaml(
      "target_type: checkerboard\ntargetCols: 4\ntargetRows: 3\nrowSpacingMeters: 0.04\n"
      "colSpacingMeters: 0.04\n",
      "fuzz");
  static const std::string kEncodings[] = {sensor_msgs::image_encodings::MONO8,
                                           sensor_msgs::image_encodings::MONO16,
                                           sensor_msgs::image_encodings::BGR8,
                                           sensor_msgs::image_encodings::RGBA8,
                                           sensor_msgs::image_encodings::BAYER_RGGB8,
                                           sensor_msgs::image_encodings::TYPE_32FC1,
                                           "yuv422",
                                           "no such encoding"};
  static const char* const kModels[] = {"plumb_bob", "equidistant", "rational_polynomial", "",
                                        "fisheye?"};
  cia::PipelineSettings settings;
  settings.min_poses_to_solve = 2;
  cia::OnlineSettings online;
  online.threaded = false;
  online.min_poses = 2;
  cia::OnlineCallbacks callbacks;
  callbacks.on_estimate = [](const cia::EstimateEvent& e) { checkFinite(e.result); };
  callbacks.on_broadcast = [](const cia::BroadcastEstimate& b) {
    if (!b.R_cam_imu.allFinite()) __builtin_trap();
  };
  cia::OnlineCalibrator calibrator(target, settings, online, callbacks);
  cia::MessageInput input(&calibrator);
  Reader in{data, size};
  while (in.more()) {
    const std::uint8_t type = in.byte() % 6;
    if (type == 0) {
      sensor_msgs::Imu msg;
      msg.header = in.header();
      fill(in, &msg.angular_velocity);
      fill(in, &msg.linear_acceleration);
      if (in.byte() % 2) {
        fillQuaternion(in, &msg.orientation);
      } else {
        msg.orientation_covariance[0] = -1.0;  // no orientation
      }
      input.addImu(msg);
    } else if (type == 1) {
      sensor_msgs::MagneticField msg;
      msg.header = in.header();
      fill(in, &msg.magnetic_field);
      input.addMagnetic(msg);
    } else if (type == 2) {
      geometry_msgs::PoseStamped msg;
      msg.header = in.header();
      fill(in, &msg.pose.position);
      fillQuaternion(in, &msg.pose.orientation);
      input.addCameraPose(msg);
    } else if (type == 3) {
      sensor_msgs::Image msg;
      msg.header = in.header();
      msg.width = in.byte() % 40;
      msg.height = in.byte() % 30;
      msg.encoding = kEncodings[in.byte() % 8];
      msg.is_bigendian = in.byte() % 2;
      msg.step = msg.width * (1 + in.byte() % 4);
      const std::uint8_t fill_value = in.byte();
      msg.data.assign(static_cast<std::size_t>(msg.step) * msg.height, fill_value);
      if (in.byte() % 4 == 0 && !msg.data.empty()) msg.data.resize(msg.data.size() / 2);  // short
      input.addImage(msg);
    } else if (type == 4) {
      sensor_msgs::CompressedImage msg;
      msg.header = in.header();
      msg.format = in.byte() % 2 ? "png" : "jpeg";
      msg.data = in.bytes(200);
      input.addImage(msg);
    } else {
      sensor_msgs::CameraInfo msg;
      msg.header = in.header();
      msg.width = in.byte() % 64;
      msg.height = in.byte() % 48;
      msg.distortion_model = kModels[in.byte() % 5];
      msg.D.resize(in.byte() % 9);
      for (double& d : msg.D) d = in.number();
      for (double& k : msg.K) k = in.number();
      input.setCameraInfo(msg);
    }
  }
  calibrator.finish();
  const cia::CalibrateOutcome outcome = calibrator.calibrateNow(false);
  checkFinite(outcome.result);
  return 0;
}
