// Deferred freeing: see deferred_free.h.
#include "deferred_free.h"

#include <algorithm>

namespace pcsg::tracer {

DeferredFree::~DeferredFree() = default;

DeferredFree::Slot* DeferredFree::join() {
    std::lock_guard<std::mutex> lock(mutex_);
    slots_.push_back(std::make_unique<Slot>());
    return slots_.back().get();
}

void DeferredFree::leave(Slot* s) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::erase_if(slots_, [s](const std::unique_ptr<Slot>& p) { return p.get() == s; });
    reclaimLocked();
}

void DeferredFree::retireErased(std::shared_ptr<void> objects, size_t bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    // The objects are out of the structure already: a reader that reads this epoch or a
    // later one (acquire) looks the structure up after that.
    const uint64_t tag = epoch_.fetch_add(1, std::memory_order_acq_rel);
    retired_.push_back(Retired{tag, std::move(objects), bytes});
    pendingBytes_.fetch_add(bytes, std::memory_order_relaxed);
    reclaimLocked();
}

void DeferredFree::reclaim() {
    std::lock_guard<std::mutex> lock(mutex_);
    reclaimLocked();
}

void DeferredFree::reclaimLocked() {
    if (retired_.empty()) return;
    // Pairs with pin()'s fence: either the reader's pin is seen here, or its look-up came
    // after the objects were taken out.
    std::atomic_thread_fence(std::memory_order_seq_cst);
    uint64_t oldest = kIdle;
    for (const auto& s : slots_)
        oldest = std::min(oldest, s->epoch.load(std::memory_order_relaxed));
    size_t freed = 0;
    std::erase_if(retired_, [&](const Retired& r) {
        if (r.epoch >= oldest) return false;
        freed += r.bytes;
        return true;
    });
    pendingBytes_.fetch_sub(freed, std::memory_order_relaxed);
}

size_t DeferredFree::pending() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return retired_.size();
}

}  // namespace pcsg::tracer
