#!/usr/bin/env bash
# verify must be able to fail. Exports a scene, changes one thing in the POV-Ray text
# (every pigment colour, or the first transformation matrix), and checks that
# `pcsg verify --pov` reports that the images differ (exit status 1), while the
# unchanged text agrees (exit status 0).
#   usage: verify_detects_change.sh PCSG SCENE material|transform
set -euo pipefail
pcsg=$1 scene=$2 what=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
W=160 H=120 SS=2
"$pcsg" export-pov "$scene" -o "$work/scene.pov" --width $((W * SS)) --height $((H * SS))

"$pcsg" verify "$scene" --pov "$work/scene.pov" --width $W --height $H --ss $SS --threads 2
echo "unchanged export agrees: ok"

case "$what" in
  material)  # every colour becomes pure blue
    sed -E 's/rgb *<[^>]*>/rgb <0, 0, 1>/g' "$work/scene.pov" > "$work/changed.pov" ;;
  transform) # the first matrix is moved half a unit along x
    awk 'done == 0 && /matrix *</ { sub(/matrix *</, "translate <0.5,0,0> matrix <"); done = 1 } { print }' \
      "$work/scene.pov" > "$work/changed.pov" ;;
  *) echo "unknown change $what" >&2; exit 2 ;;
esac
if cmp -s "$work/scene.pov" "$work/changed.pov"; then
  echo "the change found nothing to change in the exported text" >&2
  exit 1
fi
set +e
"$pcsg" verify "$scene" --pov "$work/changed.pov" --width $W --height $H --ss $SS --threads 2
status=$?
set -e
if [ "$status" -ne 1 ]; then
  echo "verify returned $status for a changed $what; expected 1 (differ)" >&2
  exit 1
fi
echo "changed $what detected: ok"
