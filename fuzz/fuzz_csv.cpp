// libFuzzer: the pairs and poses CSV readers. Any input must give rows or an InputError, never a
// crash, a hang or undefined behaviour; rows read must hold finite rotations.
#include <cstdint>

#include "camera_imu_alignment/io/csv_io.h"
#include "camera_imu_alignment/solver/rotation_math.h"
#include "fuzz_common.h"

namespace cia = camera_imu_alignment;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = cia::fuzz::writeInput(data, size, ".csv");
  try {
    for (const auto& p : cia::readPairsCsv(path)) {
      if (!cia::isRotationMatrix(p.A_cam, 1e-6) || !cia::isRotationMatrix(p.B_imu, 1e-6)) {
        __builtin_trap();  // a reader must never hand out a non-rotation
      }
    }
  } catch (const cia::InputError&) {
  }
  try {
    for (const auto& p : cia::readPosesCsv(path)) {
      if (!cia::isRotationMatrix(p.R_target_cam, 1e-6) ||
          !cia::isRotationMatrix(p.R_world_imu, 1e-6)) {
        __builtin_trap();
      }
    }
  } catch (const cia::InputError&) {
  }
  return 0;
}
