// What each module's sub-graph depends on: see walk.h.
#include "walk.h"

#include <algorithm>

namespace pcsg {

namespace {

void exprInfo(const Graph& g, ExprId id, bool& usesPath, bool& usesTime,
              std::vector<uint8_t>& readSet) {
    if (id == kNone || id >= g.exprs.size()) return;
    const Expr& e = g.exprs[id];
    if (e.usesPath) usesPath = true;
    if (e.usesTime) usesTime = true;
    for (uint32_t pc = e.begin; pc < e.end; ++pc) {
        const Instr& in = g.code[pc];
        if (in.op == Op::Load && in.a < readSet.size()) readSet[in.a] = 1;
        // Belt and braces: an expression that says it does not use the path but calls
        // rand() or choose() still does.
        if (in.op == Op::Rand0 || in.op == Op::Choose) usesPath = true;
        if (in.op == Op::Clock || in.op == Op::Frame) usesTime = true;
    }
}

void nodeInfo(const Graph& g, NodeId n, bool& usesPath, bool& usesTime,
              std::vector<uint8_t>& readSet) {
    const Node& node = g.nodes[n];
    switch (node.kind) {
        case NodeKind::Select: {
            const Module& m = g.modules[node.payload];
            exprInfo(g, m.select, usesPath, usesTime, readSet);
            for (ExprId c : m.conditions) exprInfo(g, c, usesPath, usesTime, readSet);
            break;
        }
        case NodeKind::Calc: {
            const Calc& c = g.calcs[node.payload];
            for (uint32_t i = 0; i < c.count; ++i)
                exprInfo(g, g.assignments[c.first + i].value, usesPath, usesTime, readSet);
            break;
        }
        case NodeKind::Transform: {
            const Transform& t = g.transforms[node.payload];
            if (!t.constant)
                for (uint32_t i = 0; i < t.argCount; ++i)
                    exprInfo(g, g.args[t.firstArg + i], usesPath, usesTime, readSet);
            break;
        }
        case NodeKind::Primitive: {
            const Primitive& p = g.primitives[node.payload];
            if (!p.constant)
                for (uint32_t i = 0; i < p.argCount; ++i)
                    exprInfo(g, g.args[p.firstArg + i], usesPath, usesTime, readSet);
            break;
        }
        default:
            break;
    }
}

}  // namespace

// One depth-first search per module over everything reachable from its S-node. When
// that would be too much work (a huge graph with many modules), nothing is memoised:
// the count stays correct, only slower.
std::vector<ModuleDependencies> moduleDependencies(const Graph& g) {
    std::vector<ModuleDependencies> info(g.modules.size());
    const uint64_t work =
        static_cast<uint64_t>(g.modules.size()) * (g.nodes.size() + g.edges.size());
    if (work > 50'000'000) return info;
    std::vector<uint32_t> seen(g.nodes.size(), UINT32_MAX);
    std::vector<uint8_t> readSet(g.slotCount());
    std::vector<NodeId> todo;
    for (uint32_t m = 0; m < g.modules.size(); ++m) {
        const NodeId start = g.modules[m].node;
        if (start == kNone || start >= g.nodes.size()) continue;
        std::fill(readSet.begin(), readSet.end(), 0);
        bool usesPath = false, usesTime = false;
        todo.assign(1, start);
        seen[start] = m;
        while (!todo.empty()) {
            const NodeId n = todo.back();
            todo.pop_back();
            nodeInfo(g, n, usesPath, usesTime, readSet);
            const Node& node = g.nodes[n];
            for (uint32_t i = 0; i < node.childCount; ++i) {
                const NodeId c = g.child(n, i);
                if (c < g.nodes.size() && seen[c] != m) {
                    seen[c] = m;
                    todo.push_back(c);
                }
            }
        }
        info[m].analysed = true;
        info[m].usesPath = usesPath;
        info[m].usesTime = usesTime;
        for (Slot s = 0; s < readSet.size(); ++s)
            if (readSet[s]) info[m].reads.push_back(s);
    }
    return info;
}

}  // namespace pcsg
