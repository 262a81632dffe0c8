// The colour encoding of adaptive supersampling's decision (render.h, --adaptive T): a
// pixel differs from a neighbour when the sum of the absolute differences of their
// channels, each encoded as c^(1/2.5) (POV-Ray's Antialias_Gamma 2.5), is T or more.
#pragma once

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

namespace pcsg::tracer {

// One channel, encoded: c^(1/2.5) for c > 0, else 0 (a NaN too).
inline double aaEncode(double c) {
    return c > 0 ? std::pow(c, 1.0 / 2.5) : 0.0;
}

// The distance of two pixels' colours already encoded by aaEncode.
inline double colourDistance(const double* a, const double* b) {
    double d = 0;
    for (int k = 0; k < 3; ++k) d += std::fabs(a[k] - b[k]);
    return d;
}

// aaEncode of float channels, remembering the last values met in a small direct-mapped
// table keyed by the float's bits: exactly aaEncode's doubles, for a few instructions
// where a neighbouring pixel had the same value (the sky, a flat-shaded face), instead of
// a call of pow for every channel of every pixel (and of every tile's border again). One
// per thread.
class AaEncodeMemo {
  public:
    AaEncodeMemo() {
        // A NaN's bits, whose aaEncode is 0: every slot starts out right.
        slots_.fill(Slot{kEmptyBits, 0.0});
    }
    double operator()(float c) {
        const uint32_t bits = std::bit_cast<uint32_t>(c);
        Slot& s = slots_[(bits * 0x9e3779b1u) >> (32 - kLog2)];
        if (s.bits != bits) s = Slot{bits, aaEncode(c)};
        return s.value;
    }

  private:
    static constexpr int kLog2 = 9;
    static constexpr uint32_t kEmptyBits = 0xffffffffu;
    struct Slot {
        uint32_t bits;
        double value;
    };
    std::array<Slot, size_t{1} << kLog2> slots_;
};

}  // namespace pcsg::tracer
