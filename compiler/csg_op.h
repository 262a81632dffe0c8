// The three CSG operators, one enum for every stage that has them: the syntax tree, the
// cyclic graph, the expanded tree and the tracer's unrolled instances (docs/language.md
// section 5).
#pragma once

#include <cstdint>

namespace pcsg {

enum class CsgOp : uint8_t {
    Union,         // ∪ or |
    Intersection,  // ∩ or &
    Difference,    // \: the first operand minus all the others
};

// The one rule for operands that hold nothing (an `empty`, or a sub-graph that grows
// nothing): a union drops them; an intersection becomes empty, and so does a difference
// whose first operand is empty (later empty operands of a difference are dropped).
constexpr bool emptyOperandEmptiesAll(CsgOp op, uint32_t operand) {
    return op == CsgOp::Intersection || (op == CsgOp::Difference && operand == 0);
}

// Whether an operator holds nothing, given which of its `count` operands do
// (`operandEmpty(i)`), by the rule above.
template <class OperandEmpty>
bool csgHoldsNothing(CsgOp op, uint32_t count, OperandEmpty operandEmpty) {
    uint32_t kept = 0;
    for (uint32_t i = 0; i < count; ++i) {
        if (!operandEmpty(i))
            ++kept;
        else if (emptyOperandEmptiesAll(op, i))
            return true;
    }
    return kept == 0;
}

// "union", "intersection", "difference": POV-Ray's keywords and the words of messages.
constexpr const char* csgOpName(CsgOp op) {
    switch (op) {
        case CsgOp::Union:
            return "union";
        case CsgOp::Intersection:
            return "intersection";
        case CsgOp::Difference:
            return "difference";
    }
    return "?";
}

}  // namespace pcsg
