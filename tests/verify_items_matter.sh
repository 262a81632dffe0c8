#!/usr/bin/env bash
# A hand-written POV-Ray probe agrees with the native render, and stops agreeing when any
# one item in its POV-Ray text changes: the comparison sees each of them, so the
# verify_hand_written_* test of the probe can fail for each formula (finish, transparency,
# noise patterns, normals: tests/CMakeLists.txt lists the changes).
#   verify_items_matter.sh PCSG SCENE.pcsg SCENE.pov SED-CHANGE...
# VERIFY_OPTS adds options to every verify (the thresholds the probe's own test uses).
set -euo pipefail
pcsg=$1 scene=$2 pov=$3
shift 3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
W=160 H=120 SS=2
read -r -a opts <<< "${VERIFY_OPTS:-}"

"$pcsg" verify "$scene" --pov "$pov" --width $W --height $H --ss $SS --threads 2 "${opts[@]}" > /dev/null
echo "unchanged scene agrees: ok"

for change in "$@"; do
  sed -E "$change" "$pov" > "$work/changed.pov"
  if cmp -s "$pov" "$work/changed.pov"; then
    echo "'$change' found nothing to change" >&2
    exit 1
  fi
  set +e
  "$pcsg" verify "$scene" --pov "$work/changed.pov" --width $W --height $H --ss $SS --threads 2 "${opts[@]}" > "$work/out.txt"
  status=$?
  set -e
  if [ "$status" -ne 1 ]; then
    cat "$work/out.txt" >&2
    echo "verify returned $status after '$change'; expected 1 (differ)" >&2
    exit 1
  fi
  echo "'$change' detected: ok"
done
