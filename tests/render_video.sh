#!/usr/bin/env bash
# pcsg render -o OUT.mp4 / OUT.gif --frames 4: ffprobe counts 4 frames in each video, and
# the PNG frames are removed without --keep-frames, kept next to OUT (POV-Ray names) with
# it. Skipped (exit 77) when ffmpeg is not installed.
#   usage: render_video.sh PCSG SCENE
set -euo pipefail
pcsg=$1 scene=$2
command -v ffmpeg > /dev/null && command -v ffprobe > /dev/null || { echo "no ffmpeg: skipped"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export TMPDIR=$work/tmp
mkdir -p "$TMPDIR" "$work/out"
count() {
  ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames \
    -of csv=p=0 "$1"
}
for ext in mp4 gif; do
  "$pcsg" render "$scene" -o "$work/out/anim.$ext" --frames 4 --cyclic --width 48 --height 36 \
    --threads 2
  n=$(count "$work/out/anim.$ext")
  [ "$n" = 4 ] || { echo "anim.$ext has $n frames, expected 4" >&2; exit 1; }
  echo "anim.$ext: 4 frames: ok"
done
left=$(find "$work" -name '*.png' | wc -l)
[ "$left" = 0 ] || { echo "$left frame(s) left behind without --keep-frames" >&2; exit 1; }
echo "frames removed: ok"
"$pcsg" render "$scene" -o "$work/out/kept.mp4" --frames 4 --width 48 --height 36 --threads 2 \
  --keep-frames
for f in 1 2 3 4; do
  [ -f "$work/out/kept$f.png" ] || { echo "kept$f.png missing with --keep-frames" >&2; exit 1; }
done
[ "$(count "$work/out/kept.mp4")" = 4 ] || { echo "kept.mp4 has not 4 frames" >&2; exit 1; }
echo "frames kept with --keep-frames: ok"
