// The values of a function computed last, per thread, direct-mapped by the bits of its
// arguments: the plain machine's sin(), pow() and ln() (eval.cpp) and the fast machine's
// rnd chain (fast_eval.cpp). Internal to the compiler library.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <tuple>

namespace pcsg {

// A C-node's values repeat (the terrains' taper takes the sine of each corner's
// coordinates, 513 values at order 9, and a power of each corner, for every triangle at that
// corner; their displacements a logarithm of each edge's random number, for both triangles
// at the edge; in the instance boxes' prefill, the expansions and the rays' walk), and
// std::fmod with std::sin, std::pow or std::log cost some 100 to 150 instructions. A value
// recalled is the one computed for the same bits of all N arguments. The slot is chosen by
// the first `Hashed` arguments only (the others, constants of a scene, are compared but not
// hashed). At first every slot holds the value at +0 arguments.
template <size_t N, class F, size_t Hashed = N>
class Recall {
  public:
    explicit Recall(F f) : f_(f) {
        const double atZero = std::apply(f_, std::array<double, N>{});
        for (Slot& s : slot_) s = Slot{{}, atZero};
    }
    double operator()(const std::array<double, N>& args) {
        std::array<uint64_t, N> bits;
        uint64_t h = 0;
        for (size_t i = 0; i < N; ++i) {
            bits[i] = std::bit_cast<uint64_t>(args[i]);
            if (i < Hashed) h = (h ^ bits[i]) * 0x9e3779b97f4a7c15ull;
        }
        Slot& s = slot_[h >> (64 - kLog2)];
        if (s.bits != bits) s = Slot{bits, std::apply(f_, args)};
        return s.value;
    }

  private:
    static_assert(Hashed >= 1 && Hashed <= N);
    static constexpr int kLog2 = 10;
    struct Slot {
        std::array<uint64_t, N> bits;
        double value;
    };
    F f_;
    std::array<Slot, size_t{1} << kLog2> slot_;
};

}  // namespace pcsg
