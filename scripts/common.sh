#!/usr/bin/env bash
# Shared set-up for run.sh and test.sh: install missing Debian packages, configure and build Release.
# Sourced, not executed. Honours PNEUMA_BUILD_DIR (default: build) and PNEUMA_JOBS (default: nproc).

PNEUMA_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PNEUMA_BUILD_DIR="${PNEUMA_BUILD_DIR:-$PNEUMA_ROOT/build}"
PNEUMA_JOBS="${PNEUMA_JOBS:-$(nproc)}"

# Debian 12 packages Pneuma builds, tests and runs with.
PNEUMA_PACKAGES=(
  cmake ninja-build g++ pkg-config
  libeigen3-dev nlohmann-json3-dev libcli11-dev
  libcgal-dev libtet1.5-dev libassimp-dev assimp-testmodels
  qtbase5-dev libqt5svg5-dev libqt5opengl5-dev
  libvtk9-dev libvtk9-qt-dev libtinygltf-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  xvfb xauth chromium nodejs
  help2man clang-format ffmpeg
  slurm-wlm munge
  pybind11-dev python3-dev python3-numpy python3-matplotlib
)

pneuma_log() { printf '[pneuma] %s\n' "$*" >&2; }

# install only what is missing; quiet when everything is present
pneuma_install_packages() {
  local missing=()
  local pkg
  for pkg in "${PNEUMA_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$pkg")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0

  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
      pneuma_log "missing packages: ${missing[*]}; run as root or install sudo"
      return 1
    fi
  fi
  pneuma_log "installing missing Debian packages: ${missing[*]}"
  $sudo apt-get update -qq >/dev/null || { pneuma_log "apt-get update failed"; return 1; }
  if ! DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; then
    # name exactly which packages could not be installed
    local still=()
    for pkg in "${missing[@]}"; do
      dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || still+=("$pkg")
    done
    pneuma_log "could not install Debian package(s): ${still[*]}"
    return 1
  fi
}

# the npm packages of the glTF checks (tests/gltf: gltf-validator, three, playwright-core), pinned by its
# package-lock.json; installed once, again only when the lock file changes; the browser is Debian's chromium
pneuma_install_npm() {
  local dir="$PNEUMA_ROOT/tests/gltf"
  if [ -f "$dir/node_modules/.package-lock.json" ] && ! [ "$dir/package-lock.json" -nt "$dir/node_modules/.package-lock.json" ]; then
    return 0
  fi
  # Debian's nodejs comes without npm (NodeSource's has it built in)
  if ! command -v npm >/dev/null 2>&1; then
    local PNEUMA_PACKAGES=(npm)
    pneuma_install_packages || return 1
  fi
  pneuma_log "installing the npm packages of the glTF checks (tests/gltf)"
  (cd "$dir" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error) || return 1
}

# configure once (Ninja, Release), then build incrementally
pneuma_build() {
  if [ ! -f "$PNEUMA_BUILD_DIR/build.ninja" ]; then
    pneuma_log "configuring Release build in $PNEUMA_BUILD_DIR"
    cmake -S "$PNEUMA_ROOT" -B "$PNEUMA_BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null || return 1
  fi
  pneuma_log "building ($PNEUMA_JOBS jobs)"
  cmake --build "$PNEUMA_BUILD_DIR" -j "$PNEUMA_JOBS" -- --quiet || cmake --build "$PNEUMA_BUILD_DIR" -j 1
}
