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

}  // namespace pcsg::tracer
