// The boxes of a union's operands, per instance of the S-node whose rule is that union: a
// thread's table for the walk's first-hit rays (traversal.h).
//
// A union tests each operand's hyper-bounding box before it walks into it, but that box
// holds every instance of the operand's node: below a terrain's sub-triangle, whose
// operands are `C-node T-node S-node` chains met at every depth, it spans the terrain's
// whole height and culls nothing. The operand's own S-node instance has an exact box
// (instance_boxes.h), but it is keyed by the frame the operand's C-node computes, so the
// walk took that C-step (and the S-node's key and box look-up) for every operand of every
// union it entered, and only then rejected most of them. An operand's box is a function of
// the S-node instance above the union (its InstanceBoxes key), so the walk computes the
// operands' boxes once per instance, mapped into the union's frame, and keeps them here:
// the next rays through that instance cull its operands before they step into them, and
// meet the remaining ones front to back by their entry into boxes that fit them.
//
// Direct-mapped by the instance's key: a hit is the boxes any thread would compute for
// that instance (they are a function of its key), so which rays filled the table never
// changes what a box culls beyond what the operand's own tests would. Memory is taken on
// the first store only (scenes without such unions pay nothing).
#pragma once

#include <cstdint>
#include <vector>

#include "geometry.h"
#include "instance_boxes.h"

namespace pcsg::tracer {

class OperandBoxes {
  public:
    static constexpr uint32_t kMaxOperands = 4;
    struct Entry {
        InstanceBoxes::Key key;  // key.a == 0: empty (no key has a == 0)
        NodeId select = kNone;
        uint32_t depth = 0;
        Box box[kMaxOperands];  // operand i's box in the union's frame
    };

    explicit OperandBoxes(uint32_t entriesLog2 = 11) : entriesLog2_(entriesLog2) {}

    // The boxes stored for the S-node instance (select, key) at `depth`, or null.
    const Entry* find(NodeId select, const InstanceBoxes::Key& k, uint32_t depth) const {
        if (table_.empty()) return nullptr;
        const Entry& e = table_[k.b & mask_];
        return e.key == k && e.select == select && e.depth == depth ? &e : nullptr;
    }
    // The entry for that instance, emptied (its key unset): the caller fills its boxes and
    // then marks it with `keep`, so that an entry whose filling failed stays empty.
    Entry& slot(const InstanceBoxes::Key& k);
    static void keep(Entry& e, NodeId select, const InstanceBoxes::Key& k, uint32_t depth) {
        e.key = k, e.select = select, e.depth = depth;
    }
    size_t bytes() const { return table_.size() * sizeof(Entry); }

  private:
    uint32_t entriesLog2_;
    uint64_t mask_ = 0;
    std::vector<Entry> table_;
};

}  // namespace pcsg::tracer
