// The constant tables of POV-Ray 3.7's noise (noise.cpp): data, not code, kept apart so
// that noise.cpp reads as the algorithm.
#pragma once

#include <array>

namespace pcsg::noise_detail {

// POV-Ray's RTable: 267 pseudo-random values in [-1, 1] (texture.cpp / noise.cpp of
// POV-Ray 3.7, "RTable"), the even entries of its interleaved table. POV-Ray stores each
// value v at 2i and, at start-up, v / 2 at 2i + 1; noise.cpp rebuilds that layout.
extern const std::array<double, 267> kRTableValues;

}  // namespace pcsg::noise_detail
