#!/usr/bin/env python3
"""Predicts the speed-up of `mpirun -np P pcsg render` from measured per-tile costs.

    python3 tools/dev/mpi_schedule_sim.py TILES.csv --render-json RENDER.json [options]
    python3 tools/dev/mpi_schedule_sim.py --self-test

TILES.csv is what `pcsg render --tile-times TILES.csv` writes for a one-process render
(pass,x0,y0,x1,y1,seconds: every 16x16 tile of pass 1, the pixel centres, and of pass 2,
adaptive supersampling); RENDER.json is the same render's --json output (image size, compile
and bounds time, image write time). docs/distributed.md shows a run on the terrain.

The model (docs/distributed.md states the assumptions):
  - Units are cut as tools/cli/work_plan.cpp cuts them (guided self-scheduling over 32x32
    tiles: ceil(R / (f P)) of the R tiles left, f = min(16, 2P), whole rows or part of one
    row). Keep the two in step. Two units are in flight per rank.
  - Each rank's first tiles pay a warm-up (caches the tracer fills lazily, the same on every
    rank): the --warmup-tiles costliest tiles of the measurement are taken out of the work
    and paid by every rank before it renders.
  - A unit's cost on a rank is the measured cost of its tiles divided by the rank's cores
    (--cores), plus pass 1 over its one-pixel border (adaptive sampling reads the neighbours'
    centres), at the pass-1 cost per pixel of the tile beside it; never less than its
    costliest tile (a tile is not split between threads).
  - Every rank compiles the scene and computes the bounds before it renders (in parallel:
    a constant); rank 0 writes the image after the last unit (serial).
  - Messages: a latency (--latency) each way; a result carries 12 bytes per pixel (linear
    float RGB) and all results share rank 0's network link (--bandwidth bytes/s), one after
    another. Rank 0's own units send nothing.
  - Rank 0's main thread handles each result (--handle seconds, plus copying its pixels at
    --copy-bandwidth) one at a time and answers with the next unit; it polls every --poll
    seconds when idle (half of that on average). Its handling time is taken from rank 0's
    rendering (the same cores).
Efficiency = T(1) / (P T(P)).
"""
import argparse
import csv
import heapq
import json
import math
import sys

WORK_TILE = 32  # tools/cli/work_plan.h kWorkTile
MAX_GUIDED_FACTOR = 16  # tools/cli/work_plan.h: a unit is ceil(R / (min(16, 2P) P)) tiles
TRACE_TILE = 16  # tracer/render.cpp kTile: the tiles of --tile-times


