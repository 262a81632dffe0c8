// The walker's memory of C- and T-steps: see step_memo.h.
#include "step_memo.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <type_traits>
#include <utility>

namespace pcsg {

namespace {

// Slots a key need not hold: fixed ones, and those the C-node has assigned already.
struct Unread {
    const FixedSlots* fixed;
    NodeId node;
    const std::vector<Slot>* assigned;
    bool operator()(Slot s) const {
        return (fixed && fixed->fixed(node, s)) ||
               std::find(assigned->begin(), assigned->end(), s) != assigned->end();
    }
};

// What one expression reads, added to `reads` (without repeats).
void addReads(const Graph& g, ExprId id, std::vector<uint32_t>& reads, bool& usesPath,
              const Unread& unread) {
    const Expr& e = g.exprs[id];
    for (uint32_t pc = e.begin; pc < e.end; ++pc) {
        const Instr& in = g.code[pc];
        uint32_t r;
        if (in.op == Op::Load && unread(in.a))
            continue;
        else if (in.op == Op::Load)
            r = in.a;
        else if (in.op == Op::Clock)
            r = StepMemoPlan::kClock;
        else if (in.op == Op::Frame)
            r = StepMemoPlan::kFrame;
        else {
            if (in.op == Op::Rand0 || in.op == Op::Choose) usesPath = true;
            continue;
        }
        if (std::find(reads.begin(), reads.end(), r) == reads.end()) reads.push_back(r);
    }
}

// Doubles differ in their high bits (exponent and leading mantissa), so each value is
// folded down as it is added, and the sum is finished with MurmurHash3's finaliser: the
// table index takes the low bits.
uint64_t add(uint64_t h, uint64_t v) {
    return (h ^ v ^ (v >> 29)) * 0x9e3779b97f4a7c15ull;
}

uint64_t finish(uint64_t h) {
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    return h ^ (h >> 33);
}

uint64_t bits(double v) {
    return std::bit_cast<uint64_t>(v);
}

double value(uint64_t b) {
    return std::bit_cast<double>(b);
}

void toBits(const Affine& m, uint64_t* out) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) out[3 * i + j] = bits(m.l[i][j]);
    out[9] = bits(m.t.x), out[10] = bits(m.t.y), out[11] = bits(m.t.z);
}

void fromBits(const uint64_t* in, Affine& m) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m.l[i][j] = value(in[3 * i + j]);
    m.t = Vec3{value(in[9]), value(in[10]), value(in[11])};
}

// The values a node writes into an entry: C: its assignments; S: the rule; T: two
// matrices of 12.
uint32_t writesOf(const Graph& g, const Node& node) {
    if (node.kind == NodeKind::Calc) return g.calcs[node.payload].count;
    return node.kind == NodeKind::Select ? 1 : 24;
}

}  // namespace

StepMemoPlan::StepMemoPlan(const Graph& g, const FixedSlots* fixed) : nodes_(g.nodes.size()) {
    std::vector<uint32_t> reads;
    std::vector<Slot> assigned;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        const Node& node = g.nodes[n];
        NodePlan& p = nodes_[n];
        reads.clear();
        assigned.clear();
        const Unread unread{fixed, n, &assigned};
        if (node.kind == NodeKind::Calc) {
            const Calc& c = g.calcs[node.payload];
            if (c.count > kMaxWrites) continue;
            for (uint32_t i = 0; i < c.count; ++i) {
                const Assignment& a = g.assignments[c.first + i];
                addReads(g, a.value, reads, p.usesPath, unread);
                if (!c.simultaneous) assigned.push_back(a.slot);  // later reads see it
            }
        } else if (node.kind == NodeKind::Select) {
            const Module& m = g.modules[node.payload];
            if (!m.notationB) addReads(g, m.select, reads, p.usesPath, unread);
            for (ExprId c : m.conditions)
                if (c != kNone) addReads(g, c, reads, p.usesPath, unread);
        } else if (node.kind == NodeKind::Transform) {
            const Transform& t = g.transforms[node.payload];
            if (t.constant) continue;
            for (uint32_t i = 0; i < t.argCount; ++i)
                addReads(g, g.args[t.firstArg + i], reads, p.usesPath, unread);
        } else {
            continue;
        }
        if (reads.size() > kMaxReads) continue;
        // the reads of clock and frame first: a lookup tests for them only until the slots
        std::stable_partition(reads.begin(), reads.end(), [](uint32_t r) { return r >= kFrame; });
        p.firstRead = static_cast<uint32_t>(reads_.size());
        p.readCount = static_cast<uint32_t>(reads.size());
        p.memoised = true;
        reads_.insert(reads_.end(), reads.begin(), reads.end());
        maxReads_ = std::max(maxReads_, p.readCount);
        maxWrites_ = std::max(maxWrites_, writesOf(g, node));
    }
}

