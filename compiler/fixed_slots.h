// Parameters with one value in every walk: constant propagation from the axiom.
//
// A walk starts at the axiom with every slot unassigned, and only C-nodes change the
// frame. A slot is fixed at a node when it holds the same value, bit for bit, on entry to
// the node in every walk that reaches it (the terrain's a, b, c, d, frc, ...: assigned
// once, from constants, above the recursion). A C-node's assignment gives a fixed value
// only when evalExpr (the machine every walk's values match) computes it from fixed
// values alone, without rand()/choose() (the path) or clock/frame (the time): so a fixed
// value is the same in every frame of a sequence too.
//
// Whatever depends on a node's parameters depends on its fixed slots only through their
// one value, so memo and cache keys may leave them out (step_memo.h, the tracer's
// instance keys).
#pragma once

#include <vector>

#include "graph.h"

namespace pcsg {

class FixedSlots {
  public:
    // Analyses the graph; a graph too large to analyse cheaply gets no fixed slots.
    explicit FixedSlots(const Graph& g);

    // Whether slot s holds one value on entry to node n in every walk from the axiom
    // (false for a node no walk reaches).
    bool fixed(NodeId n, Slot s) const {
        return n < first_.size() && first_[n] != kNone && s < slots_ && fixed_[first_[n] + s];
    }

  private:
    size_t slots_ = 0;
    std::vector<uint32_t> first_;  // per node: its slots' index in fixed_, kNone: unreached
    std::vector<uint8_t> fixed_;
};

}  // namespace pcsg
