// The per-thread table of union operands' boxes (operand_boxes.h).
#include "operand_boxes.h"

#include <gtest/gtest.h>

namespace pcsg::tracer {
namespace {

TEST(OperandBoxes, TakesNoMemoryUntilTheFirstStore) {
    OperandBoxes t(4);
    EXPECT_EQ(t.bytes(), 0u);
    EXPECT_EQ(t.find(3, InstanceBoxes::Key{1, 2}, 5), nullptr);
    t.slot(InstanceBoxes::Key{1, 2});
    EXPECT_EQ(t.bytes(), 16 * sizeof(OperandBoxes::Entry));
}

TEST(OperandBoxes, FindsAnEntryOnlyOnceKeptAndOnlyForItsInstance) {
    OperandBoxes t(4);
    const InstanceBoxes::Key k{7, 9};
    OperandBoxes::Entry& e = t.slot(k);
    e.box[0] = Box{{0, 0, 0}, {1, 1, 1}};
    EXPECT_EQ(t.find(3, k, 5), nullptr);  // not kept yet (its filling may still fail)
    OperandBoxes::keep(e, 3, k, 5);
    const OperandBoxes::Entry* found = t.find(3, k, 5);
    ASSERT_NE(found, nullptr);
    EXPECT_EQ(found->box[0].hi.x, 1);
    EXPECT_EQ(t.find(4, k, 5), nullptr);                         // another S-node
    EXPECT_EQ(t.find(3, k, 6), nullptr);                         // another depth
    EXPECT_EQ(t.find(3, InstanceBoxes::Key{8, 9}, 5), nullptr);  // same slot, other key
    // Another instance in the same slot replaces it, and the slot is empty while filled.
    OperandBoxes::Entry& again = t.slot(InstanceBoxes::Key{8, 9 + 16});
    EXPECT_EQ(&again, &e);
    EXPECT_EQ(t.find(3, k, 5), nullptr);
}

TEST(OperandBoxes, ADepthWhoseBoxesAreSeldomFoundIsLeftToTheStaticBoxes) {
    OperandBoxes t;
    for (uint32_t k = 0; k < OperandBoxes::kTrial; ++k) {
        EXPECT_TRUE(t.wanted(3));
        EXPECT_TRUE(t.wanted(4));
        for (uint32_t r = 0; r < OperandBoxes::kReuse; ++r) t.found(4);
        t.found(3);
        t.computed(3);
        t.computed(4);
    }
    EXPECT_FALSE(t.wanted(3));  // found once per computation
    EXPECT_TRUE(t.wanted(4));   // kReuse times
    EXPECT_TRUE(t.wanted(5));   // (not tried)
}

}  // namespace
}  // namespace pcsg::tracer
