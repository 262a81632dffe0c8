// The expander: unrolls the cyclic CSG graph into a finite CSG tree, walking the graph
// exactly as the tracer does (the one semantics of eval.h: selection, C-nodes, T-node
// matrices, instance paths and rand()). Unary nodes disappear into the primitives'
// accumulated matrices and materials; ∪ ∩ \ nodes stay as derived, with `empty`
// folded away (∪ drops it, ∩ with it is empty, A \ empty is A, empty \ B is empty) and
// operators left with one operand replaced by that operand.
//
// Both the expansion and the counting pass are sinks of the shared walk (compiler/walk.h),
// which uses an explicit stack: no recursion on the C++ stack, whatever the graph's depth.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "graph.h"
#include "subtree_count.h"
#include "walk.h"

namespace pcsg {

// One primitive of the expanded tree: its kind in its own coordinates (docs/language.md
// section 5), the accumulated object-to-world map, its material and its arguments.
struct TreePrimitive {
    Affine toWorld;             // p_world = L p_object + t
    uint32_t material = 0;      // the innermost paint's, Graph::materials (0: the default)
    uint32_t firstArg = kNone;  // ExpandedTree::args: torus R r, triangle 9 coordinates
    PrimitiveKind kind = PrimitiveKind::Sphere;
};

struct TreeNode {
    bool primitive = false;  // a primitive, else an operator
    CsgOp op = CsgOp::Union;
    uint32_t first = 0;  // primitives: index into primitives; operators: into children
    uint32_t count = 0;  // operators: the number of children (at least 2)
    // The material a paint node applied here (kNone: none), which POV-Ray gives to every
    // primitive below that has none of its own: the exporter writes it on this node, so
    // that `paint(m)` over a big union is one texture, not a copy on each primitive. The
    // root has one (the default material, 0, if no paint stands there).
    uint32_t texture = kNone;
    // For a texture with a pattern (section 10's pattern space): its paint node's frame,
    // ExpandedTree::textureFrames[textureFrame] (kNone: a plain texture, no frame needed).
    uint32_t textureFrame = kNone;

    bool is(CsgOp o) const { return !primitive && op == o; }
};

// A finite CSG tree in flat arrays. Nodes are stored in post-order: every node's
// children come before it, so a forward loop over `nodes` visits children first.
struct ExpandedTree {
    std::vector<TreeNode> nodes;
    std::vector<uint32_t> children;  // node ids, each operator's run in operand order
    std::vector<TreePrimitive> primitives;
    std::vector<double> args;
    std::vector<Affine> textureFrames;  // paint frames to world, of patterned textures
    uint32_t root = kNone;              // kNone: the scene expands to nothing

    const Affine* textureFrameOf(uint32_t n) const {
        const uint32_t f = nodes[n].textureFrame;
        return f == kNone ? nullptr : &textureFrames[f];
    }

    const uint32_t* childrenOf(uint32_t n) const { return children.data() + nodes[n].first; }
    const TreePrimitive& primitiveOf(uint32_t n) const { return primitives[nodes[n].first]; }
    bool empty() const { return root == kNone; }

    // The bytes the tree's contents occupy (exact when its vectors were reserved from a
    // count, as expand() does): the "expanded tree bytes" of the statistics.
    size_t bytes() const;
};

// What the expanded tree would hold, found without building it. Figures saturate at
// UINT64_MAX.
struct ExpansionCount {
    uint64_t primitives = 0;  // primitives the tree holds (`empty` is not one)
    uint64_t nodes = 0;       // primitives and operator nodes
    uint64_t args = 0;        // torus and triangle argument values
    bool complete = true;     // false: the work limit stopped the count (figures invalid)
    uint64_t visits = 0;      // graph nodes visited (memoised sub-graphs count once)

    // The bytes ExpandedTree::bytes() reports for a tree of this size.
    size_t treeBytes() const;
};

struct CountOptions {
    // Stop (complete = false) after this many node visits.
    uint64_t maxVisits = UINT64_MAX;
    // S-node instances counted before (InstanceBoxes::prefill's): their counts are taken
    // instead of walking below them. Null: everything is walked here.
    const KnownCounts* known = nullptr;
};

// Counts the expanded tree without building it. Sub-graphs below an S-node whose
// evaluation does not depend on the instance path (no rand() or choose() reachable) are
// memoised per (S-node, depth, values of the parameters the sub-graph reads), so a
// Sierpinski tetrahedron of order 12 counts in microseconds. Throws RuntimeError exactly
// where the expansion would.
ExpansionCount countExpansion(const Graph& g, const CountOptions& options = {});

// The node budget was exceeded (docs/language.md has no such error: it is the exporter's).
class BudgetError : public std::runtime_error {
  public:
    BudgetError(std::string message, uint64_t limit, std::optional<uint64_t> needed);
    uint64_t limit;                  // --max-nodes
    std::optional<uint64_t> needed;  // the nodes the tree would need, when known
};

struct ExpandOptions {
    uint64_t maxNodes = 10'000'000;  // --max-nodes
    // Work limit (graph-node visits) of the counting pass that runs first: it sizes the
    // arrays exactly and reports the exact need of an expansion over budget. 0: the
    // larger of 16 * maxNodes + 10^6 and 10^8.
    uint64_t countVisits = 0;
};

// Expands the graph. Throws RuntimeError (with its module path) on a run-time error of
// the scene, BudgetError when the tree would have more than maxNodes nodes.
ExpandedTree expand(const Graph& g, const ExpandOptions& options = {});

}  // namespace pcsg
