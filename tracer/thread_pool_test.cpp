#include "thread_pool.h"

#include <gtest/gtest.h>
#include <pthread.h>

#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace pcsg::tracer {
namespace {

// The calling thread's stack size, as pthread reports it.
size_t ownStackBytes() {
    pthread_attr_t attr;
    pthread_getattr_np(pthread_self(), &attr);
    size_t bytes = 0;
    pthread_attr_getstacksize(&attr, &bytes);
    pthread_attr_destroy(&attr);
    return bytes;
}

// Each index once, whatever the thread count.
TEST(ThreadPool, RunsEveryIndexOnce) {
    for (int threads : {1, 2, 3, 5}) {
        const ParallelLimits limits(threads, 0);
        std::vector<std::atomic<int>> runs(1000);
        parallelFor(runs.size(), [&](size_t i, int) { ++runs[i]; });
        for (size_t i = 0; i < runs.size(); ++i) ASSERT_EQ(runs[i].load(), 1) << i;
    }
}

// The limit's thread count: slots 0 to threads - 1, each on one thread at a time (so the
// same slot is never seen on two threads at once), and more than one thread used when the
// bodies wait for each other.
TEST(ThreadPool, SlotsAreTheLimitsThreadsOneThreadEach) {
    const ParallelLimits limits(3, 0);
    EXPECT_EQ(parallelSlots(), 3);
    std::mutex m;
    std::map<int, int> inSlot;  // slot -> bodies running in it now
    std::set<std::thread::id> threads;
    std::atomic<int> arrived{0};
    bool overlap = false;
    parallelFor(3, [&](size_t, int slot) {
        {
            std::lock_guard<std::mutex> lock(m);
            ASSERT_GE(slot, 0);
            ASSERT_LT(slot, 3);
            if (++inSlot[slot] > 1) overlap = true;
            threads.insert(std::this_thread::get_id());
        }
        ++arrived;
        // Hold the slot until every index was taken (bounded: a one-thread pool passes).
        for (int spin = 0; spin < 20000 && arrived.load() < 3; ++spin)
            std::this_thread::sleep_for(std::chrono::microseconds(500));
        std::lock_guard<std::mutex> lock(m);
        --inSlot[slot];
    });
    EXPECT_FALSE(overlap);
    EXPECT_EQ(threads.size(), 3u);
}

// The pool's threads get the stack size asked for (the walk recurses once per node visit),
// and a larger one starts the pool again.
TEST(ThreadPool, ThreadsHaveTheStackAskedFor) {
    for (size_t mb : {size_t{3}, size_t{24}}) {
        const ParallelLimits limits(2, mb << 20);
        std::mutex m;
        std::vector<size_t> stacks;
        std::atomic<int> arrived{0};
        parallelFor(2, [&](size_t, int slot) {
            ++arrived;
            for (int spin = 0; spin < 20000 && arrived.load() < 2; ++spin)
                std::this_thread::sleep_for(std::chrono::microseconds(500));
            if (slot == 0) return;
            std::lock_guard<std::mutex> lock(m);
            stacks.push_back(ownStackBytes());
        });
        ASSERT_EQ(stacks.size(), 1u);
        EXPECT_GE(stacks[0], mb << 20);
    }
}

// The first exception is rethrown by the caller; the pool runs the next loop.
TEST(ThreadPool, RethrowsABodysExceptionAndRunsOn) {
    const ParallelLimits limits(2, 0);
    EXPECT_THROW(parallelFor(100,
                             [](size_t i, int) {
                                 if (i == 17) throw std::runtime_error("seventeen");
                             }),
                 std::runtime_error);
    std::atomic<int> sum{0};
    parallelFor(100, [&](size_t i, int) { sum += static_cast<int>(i); });
    EXPECT_EQ(sum.load(), 4950);
}

// A loop inside a body runs on that body's thread alone, in slot 0, and completes.
TEST(ThreadPool, ANestedLoopRunsOnItsThread) {
    const ParallelLimits limits(2, 0);
    std::atomic<int> inner{0}, wrongThread{0}, wrongSlot{0};
    parallelFor(4, [&](size_t, int) {
        const auto self = std::this_thread::get_id();
        parallelFor(10, [&](size_t, int slot) {
            ++inner;
            if (std::this_thread::get_id() != self) ++wrongThread;
            if (slot != 0) ++wrongSlot;
        });
    });
    EXPECT_EQ(inner.load(), 40);
    EXPECT_EQ(wrongThread.load(), 0);
    EXPECT_EQ(wrongSlot.load(), 0);
}

// Limits nest and end with their scope.
TEST(ThreadPool, LimitsNestAndEnd) {
    const int machine = parallelSlots();
    {
        const ParallelLimits outer(2, 1 << 20);
        {
            const ParallelLimits inner(1, 2 << 20);
            EXPECT_EQ(parallelSlots(), 1);
            EXPECT_EQ(parallelStackBytes(), size_t{2} << 20);
        }
        EXPECT_EQ(parallelSlots(), 2);
        EXPECT_EQ(parallelStackBytes(), size_t{1} << 20);
    }
    EXPECT_EQ(parallelSlots(), machine);
    EXPECT_EQ(parallelStackBytes(), 0u);
}

}  // namespace
}  // namespace pcsg::tracer
