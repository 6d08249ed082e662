// libFuzzer: the YAML readers (pipeline/nodelet settings, Kalibr target, result file). Any input
// must parse or throw InputError, never crash; what parses must be usable.
#include <cmath>
#include <cstdint>
#include <string>

#include "camera_imu_alignment/common/input_error.h"
#include "camera_imu_alignment/config/pipeline_config.h"
#include "camera_imu_alignment/io/result_yaml.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "camera_imu_alignment/vision/target_description.h"
#include "fuzz_common.h"

namespace cia = camera_imu_alignment;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    cia::PipelineSettings settings;
    cia::parsePipelineConfig(text, "fuzz", &settings);
    if (!settings.validate().empty()) __builtin_trap();  // accepted settings are valid
  } catch (const cia::InputError&) {
  }
  try {
    const cia::TargetDescription target = cia::parseTargetYaml(text, "fuzz");
    const int n = target.numPoints();
    if (n <= 0 || n > 1000000) __builtin_trap();
    if (!target.point(n - 1).allFinite()) __builtin_trap();
  } catch (const cia::InputError&) {
  }
  try {
    const cia::StoredCalibration c =
        cia::readResultYaml(cia::fuzz::writeInput(data, size, ".yaml"));
    if (!cia::isRotationMatrix(c.R_cam_imu, 1e-6)) __builtin_trap();
  } catch (const cia::InputError&) {
  }
  return 0;
}
