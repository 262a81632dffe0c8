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

// Two pixels' colours (linear, three floats each) too close to differ at the threshold:
// NearColours(T)(a, b) true guarantees that colourDistance(aaEncode(a), aaEncode(b)) >= T
// is false, so the decision can skip the encoding for pixels whose neighbours are all near
// (the sky, a smoothly lit floor). Colours with the same bits are near (their distance is
// 0, or NaN for infinities). Otherwise the bound: for u, v >= 0, |u^0.4 - v^0.4| <=
// |u - v|^0.4 (x^0.4 is concave and 0 at 0), and aaEncode clamps below 0, which only brings
// values closer; with every channel within m = (T/6)^2.5 the distance is at most
// 3 (T/6) = T/2, a margin far beyond pow's rounding. A NaN or an infinity is then never
// near (the caller encodes as before), and neither is anything for a threshold under
// 1e-6, where the margin would shrink towards the rounding.
class NearColours {
  public:
    explicit NearColours(double threshold)
        : bound_(threshold >= 1e-6 ? std::pow(threshold / 6, 2.5) : -1.0) {}
    bool operator()(const float* a, const float* b) const {
        if (std::bit_cast<uint32_t>(a[0]) == std::bit_cast<uint32_t>(b[0]) &&
            std::bit_cast<uint32_t>(a[1]) == std::bit_cast<uint32_t>(b[1]) &&
            std::bit_cast<uint32_t>(a[2]) == std::bit_cast<uint32_t>(b[2]))
            return true;
        for (int k = 0; k < 3; ++k) {
            const double d = static_cast<double>(a[k]) - static_cast<double>(b[k]);
            if (!(std::fabs(d) <= bound_)) return false;
        }
        return true;
    }
    double bound() const { return bound_; }

  private:
    double bound_;
};

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
