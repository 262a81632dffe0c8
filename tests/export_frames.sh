#!/usr/bin/env bash
# pcsg export-pov -o OUT.pov --frames N writes OUT01.pov ..., the driver OUT.pov and
# OUT.ini; `povray OUT.ini` renders every frame under the names `pcsg render -o OUT.png
# --frames N` writes; and frame 2's export agrees with the native render at its clock.
#   usage: export_frames.sh PCSG SCENE
set -euo pipefail
pcsg=$1 scene=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/pov" "$work/native"
N=12 W=40 H=30
"$pcsg" export-pov "$scene" -o "$work/pov/anim.pov" --frames $N --cyclic --width $W --height $H
(cd "$work/pov" && povray anim.ini -D +WT2 > povray.log 2>&1) || { cat "$work/pov/povray.log"; exit 1; }
"$pcsg" render "$scene" -o "$work/native/anim.png" --frames $N --cyclic --width $W --height $H \
  --threads 2 > /dev/null
want=$(cd "$work/native" && ls *.png)
got=$(cd "$work/pov" && ls *.png)
[ "$want" = "$got" ] || { echo "POV-Ray wrote [$got], pcsg render wrote [$want]" >&2; exit 1; }
[ "$(echo "$got" | wc -l)" = $N ] || { echo "expected $N frames" >&2; exit 1; }
echo "povray anim.ini wrote the $N frames under pcsg render's names: ok"
# frame 2 of 12 cyclic has clock 1/12: its export agrees with the native render there.
"$pcsg" export-pov "$scene" -o "$work/f.pov" --frames $N --cyclic --width $((2 * W)) \
  --height $((2 * H)) > /dev/null
"$pcsg" verify "$scene" --pov "$work/f02.pov" --clock "$(python3 -c 'print(1/12)')" \
  --width $W --height $H --ss 2 --threads 2 > /dev/null
echo "frame 2's export agrees with the native render at clock 1/12: ok"
