#!/usr/bin/env bash
# OpenImageIO's ~260 shared libraries cost every process that loads them ~130 MB of peak
# RSS, so only the pcsg-image helper may link it: not pcsg (which renders and writes a PNG
# itself through libpng), not the test programs that do not read images back. ldd lists
# what the dynamic loader would load, indirect dependencies included. Then a PNG render is
# run with the dynamic loader's own record of every library it loads (LD_DEBUG=files, for
# the command's every process, dlopen included): OpenImageIO must not be among them. An
# EXR render, which runs pcsg-image, shows that the record can see it.
#   usage: links_without_openimageio.sh HELPER PCSG SCENE [PROGRAM...]
# HELPER must load libOpenImageIO (which shows the check can see it); neither PCSG nor any
# PROGRAM may; `PCSG render SCENE` of a PNG must not load it at run time.
set -euo pipefail
if (($# < 3)); then
    echo "usage: $0 HELPER PCSG SCENE [PROGRAM...]" >&2
    exit 2
fi
helper=$1 pcsg=$2 scene=$3
shift 3

loads_oiio() {
    local libs
    if ! libs=$(ldd "$1" 2>&1); then
        # A static program (the release pcsg) loads no shared library at all.
        grep -q 'not a dynamic executable' <<<"$libs" && return 1
        echo "ldd failed on $1" >&2
        exit 2
    fi
    grep -i 'libOpenImageIO' <<<"$libs"
}

if ! loads_oiio "$helper" >/dev/null; then
    echo "FAIL: $helper does not load libOpenImageIO: this check cannot see it" >&2
    exit 1
fi
echo "ok: $helper loads libOpenImageIO"

failed=0
for program in "$pcsg" "$@"; do
    if found=$(loads_oiio "$program"); then
        echo "FAIL: $program loads OpenImageIO:" >&2
        echo "$found" >&2
        failed=1
    else
        echo "ok: $program does not load OpenImageIO ($(ldd "$program" 2>&1 | grep -c '=>') libraries)"
    fi
done

# render OUT: the libraries the whole `pcsg render` command loaded, one "file=" line each.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
render() {
    if ! LD_DEBUG=files LD_DEBUG_OUTPUT="$work/ld" "$pcsg" render "$scene" -o "$work/$1" \
        --width 16 --height 12 >/dev/null; then
        echo "FAIL: pcsg render $scene -o $1 failed" >&2
        exit 1
    fi
    cat "$work"/ld.* 2>/dev/null | grep -o 'file=[^ ]*'
    rm -f "$work"/ld.*
}
if ! render image.exr | grep -qi 'libOpenImageIO'; then
    echo "FAIL: an EXR render shows no libOpenImageIO in LD_DEBUG: this check cannot see it" >&2
    exit 1
fi
echo "ok: an EXR render loads libOpenImageIO (in pcsg-image)"
if found=$(render image.png | grep -i 'libOpenImageIO'); then
    echo "FAIL: a PNG render loads OpenImageIO:" >&2
    echo "$found" >&2
    failed=1
else
    echo "ok: a PNG render loads no OpenImageIO ($(render image.png | sort -u | wc -l) libraries)"
fi
exit $failed