namespace {

// The most bytes a thread's table starts with: 2^entriesLog2 entries, halved until they
// fit. A Sierpinski tetrahedron's 32-byte entries keep their 4,096 (128 KB); the growing
// tree's 240-byte ones (a T-node's two matrices) get 512 (123 KB a thread, in every frame
// of a sequence), where it misses for none of its steps, so that its table never grows
// (StepMemoGrowth). At 4,096 its 48 frames at 640x480 on two threads took 18.3 MB of peak
// RSS, at 1,024 16.7 MB (docs/benchmarks.md, branch static), and 512 saves 0.15 MB more
// (the median of eight runs; "The terrain's ceiling"). Tables that miss more grow.
constexpr size_t kStartTableBytes = size_t{128} << 10;

uint32_t entriesLog2Within(size_t stride, uint32_t entriesLog2, size_t maxBytes) {
    while (entriesLog2 > 0 && (stride * sizeof(uint64_t) << entriesLog2) > maxBytes) --entriesLog2;
    return entriesLog2;
}

}  // namespace

StepMemo::StepMemo(const Graph& g, const StepMemoPlan& plan, uint32_t entriesLog2,
                   const StepMemoGrowth& growth)
    : g_(g),
      plan_(plan),
      stride_(kKey + plan.maxReads() + plan.maxWrites()),
      maxLog2_(entriesLog2Within(stride_, entriesLog2, growth.maxBytes)),
      growth_(growth),
      windowEnd_(growth.window) {
    resize(std::min(maxLog2_, entriesLog2Within(stride_, entriesLog2, kStartTableBytes)));
}

void StepMemo::resize(uint32_t entriesLog2) {
    log2_ = entriesLog2;
    table_.assign(stride_ << entriesLog2, 0);
    mask_ = (uint32_t{1} << entriesLog2) - 1;
    for (size_t i = 0; i < table_.size(); i += stride_) table_[i] = kNone;
}

void StepMemo::endWindow() {
    const uint64_t missed = misses_ - windowMisses_;
    if (log2_ < maxLog2_ && missed * growth_.missShare > growth_.window) resize(log2_ + 1);
    windowMisses_ = misses_;
    windowEnd_ = hits_ + misses_ + growth_.window;
}

namespace {

// An entry's words before its key: the node and the path (StepMemo::kKey).
constexpr uint32_t kEntryKey = 2;

// What a lookup knows besides the key: the node, the path it is keyed by, the table.
struct Probe {
    uint64_t node, path;
    bool usesPath;
    uint64_t* table;
    uint32_t mask;
    size_t stride;
};

// The entry for a key of `count` values hashed into h (the node's and the values' hash,
// not yet the path's): found (true), or made ready to fill (false, the key written). A
// count known at compile time (std::integral_constant) unrolls the comparison.
template <class Count>
[[gnu::always_inline]] inline bool settle(const Probe& q, uint64_t h, const uint64_t* key,
                                          Count count, uint64_t*& e) {
    const uint32_t n = count;
    if (q.usesPath) h = add(h, q.path);
    e = q.table + (finish(h) & q.mask) * q.stride;
    uint64_t differ = (e[0] ^ q.node) | (e[1] ^ q.path);
    for (uint32_t i = 0; i < n; ++i) differ |= e[kEntryKey + i] ^ key[i];
    if (differ == 0) return true;
    e[0] = kNone;  // filled in by the caller once the step has succeeded
    e[1] = q.path;
    for (uint32_t i = 0; i < n; ++i) e[kEntryKey + i] = key[i];
    return false;
}

// The value of a read of the time (StepMemoPlan::kClock or kFrame).
double timeValue(const Time& t, uint32_t r) {
    return r == StepMemoPlan::kClock ? t.clock : t.frame;
}

// A key of T reads of the time (clock or frame, first in the plan) and then N - T slots, read
// and hashed unrolled: no bound test and no test for the time per value.
template <uint32_t T, uint32_t N>
bool probeKey(const Time& t, const Probe& q, const uint32_t* reads, const double* frame,
              uint64_t*& e) {
    uint64_t key[N ? N : 1];
    uint64_t h = add(0, q.node);
    for (uint32_t i = 0; i < N; ++i) {
        key[i] = bits(i < T ? timeValue(t, reads[i]) : frame[reads[i]]);
        h = add(h, key[i]);
    }
    return settle(q, h, key, std::integral_constant<uint32_t, N>(), e);
}

// A key of N slots (no clock or frame).
template <uint32_t N>
bool probeSlots(const Probe& q, const uint32_t* reads, const double* frame, uint64_t*& e) {
    return probeKey<0, N>(Time{}, q, reads, frame, e);
}

using ProbeSlots = bool (*)(const Probe&, const uint32_t*, const double*, uint64_t*&);
template <uint32_t... N>
constexpr std::array<ProbeSlots, sizeof...(N)> probesFor(std::integer_sequence<uint32_t, N...>) {
    return {probeSlots<N>...};
}
constexpr auto kProbeSlots =
    probesFor(std::make_integer_sequence<uint32_t, StepMemoPlan::kMaxReads + 1>());

// Keys that read the time once or twice (clock, frame or both): [T - 1][N], none for N < T.
using ProbeTimed = bool (*)(const Time&, const Probe&, const uint32_t*, const double*, uint64_t*&);
template <uint32_t T, uint32_t... N>
constexpr std::array<ProbeTimed, sizeof...(N)> timedFor(std::integer_sequence<uint32_t, N...>) {
    return {(N < T ? nullptr : probeKey<T, (N < T ? T : N)>)...};
}
constexpr std::array<std::array<ProbeTimed, StepMemoPlan::kMaxReads + 1>, 2> kProbeTimed{
    timedFor<1>(std::make_integer_sequence<uint32_t, StepMemoPlan::kMaxReads + 1>()),
    timedFor<2>(std::make_integer_sequence<uint32_t, StepMemoPlan::kMaxReads + 1>())};

}  // namespace

