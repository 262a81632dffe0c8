// The render's threads: one pool for the process, as oneTBB's was, so that what the threads
// keep (thread_local build arrays, recalled sines) outlives a frame. pcsg does not link
// oneTBB: its shared library and the shared libstdc++ it needs cost every pcsg process
// some 2 MB of peak RSS (docs/benchmarks.md, branch lean).
//
//  - parallelFor(count, body) runs body(index, slot) once for each index in [0, count):
//    the calling thread (slot 0) and the pool's threads (slots 1 to threads - 1) each take
//    the next index until none is left, and it returns when all are done. A slot is run by
//    one thread at a time, so per-slot state needs no lock.
//  - ParallelLimits, for its lifetime and on the thread that made it, sets how many threads
//    the loops of that thread use and the stack size of the pool's threads (the walk
//    recurses once per node visit). Without one: all cores, 8 MB stacks. The pool is
//    started again when a loop needs another thread count or a larger stack.
//  - The first exception a body throws is rethrown by parallelFor once every thread has
//    stopped; the indices not yet taken are skipped.
//  - A loop started inside a body, or while another thread's loop holds the pool, runs on
//    the calling thread alone (slot 0 of its own).
#pragma once

#include <cstddef>
#include <functional>

namespace pcsg::tracer {

class ParallelLimits {
  public:
    // `threads` 0: all cores.
    ParallelLimits(int threads, size_t stackBytes);
    ~ParallelLimits();
    ParallelLimits(const ParallelLimits&) = delete;
    ParallelLimits& operator=(const ParallelLimits&) = delete;

  private:
    int threads_;
    size_t stackBytes_;
    const ParallelLimits* outer_;
    friend int parallelSlots();
    friend size_t parallelStackBytes();
};

// How many slots the calling thread's loops use (its ParallelLimits' threads).
int parallelSlots();
// The stack size of the pool's threads for the calling thread's loops.
size_t parallelStackBytes();

void parallelFor(size_t count, const std::function<void(size_t index, int slot)>& body);

}  // namespace pcsg::tracer
