#!/usr/bin/env bash
# The hand-written glass probe (tests/povray/glass_probe.pov) agrees with the native render, and stops agreeing when
# any one transparency item in the POV-Ray text changes: the comparison sees each of them, so
# verify_hand_written_glass_scene can fail for each of them.
#   verify_transparency_items_matter.sh PCSG SCENE.pcsg SCENE.pov
set -euo pipefail
pcsg=$1 scene=$2 pov=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
W=160 H=120 SS=2

"$pcsg" verify "$scene" --pov "$pov" --width $W --height $H --ss $SS --threads 2 > /dev/null
echo "unchanged scene agrees: ok"

changes=(
  's/max_trace_level 8/max_trace_level 3/'
  's/ior 1.5/ior 1.3/'
  's/ fade_distance 2 fade_power 2//'
  's/ conserve_energy//'
  's/rgbf <1, 0.6, 0.1, 0.85>/rgbt <1, 0.6, 0.1, 0.85>/'
  's/rgbt <0.3, 0.4, 1, 0.7>/rgbt <0.3, 0.4, 1, 0.4>/'
)
for change in "${changes[@]}"; do
  sed -E "$change" "$pov" > "$work/changed.pov"
  if cmp -s "$pov" "$work/changed.pov"; then
    echo "'$change' found nothing to change" >&2
    exit 1
  fi
  set +e
  "$pcsg" verify "$scene" --pov "$work/changed.pov" --width $W --height $H --ss $SS --threads 2 > "$work/out.txt"
  status=$?
  set -e
  if [ "$status" -ne 1 ]; then
    cat "$work/out.txt" >&2
    echo "verify returned $status after '$change'; expected 1 (differ)" >&2
    exit 1
  fi
  echo "'$change' detected: ok"
done
