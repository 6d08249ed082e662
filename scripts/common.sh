#!/usr/bin/env bash
# Shared by scripts/demo, scripts/test and scripts/bench (sourced, not run): installs the Debian
# packages this package needs, lays out the git-ignored catkin workspace .ws/ (whose
# src/camera_imu_alignment links to the repository's files) and builds it with catkin_make -j2.

REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WS="${REPO_ROOT}/.ws"
mkdir -p "${WS}"  # the scripts log into it before the first build

# Debian's catkin and pluginlib need Debian's own python3 first on PATH (a pyenv python breaks the
# configure step: "No module named catkin_pkg").
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:${PATH}"
export ROS_HOSTNAME=localhost
export ROS_HOME="${WS}/ros_home"

CIA_PACKAGES=(
  build-essential cmake catkin ros-base-dev rosbash python3-rostest python3-rosbag
  libeigen3-dev libboost-dev libceres-dev libopencv-dev libopencv-contrib-dev libyaml-cpp-dev libgtest-dev libbenchmark-dev
  librosbag-dev libsensor-msgs-dev libstd-msgs-dev libgeometry-msgs-dev libstd-srvs-dev
  libnodelet-dev libimage-transport-dev libtf2-dev libtf2-msgs-dev libtf2-ros-dev
  libdiagnostic-updater-dev libdiagnostic-msgs-dev tf2-tools libcv-bridge-dev libtf2-eigen-dev
  python3-std-srvs python3-diagnostic-msgs
  librviz-dev rviz qtbase5-dev
  catkin-lint clang-format
)

cia_log() { echo "[camera_imu_alignment] $*" >&2; }

cia_install_packages() {
  local missing=() pkg
  for pkg in "${CIA_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "${pkg}" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("${pkg}")
    fi
  done
  if ((${#missing[@]} == 0)); then
    return 0
  fi
  cia_log "installing missing Debian packages: ${missing[*]}"
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then sudo=(sudo); fi
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
}

# .ws/src/camera_imu_alignment is a real directory of links to the repository's top-level entries,
# never to .ws itself: a link to the whole repository would make .ws contain itself, and rosrun's
# `find -L` would report a file-system loop on every call.
cia_setup_workspace() {
  local pkg="${WS}/src/camera_imu_alignment" entry
  mkdir -p "${WS}/src" "${ROS_HOME}"
  if [ -L "${pkg}" ]; then rm -f "${pkg}"; fi
  mkdir -p "${pkg}"
  find "${pkg}" -maxdepth 1 -type l -delete
  for entry in "${REPO_ROOT}"/* "${REPO_ROOT}/.clang-format"; do
    ln -sfn "${entry}" "${pkg}/$(basename "${entry}")"
  done
}

# cia_build [extra catkin_make targets...]
# A ccache on the machine is used when present (optional: rebuilds and several checkouts of the
# repository share one cache; CCACHE_BASEDIR makes the workspace's paths relative).
cia_build() {
  cia_setup_workspace
  local launcher=()
  if command -v ccache >/dev/null 2>&1; then
    export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(dirname "${REPO_ROOT}")}"
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  fi
  (cd "${WS}" && catkin_make -j2 -DCMAKE_BUILD_TYPE=Release -DCATKIN_ENABLE_TESTING=ON \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 "${launcher[@]}" "$@")
}

# devel/setup.bash reads unset variables (ROS_DISTRO): never source it under set -u.
cia_source_workspace() {
  set +u
  # shellcheck disable=SC1091
  source "${WS}/devel/setup.bash"
  set -u
}
