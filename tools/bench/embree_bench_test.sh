#!/usr/bin/env bash
# pcsg-embree on the Sierpinski tetrahedron of order 8 at a small size: it reports
# 65,536 tetrahedra as 4 triangles each and traces rays, in packets and one at a time
# alike; a scene with a sphere is refused with exit status 2.
#   embree_bench_test.sh PCSG_EMBREE SIERPINSKI_8
set -euo pipefail
embree=$1 scene=$2
out=$("$embree" "$scene" --width 64 --height 48 --json)
python3 - "$out" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
assert j["triangles"] == 65536 * 4, j
assert j["rays"] > 64 * 48, j   # every camera ray, and shadow rays for the hits
assert j["hits"] > 0 and j["rays_per_second"] > 0, j
assert j["build_seconds"] >= 0 and j["trace_seconds"] > 0 and j["peak_rss_bytes"] > 0, j
assert j["packets"] and j["passes"] == 5 and len(j["pass_seconds"]) == 5, j
print("pcsg-embree:", j["triangles"], "triangles,", j["rays"], "rays")
PY
# One ray at a time: the same rays and the same hits as the packets'.
single=$("$embree" "$scene" --width 64 --height 48 --json --single --passes 2)
python3 - "$out" "$single" <<'PY'
import json, sys
p, s = json.loads(sys.argv[1]), json.loads(sys.argv[2])
assert not s["packets"] and len(s["pass_seconds"]) == 2, s
assert (s["rays"], s["hits"]) == (p["rays"], p["hits"]), (s, p)
print("one ray at a time:", s["rays"], "rays,", s["hits"], "hits, as the packets'")
PY
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
printf 'camera { location <0, -5, 2> look_at <0, 0, 0> }\nsphere\n' >"$dir/sphere.pcsg"
status=0
"$embree" "$dir/sphere.pcsg" --width 8 --height 6 2>"$dir/err" || status=$?
if [[ $status != 2 ]] || ! grep -q "sphere" "$dir/err"; then
    echo "expected exit status 2 and a message naming the sphere, got $status:" >&2
    cat "$dir/err" >&2
    exit 1
fi
echo "a scene with a sphere: exit 2 ($(cat "$dir/err"))"