def plan_units(width, height, ranks, frames=1, tile=WORK_TILE, factor=None):
    """The units of tools/cli/work_plan.cpp, as (frame, x0, y0, x1, y1)."""
    tiles_x, tiles_y = -(-width // tile), -(-height // tile)
    frame_tiles = tiles_x * tiles_y
    left = frame_tiles * frames
    whole = frames >= ranks
    factor = factor or min(MAX_GUIDED_FACTOR, 2 * ranks)
    units = []
    for frame in range(frames):
        at = 0
        while at < frame_tiles:
            row, col = divmod(at, tiles_x)
            take = frame_tiles if whole else max(1, -(-left // (factor * ranks)))
            if col == 0 and take >= tiles_x:
                rows = min(take // tiles_x, tiles_y - row)
                units.append((frame, 0, row * tile, width, min(height, (row + rows) * tile)))
                taken = rows * tiles_x
            else:
                n = min(take, tiles_x - col)
                units.append((frame, col * tile, row * tile, min(width, (col + n) * tile),
                              min(height, (row + 1) * tile)))
                taken = n
            at += taken
            left -= taken
    return units


class TileCosts:
    """Pass-1 and pass-2 seconds of each 16x16 tile, and the unit costs made of them."""

    def __init__(self, width, height, rows):
        self.width, self.height = width, height
        self.tx, self.ty = -(-width // TRACE_TILE), -(-height // TRACE_TILE)
        self.pass1 = [[0.0] * self.tx for _ in range(self.ty)]
        self.pass2 = [[0.0] * self.tx for _ in range(self.ty)]
        for p, x0, y0, _x1, y1, s in rows:
            grid = self.pass1 if p == 1 else self.pass2
            # (by the tile's middle row: pass 2's tiles are the bands shifted up a row)
            j = min(self.ty - 1, (y0 + y1) // 2 // TRACE_TILE)
            grid[j][x0 // TRACE_TILE] += s

    def take_warmup(self, n):
        """Moves the n costliest tiles' excess over their neighbours' median into a
        per-rank warm-up (each thread's first tile pays for caches the tracer fills
        lazily, the same on every rank); returns the warm-up in seconds."""
        both = [[self.pass1[j][i] + self.pass2[j][i] for i in range(self.tx)]
                for j in range(self.ty)]
        worst = sorted(((both[j][i], i, j) for j in range(self.ty) for i in range(self.tx)),
                       reverse=True)[:n]
        warmup = 0.0
        for cost, i, j in worst:
            around = sorted(both[y][x] for y in range(max(0, j - 1), min(self.ty, j + 2))
                            for x in range(max(0, i - 1), min(self.tx, i + 2)) if (x, y) != (i, j))
            normal = around[len(around) // 2]
            scale = normal / cost if cost > 0 else 1.0
            self.pass1[j][i] *= scale
            self.pass2[j][i] *= scale
            warmup = max(warmup, cost - normal)
        return warmup

    def total(self):
        return sum(map(sum, self.pass1)) + sum(map(sum, self.pass2))

    def pixel_cost1(self, i, j):
        """Pass-1 seconds per pixel in 16x16 tile (i, j)."""
        w = min(self.width, (i + 1) * TRACE_TILE) - i * TRACE_TILE
        h = min(self.height, (j + 1) * TRACE_TILE) - j * TRACE_TILE
        return self.pass1[j][i] / (w * h)

    def line_cost1(self, x0, x1, y0, y1):
        """Pass 1 over the pixels [x0, x1) x [y0, y1) (a row or column of the border)."""
        if x0 < 0 or y0 < 0 or x1 > self.width or y1 > self.height or x0 >= x1 or y0 >= y1:
            return 0.0
        cost = 0.0
        for j in range(y0 // TRACE_TILE, -(-y1 // TRACE_TILE)):
            for i in range(x0 // TRACE_TILE, -(-x1 // TRACE_TILE)):
                w = min(x1, (i + 1) * TRACE_TILE) - max(x0, i * TRACE_TILE)
                h = min(y1, (j + 1) * TRACE_TILE) - max(y0, j * TRACE_TILE)
                cost += self.pixel_cost1(i, j) * w * h
        return cost

    def unit_cost(self, x0, y0, x1, y1, cores, adaptive=True):
        tiles = [self.pass1[j][i] + self.pass2[j][i]
                 for j in range(y0 // TRACE_TILE, -(-y1 // TRACE_TILE))
                 for i in range(x0 // TRACE_TILE, -(-x1 // TRACE_TILE))]
        border = 0.0
        if adaptive:  # the one-pixel border's centres, clipped to the image
            bx0, bx1 = max(0, x0 - 1), min(self.width, x1 + 1)
            border = (self.line_cost1(bx0, bx1, y0 - 1, y0) + self.line_cost1(bx0, bx1, y1, y1 + 1)
                      + self.line_cost1(x0 - 1, x0, y0, y1) + self.line_cost1(x1, x1 + 1, y0, y1))
        return max(sum(tiles) / cores + border / cores, max(tiles))


def simulate(costs, ranks, m):
    """The wall time of the render on `ranks` ranks, and what limited it (a dict)."""
    units = plan_units(costs.width, costs.height, ranks, factor=m.factor)
    unit_cost = [costs.unit_cost(u[1], u[2], u[3], u[4], m.cores, m.adaptive) for u in units]
    ev = []  # (time, order, kind, rank, unit)
    order = [0]

    def push(t, kind, rank, unit):
        order[0] += 1
        heapq.heappush(ev, (t, order[0], kind, rank, unit))

    setup = m.setup + getattr(m, "warmup", 0.0)
    nxt = 0
    queue = [[] for _ in range(ranks)]
    busy_until = [setup] * ranks
    idle = [True] * ranks
    master_cpu = setup
    nic_free = setup
    master_busy = nic_busy = 0.0
    for _ in range(2):  # two in flight per rank
        for r in range(ranks):
            if nxt < len(units):
                push(setup + (m.latency if r else 0), "arrive", r, nxt)
                nxt += 1
    end = setup

    def start(r, t):
        if queue[r]:
            u = queue[r].pop(0)
            idle[r] = False
            push(t + unit_cost[u], "finish", r, u)
        else:
            idle[r] = True

    while ev:
        t, _, kind, r, u = heapq.heappop(ev)
        if kind == "arrive":
            queue[r].append(u)
            if idle[r]:
                start(r, max(t, busy_until[r]))
        elif kind == "finish":
            busy_until[r] = t
            start(r, t)
            x0, y0, x1, y1 = units[u][1:]
            nbytes = 12 * (x1 - x0) * (y1 - y0) + 128
            arrive = t
            if r:
                begin = max(t + m.latency, nic_free)
                nic_free = begin + nbytes / m.bandwidth
                nic_busy += nbytes / m.bandwidth
                arrive = nic_free
            handle = m.handle + nbytes / m.copy_bandwidth
            begin = max(arrive + m.poll / 2, master_cpu)
            master_cpu = begin + handle
            master_busy += handle
            end = max(end, master_cpu)
            if nxt < len(units):
                push(master_cpu + (m.latency if r else 0), "arrive", r, nxt)
                nxt += 1
    # Rank 0's handling took time from its rendering: spread over the ranks' work.
    wall = end + m.write + master_busy * (1.0 / ranks if ranks > 1 else 0.0)
    return {"wall": wall, "units": len(units), "master_busy": master_busy,
            "nic_busy": nic_busy, "render_span": end - setup,
            "last_unit": max(unit_cost[-min(len(units), 2 * ranks):])}


def table(costs, m, ranks_list):
    t1 = simulate(costs, 1, m)["wall"]
    rows = []
    for p in ranks_list:
        s = simulate(costs, p, m)
        span = s["render_span"]
        rows.append({"ranks": p, "wall": s["wall"], "speedup": t1 / s["wall"],
                     "efficiency": t1 / (p * s["wall"]), "units": s["units"],
                     "master_share": s["master_busy"] / span if span else 0,
                     "link_share": s["nic_busy"] / span if span else 0,
                     "serial_share": (m.setup + getattr(m, "warmup", 0.0) + m.write) / s["wall"]})
    return t1, rows


def read_tiles(path):
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            rows.append((int(r["pass"]), int(r["x0"]), int(r["y0"]), int(r["x1"]),
                         int(r["y1"]), float(r["seconds"])))
    return rows


def print_table(t1, rows, m):
    print(f"one rank: {t1:.2f} s (set-up {m.setup:.3f} s, warm-up {m.warmup:.3f} s, "
          f"write {m.write:.3f} s, {m.cores} core(s) per rank, guided factor "
          f"{m.factor or 'min(16, 2P)'})")
    print(" ranks   wall s  speed-up  efficiency  units  master busy  link busy  serial")
    for r in rows:
        print(f"{r['ranks']:6d} {r['wall']:8.3f} {r['speedup']:9.1f} {r['efficiency']:10.0%} "
              f"{r['units']:6d} {r['master_share']:11.1%} {r['link_share']:10.1%} "
              f"{r['serial_share']:7.1%}")


def self_test():
    # The plan is work_plan.cpp's (its test: 64x64, tiles of 16, two ranks).
    sizes = [(u[3] - u[1]) * (u[4] - u[2]) // 256 for u in plan_units(64, 64, 2, tile=16)]
    assert sizes == [2, 2, 2, 2] + [1] * 8, sizes
    assert len(plan_units(64, 64, 1, tile=16)) == 1
    for w, h, p in [(1000, 700, 4), (1920, 1080, 64), (100, 60, 8)]:
        cover = [[0] * w for _ in range(h)]
        for _, x0, y0, x1, y1 in plan_units(w, h, p):
            for y in range(y0, y1):
                for x in range(x0, x1):
                    cover[y][x] += 1
        assert all(c == 1 for row in cover for c in row), (w, h, p)
    # Uniform tiles, free messages: near-perfect scaling; one rank is the sum.
    rows = [(1, x, y, x + 16, y + 16, 0.01) for y in range(0, 512, 16) for x in range(0, 512, 16)]
    costs = TileCosts(512, 512, rows)
    free = argparse.Namespace(factor=None, cores=1, adaptive=False, setup=0.0, write=0.0, latency=0.0,
                              bandwidth=1e18, copy_bandwidth=1e18, handle=0.0, poll=0.0)
    assert abs(simulate(costs, 1, free)["wall"] - costs.total()) < 1e-9
    _, rows8 = table(costs, free, [8])
    assert rows8[0]["efficiency"] > 0.95, rows8
    # A slow link: the gather bounds the wall time from below.
    slow = argparse.Namespace(**{**vars(free), "bandwidth": 1e6})
    s = simulate(costs, 16, slow)
    assert s["wall"] >= 512 * 512 * 12 * (15 / 16) / 1e6 * 0.99, s
    # The serial parts bound the speed-up (Amdahl).
    serial = argparse.Namespace(**{**vars(free), "setup": 1.0, "write": 1.0})
    t1, rows64 = table(costs, serial, [64])
    assert rows64[0]["speedup"] < t1 / 2.0, rows64
    print("mpi_schedule_sim self-test: ok")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("tiles", nargs="?")
    ap.add_argument("--render-json", help="the render's --json output")
    ap.add_argument("--cores", type=int, default=1, help="cores per rank (default 1)")
    ap.add_argument("--latency", type=float, default=20e-6, help="one way, s (20e-6)")
    ap.add_argument("--bandwidth", type=float, default=1.1e9,
                    help="rank 0's link, bytes/s (1.1e9: 10 Gb Ethernet)")
    ap.add_argument("--copy-bandwidth", type=float, default=5e9,
                    help="rank 0 placing pixels into the image, bytes/s")
    ap.add_argument("--handle", type=float, default=20e-6, help="rank 0's work per result, s")
    ap.add_argument("--poll", type=float, default=300e-6, help="rank 0's poll sleep, s")
    ap.add_argument("--ranks", default="1,2,4,8,16,32,64,128,256")
    ap.add_argument("--factor", type=int, default=None,
                    help="guided factor f: a unit is ceil(R / (f P)) tiles (min(16, 2P))")
    ap.add_argument("--write", type=float, default=None,
                    help="rank 0's image write, s (default: the render's image_write_seconds)")
    ap.add_argument("--setup", type=float, default=None,
                    help="each rank's compile and bounds, s (default: the render's)")
    ap.add_argument("--warmup-tiles", type=int, default=2,
                    help="the costliest tiles taken as each rank's warm-up (default 2: the "
                         "first tile of each of the measured run's 2 threads)")
    ap.add_argument("--no-warmup", action="store_true",
                    help="take the warm-up tiles out and charge no warm-up (what if it were free)")
    ap.add_argument("--json", action="store_true", help="print the table as JSON")
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        self_test()
        return 0
    if not a.tiles or not a.render_json:
        ap.error("TILES.csv and --render-json are needed (or --self-test)")
    info = json.load(open(a.render_json))
    costs = TileCosts(info["width"], info["height"], read_tiles(a.tiles))
    a.adaptive = float(info.get("adaptive", 0)) > 0
    a.warmup = 0.0 if a.no_warmup else costs.take_warmup(a.warmup_tiles)
    if a.no_warmup:
        costs.take_warmup(a.warmup_tiles)
    if a.setup is None:
        a.setup = float(info.get("parse_seconds", 0)) + float(info.get("bounds_seconds", 0))
    if a.write is None:
        a.write = float(info.get("image_write_seconds", 0))
    t1, rows = table(costs, a, [int(p) for p in a.ranks.split(",")])
    if a.json:
        print(json.dumps({"one_rank_seconds": t1, "warmup_seconds": a.warmup, "rows": rows},
                         indent=2))
    else:
        print_table(t1, rows, a)
    return 0


if __name__ == "__main__":
    sys.exit(main())
