#include "process_memory.h"

#include <cstdlib>  // defines __GLIBC__ with glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace pcsg::tools {

void fixMallocThresholds() {
#if defined(__GLIBC__)
    constexpr int kBytes = 128 * 1024;  // glibc's starting values of both
    mallopt(M_MMAP_THRESHOLD, kBytes);
    mallopt(M_TRIM_THRESHOLD, kBytes);
    mallopt(M_TOP_PAD, kTopPadBytes);
#endif
}

}  // namespace pcsg::tools
