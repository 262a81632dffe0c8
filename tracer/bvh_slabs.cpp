// The constants of the float box test (bvh_slabs.h), defined here so that the walks take
// them from memory as operands instead of broadcasting them from scalars at every node.
#include "bvh_slabs.h"

namespace pcsg::tracer {

#if defined(__SSE2__)
const FloatSlabConstants kFloatSlabs{{1 - 0x1p-19f, 1 - 0x1p-19f, 1 - 0x1p-19f, 1 - 0x1p-19f},
                                     {1 + 0x1p-19f, 1 + 0x1p-19f, 1 + 0x1p-19f, 1 + 0x1p-19f},
                                     {FLT_MAX, FLT_MAX, FLT_MAX, FLT_MAX},
                                     {-FLT_MAX, -FLT_MAX, -FLT_MAX, -FLT_MAX},
                                     {0x1p60f, 0x1p60f, 0x1p60f, 0x1p60f},
                                     {0x1p-60f, 0x1p-60f, 0x1p-60f, 0x1p-60f},
                                     {0x1p-21f, 0x1p-21f, 0x1p-21f, 0x1p-21f},
                                     {0x1p-120f, 0x1p-120f, 0x1p-120f, 0x1p-120f},
                                     {0x7fffffff, 0x7fffffff, 0x7fffffff, 0x7fffffff}};
#endif

}  // namespace pcsg::tracer