bool StepMemo::lookup(NodeId n, const StepMemoPlan::NodePlan& p, EvalState in, uint64_t*& e) {
    static_assert(kKey == kEntryKey);
    if (hits_ + misses_ == windowEnd_) endWindow();
    const uint32_t* reads = plan_.reads(p);
    const Probe q{n, p.usesPath ? in.path : 0, p.usesPath, table_.data(), mask_, stride_};
    bool found;
    if (p.readCount == 0 || reads[0] < StepMemoPlan::kFrame) [[likely]]
        found = kProbeSlots[p.readCount](q, reads, in.frame, e);
    else  // the time's reads come first: a second one is the other of clock and frame
        found = kProbeTimed[p.readCount > 1 && reads[1] >= StepMemoPlan::kFrame][p.readCount](
            g_.time, q, reads, in.frame, e);
    ++(found ? hits_ : misses_);
    return found;
}

uint32_t StepMemo::select(NodeId n, EvalState in) {
    const StepMemoPlan::NodePlan& p = plan_.of(n);
    if (!p.memoised) return selectRule(g_, n, in);
    uint64_t* e;
    if (lookup(n, p, in, e)) return static_cast<uint32_t>(out(e)[0]);
    const uint32_t rule = selectRule(g_, n, in);
    out(e)[0] = rule;
    e[0] = n;
    return rule;
}

void StepMemo::calc(NodeId n, EvalState in, double* frame) {
    const StepMemoPlan::NodePlan& p = plan_.of(n);
    if (!p.memoised) return applyCalc(g_, n, in, frame);
    const Calc& c = g_.calcs[g_.nodes[n].payload];
    const Assignment* as = g_.assignments.data() + c.first;
    uint64_t* e;
    if (lookup(n, p, in, e)) {
        std::memcpy(frame, in.frame, g_.slotCount() * sizeof(double));
        for (uint32_t i = 0; i < c.count; ++i) frame[as[i].slot] = value(out(e)[i]);
        return;
    }
    applyCalc(g_, n, in, frame);
    for (uint32_t i = 0; i < c.count; ++i) out(e)[i] = bits(frame[as[i].slot]);
    e[0] = n;
}

void StepMemo::transform(NodeId n, EvalState in, Affine& forward, Affine& inverse) {
    const StepMemoPlan::NodePlan& p = plan_.of(n);
    if (!p.memoised) return transformPair(g_, n, in, forward, inverse);
    uint64_t* e;
    if (lookup(n, p, in, e)) {
        fromBits(out(e), forward);
        fromBits(out(e) + 12, inverse);
        return;
    }
    transformPair(g_, n, in, forward, inverse);
    toBits(forward, out(e));
    toBits(inverse, out(e) + 12);
    e[0] = n;
}

}  // namespace pcsg
