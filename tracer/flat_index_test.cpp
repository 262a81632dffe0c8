// The unroller's flat key-to-index map (flat_index.h) answers as std::unordered_map's
// try_emplace does, through its growth and for keys that differ only in high or low bits.
#include "flat_index.h"

#include <gtest/gtest.h>

#include <random>
#include <unordered_map>

namespace pcsg::tracer {
namespace {

TEST(FlatIndex, KeepsTheValueStoredFirst) {
    FlatIndex index;
    EXPECT_EQ(index.tryEmplace(7, 1), std::make_pair(1u, true));
    EXPECT_EQ(index.tryEmplace(7, 2), std::make_pair(1u, false));
    EXPECT_EQ(index.tryEmplace(0, 3), std::make_pair(3u, true));  // key 0 is a key like any
    EXPECT_EQ(index.tryEmplace(0, 4), std::make_pair(3u, false));
    EXPECT_EQ(index.size(), 2u);
}

// Random keys, pairs (parent << 32 | matrix) as the links use, and keys that differ only
// above bit 32, against std::unordered_map, through many doublings.
TEST(FlatIndex, AnswersAsAnUnorderedMapThroughItsGrowth) {
    std::mt19937_64 rng(13);
    FlatIndex index;
    std::unordered_map<uint64_t, uint32_t> reference;
    for (uint32_t i = 0; i < 20000; ++i) {
        uint64_t key = 0;
        switch (i % 4) {
            case 0:
                key = rng();
                break;
            case 1:
                key = (static_cast<uint64_t>(rng() % 64) << 32) | (rng() % 64);
                break;
            case 2:
                key = static_cast<uint64_t>(rng() % 4096) << 32;
                break;
            default:
                key = rng() % 512;
                break;
        }
        const auto [it, added] = reference.try_emplace(key, i);
        const std::pair<uint32_t, bool> got = index.tryEmplace(key, i);
        ASSERT_EQ(got.first, it->second) << "key " << key << " at " << i;
        ASSERT_EQ(got.second, added) << "key " << key << " at " << i;
    }
    EXPECT_EQ(index.size(), reference.size());
}

// clear() empties the index for the next expansion and keeps its slots: the keys stored
// before are gone (stored anew, with the new values), the table is not grown again, and
// release() frees it.
TEST(FlatIndex, ClearedItForgetsEveryKeyAndKeepsItsSlots) {
    FlatIndex index;
    for (uint32_t round = 0; round < 3; ++round) {
        for (uint32_t k = 0; k < 1000; ++k) {
            const uint64_t key = (static_cast<uint64_t>(k % 37) << 32) | k;
            ASSERT_EQ(index.tryEmplace(key, k + round), std::make_pair(k + round, true))
                << "round " << round << " key " << k;
            ASSERT_EQ(index.tryEmplace(key, 7), std::make_pair(k + round, false));
        }
        EXPECT_EQ(index.size(), 1000u);
        const size_t slots = index.slots();
        EXPECT_GE(slots, 2000u);  // (at most half full)
        index.clear();
        EXPECT_EQ(index.size(), 0u);
        EXPECT_EQ(index.slots(), slots);
    }
    index.release();
    EXPECT_EQ(index.slots(), 0u);
    EXPECT_EQ(index.tryEmplace(5, 1), std::make_pair(1u, true));
}

}  // namespace
}  // namespace pcsg::tracer
