// Shared by the libFuzzer targets (scripts/fuzz): the input written to a per-process file for the
// readers that take a path.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace camera_imu_alignment {
namespace fuzz {

inline std::string writeInput(const std::uint8_t* data, std::size_t size, const char* suffix) {
  const std::string path = "/tmp/cia_fuzz_" + std::to_string(getpid()) + suffix;
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    if (size > 0) std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  return path;
}

}  // namespace fuzz
}  // namespace camera_imu_alignment
