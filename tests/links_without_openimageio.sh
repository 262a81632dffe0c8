#!/usr/bin/env bash
# OpenImageIO's ~260 shared libraries cost every process that loads them ~130 MB of peak
# RSS, so only the pcsg-image helper may link it: not pcsg (which renders), not the test
# programs that do not read or write images. ldd lists what the dynamic loader would
# load, indirect dependencies included.
#   usage: links_without_openimageio.sh HELPER PROGRAM...
# HELPER must load libOpenImageIO (which shows the check can see it); no PROGRAM may.
set -euo pipefail
if (($# < 2)); then
    echo "usage: $0 HELPER PROGRAM..." >&2
    exit 2
fi
helper=$1
shift

loads_oiio() {
    local libs
    if ! libs=$(ldd "$1"); then
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
for program in "$@"; do
    if found=$(loads_oiio "$program"); then
        echo "FAIL: $program loads OpenImageIO:" >&2
        echo "$found" >&2
        failed=1
    else
        echo "ok: $program does not load OpenImageIO ($(ldd "$program" | wc -l) libraries)"
    fi
done
exit $failed
