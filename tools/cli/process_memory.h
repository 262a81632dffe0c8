// How pcsg's allocator gives freed memory back (glibc malloc).
//
// glibc starts with blocks of 128 KB and more in mappings of their own, returned when freed,
// and the heap trimmed when 128 KB at its top are free; but each time a mapped block is
// freed it raises both thresholds to that block's size (up to 32 MB), so that after the
// first frame-sized buffer was freed the next ones came from the heap and stayed in it.
// fixMallocThresholds() keeps the starting values for the whole run. Whole-command peak
// RSS (/usr/bin/time -v, loaded machine) of the growing tree's 48 frames at 640x480
// +A0.3: 23.3 and 23.5 -> 21.6 and 21.9 MB, for 0.2 s more system time (each frame's
// buffers are fresh pages: 6.4 K -> 110 K minor faults); the terrain and Sierpinski order
// 8 within their noise (docs/benchmarks.md, branch lean). Nothing elsewhere than glibc.
//
// It also pads the heap: each time a heap grows it takes kTopPadBytes more, and a trim
// leaves that much free at its top. The terrain's expansions (about 100 KB each, some
// 13,000 built and evicted in a render at 640x480) had each been given fresh pages after
// the trims, 27,000 minor faults and 0.26 s of system time; with the pad 10,000 and
// 0.08 s, at the same peak RSS (the pages kept are ones the render touched anyway).
// Order 8's and the growing tree's peak RSS are the same.
#pragma once

#include <cstddef>

namespace pcsg::tools {

constexpr size_t kTopPadBytes = size_t{16} << 20;

void fixMallocThresholds();

}  // namespace pcsg::tools
