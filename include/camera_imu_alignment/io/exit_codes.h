// The exit codes of the command-line tools (doc/CONVENTIONS.md, "Exit codes of the command-line
// tools"): an interface scripts depend on, defined once here.
#pragma once

namespace camera_imu_alignment {

constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;              ///< bad input or usage; the message names the culprit
constexpr int kExitNotEnoughInformation = 3;  ///< not observable, or the two-step did not fit
/// The estimate exists but fails the nodelet's quality gates (inconsistent data, 1-sigma too
/// large) or the mount changed during the recording: calibrate_bag prints it and writes it only
/// when forced (--force), marked FAILED.
constexpr int kExitQualityGate = 4;

}  // namespace camera_imu_alignment
