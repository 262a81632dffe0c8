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
// An instance's boxes pay only if rays come back to it: computing them takes each operand's
// C-step (which then misses the step memo) and box, where a ray that walks the instance
// once takes only those of the operands its own tests do not cull. So the table watches,
// per depth, how often its boxes are found per computation: after kTrial computations at
// a depth, a depth where they were found fewer than kReuse times each is left to the
// operands' static boxes (the terrain at 160x120: its instances of 4 and 16 triangles, met
// by about one ray each; at 320x240 the depths it expands, whose instances the walk meets
// once before they are built).
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

    // The trial per depth (see above): whether to keep boxes for instances at `depth`, and
    // the note of a find or a computation there.
    static constexpr uint32_t kTrial = 256, kReuse = 4;
    bool wanted(uint32_t depth) const { return depth >= trials_.size() || !trials_[depth].off; }
    void found(uint32_t depth) { ++trial(depth).found; }
    void computed(uint32_t depth);

  private:
    uint32_t entriesLog2_;
    uint64_t mask_ = 0;
    std::vector<Entry> table_;
    struct Trial {
        uint32_t computed = 0, found = 0;
        bool off = false;
    };
    std::vector<Trial> trials_;
    Trial& trial(uint32_t depth) {
        if (depth >= trials_.size()) trials_.resize(depth + 1);
        return trials_[depth];
    }
};

}  // namespace pcsg::tracer
