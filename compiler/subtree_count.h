// The size of an expanded sub-tree, counted without building it: the arithmetic of the
// primitive-equivalence count (povexport/expander.h, countExpansion), shared with the
// tracer's instance-box fill (tracer/instance_boxes.h), which walks the same sub-trees
// and counts them on the way, so that the count need not walk them again.
#pragma once

#include <cstdint>

#include "csg_op.h"
#include "graph.h"

namespace pcsg {

// Figures saturate at UINT64_MAX.
struct SubtreeCount {
    uint64_t prims = 0, nodes = 0, args = 0;
    bool empty = true;  // the sub-tree expands to nothing
};

namespace subtree_count_detail {
constexpr uint64_t kSat = UINT64_MAX;
constexpr uint64_t addSat(uint64_t a, uint64_t b) {
    return a > kSat - b ? kSat : a + b;
}
}  // namespace subtree_count_detail

// A primitive: one node (`empty` is none), with its argument values.
inline SubtreeCount countPrimitive(PrimitiveKind kind, uint32_t argc) {
    if (kind == PrimitiveKind::Empty) return SubtreeCount{};
    return SubtreeCount{1, 1, argc, false};
}

// An operator over its n operands' counts (operand(i) is the i-th), folded as the
// expander folds it: empty operands dropped, an operator that holds nothing is nothing,
// one with a single operand left is that operand.
template <class Operand>
SubtreeCount countOperator(CsgOp op, uint32_t n, Operand operand) {
    using subtree_count_detail::addSat;
    if (csgHoldsNothing(op, n, [&](uint32_t i) { return operand(i).empty; })) return SubtreeCount{};
    SubtreeCount sum;
    uint32_t kept = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const SubtreeCount& r = operand(i);
        if (r.empty) continue;
        sum.prims = addSat(sum.prims, r.prims);
        sum.nodes = addSat(sum.nodes, r.nodes);
        sum.args = addSat(sum.args, r.args);
        ++kept;
    }
    if (kept == 0) return SubtreeCount{};
    sum.empty = false;
    if (kept >= 2) sum.nodes = addSat(sum.nodes, 1);
    return sum;
}

// Counts of S-node instances found before the count began (by the instance-box fill),
// which the count takes instead of walking below them. `visits` is the number of node
// visits a walk below the instance makes without any memo (every visit below the
// S-node's own step), against the count's work limit.
struct KnownSubtree {
    SubtreeCount count;
    uint64_t visits = 0;
};

class KnownCounts {
  public:
    virtual ~KnownCounts() = default;
    // The instance of S-node `select` entered at `depth` (S-nodes passed before it, as
    // the walk's lookup sees it) with this frame and path, when known.
    virtual bool find(NodeId select, uint32_t depth, const double* frame, uint64_t path,
                      KnownSubtree& out) const = 0;
};

}  // namespace pcsg
