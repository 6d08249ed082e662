// The pipeline's settings' enum words and the joint estimate's settings as the pipeline uses them
// (pipeline_settings.h).
#include "camera_imu_alignment/config/pipeline_settings.h"

namespace camera_imu_alignment {

const char* toString(ImuOrientationSource source) {
  switch (source) {
    case ImuOrientationSource::kMagnetometer:
      return "magnetometer";
    case ImuOrientationSource::kMessage:
      return "message";
    case ImuOrientationSource::kJoint:
      return "joint";
    default:
      return "auto";
  }
}

bool usesJointEstimate(ImuOrientationSource source) {
  return source == ImuOrientationSource::kJoint || source == ImuOrientationSource::kMagnetometer;
}

bool parseImuOrientationSource(const std::string& text, ImuOrientationSource* source) {
  if (text == "joint") {
    *source = ImuOrientationSource::kJoint;
  } else if (text == "auto") {
    *source = ImuOrientationSource::kAuto;
  } else if (text == "magnetometer") {
    *source = ImuOrientationSource::kMagnetometer;
  } else if (text == "message") {
    *source = ImuOrientationSource::kMessage;
  } else {
    return false;
  }
  return true;
}

JointSettings jointSettingsOf(const PipelineSettings& settings) {
  JointSettings joint = settings.joint;
  joint.gravity_m_s2 = settings.stationary.gravity_m_s2;
  return joint;
}

}  // namespace camera_imu_alignment
