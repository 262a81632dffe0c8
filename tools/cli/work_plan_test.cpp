#include "work_plan.h"

#include <gtest/gtest.h>

#include <vector>

namespace pcsg::tools {
namespace {

// Every pixel of every frame is in exactly one unit; returns the units.
std::vector<WorkUnit> coverOnce(WorkPlan& plan, int width, int height) {
    std::vector<WorkUnit> units;
    std::vector<int> covered(static_cast<size_t>(width) * height * plan.frames().size(), 0);
    while (auto u = plan.next()) {
        EXPECT_LT(u->x0, u->x1);
        EXPECT_LT(u->y0, u->y1);
        EXPECT_EQ(u->id, static_cast<int>(units.size()));
        for (int y = u->y0; y < u->y1; ++y)
            for (int x = u->x0; x < u->x1; ++x)
                ++covered[(static_cast<size_t>(u->frameIndex) * height + y) * width + x];
        units.push_back(*u);
    }
    for (int c : covered) EXPECT_EQ(c, 1);
    return units;
}

TEST(WorkPlan, AStillIsCutIntoShrinkingUnitsCoveringEveryPixelOnce) {
    WorkPlan plan(1000, 700, {{1, 0.0}}, 0, 2);
    const auto units = coverOnce(plan, 1000, 700);
    ASSERT_GT(units.size(), 8u);
    EXPECT_EQ(units.front().count, 1);
    EXPECT_EQ(units.front().x1, 1000);  // whole rows first
    EXPECT_GT(units.front().pixels(), units.back().pixels());
    EXPECT_EQ(units.back().pixels(), 8u * 28);  // the last tile of the last row
    for (size_t i = 1; i < units.size(); ++i) EXPECT_EQ(units[i].count, 0);
    EXPECT_EQ(plan.totalPixels(), 700000u);
}

TEST(WorkPlan, TwoRanksTakeAnEighthOfWhatIsLeftWithinARow) {
    WorkPlan plan(64, 64, {{1, 0.0}}, 0, 2, 16);  // 4 x 4 tiles
    const auto units = coverOnce(plan, 64, 64);
    // ceil(left / (f P)) with f = min(16, 2 P) = 4: 2, 2, 2, 2, then single tiles.
    std::vector<uint64_t> tiles;
    for (const WorkUnit& u : units) tiles.push_back(u.pixels() / 256);
    EXPECT_EQ(tiles, (std::vector<uint64_t>{2, 2, 2, 2, 1, 1, 1, 1, 1, 1, 1, 1}));
}

TEST(WorkPlan, ManyRanksStartWithSmallUnits) {
    // 64 ranks: f = 16, so the first unit is 1/1024 of the frame's 120 x 68 tiles.
    WorkPlan plan(3840, 2160, {{1, 0.0}}, 0, 64);
    EXPECT_EQ(plan.next()->pixels(), 8u * kWorkTile * kWorkTile);
}

TEST(WorkPlan, OneRankTakesTheWholeFrame) {
    WorkPlan plan(64, 64, {{1, 0.0}}, 0, 1, 16);
    const auto units = coverOnce(plan, 64, 64);
    ASSERT_EQ(units.size(), 1u);
}

TEST(WorkPlan, FewerFramesThanRanksCutsFramesIntoTilesInFrameOrder) {
    WorkPlan plan(100, 60, {{1, 0.0}, {2, 0.5}, {3, 1.0}}, 3, 8, 16);
    const auto units = coverOnce(plan, 100, 60);
    int counts = 0;
    for (size_t i = 0; i < units.size(); ++i) {
        counts += units[i].count;
        if (i > 0) {
            EXPECT_GE(units[i].frameIndex, units[i - 1].frameIndex);
        }
        EXPECT_EQ(units[i].framesInSequence, 3);
        EXPECT_EQ(units[i].clock, 0.5 * units[i].frameIndex);
    }
    EXPECT_EQ(counts, 3);
}

TEST(WorkPlan, AsManyFramesAsRanksMakesWholeFrameUnits) {
    WorkPlan plan(100, 60, {{1, 0.0}, {2, 1.0}}, 2, 2);
    const auto units = coverOnce(plan, 100, 60);
    ASSERT_EQ(units.size(), 2u);
    EXPECT_EQ(units[1].frame, 2);
    EXPECT_EQ(units[1].pixels(), 6000u);
    EXPECT_EQ(units[1].count, 1);
}

}  // namespace
}  // namespace pcsg::tools
