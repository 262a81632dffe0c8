#!/usr/bin/env bash
# The measurement of docs/distributed.md "Measured on this machine": one process with 2
# threads against `mpirun -np 2` with 1 thread per rank, interleaved (other work on the
# machine disturbs both alike), each pair also byte-compared.
#   usage: tools/dev/mpi_one_vs_two.sh [PCSG] [ROUNDS] [-- render options...]
#   default: build/tools/pcsg, 3 rounds, scenes/terrain.pcsg 640x480 --adaptive 0.3
set -euo pipefail
pcsg=${1:-build/tools/pcsg}
rounds=${2:-3}
shift $(($# >= 2 ? 2 : $#))
[[ ${1:-} == -- ]] && shift
args=("$@")
((${#args[@]})) || args=(scenes/terrain.pcsg --width 640 --height 480 --adaptive 0.3)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
wall() { /usr/bin/time -f %e -o "$work/t" "$@" > /dev/null && cat "$work/t"; }
echo "round  one process x 2 threads (s)  2 ranks x 1 thread (s)  same image"
for ((i = 1; i <= rounds; i++)); do
  a=$(wall "$pcsg" render "${args[@]}" -o "$work/one.png" --threads 2)
  b=$(wall mpirun -np 2 "$pcsg" render "${args[@]}" -o "$work/two.png" --threads 1)
  same=$(cmp -s "$work/one.png" "$work/two.png" && echo yes || echo NO)
  printf "%5d  %28s  %22s  %s\n" "$i" "$a" "$b" "$same"
done
uptime
