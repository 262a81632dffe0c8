// The builder's checks on the finished graph: triangles under ∩ and \ (docs/language.md
// section 5). See build_checks.h.
#include "build_checks.h"

#include <fmt/format.h>

namespace pcsg {

namespace {

// Each node's parents, as a compressed adjacency list: the parents of node n are
// parents[start[n], start[n+1]).
struct Parents {
    std::vector<uint32_t> start;
    std::vector<NodeId> parents;
};

Parents parentsOf(const Graph& g) {
    const size_t count = g.nodes.size();
    Parents p;
    p.start.assign(count + 1, 0);
    for (NodeId i = 0; i < count; ++i)
        for (uint32_t k = 0; k < g.nodes[i].childCount; ++k) {
            const NodeId c = g.child(i, k);
            if (c < count) ++p.start[c + 1];
        }
    for (size_t i = 0; i < count; ++i) p.start[i + 1] += p.start[i];
    p.parents.resize(p.start[count]);
    std::vector<uint32_t> fill(p.start.begin(), p.start.end() - 1);
    for (NodeId i = 0; i < count; ++i)
        for (uint32_t k = 0; k < g.nodes[i].childCount; ++k) {
            const NodeId c = g.child(i, k);
            if (c < count) p.parents[fill[c]++] = i;
        }
    return p;
}

// For every node, a triangle reachable from it (kNone: none), by a breadth-first search
// up the edges from the triangles; empty when the graph has no triangle.
std::vector<NodeId> reachableTriangles(const Graph& g) {
    const size_t count = g.nodes.size();
    std::vector<NodeId> source(count, kNone);
    std::vector<NodeId> queue;
    for (NodeId i = 0; i < count; ++i) {
        const Node& n = g.nodes[i];
        if (n.kind == NodeKind::Primitive && isTriangle(g.primitives[n.payload].kind)) {
            source[i] = i;
            queue.push_back(i);
        }
    }
    if (queue.empty()) return {};
    const Parents p = parentsOf(g);
    for (size_t q = 0; q < queue.size(); ++q) {
        const NodeId n = queue[q];
        for (uint32_t k = p.start[n]; k < p.start[n + 1]; ++k) {
            const NodeId parent = p.parents[k];
            if (source[parent] != kNone) continue;
            source[parent] = source[n];
            queue.push_back(parent);
        }
    }
    return source;
}

}  // namespace

void checkTriangles(BuildContext& ctx) {
    const Graph& g = ctx.g;
    const std::vector<NodeId> source = reachableTriangles(g);
    if (source.empty()) return;
    const size_t count = g.nodes.size();
    for (NodeId i = 0; i < count; ++i) {
        const Node& n = g.nodes[i];
        if (n.kind != NodeKind::Operator || n.op() == CsgOp::Union) continue;
        for (uint32_t k = 0; k < n.childCount; ++k) {
            const NodeId c = g.child(i, k);
            if (c >= count || source[c] == kNone) continue;
            const Node& tri = g.nodes[source[c]];
            ctx.diags.error(
                n.loc,
                fmt::format("a triangle ({} at line {}) is reachable as an operand of this {}: "
                            "triangles are surfaces without an inside, so only '∪' may "
                            "combine them",
                            primitiveName(g.primitives[tri.payload].kind), tri.loc.line,
                            csgOpName(n.op())));
            break;
        }
    }
}

}  // namespace pcsg
