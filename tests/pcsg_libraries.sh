#!/usr/bin/env bash
# The shared libraries a release pcsg loads are glibc's and the dynamic loader: libstdc++
# and libgcc are linked statically, libpng and zlib from Debian's archives, fmt compiled
# in, and oneTBB is not used (the render's threads are tracer/thread_pool.h's). Each of
# those shared libraries cost every pcsg process its mapped pages (docs/benchmarks.md,
# branch lean). ldd lists what the dynamic loader would load, indirect dependencies
# included; then a PNG render runs with the loader's own record of what it loads
# (LD_DEBUG=files, dlopen included).
#   usage: pcsg_libraries.sh HELPER PCSG SCENE
# HELPER (pcsg-image, which OpenImageIO makes load libstdc++) shows the check can see them.
set -euo pipefail
if (($# != 3)); then
    echo "usage: $0 HELPER PCSG SCENE" >&2
    exit 2
fi
helper=$1 pcsg=$2 scene=$3
unwanted='lib(stdc\+\+|gcc_s|tbb|fmt|png|z)\.so'

# (ldd's list read whole first: grep -q stops at the first match, and under pipefail the
# SIGPIPE that ldd then gets failed this check in about half the runs)
helperLibraries=$(ldd "$helper")
if ! grep -Eq "$unwanted" <<<"$helperLibraries"; then
    echo "FAIL: $helper loads none of $unwanted: this check cannot see them" >&2
    exit 1
fi
echo "ok: $helper loads $(grep -Eo "$unwanted" <<<"$helperLibraries" | sort -u | tr '\n' ' ')"

failed=0
if found=$(ldd "$pcsg" | grep -E "$unwanted"); then
    echo "FAIL: $pcsg links:" >&2
    echo "$found" >&2
    failed=1
else
    echo "ok: $pcsg links none of them ($(ldd "$pcsg" | wc -l) libraries)"
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if ! LD_DEBUG=files LD_DEBUG_OUTPUT="$work/ld" "$pcsg" render "$scene" -o "$work/image.png" \
    --width 16 --height 12 --threads 2 >/dev/null; then
    echo "FAIL: pcsg render $scene failed" >&2
    exit 1
fi
if found=$(cat "$work"/ld.* | grep -o 'file=[^ ]*' | grep -E "$unwanted"); then
    echo "FAIL: a PNG render loads:" >&2
    echo "$found" >&2
    failed=1
else
    echo "ok: a PNG render loads none of them"
fi
exit $failed
