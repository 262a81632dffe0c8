// Deferred freeing (deferred_free.h): an object retired while a reader is pinned lives
// until that reader unpins; readers pinned later or unpinned do not hold it up.
#include "deferred_free.h"

#include <gtest/gtest.h>

namespace pcsg::tracer {
namespace {

// Counts its destructions.
struct Counted {
    explicit Counted(int& n) : freed(n) {}
    ~Counted() { ++freed; }
    int& freed;
};

std::vector<std::unique_ptr<Counted>> one(int& freed) {
    std::vector<std::unique_ptr<Counted>> v;
    v.push_back(std::make_unique<Counted>(freed));
    return v;
}

TEST(DeferredFree, AnObjectLivesUntilTheReadersPinnedBeforeItsRetirementUnpin) {
    DeferredFree d;
    DeferredFree::Slot* a = d.join();
    DeferredFree::Slot* b = d.join();
    int freed = 0;
    d.pin(*a);
    auto v = one(freed);
    d.retire(v, 100);
    EXPECT_EQ(freed, 0);
    EXPECT_EQ(d.pendingBytes(), 100u);
    d.pin(*b);  // pinned after the retirement: does not hold it
    d.reclaim();
    EXPECT_EQ(freed, 0);  // a still does
    d.unpin(*a);
    d.reclaim();
    EXPECT_EQ(freed, 1);
    EXPECT_EQ(d.pendingBytes(), 0u);
    // b, pinned before this one, holds it; leaving frees it.
    auto w = one(freed);
    d.retire(w, 7);
    EXPECT_EQ(freed, 1);
    d.leave(b);
    EXPECT_EQ(freed, 2);
    d.leave(a);
}

TEST(DeferredFree, WithNoReaderPinnedARetiredObjectIsFreedAtOnce) {
    DeferredFree d;
    DeferredFree::Slot* a = d.join();
    int freed = 0;
    auto v = one(freed);
    d.retire(v, 1);
    EXPECT_EQ(freed, 1);
    EXPECT_EQ(d.pending(), 0u);
    d.leave(a);
}

TEST(DeferredFree, WhatIsStillRetiredAtTheEndIsFreed) {
    int freed = 0;
    {
        DeferredFree d;
        DeferredFree::Slot* a = d.join();
        d.pin(*a);
        auto v = one(freed);
        d.retire(v, 1);
        EXPECT_EQ(freed, 0);
        d.unpin(*a);
    }
    EXPECT_EQ(freed, 1);
}

}  // namespace
}  // namespace pcsg::tracer
