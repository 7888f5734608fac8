#!/usr/bin/env bash
# Pneuma fuzzing: build the libFuzzer target of every loader with clang (ASan + UBSan) and run each for a while.
set -euo pipefail

usage() {
  cat <<'USAGE'
Usage: scripts/fuzz.sh [--help] SECONDS [LOADER...]

Installs clang and libclang-rt-14-dev when missing (Debian 12, needs root or sudo), configures build-fuzz/
(clang, PNEUMA_BUILD_FUZZERS=ON, no app), builds the fuzzers, and runs each LOADER (default: model anatomy
gains style scenario pattern) for SECONDS seconds, one after the other. Each run starts from the seed corpus
fuzz/corpus/<loader>/ and grows a working copy in build-fuzz/corpus/<loader>/; crashes, hangs (> 10 s per
input) and sanitizer reports stop the run and leave their input in build-fuzz/artifacts/<loader>/. Copy such an
input to fuzz/reproducers/<loader>/ once fixed: the normal test suite replays it (pneuma_fuzz_replay_test).
Prints the executions and the corpus size of each loader at the end.
USAGE
}

[ $# -ge 1 ] || { usage >&2; exit 2; }
case "$1" in --help|-h) usage; exit 0 ;; esac
seconds="$1"; shift
[[ "$seconds" =~ ^[0-9]+$ ]] && [ "$seconds" -ge 1 ] || { echo "fuzz.sh: SECONDS must be a positive integer, got '$seconds'" >&2; exit 2; }
loaders=("$@")
[ ${#loaders[@]} -gt 0 ] || loaders=(model anatomy gains style scenario pattern)

source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
PNEUMA_PACKAGES+=(clang libclang-rt-14-dev)
pneuma_install_packages
fuzz_dir="$PNEUMA_ROOT/build-fuzz"

if [ ! -f "$fuzz_dir/build.ninja" ]; then
  pneuma_log "configuring the fuzzers in $fuzz_dir"
  CC=clang CXX=clang++ cmake -S "$PNEUMA_ROOT" -B "$fuzz_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DPNEUMA_BUILD_FUZZERS=ON -DPNEUMA_BUILD_APP=OFF -DPNEUMA_BUILD_TESTS=OFF -DPNEUMA_BUILD_BENCHMARKS=OFF >/dev/null
fi
targets=()
for l in "${loaders[@]}"; do targets+=("pneuma_fuzz_$l"); done
pneuma_log "building ${targets[*]} ($PNEUMA_JOBS jobs)"
cmake --build "$fuzz_dir" -j "$PNEUMA_JOBS" --target "${targets[@]}" -- --quiet

summary=()
status=0
for l in "${loaders[@]}"; do
  corpus="$fuzz_dir/corpus/$l"; artifacts="$fuzz_dir/artifacts/$l"
  mkdir -p "$corpus" "$artifacts"
  cp -n "$PNEUMA_ROOT/fuzz/corpus/$l/"* "$corpus/" 2>/dev/null || true
  log="$fuzz_dir/$l.log"
  pneuma_log "fuzzing $l for $seconds s (log: $log)"
  if ! "$fuzz_dir/bin/pneuma_fuzz_$l" "$corpus" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -max_len=262144 -print_final_stats=1 -artifact_prefix="$artifacts/" >"$log" 2>&1; then
    pneuma_log "$l: the fuzzer stopped on a failure; its input is in $artifacts/ (see $log)"
    status=1
  fi
  execs=$(grep -a -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  summary+=("$l: ${execs:-?} executions, corpus $(ls "$corpus" | wc -l) inputs ($(du -sh "$corpus" | cut -f1))")
done
printf '%s\n' "${summary[@]}"
exit $status
