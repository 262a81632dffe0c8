// A walker's memory of the steps it has already taken: the rule an S-node selects, the new
// values of a C-node and the matrices of a T-node whose arguments read parameters, keyed
// by exactly what they read.
//
// A ray walks the graph from the root, so every ray that reaches an instance recomputes
// the same selections, C-nodes and T-node matrices on the way (a growing tree's lengths and angles
// are all functions of the clock and the depth: half of the tracer's instructions went there).
// Their results are functions of a few values: the parameter slots their expressions
// load, the instance path when they call rand() or choose(), and the time when they read
// clock or frame. StepMemo keeps the last results per thread in a direct-mapped table,
// keyed by those values bit for bit, so a hit gives the same numbers the step would
// compute (and a step that would throw is never stored: it throws again).
//
// Semantics::enter() consults it when the walker lends one in StepScratch::memo; a node
// that reads more than kMaxReads values, or a C-node that writes more than kMaxWrites
// slots, is always computed.
#pragma once

#include <cstdint>
#include <vector>

#include "eval.h"
#include "fixed_slots.h"
#include "graph.h"

namespace pcsg {

// What each C- and T-node reads and writes: computed once per graph, shared by threads.
class StepMemoPlan {
  public:
    static constexpr uint32_t kMaxReads = 16;
    static constexpr uint32_t kMaxWrites = 24;
    static constexpr uint32_t kClock = UINT32_MAX;      // a read of `clock`
    static constexpr uint32_t kFrame = UINT32_MAX - 1;  // a read of `frame`

    // With `fixed`, a node's key leaves out the slots fixed on entry to it (fixed_slots.h):
    // for walks from the axiom only. A C-node's key holds the slots it reads before it
    // assigns them.
    explicit StepMemoPlan(const Graph& g, const FixedSlots* fixed = nullptr);

    struct NodePlan {
        uint32_t firstRead = 0,
                 readCount = 0;  // reads_[firstRead, +readCount): slots or kClock/kFrame
        bool usesPath = false;
        bool memoised = false;
    };
    const NodePlan& of(NodeId n) const { return nodes_[n]; }
    const uint32_t* reads(const NodePlan& p) const { return reads_.data() + p.firstRead; }
    // The most values a memoised node reads and writes: what an entry of the memo holds.
    uint32_t maxReads() const { return maxReads_; }
    uint32_t maxWrites() const { return maxWrites_; }

  private:
    std::vector<NodePlan> nodes_;
    std::vector<uint32_t> reads_;
    uint32_t maxReads_ = 0, maxWrites_ = 0;
};

// When a thread's table grows (StepMemo's constructor): after every `window` lookups, by
// doubling, if more than 1/missShare of that window's lookups missed, up to `maxBytes`.
struct StepMemoGrowth {
    uint64_t window = 1u << 16;
    uint32_t missShare = 16;
    size_t maxBytes = size_t{2} << 20;
};

// Per thread: the table (a few thousand entries). An entry holds as many read and written
// values as the plan's nodes need at most (a Sierpinski tetrahedron's one slot: 32 bytes,
// where room for kMaxReads and kMaxWrites took 336). The table starts within 128 KB and
// grows towards 2^entriesLog2 entries while it misses often (StepMemoGrowth): the terrain's
// 304-byte entries start at 256 and grow while its rays miss for many of their steps.
class StepMemo {
  public:
    StepMemo(const Graph& g, const StepMemoPlan& plan, uint32_t entriesLog2 = 12,
             const StepMemoGrowth& growth = {});

    // Semantics' S-node step: the rule selected (0-based).
    uint32_t select(NodeId n, EvalState in);
    // Semantics' C-node step: the new frame into `out` (Graph::slotCount() values).
    void calc(NodeId n, EvalState in, double* out);
    // Semantics' T-node step for a T-node whose arguments are not constant.
    void transform(NodeId n, EvalState in, Affine& forward, Affine& inverse);

    uint64_t hits() const { return hits_; }
    // The table's size.
    size_t bytes() const { return table_.size() * sizeof(uint64_t); }
    uint64_t misses() const { return misses_; }

  private:
    // An entry is stride_ words: the node (kNone: empty), the path, plan_.maxReads() values
    // read, then plan_.maxWrites() values written (C: the new values; S: the rule; T:
    // forward, inverse), doubles as their bits.
    static constexpr uint32_t kKey = 2;
    // The entry for (n, in): found (true) or to fill (false); its key gets the read values.
    bool lookup(NodeId n, const StepMemoPlan::NodePlan& p, EvalState in, uint64_t*& e);
    uint64_t* out(uint64_t* e) const { return e + kKey + plan_.maxReads(); }
    // At the end of a window of lookups: doubles the table (emptied) if the window missed
    // often and the table may still grow.
    void endWindow();
    void resize(uint32_t entriesLog2);

    const Graph& g_;
    const StepMemoPlan& plan_;
    size_t stride_;
    std::vector<uint64_t> table_;
    uint32_t mask_ = 0;
    uint32_t log2_ = 0, maxLog2_ = 0;  // the table's entries, now and at most
    StepMemoGrowth growth_;
    uint64_t hits_ = 0, misses_ = 0;
    uint64_t windowEnd_ = 0, windowMisses_ = 0;  // the lookups and misses at the window's start
};

}  // namespace pcsg
