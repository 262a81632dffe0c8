#!/usr/bin/env bash
# verify --frames must report a differing frame. Exports tests/scenes/clock_probe.pcsg at
# clock 0 and hands that one POV-Ray file to `pcsg verify --frames 3 --pov`: frame 1
# (clock 0) agrees, frames 2 and 3 (clock 0.5 and 1, where the native side moves) differ,
# so the scene differs (exit status 1), each frame reported with its number and clock.
#   usage: verify_frames_detects_change.sh PCSG SCENE
set -euo pipefail
pcsg=$1 scene=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
W=80 H=60 SS=2
"$pcsg" export-pov "$scene" -o "$work/frame0.pov" --width $((W * SS)) --height $((H * SS))
set +e
"$pcsg" verify "$scene" --frames 3 --pov "$work/frame0.pov" --width $W --height $H --ss $SS \
  --threads 2 --json > "$work/out.json"
status=$?
set -e
cat "$work/out.json"
if [ "$status" -ne 1 ]; then
  echo "verify --frames returned $status for a frame that differs; expected 1 (differ)" >&2
  exit 1
fi
python3 - "$work/out.json" <<'PY'
import json, sys
runs = json.load(open(sys.argv[1]))
got = [(r["frame"], r["frames"], r["clock"], r["status"]) for r in runs]
want = [(1, 3, 0, "agree"), (2, 3, 0.5, "differ"), (3, 3, 1, "differ")]
if got != want:
    sys.exit(f"frames reported {got}, expected {want}")
PY
echo "differing frames detected and reported with their numbers and clocks: ok"
