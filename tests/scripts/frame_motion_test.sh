#!/bin/sh
# scripts/frame_motion.py on a calm breath exported with --vtk: every moving rib from 3 to 10 turns by 0.5-15 deg
# and the dome's central band descends (the script's figures are what the issue-13 notes quote)
set -eu
cli="$1"; script="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$cli" simulate --style calm --duration 6 --vtk --output-rate 10 --out "$work/run" > "$work/log" 2>&1 || { cat "$work/log"; exit 1; }
/usr/bin/python3 "$script" "$work/run" --from 4 --json "$work/motion.json"
/usr/bin/python3 - "$work/motion.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
ribs = [r for r in m["ribs"] if r["name"].split("_")[0] in ["rib%d" % k for k in range(3, 11)]]
assert len(ribs) == 16, "expected ribs 3-10 on both sides, got %d" % len(ribs)
for r in ribs:
    assert 0.5 < r["angle_deg"] < 15.0, r
centre = [d for d in m["dome"] if d["band_mm"][0] == 0]
assert centre and all(d["cranial_mm"] < -5.0 for d in centre), centre
print("ok: %d ribs, dome centre %.1f mm" % (len(ribs), sum(d["cranial_mm"] for d in centre) / len(centre)))
PY
