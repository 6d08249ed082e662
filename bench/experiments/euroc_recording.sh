#!/usr/bin/env bash
# The real EuRoC imu_april recording (cam1, ../shared/realdata/euroc_imu_april_cam1) through
# calibrate_bag: the defaults, the clips --end 8/20/40 and each imu_prior_* key x10 and /10, each
# against the published rotation, with its wall time. Run by hand after a build (scripts/test or
# scripts/demo); feeds BENCHMARKS.md ("Real recordings"). Usage: bench/experiments/euroc_recording.sh
# [REALDATA_DIR]
set -euo pipefail
source "$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)/scripts/common.sh"
cia_source_workspace
DATA="${1:-${REPO_ROOT}/../shared/realdata}/euroc_imu_april_cam1"
BAG="${DATA}/imu_april_cam1.bag"
[ -f "${BAG}" ] || { echo "no ${BAG}" >&2; exit 2; }
TMP="$(mktemp -d)"
trap 'rm -rf "${TMP}"' EXIT
printf 'R_cam_imu:\n  quaternion_xyzw: [0.002550237, -0.015323927, -0.702486686, 0.711527322]\n' \
  >"${TMP}/truth.yaml"
run() {  # run LABEL [calibrate_bag options...]
  local label="$1" start end rc
  shift
  start=$(date +%s.%N)
  set +e
  rosrun camera_imu_alignment calibrate_bag --bag "${BAG}" --truth "${TMP}/truth.yaml" --quiet "$@" \
    >"${TMP}/out.txt" 2>"${TMP}/err.txt"
  rc=$?
  set -e
  end=$(date +%s.%N)
  printf '%-48s exit %d, %5.2f s | %s | %s | %s\n' "${label}" "${rc}" \
    "$(echo "${end} - ${start}" | bc)" \
    "$(grep -o 'error [0-9.]* deg, about.*1-sigma' "${TMP}/out.txt" | head -1)" \
    "$(grep -o 'timeshift_cam_imu_s: [-0-9.]* s +- [0-9.]*' "${TMP}/out.txt" | head -1)" \
    "$(grep -o 'mount changed[^;,]*' "${TMP}/out.txt" "${TMP}/err.txt" | head -1)"
}
run "defaults"
for end in 8 20 40; do run "--end ${end}" --end "${end}"; done
while read -r key value; do
  for factor in 10 0.1; do
    printf '%s: %s\n' "${key}" "$(echo "${value} * ${factor}" | bc -l)" >"${TMP}/prior.yaml"
    run "${key} x${factor}" --config "${TMP}/prior.yaml"
  done
done <<'PRIORS'
imu_prior_gyro_scale 0.015
imu_prior_gyro_cross_axis 0.01
imu_prior_gyro_bias_walk_rad_s_sqrt_s 0.0001
imu_prior_accel_scale 0.01
imu_prior_accel_cross_axis 0.01
imu_prior_accel_bias_m_s2 0.2
imu_prior_accel_bias_walk_m_s2_sqrt_s 0.001
PRIORS
