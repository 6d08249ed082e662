// Files written atomically: the contents go to a temporary file in the target's folder
// (`path + ".tmp"`), which is then renamed over the target, so that a reader never sees half a
// file and a failed write (no permission, disk full) leaves the previous file as it was. Every
// file the package writes for its user goes through it (result YAML, CSV, report, imu.yaml).
#pragma once

#include <string>

namespace camera_imu_alignment {

/// Writes `contents` to `path` atomically (temporary file, flushed to disk, renamed over `path`).
/// Throws InputError naming `path` and the reason (errno's text), ending "the previous file is
/// unchanged"; no temporary file is left behind.
void writeFileAtomically(const std::string& path, const std::string& contents);

/// Why writeFileAtomically(path, ...) would fail, "" when it would not: the folder is missing or is
/// not a folder, a file cannot be created in it (no permission, read-only file system: a probe file
/// is created there and removed), or `path` is itself a folder. For checking every output before a
/// long job; the message names the path.
std::string whyNotWritable(const std::string& path);

}  // namespace camera_imu_alignment
