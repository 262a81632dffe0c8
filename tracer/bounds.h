// Hyper-bounding boxes (the seed paper, section 5): one axis-aligned box per node of the
// cyclic graph, in the node's own frame (the frame in which the node receives the ray),
// enclosing everything the node stands for in every instance, whatever the path that led
// there. The tracer tests them in every cycle to discard rays.
//
// How they are computed (before rendering, from the graph alone):
//  - Parameter ranges: an abstract interpretation of the graph with intervals per slot
//    (interval.h) walks the graph from the axiom, applying each C-node to intervals,
//    evaluating selection functions on intervals to find the rules an S-node can take,
//    and bounding each parameter-dependent T-node matrix and primitive argument.
//    States are kept per node and per S-node depth (the number of S-nodes on the path),
//    which makes the walk acyclic: depth grows at every S-node and stops at max_depth,
//    so no widening is needed. (When max_depth times the graph size is too large for
//    that, depths beyond a cut-off share one summary state per node, computed by a
//    fixpoint with widening to infinite bounds.)
//  - Boxes: bottom-up over the same (node, depth) states: a primitive's box from its
//    (bounded) arguments; ∪ unites, ∩ intersects, \ keeps its first operand's box; a
//    T-node maps its child's box by every matrix its interval bounds allow (interval
//    arithmetic, Arvo's method for constant matrices); C-, paint- and S-nodes pass their
//    children's boxes up. Summary states are iterated from empty boxes to a candidate,
//    which is widened slightly and accepted only if it is a post-fixpoint (F(B) ⊆ B);
//    nodes where that cannot be shown get an infinite box: nothing is ever culled that
//    is there.
//  - Run-time errors count as "there": an S-node whose selection may fail (a rule number
//    out of range, no notation-B condition true) and an S-node reached beyond max_depth
//    get an infinite box at that depth, so culling never turns an error into a picture
//    of nothing. (Depths handled by the summary fixpoint do not track max_depth.)
//  - A node's box is the union over its depths. S-nodes also keep their box per depth,
//    which is tighter (the tracer knows the depth of every S-node it visits).
//
// All boxes are padded by a small relative margin, so that rounding in the ray's
// transformation to a child frame never culls a surface that touches its box.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "geometry.h"
#include "graph.h"

namespace pcsg::tracer {

struct Bounds {
    std::vector<Box> node;  // per node, in the node's own frame

    // Per-depth boxes of the S-nodes: depthBox[moduleIndex * levels + depth] for
    // depth < levels (S-node depths start at 1); deeper S-nodes use their node box.
    uint32_t levels = 0;
    std::vector<Box> depthBox;

    // Statistics for --json and tests.
    uint32_t infiniteNodes = 0;  // nodes left with an unbounded box
    uint32_t summaryFrom = 0;    // first depth handled by the summary fixpoint (0: none)

    const Box& select(const Graph& g, NodeId n, uint32_t depth) const {
        const uint32_t m = g.nodes[n].payload;
        if (depth < levels) return depthBox[static_cast<size_t>(m) * levels + depth];
        return node[n];
    }
};

struct BoundsOptions {
    // Depth levels kept exactly: at most this many (node, depth) pairs in total; beyond
    // that, a summary state per node (widening, post-fixpoint check).
    uint64_t maxStates = 400'000;
    // Kleene iterations of the summary boxes before the post-fixpoint check.
    int iterations = 60;
    // Apply the safety padding (tests of the raw analysis turn it off).
    bool pad = true;
    // The times the boxes hold for (`clock` and `frame` range over them); none: the
    // graph's time alone. An animation may compute its boxes once for all its frames.
    std::optional<TimeRange> time;
};

Bounds computeBounds(const Graph& g, const BoundsOptions& options = {});

// b (not empty) enlarged along axis i as growBox does, where an end is infinite.
Box growUnboundedBox(const Box& b, double rel, double abs);

// b enlarged on every finite side by rel * (finite extent) + abs * max(|ends|, 1).
// Inline for the bounded boxes (an expansion grows one per node and operand): one test
// of the extents stands for the tests of both ends, the same operations otherwise.
inline Box growBox(const Box& b, double rel, double abs) {
    if (b.isEmpty()) return b;
    const Vec3 extent = b.hi - b.lo;  // (finite: then both ends are)
    if (!isFinite(extent)) return growUnboundedBox(b, rel, abs);
    Box r;
    for (int i = 0; i < 3; ++i) {
        const double lo = b.lo[i], hi = b.hi[i];
        const double big = std::max(std::max(1.0, std::fabs(lo)), std::fabs(hi));
        const double m = rel * extent[i] + abs * big;
        r.lo[i] = lo - m;
        r.hi[i] = hi + m;
    }
    return r;
}
// The padding every box the tracer tests gets, so that rounding in the ray's
// transformation to a child frame never culls a surface that touches its box.
inline Box paddedBox(const Box& b) {
    return growBox(b, 1e-9, 1e-10);
}

}  // namespace pcsg::tracer
