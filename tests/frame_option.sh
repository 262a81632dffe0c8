#!/usr/bin/env bash
# --frame F: frame F of a sequence rendered or exported alone is the sequence's frame F,
# and `pcsg verify --frames` passes each frame's number on: a POV-Ray file of frame 3
# agrees with frame 3 only.
#   usage: frame_option.sh PCSG SCENE (a scene that reads `frame`)
set -euo pipefail
pcsg=$1 scene=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$pcsg" render "$scene" -o "$work/seq.png" --frames 3 --subset 3,3 --width 64 --height 48 > /dev/null
"$pcsg" render "$scene" -o "$work/one.png" --clock 1 --frame 3 --width 64 --height 48 > /dev/null
cmp "$work/seq3.png" "$work/one.png"
"$pcsg" render "$scene" -o "$work/first.png" --clock 1 --width 64 --height 48 > /dev/null
if cmp -s "$work/first.png" "$work/one.png"; then
  echo "the scene does not read frame: --frame 3 and frame 1 look the same" >&2
  exit 1
fi
echo "render --clock 1 --frame 3 is frame 3 of 3: ok"
"$pcsg" export-pov "$scene" -o "$work/seq.pov" --frames 3 --width 160 --height 120 > /dev/null
"$pcsg" export-pov "$scene" -o "$work/one.pov" --clock 1 --frame 3 --width 160 --height 120 > /dev/null
cmp "$work/seq3.pov" "$work/one.pov"
echo "export-pov --clock 1 --frame 3 is frame 3 of 3: ok"
set +e
"$pcsg" verify "$scene" --frames 3 --all-frames --pov "$work/seq3.pov" --width 80 --height 60 \
  --ss 2 --threads 2 --json > "$work/out.json"
status=$?
set -e
[ "$status" = 1 ] || { cat "$work/out.json"; echo "verify returned $status, expected 1" >&2; exit 1; }
python3 - "$work/out.json" <<'PY'
import json, sys
got = [(r["frame"], r["status"]) for r in json.load(open(sys.argv[1]))]
want = [(1, "differ"), (2, "differ"), (3, "agree")]
if got != want:
    sys.exit(f"verify --frames reported {got}, expected {want}")
PY
echo "verify --frames passes the frame number: ok"
