#!/usr/bin/env bash
# The hand-written finish probe agrees with the native render, and stops agreeing when
# any one finish item in the POV-Ray text changes: the comparison sees each of them, so
# verify_hand_written_finish_scene can fail for each formula.
#   verify_finish_items_matter.sh PCSG SCENE.pcsg SCENE.pov
set -euo pipefail
pcsg=$1 scene=$2 pov=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
W=160 H=120 SS=2

"$pcsg" verify "$scene" --pov "$pov" --width $W --height $H --ss $SS --threads 2 > /dev/null
echo "unchanged scene agrees: ok"

changes=(
  's/brilliance 2.5/brilliance 1/'
  's/reflection \{ 0.2, 0.7 metallic \}/reflection { 0.2, 0.7 }/'
  's/fresnel on/fresnel off/'
  's/reflection \{ 0, 0.6 \}/reflection 0.3/'
  's/roughness 0.01/roughness 0.2/'
  's/ior 1.5/ior 4/'
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
