#!/usr/bin/env bash
# Pneuma test run: install what is missing, build Release into build/, and run the whole ctest suite.
set -euo pipefail

usage() {
  cat <<'USAGE'
Usage: scripts/test.sh [--help] [-L LABEL] [-R REGEX]

Installs the missing Debian 12 packages (needs root or sudo), configures and builds Pneuma
(Release, into build/), then runs every ctest test (labels: unit, validation, gui, gltf, bench-smoke).
The glTF checks' npm packages (tests/gltf/package-lock.json) are installed with npm ci.
GUI and off-screen rendering tests run inside xvfb-run -a -s "-screen 0 1280x800x24".

Options:
  -L LABEL   only run tests with this ctest label
  -R REGEX   only run tests whose name matches
  --help     show this help
USAGE
}

ctest_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --help|-h) usage; exit 0 ;;
    -L|-R) ctest_args+=("$1" "${2:?$1 needs a value}"); shift ;;
    *) echo "test.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done

source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
pneuma_install_packages
pneuma_install_npm
pneuma_build

pneuma_log "running tests"
cd "$PNEUMA_BUILD_DIR"
exec xvfb-run -a -s "-screen 0 1280x800x24" \
  ctest --output-on-failure -j "$PNEUMA_JOBS" --timeout 900 "${ctest_args[@]}"
