#!/usr/bin/env bash
# The hand-written light and fog probes agree with their native renders at strict
# thresholds (a channel off by 0.02 on at most 0.1% of the pixels), and stop agreeing when
# any one light or fog item of the POV-Ray text changes: the comparisons see each of them,
# so verify_hand_written_*_light/fog scenes can fail for each formula.
#   verify_light_items_matter.sh PCSG SOURCE_DIR
set -euo pipefail
pcsg=$1 src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
args=(--width 160 --height 120 --ss 2 --threads 2 --pixel-threshold 0.02 --max-off 0.001)

# probe | change to its POV-Ray text
changes=(
  'area_light_probe|s/6, 6 adaptive 1/5, 5 adaptive 1/'
  'area_light_probe|s/ circular orient/ circular/'
  'area_light_probe|s/<2, 0, 0>, <0, 2, 0>/<1, 0, 0>, <0, 1, 0>/'
  'spotlight_probe|s/radius 12 /radius 8 /'
  'spotlight_probe|s/tightness 5/tightness 1/'
  'spotlight_probe|s/fade_power 2/fade_power 1/'
  'spotlight_probe|s/ shadowless / /'
  'fog_probe|s/0.3, 0.15>/0, 0.15>/'
  'fog_probe|s/0.3, 0.15>/0.3, 0>/'
  'fog_probe|s/distance 7/distance 9/'
  'ground_fog_probe|s/fog_alt 0.5/fog_alt 0.8/'
  'ground_fog_probe|s/fog_offset 0.4/fog_offset 0.2/'
)
for probe in area_light_probe spotlight_probe fog_probe ground_fog_probe; do
  "$pcsg" verify "$src/tests/scenes/$probe.pcsg" --pov "$src/tests/povray/$probe.pov" \
    "${args[@]}" > /dev/null
  echo "$probe unchanged agrees: ok"
done
for entry in "${changes[@]}"; do
  probe=${entry%%|*} change=${entry#*|}
  pov=$src/tests/povray/$probe.pov
  sed -E "$change" "$pov" > "$work/changed.pov"
  if cmp -s "$pov" "$work/changed.pov"; then
    echo "'$change' found nothing to change in $probe.pov" >&2
    exit 1
  fi
  set +e
  "$pcsg" verify "$src/tests/scenes/$probe.pcsg" --pov "$work/changed.pov" "${args[@]}" \
    > "$work/out.txt"
  status=$?
  set -e
  if [ "$status" -ne 1 ]; then
    cat "$work/out.txt" >&2
    echo "verify returned $status after '$change' in $probe.pov; expected 1 (differ)" >&2
    exit 1
  fi
  echo "$probe: '$change' detected: ok"
done
