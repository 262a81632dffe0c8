// Deferred freeing for data shared by threads that read it without locks or reference
// counts (epoch-based reclamation): an object taken out of a shared structure is
// "retired", and freed only when no reader can still hold it.
//
// A reader pins itself while it may hold pointers into the structure (the tracer: for
// one ray) and unpins after. Pinning records the global epoch; retiring an object tags it
// with the epoch and advances it. An object is freed once every reader is unpinned or
// pinned at a later epoch than its tag: such a reader looked the structure up after the
// object was taken out of it (the fences order the two), so it cannot hold it.
//
// Readers pin and unpin on their own cache lines (two stores and a fence); retiring and
// freeing take a mutex (they are rare: an eviction).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace pcsg::tracer {

class DeferredFree {
  public:
    DeferredFree() = default;
    ~DeferredFree();  // frees everything retired (no reader may be pinned)
    DeferredFree(const DeferredFree&) = delete;
    DeferredFree& operator=(const DeferredFree&) = delete;

    // One reader's state: its epoch while pinned, kIdle else.
    struct alignas(64) Slot {
        std::atomic<uint64_t> epoch{kIdle};
    };
    static constexpr uint64_t kIdle = UINT64_MAX;

    Slot* join();
    void leave(Slot* s);  // (unpinned)

    void pin(Slot& s) {
        s.epoch.store(epoch_.load(std::memory_order_acquire), std::memory_order_relaxed);
        std::atomic_thread_fence(std::memory_order_seq_cst);
    }
    void unpin(Slot& s) { s.epoch.store(kIdle, std::memory_order_release); }

    // Hands over objects already taken out of the shared structure (`bytes` in all), then
    // frees what no reader can hold any more. `Owner`: std::unique_ptr, or std::shared_ptr
    // (then an object lives on while another owner holds it).
    template <class Owner>
    void retire(std::vector<Owner>& objects, size_t bytes);
    // Frees what no reader can hold any more.
    void reclaim();

    size_t pendingBytes() const { return pendingBytes_.load(std::memory_order_relaxed); }
    size_t pending() const;

  private:
    struct Retired {
        uint64_t epoch;
        std::shared_ptr<void> objects;  // (type-erased: frees the vector and its objects)
        size_t bytes;
    };
    void retireErased(std::shared_ptr<void> objects, size_t bytes);
    void reclaimLocked();

    std::atomic<uint64_t> epoch_{1};
    std::atomic<size_t> pendingBytes_{0};
    mutable std::mutex mutex_;  // slots_, retired_
    std::vector<std::unique_ptr<Slot>> slots_;
    std::vector<Retired> retired_;
};

template <class Owner>
void DeferredFree::retire(std::vector<Owner>& objects, size_t bytes) {
    if (objects.empty()) return;
    retireErased(std::make_shared<std::vector<Owner>>(std::move(objects)), bytes);
    objects.clear();
}

}  // namespace pcsg::tracer
