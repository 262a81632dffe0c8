// The parameters an instance key hashes (key_slots.h): dead and fixed slots are left out,
// everything that can differ between instances stays.
#include "key_slots.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "test_support.h"

namespace pcsg::tracer {
namespace {

using testing::compile;

// The names of the slots the key of module `name` hashes, after narrowing.
std::vector<std::string> keyed(const Graph& g, const std::string& name) {
    std::vector<ModuleDependencies> deps = moduleDependencies(g);
    narrowKeySlots(g, FixedSlots(g), deps);
    for (size_t m = 0; m < g.modules.size(); ++m) {
        if (g.modules[m].name != name) continue;
        EXPECT_TRUE(deps[m].analysed);
        std::vector<std::string> out;
        for (Slot s : deps[m].reads) out.push_back(g.slotNames[s]);
        std::sort(out.begin(), out.end());
        return out;
    }
    ADD_FAILURE() << "no module " << name;
    return {};
}

using Names = std::vector<std::string>;

TEST(KeySlots, DropsScratchSlotsAndConstantsSetAboveTheRecursion) {
    // k is set once from constants (fixed); t is assigned before every read (dead).
    auto c = compile(
        "{ k = 2; m = pow(k, 3); n = 4 } S\n"
        "S if(n > 0, 1, 2)\n"
        "1: S -> { t = n*k + m; n = n - 1 } move(t, 0, 0) S\n"
        "2: S -> sphere\n");
    ASSERT_TRUE(c->graph);
    EXPECT_EQ(keyed(*c->graph, "S"), Names{"n"});
}

TEST(KeySlots, KeepsSlotsThatDifferBetweenInstances) {
    // k differs between the two operands; r comes from the path; c from the clock (the
    // same in both, but not in every frame of a sequence).
    auto c = compile(
        "{ k = 1; n = 2; r = rand(); c = clock } S ∪ { k = 2; n = 2; r = rand(); c = clock } S\n"
        "S if(n > 0, 1, 2)\n"
        "1: S -> { n = n - 1 } move(k + r + c, 0, 0) S\n"
        "2: S -> sphere\n");
    ASSERT_TRUE(c->graph);
    EXPECT_EQ(keyed(*c->graph, "S"), (Names{"c", "k", "n", "r"}));
}

TEST(KeySlots, KeepsSlotsReadBeforeTheyAreAssignedOnSomePath) {
    // t is assigned before the read on rule 1's path only: it is live at S.
    auto c = compile(
        "{ n = 2; t = 0 } S\n"
        "S if(n > 1, 1, 2)\n"
        "1: S -> { t = n; n = n - 1 } move(t, 0, 0) S\n"
        "2: S -> { n = n - 1 } move(t, 0, 0) sphere\n");
    ASSERT_TRUE(c->graph);
    EXPECT_EQ(keyed(*c->graph, "S"), (Names{"n", "t"}));
}

TEST(KeySlots, ASlotAssignedInTheRecursionIsNotFixed) {
    // k starts fixed but the recursion halves it.
    auto c = compile(
        "{ k = 1; n = 3 } S\n"
        "S if(n > 0, 1, 2)\n"
        "1: S -> { k = k/2; n = n - 1 } scale(k, k, k) S\n"
        "2: S -> sphere\n");
    ASSERT_TRUE(c->graph);
    EXPECT_EQ(keyed(*c->graph, "S"), (Names{"k", "n"}));
}

}  // namespace
}  // namespace pcsg::tracer
