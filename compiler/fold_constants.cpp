// Constant parameters: see fold_constants.h.
#include "fold_constants.h"

#include <bit>
#include <cmath>
#include <optional>
#include <vector>

#include "eval.h"
#include "fast_code.h"

namespace pcsg {

namespace {

bool readsSlot(const Graph& g, ExprId id, Slot s) {
    const Expr& e = g.exprs[id];
    for (uint32_t pc = e.begin; pc < e.end; ++pc)
        if (g.code[pc].op == Op::Load && g.code[pc].a == s) return true;
    return false;
}

// Calls f(expr) for every expression node n evaluates when a walk visits it (for a C-node:
// all its assignments' values).
template <class F>
void forEachExpr(const Graph& g, NodeId n, F f) {
    const Node& node = g.nodes[n];
    switch (node.kind) {
        case NodeKind::Select: {
            const Module& m = g.modules[node.payload];
            if (m.select != kNone) f(m.select);
            for (ExprId c : m.conditions)
                if (c != kNone) f(c);
            break;
        }
        case NodeKind::Calc: {
            const Calc& c = g.calcs[node.payload];
            for (uint32_t i = 0; i < c.count; ++i) f(g.assignments[c.first + i].value);
            break;
        }
        case NodeKind::Transform: {
            const Transform& t = g.transforms[node.payload];
            for (uint32_t i = 0; i < t.argCount; ++i) f(g.args[t.firstArg + i]);
            break;
        }
        case NodeKind::Primitive: {
            const Primitive& p = g.primitives[node.payload];
            for (uint32_t i = 0; i < p.argCount; ++i) f(g.args[p.firstArg + i]);
            break;
        }
        default:
            break;
    }
}

// Whether every assignment to s is a constant expression with one and the same value;
// that value.
std::optional<double> constantValue(const Graph& g, Slot s) {
    std::optional<uint64_t> bits;
    for (const Assignment& a : g.assignments) {
        if (a.slot != s) continue;
        const Expr& e = g.exprs[a.value];
        if (!e.constant) return std::nullopt;
        const double v = evalExpr(g, a.value, EvalState{nullptr, kRootPath});
        if (!std::isfinite(v)) return std::nullopt;
        const uint64_t b = std::bit_cast<uint64_t>(v);
        if (bits && *bits != b) return std::nullopt;
        bits = b;
    }
    if (!bits) return std::nullopt;
    return std::bit_cast<double>(*bits);
}

// Whether some read of s can happen before s is assigned: a node reached from the axiom
// without passing a C-node that assigns s reads it, or such a C-node reads it before (or,
// for a call, while) assigning it.
bool mayReadUnassigned(const Graph& g, Slot s) {
    std::vector<uint8_t> seen(g.nodes.size(), 0);
    std::vector<NodeId> todo;
    if (g.axiom != kNone) todo.push_back(g.axiom);
    while (!todo.empty()) {
        const NodeId n = todo.back();
        todo.pop_back();
        if (seen[n]) continue;
        seen[n] = 1;
        const Node& node = g.nodes[n];
        if (node.kind == NodeKind::Calc) {
            const Calc& c = g.calcs[node.payload];
            bool assigns = false;
            for (uint32_t i = 0; i < c.count; ++i) {
                const Assignment& a = g.assignments[c.first + i];
                if (!(assigns && !c.simultaneous) && readsSlot(g, a.value, s)) return true;
                if (a.slot == s) assigns = true;
            }
            if (assigns) continue;  // below here, s holds its value
        } else {
            bool reads = false;
            forEachExpr(g, n, [&](ExprId e) { reads = reads || readsSlot(g, e, s); });
            if (reads) return true;
        }
        for (uint32_t i = 0; i < node.childCount; ++i) todo.push_back(g.child(n, i));
    }
    return false;
}

// Re-derives an expression's `constant` flag after folding, and collapses a constant one
// into a single instruction, as the builder does.
void refreshExpr(Graph& g, ExprId id) {
    Expr& e = g.exprs[id];
    if (e.constant) return;
    for (uint32_t pc = e.begin; pc < e.end; ++pc) {
        const Op op = g.code[pc].op;
        if (op == Op::Load || op == Op::Rand0 || op == Op::Choose || op == Op::Clock ||
            op == Op::Frame)
            return;
    }
    e.constant = true;
    if (e.end - e.begin > 1) {
        const double v = evalExpr(g, id, EvalState{nullptr, kRootPath});
        g.code[e.begin] = Instr{Op::Const, 0, 0, v};
        e.end = e.begin + 1;
        e.maxStack = 1;
    }
}

// The arguments' values when all are constant and finite.
bool constantArgs(const Graph& g, uint32_t first, uint32_t count, std::vector<double>& values) {
    values.clear();
    for (uint32_t i = 0; i < count; ++i) {
        const ExprId id = g.args[first + i];
        if (!g.exprs[id].constant) return false;
        const double v = evalExpr(g, id, EvalState{nullptr, kRootPath});
        if (!std::isfinite(v)) return false;
        values.push_back(v);
    }
    return true;
}

}  // namespace

size_t foldConstantParameters(Graph& g) {
    if (g.axiom == kNone) return 0;
    dropFastCode(g);  // it rewrites the code; the compiler builds the fast form after
    // Each slot is checked against the whole graph: skip graphs where that would be a lot
    // of work (huge generated files); they are only slower to render, never wrong.
    const uint64_t work = static_cast<uint64_t>(g.slotCount()) *
                          (g.nodes.size() + g.code.size() + g.assignments.size());
    if (work > 200'000'000) return 0;
    std::vector<uint8_t> folded(g.slotCount(), 0);
    size_t count = 0;
    for (bool changed = true; changed;) {
        changed = false;
        for (Slot s = 0; s < g.slotCount(); ++s) {
            if (folded[s]) continue;
            const std::optional<double> v = constantValue(g, s);
            if (!v || mayReadUnassigned(g, s)) continue;
            for (Instr& in : g.code)
                if (in.op == Op::Load && in.a == s) in = Instr{Op::Const, 0, 0, *v};
            folded[s] = 1;
            ++count;
            changed = true;
            for (ExprId id = 0; id < g.exprs.size(); ++id) refreshExpr(g, id);
        }
    }
    if (count == 0) return 0;
    std::vector<double> values;
    for (Transform& t : g.transforms) {
        if (t.constant || !constantArgs(g, t.firstArg, t.argCount, values)) continue;
        if (const std::optional<Affine> m = constantTransform(t.op, values.data())) {
            t.constant = true;
            t.matrix = *m;
        }
    }
    for (Primitive& p : g.primitives) {
        if (p.constant || !constantArgs(g, p.firstArg, p.argCount, values)) continue;
        p.constant = true;
        p.values = values;
    }
    return count;
}

}  // namespace pcsg
