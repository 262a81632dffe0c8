#!/usr/bin/env bash
# A release pcsg is linked statically, glibc's libc.a included: it has no program
# interpreter (the dynamic loader) and no dynamic section, so it maps no shared library's
# pages (docs/benchmarks.md, branches lean and static). A PNG render then runs with the
# loader's record of what it loads (LD_DEBUG=files, child processes and dlopen included):
# there must be nothing in it.
# pcsg-dynamic, the same program for mpirun (it loads pcsg-mpi.so) and heaptrack, loads
# only glibc's shared libraries and the dynamic loader: libstdc++ and libgcc are linked
# statically, libpng and zlib from Debian's archives, fmt compiled in, and oneTBB is not
# used (the render's threads are tracer/thread_pool.h's). ldd lists what the loader would
# load, indirect dependencies included; then a PNG render runs with the loader's record.
#   usage: pcsg_libraries.sh HELPER PCSG DYNAMIC SCENE
# HELPER (pcsg-image, which OpenImageIO makes load libstdc++) shows the checks can see the
# unwanted libraries; DYNAMIC shows they can see an interpreter and a loaded library.
set -euo pipefail
if (($# != 4)); then
    echo "usage: $0 HELPER PCSG DYNAMIC SCENE" >&2
    exit 2
fi
helper=$1 pcsg=$2 dynamic=$3 scene=$4
unwanted='lib(stdc\+\+|gcc_s|tbb|fmt|png|z)\.so'
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# loaded PROGRAM: the files the dynamic loader loaded for a PNG render, one "file=" line each.
loaded() {
    rm -f "$work"/ld.*
    if ! LD_DEBUG=files LD_DEBUG_OUTPUT="$work/ld" "$1" render "$scene" -o "$work/image.png" \
        --width 16 --height 12 --threads 2 >/dev/null; then
        echo "FAIL: $1 render $scene failed" >&2
        exit 1
    fi
    cat "$work"/ld.* 2>/dev/null | grep -o 'file=[^ ]*' || true
}
interpreter() { readelf -l "$1" | grep -o 'program interpreter: [^]]*' || true; }

# (ldd's output is kept first: grep -q ends early, and ldd's SIGPIPE fails a pipeline.)
helper_libs=$(ldd "$helper")
if ! grep -Eq "$unwanted" <<<"$helper_libs"; then
    echo "FAIL: $helper loads none of $unwanted: this check cannot see them" >&2
    exit 1
fi
echo "ok: $helper loads $(grep -Eo "$unwanted" <<<"$helper_libs" | sort -u | tr '\n' ' ')"
if [[ -z $(interpreter "$dynamic") || -z $(loaded "$dynamic") ]]; then
    echo "FAIL: $dynamic shows no interpreter or no loaded library: this check cannot see them" >&2
    exit 1
fi
echo "ok: $dynamic has $(interpreter "$dynamic") and a render loads $(loaded "$dynamic" | wc -l) files"

failed=0
if found=$(interpreter "$pcsg") && [[ -n $found ]]; then
    echo "FAIL: $pcsg is not static: $found" >&2
    failed=1
elif readelf -d "$pcsg" | grep -q NEEDED; then
    echo "FAIL: $pcsg needs shared libraries:" >&2
    readelf -d "$pcsg" | grep NEEDED >&2
    failed=1
else
    echo "ok: $pcsg has no interpreter and needs no shared library"
fi
if found=$(loaded "$pcsg") && [[ -n $found ]]; then
    echo "FAIL: a PNG render of $pcsg loads:" >&2
    echo "$found" >&2
    failed=1
else
    echo "ok: a PNG render of $pcsg loads no file"
fi

if found=$(ldd "$dynamic" | grep -E "$unwanted"); then
    echo "FAIL: $dynamic links:" >&2
    echo "$found" >&2
    failed=1
else
    echo "ok: $dynamic links none of them ($(ldd "$dynamic" | wc -l) libraries)"
fi
if found=$(loaded "$dynamic" | grep -E "$unwanted"); then
    echo "FAIL: a PNG render of $dynamic loads:" >&2
    echo "$found" >&2
    failed=1
else
    echo "ok: a PNG render of $dynamic loads none of them"
fi
exit $failed
