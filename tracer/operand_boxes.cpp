// The boxes of a union's operands per S-node instance: see operand_boxes.h.
#include "operand_boxes.h"

namespace pcsg::tracer {

OperandBoxes::Entry& OperandBoxes::slot(const InstanceBoxes::Key& k) {
    if (table_.empty()) {
        table_.resize(size_t{1} << entriesLog2_);
        mask_ = table_.size() - 1;
    }
    Entry& e = table_[k.b & mask_];
    e.key = InstanceBoxes::Key{};
    return e;
}

void OperandBoxes::computed(uint32_t depth) {
    Trial& t = trial(depth);
    if (++t.computed == kTrial) t.off = t.found < kReuse * kTrial;
}

}  // namespace pcsg::tracer
