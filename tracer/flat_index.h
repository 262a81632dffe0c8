// A map from 64-bit keys to 32-bit indices in one flat array: the unroller's (unrolled_
// instances.cpp) de-duplication of the matrices and the chains of matrices of an expanded
// instance.
//
// Those had been std::unordered_maps: a node allocation per entry, a terrain patch of 256
// triangles some 600 of them per expansion and 17,500 expansions per 640x480 frame, which
// with the expansions' growing and freed arrays kept glibc's allocator busy (malloc and
// free, and malloc_consolidate on each large free: about 8% of the terrain's CPU samples).
// Here the entries live in one power-of-two array with linear probing, at most half full;
// it grows by doubling and is never shrunk. A thread keeps its indices from one expansion
// to the next: clear() empties one by a new stamp (a slot is used when it holds the
// current one), so that an expansion neither grows nor rehashes the table again, nor
// writes its slots to empty it. What it answers is what the unordered_map answered: the
// value stored first under a key, so the indices an expansion gets, and so its arrays,
// are the same.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace pcsg::tracer {

class FlatIndex {
  public:
    // The value stored under `key`, or, when there is none, `value` stored under it:
    // {that value, whether it was stored now} (as std::unordered_map::try_emplace).
    std::pair<uint32_t, bool> tryEmplace(uint64_t key, uint32_t value) {
        if ((count_ + 1) * 2 > slots_.size()) grow();
        const size_t mask = slots_.size() - 1;
        for (size_t i = home(key, mask);; i = (i + 1) & mask) {
            Slot& s = slots_[i];
            if (s.stamp != stamp_) {
                s = {key, value, stamp_};
                ++count_;
                return {value, true};
            }
            if (s.key == key) return {s.value, false};
        }
    }

    size_t size() const { return count_; }
    size_t slots() const { return slots_.size(); }
    size_t bytes() const { return slots_.capacity() * sizeof(Slot); }

    // Empties the index, keeping its slots.
    void clear() {
        count_ = 0;
        if (++stamp_ != 0) return;
        for (Slot& s : slots_) s.stamp = 0;  // (the stamps wrapped: all slots empty again)
        stamp_ = 1;
    }
    // Empties the index and frees its slots.
    void release() {
        std::vector<Slot>().swap(slots_);
        count_ = 0;
    }

  private:
    struct Slot {
        uint64_t key = 0;
        uint32_t value = 0;
        uint32_t stamp = 0;  // used when stamp_
    };

    // Fibonacci hashing: keys may be (parent << 32 | matrix) pairs, whose low bits alone
    // would crowd a few slots.
    static size_t home(uint64_t key, size_t mask) {
        return static_cast<size_t>((key * 0x9e3779b97f4a7c15ULL) >> 32) & mask;
    }

    void grow() {
        std::vector<Slot> old = std::move(slots_);
        slots_.assign(old.empty() ? 64 : old.size() * 2, Slot{});
        const size_t mask = slots_.size() - 1;
        for (const Slot& o : old) {
            if (o.stamp != stamp_) continue;
            size_t i = home(o.key, mask);
            while (slots_[i].stamp == stamp_) i = (i + 1) & mask;
            slots_[i] = o;
        }
    }

    std::vector<Slot> slots_;  // size 0 or a power of two
    size_t count_ = 0;
    uint32_t stamp_ = 1;  // never 0, the stamp of a slot never used
};

}  // namespace pcsg::tracer
