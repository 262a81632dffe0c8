#!/usr/bin/env bash
# `mpirun -np 2 pcsg render` on this machine (docs/distributed.md):
#   still        a still with adaptive anti-aliasing is byte for byte the one-process image,
#                and --json reports 2 ranks, each with units and a peak RSS
#   frames       an animation, as whole frames per rank (3 frames) and as tiles of a frame
#                (1 frame), is byte for byte the one-process sequence
#   scene_error  a compile error and a run-time error are printed once, exit status 1
#   rank_dies    rank 1 aborting mid-render stops the run with a message naming rank 1,
#                within the time limit, and leaves no image
#   usage: mpi_render.sh CASE MPIRUN PCSG SOURCE_DIR
set -euo pipefail
case=$1 mpirun=$2 pcsg=$3 src=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Open MPI refuses root without these; --oversubscribe: more ranks than cores is fine.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpi() { timeout 60 "$mpirun" -np 2 --oversubscribe "$@"; }
size=(--width 96 --height 72)

case $case in
still)
  scene=$src/scenes/sierpinski.pcsg
  "$pcsg" render "$scene" -o "$work/one.png" "${size[@]}" --adaptive 0.3 --threads 2 > /dev/null
  mpi "$pcsg" render "$scene" -o "$work/two.png" "${size[@]}" --adaptive 0.3 --threads 1 \
    --json > "$work/two.json"
  cmp "$work/one.png" "$work/two.png"
  python3 - "$work/two.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["ranks"] == 2, j
ranks = j["per_rank"]
assert [r["rank"] for r in ranks] == [0, 1], ranks
assert all(r["units"] > 0 and r["peak_rss_bytes"] > 0 for r in ranks), ranks
assert sum(r["pixels"] for r in ranks) == 96 * 72, ranks
PY
  ls -A "$work" | grep -q '^\.pcsg-' && { echo "a temporary file was left" >&2; exit 1; }
  echo "mpirun -np 2: the still is the one-process image, both ranks rendered: ok"
  ;;
frames)
  scene=$src/scenes/sierpinski_orbit.pcsg
  for args in "--frames 3" "--frames 3 --subset 2,2"; do
    rm -f "$work"/*.png
    # shellcheck disable=SC2086
    "$pcsg" render "$scene" -o "$work/one.png" "${size[@]}" --adaptive 0.3 $args > /dev/null
    # shellcheck disable=SC2086
    mpi "$pcsg" render "$scene" -o "$work/two.png" "${size[@]}" --adaptive 0.3 --threads 1 \
      $args > /dev/null
    n=0
    for f in "$work"/one?.png; do
      cmp "$f" "${f/one/two}"
      n=$((n + 1))
    done
    [ "$n" -gt 0 ] || { echo "no frames were written" >&2; exit 1; }
    echo "mpirun -np 2 $args: $n frame(s) equal to one process's: ok"
  done
  ;;
scene_error)
  printf 'sphere \xe2\x88\xaa\n' > "$work/syntax.pcsg"
  printf '{c=2} S\nS if(c > 0, 3, 1)\n1: S -> sphere\n2: S -> {c=c-1} uscale(0.5) S\n' \
    > "$work/runtime.pcsg"
  for bad in syntax runtime; do
    set +e
    mpi "$pcsg" render "$work/$bad.pcsg" -o "$work/$bad.png" "${size[@]}" > "$work/out" 2> "$work/err"
    status=$?
    set -e
    [ "$status" = 1 ] || { cat "$work/err"; echo "$bad: exit status $status, expected 1" >&2; exit 1; }
    n=$(grep -c "^$work/$bad.pcsg:[0-9]*:[0-9]*: error" "$work/err" || true)
    [ "$n" = 1 ] || { cat "$work/err"; echo "$bad: the error was printed $n times" >&2; exit 1; }
    [ ! -e "$work/$bad.png" ] || { echo "$bad: an image was written" >&2; exit 1; }
    echo "mpirun -np 2, a $bad error: printed once, exit status 1, no image: ok"
  done
  ;;
rank_dies)
  scene=$src/scenes/sierpinski.pcsg
  set +e
  PCSG_MPI_TEST_ABORT_RANK=1 mpi -x PCSG_MPI_TEST_ABORT_RANK "$pcsg" render "$scene" \
    -o "$work/dead.png" "${size[@]}" --adaptive 0.3 > "$work/out" 2> "$work/err"
  status=$?
  set -e
  [ "$status" != 0 ] && [ "$status" != 124 ] ||
    { cat "$work/err"; echo "exit status $status: expected a failure, not a hang" >&2; exit 1; }
  grep -q "rank 1" "$work/err" || { cat "$work/err"; echo "no message names rank 1" >&2; exit 1; }
  if [ -n "$(ls -A "$work" | grep -v '^out$\|^err$')" ]; then
    ls -A "$work"; echo "a file was left behind" >&2; exit 1
  fi
  echo "mpirun -np 2, rank 1 aborting: stopped with exit status $status, names rank 1, no image: ok"
  ;;
*)
  echo "unknown case $case" >&2
  exit 2
  ;;
esac
