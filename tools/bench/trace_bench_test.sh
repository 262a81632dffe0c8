#!/usr/bin/env bash
# pcsg-trace on the Sierpinski tetrahedron of order 8 at a small size: the timed render
# traces exactly the rays of the build render (the same pixel centres and shadow rays),
# every camera ray at least, and its rate is its rays over its time; the order's two
# expansions fit the cache, so none is built again; without the cache none is built at
# all; the cache's budget starts where told, at most at its limit. A scene that does not
# compile exits with 1, a bad command line with 2.
#   trace_bench_test.sh PCSG_TRACE SIERPINSKI_8
set -euo pipefail
trace=$1 scene=$2
out=$("$trace" "$scene" --width 64 --height 48 --threads 2 --json)
python3 - "$out" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
assert j["rays"] == j["build_rays"], j  # the same rays, twice
assert j["rays"] >= 64 * 48, j          # every pixel centre, and shadow rays for the hits
assert j["rays"] > 64 * 48, j           # the tetrahedron is in view: some hits
assert j["build_expansions"] > 0 and j["trace_expansions"] == 0, j
assert j["passes"] == 5 and len(j["pass_seconds"]) == 5, j
assert sorted(j["pass_seconds"])[2] == j["trace_seconds"], j  # the median pass
assert j["trace_seconds"] > 0 and j["build_seconds"] > 0 and j["peak_rss_bytes"] > 0, j
rate = j["rays"] / j["trace_seconds"]
assert abs(j["rays_per_second"] - rate) <= 1e-6 * rate, j
print("pcsg-trace:", j["rays"], "rays at", round(j["rays_per_second"]), "rays/s")
PY
# Without the expansion cache (as pcsg render --expansion-cache-mb 0): nothing expanded,
# and the same rays.
bare=$("$trace" "$scene" --width 64 --height 48 --threads 2 --passes 1 --expansion-cache-mb 0 --json)
python3 - "$out" "$bare" <<'PY'
import json, sys
j, b = json.loads(sys.argv[1]), json.loads(sys.argv[2])
assert b["expansion_cache_mb"] == 0 and j["expansion_cache_mb"] == 16, (b, j)
assert b["build_expansions"] == 0 and b["trace_expansions"] == 0, b
assert b["rays"] == j["rays"] and len(b["pass_seconds"]) == 1, (b, j)
print("without expansions:", b["rays"], "rays, none expanded")
PY
# The expansion cache's budget starts at 2 MB (as pcsg render's) and order 8's two
# expansions need no more; --expansion-start-mb starts it higher, at most at the limit.
start=$("$trace" "$scene" --width 64 --height 48 --threads 2 --passes 1 --expansion-start-mb 8 --json)
over=$("$trace" "$scene" --width 64 --height 48 --threads 2 --passes 1 --expansion-start-mb 64 --json)
python3 - "$out" "$start" "$over" <<'PY'
import json, sys
j, s, o = (json.loads(a) for a in sys.argv[1:4])
mb = 1 << 20
assert j["expansion_start_mb"] == 2 and j["expansion_budget_bytes"] == 2 * mb, j
assert s["expansion_start_mb"] == 8 and s["expansion_budget_bytes"] == 8 * mb, s
assert o["expansion_budget_bytes"] == 16 * mb, o  # (the limit, --expansion-cache-mb 16)
for x in (s, o):  # (a larger budget may expand a larger instance instead: as many rays)
    assert x["rays"] == j["rays"] and x["build_expansions"] >= 1, (x, j)
print("the budget starts at 2 MB, at 8 MB when told, and at the 16 MB limit when told more")
PY
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
printf 'sphere {\n' >"$dir/broken.pcsg"
status=0
"$trace" "$dir/broken.pcsg" --width 8 --height 6 2>"$dir/err" || status=$?
if [[ $status != 1 ]] || ! grep -q "broken.pcsg" "$dir/err"; then
    echo "expected exit status 1 and a message naming the scene, got $status:" >&2
    cat "$dir/err" >&2
    exit 1
fi
status=0
"$trace" "$scene" --width 0 2>"$dir/err" || status=$?
if [[ $status != 2 ]]; then
    echo "expected exit status 2 for --width 0, got $status" >&2
    exit 1
fi
echo "a broken scene: exit 1; --width 0: exit 2"
