// The parameters an instance key must hash: see key_slots.h.
#include "key_slots.h"

#include <algorithm>
#include <cstdint>

namespace pcsg::tracer {

namespace {

// Beyond this many word operations (a huge graph), the reads stay as they are.
constexpr uint64_t kMaxWork = 50'000'000;

// A set of slots, one per node, as words.
class SlotSets {
  public:
    SlotSets(size_t nodes, size_t slots) : words_((slots + 63) / 64), bits_(nodes * words_, 0) {}
    size_t words() const { return words_; }
    uint64_t* of(NodeId n) { return bits_.data() + static_cast<size_t>(n) * words_; }
    static bool has(const uint64_t* set, Slot s) { return (set[s / 64] >> (s % 64)) & 1; }
    static void add(uint64_t* set, Slot s) { set[s / 64] |= uint64_t{1} << (s % 64); }
    static void remove(uint64_t* set, Slot s) { set[s / 64] &= ~(uint64_t{1} << (s % 64)); }

  private:
    size_t words_;
    std::vector<uint64_t> bits_;
};

void addReads(const Graph& g, ExprId id, uint64_t* set) {
    if (id == kNone || id >= g.exprs.size()) return;
    const Expr& e = g.exprs[id];
    for (uint32_t pc = e.begin; pc < e.end; ++pc)
        if (g.code[pc].op == Op::Load && g.code[pc].a < g.slotCount())
            SlotSets::add(set, g.code[pc].a);
}

void addArgReads(const Graph& g, uint32_t first, uint32_t count, uint64_t* set) {
    for (uint32_t i = 0; i < count; ++i) addReads(g, g.args[first + i], set);
}

// The slots whose values on entry to n can be read below it (before an assignment), from
// those of its children: into `out`.
void liveIn(const Graph& g, NodeId n, SlotSets& live, std::vector<uint64_t>& out) {
    std::fill(out.begin(), out.end(), 0);
    const Node& node = g.nodes[n];
    for (uint32_t i = 0; i < node.childCount; ++i) {
        const NodeId c = g.child(n, i);
        if (c >= g.nodes.size()) continue;
        const uint64_t* below = live.of(c);
        for (size_t w = 0; w < out.size(); ++w) out[w] |= below[w];
    }
    switch (node.kind) {
        case NodeKind::Select: {
            const Module& m = g.modules[node.payload];
            addReads(g, m.select, out.data());
            for (ExprId c : m.conditions) addReads(g, c, out.data());
            return;
        }
        case NodeKind::Calc: {
            const Calc& c = g.calcs[node.payload];
            const Assignment* as = g.assignments.data() + c.first;
            if (c.simultaneous) {
                for (uint32_t i = 0; i < c.count; ++i) SlotSets::remove(out.data(), as[i].slot);
                for (uint32_t i = 0; i < c.count; ++i) addReads(g, as[i].value, out.data());
                return;
            }
            for (uint32_t i = c.count; i-- > 0;) {  // in order: the last assignment first
                SlotSets::remove(out.data(), as[i].slot);
                addReads(g, as[i].value, out.data());
            }
            return;
        }
        case NodeKind::Transform: {
            const Transform& t = g.transforms[node.payload];
            if (!t.constant) addArgReads(g, t.firstArg, t.argCount, out.data());
            return;
        }
        case NodeKind::Primitive: {
            const Primitive& p = g.primitives[node.payload];
            if (!p.constant) addArgReads(g, p.firstArg, p.argCount, out.data());
            return;
        }
        case NodeKind::Paint:
        case NodeKind::Operator:
            return;
    }
    std::fill(out.begin(), out.end(), ~uint64_t{0});  // (an unknown kind: everything)
}

std::vector<std::vector<NodeId>> parentsOf(const Graph& g) {
    std::vector<std::vector<NodeId>> parents(g.nodes.size());
    for (NodeId n = 0; n < g.nodes.size(); ++n)
        for (uint32_t i = 0; i < g.nodes[n].childCount; ++i)
            if (g.child(n, i) < g.nodes.size()) parents[g.child(n, i)].push_back(n);
    return parents;
}

// Live slots on entry to every node: a backward fixpoint. False: too much work.
bool liveSlots(const Graph& g, SlotSets& live) {
    const auto parents = parentsOf(g);
    std::vector<NodeId> todo(g.nodes.size());
    std::vector<uint8_t> queued(g.nodes.size(), 1);
    for (NodeId n = 0; n < g.nodes.size(); ++n) todo[n] = n;
    std::vector<uint64_t> now(live.words());
    uint64_t work = 0;
    while (!todo.empty()) {
        const NodeId n = todo.back();
        todo.pop_back();
        queued[n] = 0;
        liveIn(g, n, live, now);
        work += (g.nodes[n].childCount + 1) * live.words() + 16;
        if (work > kMaxWork) return false;
        uint64_t* old = live.of(n);
        if (std::equal(now.begin(), now.end(), old)) continue;
        std::copy(now.begin(), now.end(), old);
        for (NodeId p : parents[n])
            if (!queued[p]) queued[p] = 1, todo.push_back(p);
    }
    return true;
}

}  // namespace

void narrowKeySlots(const Graph& g, const FixedSlots& fixed,
                    std::vector<ModuleDependencies>& deps) {
    if (static_cast<uint64_t>(g.nodes.size()) * (g.slotCount() + 64) > kMaxWork) return;
    SlotSets live(g.nodes.size(), g.slotCount());
    if (!liveSlots(g, live)) return;
    for (size_t m = 0; m < deps.size() && m < g.modules.size(); ++m) {
        const NodeId s = g.modules[m].node;
        if (!deps[m].analysed || s >= g.nodes.size()) continue;
        std::erase_if(deps[m].reads, [&](Slot slot) {
            return slot < g.slotCount() &&
                   (!SlotSets::has(live.of(s), slot) || fixed.fixed(s, slot));
        });
    }
}

}  // namespace pcsg::tracer
