// Parameters with one value in every walk: see fixed_slots.h.
#include "fixed_slots.h"

#include <algorithm>
#include <bit>
#include <cstdint>

#include "eval.h"

namespace pcsg {

namespace {

// Beyond this many slot operations (a huge graph), nothing is fixed.
constexpr uint64_t kMaxWork = 50'000'000;

struct Value {
    bool fixed = false;  // false: varies (or unknown)
    double v = 0;
};
using State = std::vector<Value>;

// The value of an expression when it depends on fixed values alone, else not fixed.
Value evalFixed(const Graph& g, ExprId id, const State& in, std::vector<double>& frame) {
    if (id == kNone || id >= g.exprs.size()) return {};
    const Expr& e = g.exprs[id];
    if (e.usesPath || e.usesTime) return {};
    for (uint32_t pc = e.begin; pc < e.end; ++pc) {
        const Instr& instr = g.code[pc];
        if (instr.op == Op::Rand0 || instr.op == Op::Choose || instr.op == Op::Clock ||
            instr.op == Op::Frame)
            return {};
        if (instr.op == Op::Load && (instr.a >= in.size() || !in[instr.a].fixed)) return {};
    }
    for (size_t s = 0; s < in.size(); ++s) frame[s] = in[s].v;
    try {
        return {true, evalExpr(g, id, EvalState{frame.data(), kRootPath})};
    } catch (const RuntimeError&) {
        return {};
    }
}

// A C-node's outgoing values.
State calcOut(const Graph& g, const Calc& c, const State& in, std::vector<double>& frame) {
    State out = in;
    const Assignment* as = g.assignments.data() + c.first;
    if (!c.simultaneous) {
        for (uint32_t i = 0; i < c.count; ++i)
            if (as[i].slot < out.size()) out[as[i].slot] = evalFixed(g, as[i].value, out, frame);
        return out;
    }
    std::vector<Value> values(c.count);
    for (uint32_t i = 0; i < c.count; ++i) values[i] = evalFixed(g, as[i].value, in, frame);
    for (uint32_t i = 0; i < c.count; ++i)
        if (as[i].slot < out.size()) out[as[i].slot] = values[i];
    return out;
}

// Joins `from` into a node's values; whether they changed.
bool join(State& into, const State& from) {
    bool changed = false;
    for (size_t s = 0; s < into.size(); ++s) {
        Value& a = into[s];
        if (a.fixed && (!from[s].fixed ||
                        std::bit_cast<uint64_t>(a.v) != std::bit_cast<uint64_t>(from[s].v))) {
            a.fixed = false;
            changed = true;
        }
    }
    return changed;
}

// The values on entry to every node reached from the axiom (empty: not reached). False:
// too much work.
bool propagate(const Graph& g, std::vector<State>& states) {
    const size_t slots = g.slotCount();
    states.assign(g.nodes.size(), State{});
    if (g.axiom >= g.nodes.size()) return true;
    std::vector<double> frame(std::max<size_t>(slots, 1));
    initFrame(g, frame.data());
    states[g.axiom].resize(slots);
    for (size_t s = 0; s < slots; ++s) states[g.axiom][s] = {true, frame[s]};
    std::vector<NodeId> todo{g.axiom};
    uint64_t work = 0;
    while (!todo.empty()) {
        const NodeId n = todo.back();
        todo.pop_back();
        const Node& node = g.nodes[n];
        const State out = node.kind == NodeKind::Calc
                              ? calcOut(g, g.calcs[node.payload], states[n], frame)
                              : states[n];
        for (uint32_t i = 0; i < node.childCount; ++i) {
            const NodeId c = g.child(n, i);
            if (c >= g.nodes.size()) continue;
            work += slots + 16;
            if (work > kMaxWork) return false;
            if (states[c].empty()) {
                states[c] = out;
                todo.push_back(c);
            } else if (join(states[c], out)) {
                todo.push_back(c);
            }
        }
    }
    return true;
}

}  // namespace

FixedSlots::FixedSlots(const Graph& g) : slots_(g.slotCount()) {
    if (static_cast<uint64_t>(g.nodes.size()) * (slots_ + 16) > kMaxWork) return;
    std::vector<State> states;
    if (!propagate(g, states)) return;
    first_.assign(g.nodes.size(), kNone);
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        if (states[n].empty()) continue;
        first_[n] = static_cast<uint32_t>(fixed_.size());
        for (const Value& v : states[n]) fixed_.push_back(v.fixed ? 1 : 0);
    }
}

}  // namespace pcsg
