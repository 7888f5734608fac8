#!/usr/bin/env bash
# Pneuma quick start: install what is missing, build Release into build/, and start the main job.
set -euo pipefail

usage() {
  cat <<'USAGE'
Usage: scripts/run.sh [--help] [--headless] [--out DIR]

Installs the missing Debian 12 packages (needs root or sudo), configures and builds Pneuma
(Release, into build/), then starts the main job:
  - with a DISPLAY: the desktop app with the default model breathing calmly;
  - without one (or with --headless): a 30 s calm-breathing simulation of the default model,
    writing plots, timeseries.csv and summary.json to a folder whose path is printed.

Options:
  --headless   run the headless job even when a display is available
  --out DIR    output folder for the headless job (default: out/quickstart-<date>-<time>)
  --help       show this help
USAGE
}

headless=0
out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --help|-h) usage; exit 0 ;;
    --headless) headless=1 ;;
    --out) out="${2:?--out needs a folder}"; shift ;;
    *) echo "run.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done

source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
pneuma_install_packages
pneuma_build

if [ -n "${DISPLAY:-}" ] && [ "$headless" -eq 0 ]; then
  pneuma_log "starting the desktop app"
  exec "$PNEUMA_BUILD_DIR/bin/pneuma" --style calm
fi

out="${out:-$PNEUMA_ROOT/out/quickstart-$(date +%Y%m%d-%H%M%S)}"
pneuma_log "no display: running the headless calm-breathing job"
"$PNEUMA_BUILD_DIR/bin/pneuma-cli" simulate --style calm --duration 30 --out "$out"
echo "Results written to: $out"
