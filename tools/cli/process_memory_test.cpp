// The allocator's thresholds stay where they start (process_memory.h).
#include "process_memory.h"

#include <gtest/gtest.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cstdlib>
#include <cstring>

namespace pcsg::tools {
namespace {

#if defined(__GLIBC__)
// Bytes in blocks with mappings of their own.
size_t mappedBytes() {
    return mallinfo2().hblkhd;
}

// A frame-sized block freed and allocated again gets a mapping of its own again, which
// its free() returns: glibc's own policy would have raised the threshold past it at the
// first free() and taken the second from the heap.
TEST(ProcessMemory, AFreedLargeBlockDoesNotMoveTheNextIntoTheHeap) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer's allocator replaces glibc's";
#endif
    fixMallocThresholds();
    constexpr size_t kBlock = 3 << 20;
    for (int round = 0; round < 3; ++round) {
        const size_t before = mappedBytes();
        void* volatile p = std::malloc(kBlock);  // volatile: not elided
        ASSERT_NE(p, nullptr);
        std::memset(p, 1, kBlock);
        EXPECT_GE(mappedBytes(), before + kBlock) << "round " << round;
        std::free(p);
        EXPECT_EQ(mappedBytes(), before) << "round " << round;
    }
}

// A block freed at the top of the heap leaves the pad there: the next ones of its size
// take pages already mapped, not fresh ones after a trim.
TEST(ProcessMemory, TheHeapKeepsItsPadAtTheTop) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer's allocator replaces glibc's";
#endif
    fixMallocThresholds();
    for (int round = 0; round < 3; ++round) {
        void* volatile p = std::malloc(100 * 1024);  // (below the mmap threshold)
        ASSERT_NE(p, nullptr);
        std::memset(p, 1, 100 * 1024);
        std::free(p);
        EXPECT_GE(mallinfo2().keepcost, kTopPadBytes) << "round " << round;
    }
}
#endif

}  // namespace
}  // namespace pcsg::tools
