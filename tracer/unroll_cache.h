// The cache of expanded instances (unrolled_instances.h) of one scene, shared by all its
// tracer threads: each instance is expanded once, for every thread, within one byte
// budget for all of them.
//
//  - Reads: shards, each a hash map behind a reader-writer lock (a use takes the read
//    lock of one shard of 64); each thread uses the cache through a Reader of its own.
//  - Lifetime: instances are immutable once built. An instance evicted while another
//    thread traces it is freed only when that thread has unpinned (deferred_free.h): a
//    tracer's Reader is pinned from its first look-up in a ray to the ray's end. The
//    top level (top_level.h) shares instances with the cache (share()): one it holds
//    lives on after the cache evicts it, and is freed with the top level.
//  - Notes: the first meeting of an instance, by any thread, leaves a note; the second,
//    by any thread, expands it. A shadow ray's meeting counts a third of one: an instance
//    that only a camera ray and its shadow rays meet (a terrain's far patch, seen by one
//    pixel, its shadow rays starting inside it) stays a note and is walked, and one that
//    only shadow rays meet (a caster out of view) is expanded at their sixth meeting.
//    While one thread expands an instance it is marked "in construction", and the others
//    walk the graph below it meanwhile, not wait.
//  - Eviction: second chance (CLOCK) over all entries, in the order of insertion, until
//    the notes and instances fit the budget again; an instance in construction stays,
//    and the one just built gets its second chance.
//  - Per (module, depth): expansions made and uses of them, counted over all threads
//    (each thread adds its uses in batches); where the expansions are used less than four
//    times each, expansion stops. None of this changes a hit: an expanded instance gives
//    the same surfaces, bit for bit, as the graph walk.
//  - Budget: it starts small (kStartBytes, at most the maximum given) and grows toward the
//    maximum where a larger budget would have saved expansions. Ghosts, as in ARC: an
//    evicted instance leaves a note behind, and one met again and rebuilt while its note
//    is there grows the budget by its bytes. Misses: a level whose instances would fit the
//    maximum's share but not the budget reached's waits (it is not turned off); once its
//    instances have been met kMisses times while kStandIns expansions elsewhere stood in
//    for them, the budget grows to hold one. A tree whose every level is one instance is
//    served by one smaller expansion (and the top level's copies of it) and stays small;
//    one whose smaller instances are many and distinct gets the larger ones. What a level's
//    misses grew the budget by goes back when expansion stops there (its larger instances
//    did not pay: a terrain's patches of depth 6 and 7). A top level refused for its
//    many copies of small instances grows it for the waiting level too (Sierpinski
//    order 12: growForWaitingLevel). Ghosts grow the budget only while
//    their meetings are at least an eighth of the evictions so far (kGhostRate): a
//    terrain's patches, met again mostly far apart, leave it below the maximum. Which budget
//    each rule uses: eviction and an instance's share, the budget reached; the thrash
//    rules below, the maximum (a rebuild that grew the budget is not counted as one).
//  - Size: one instance may take at most an eighth of the budget reached. A larger one is
//    refused (its entry stays a note that is never expanded; or, where the maximum's
//    share holds it, its level waits, above) and so, once they are more than a
//    few, are the others of its (module, depth), and expansion stops there: the walk
//    goes below them and meets the smaller instances of the deeper levels, which are
//    expanded instead. Before expanding, the bytes are estimated from the heaviest
//    instance InstanceBoxes met at that depth and the bytes per visit of the expansions
//    so far, so that a level far too large is not even tried.
//  - Thrashing: an evicted instance leaves a note behind; expanding it again counts as a
//    rebuild (when the budget is at its maximum), and where a third of the expansions are
//    rebuilds, expansion stops. Where instances larger than 1/64 of the maximum have been
//    built for more bytes, in all, than half the maximum (a terrain's patches, each used by
//    the rays of a few tiles, or a level the budget cannot hold twice over), it stops
//    too: large instances pay only where they are few and used again and again (a
//    deterministic tree or fractal, whose every level is one instance).
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

#include "deferred_free.h"
#include "instance_boxes.h"
#include "unrolled_instances.h"

namespace pcsg::tracer {

class UnrollCache {
  public:
    // A budget of at most maxBytes, starting at startBytes (or maxBytes if less).
    UnrollCache(const TraceScene& scene, size_t maxBytes, size_t startBytes = kStartBytes);
    ~UnrollCache();  // (after its readers)
    UnrollCache(const UnrollCache&) = delete;
    UnrollCache& operator=(const UnrollCache&) = delete;

    class Reader;
    class Pin;

    // Instances expanded (all threads); bytes and entries held now (notes and instances);
    // bytes of evicted instances not freed yet (a reader may still hold them).
    uint64_t expansions() const { return expansions_.load(std::memory_order_relaxed); }
    size_t bytes() const { return bytes_.load(std::memory_order_relaxed); }
    size_t entries() const { return entries_.load(std::memory_order_relaxed); }
    size_t retiredBytes() const { return retired_.pendingBytes(); }
    size_t maxBytes() const { return maxBytes_; }
    // The budget reached (the start, grown by the ghosts' hits and the misses, see above).
    size_t budget() const { return budget_.load(std::memory_order_relaxed); }
    // The largest instance kept (an eighth of the budget reached).
    size_t maxInstanceBytes() const;
    // Whether an instance under this key may be built now: false when none with its filter
    // slot is (see built()); true for every built one.
    bool mayBeBuilt(const InstanceBoxes::Key& key) const {
        return builtFilter_[filterSlot(key)].load(std::memory_order_relaxed) != 0;
    }
    // Where the budget starts (unless told).
    static constexpr size_t kStartBytes = size_t{2} << 20;

    // What happened at one (module, depth) so far.
    struct Level {
        uint64_t built = 0;    // expansions (rebuilds included)
        uint64_t rebuilt = 0;  // expansions of instances that were built and evicted before
        uint64_t refused = 0;  // expansions larger than maxInstanceBytes(), thrown away
        bool off = false;      // expansion stopped there
    };
    Level level(NodeId select, uint32_t depth) const;

    // Grows the budget to hold an instance of the waiting level (too large for the budget
    // reached, not for the maximum's share) whose instances are the smallest, as its misses
    // would; for a top level refused for its many copies of smaller instances. Returns the
    // growth (0: no level waits).
    size_t growForWaitingLevel();

    // The instance stored under `key` if it is built (else nullptr), for a holder that keeps
    // it beyond a Pin scope (the top level): it stays valid while the holder holds it,
    // whatever the cache evicts meanwhile. Not counted as a use.
    std::shared_ptr<const UnrolledInstance> share(const InstanceBoxes::Key& key) const;

  private:
    struct Entry;
    struct Shard;
    struct Yield;
    static constexpr size_t kShards = 64;

    Shard& shardOf(const InstanceBoxes::Key& k) const;
    // The filter of built instances: per slot (bits of the key that neither the shards nor
    // their maps use), how many built instances have it, so that built() knows most misses
    // without a shard's lock and map (the walk asks at every S-node of an expanded level,
    // and few of those instances are built at a time). Changed under the shard's write
    // lock as an entry becomes Built or loses its instance; read without it: a reader that
    // misses an instance built a moment ago walks the graph below it, as before the build.
    static constexpr size_t kFilterSlots = 4096;
    static size_t filterSlot(const InstanceBoxes::Key& k) {
        return static_cast<size_t>(k.b >> 40) & (kFilterSlots - 1);
    }
    void filterAdd(const InstanceBoxes::Key& k, int delta) {
        builtFilter_[filterSlot(k)].fetch_add(static_cast<uint32_t>(delta),
                                              std::memory_order_relaxed);
    }
    size_t yieldIndex(NodeId select, uint32_t depth) const;
    void evict();
    double predictedBytes(NodeId select, uint32_t depth, double maxPerVisit = 1e300) const;
    bool waitForRoom(Yield& yield, size_t bytes);
    size_t growTo(size_t bytes);
    size_t growFor(Yield& yield);
    void turnOff(Yield& yield);
    void unghost(Entry& e);
    bool stopsAt(size_t y, NodeId select, uint32_t depth, size_t ghost, uint32_t pendingUses);
    void count(size_t y, NodeId select, uint32_t depth, size_t bytes);
    void refuse(size_t y);
    bool grow(size_t bytes);
    bool ghostsPay();

    const TraceScene& scene_;
    const size_t maxBytes_, startBytes_;
    std::atomic<size_t> budget_;
    const uint32_t levels_;
    std::unique_ptr<Shard[]> shards_;
    std::unique_ptr<std::atomic<uint32_t>[]> builtFilter_;
    std::unique_ptr<Yield[]> yield_;
    std::atomic<size_t> bytes_{0}, entries_{0};
    std::atomic<uint64_t> expansions_{0};
    // The bytes of the expansions so far, and the visits InstanceBoxes gave for them
    // (bytes per visit, for the estimate of predictedTooLarge).
    std::atomic<uint64_t> builtBytes_{0}, builtWeight_{0};
    std::mutex queueMutex_;
    std::deque<InstanceBoxes::Key> queue_;  // every entry, in the order of insertion
    std::atomic<size_t> ghostBytes_{0};     // of the evicted instances whose ghosts stay
    std::atomic<uint64_t> evicted_{0}, ghostHits_{0};
    DeferredFree retired_;
};

// One thread's use of the cache: its pins, its scratch space, its batch of use counts.
class UnrollCache::Reader {
  public:
    explicit Reader(UnrollCache& cache);
    ~Reader();
    Reader(const Reader&) = delete;
    Reader& operator=(const Reader&) = delete;

    // The expanded instance of the S-node instance (select, frame, path) at `depth`, or
    // nullptr (not worth expanding yet, being expanded by another thread, or too large).
    // Valid until the end of the Pin scope it was asked in. Throws RuntimeError (without
    // this S-node in its module path) when unrolling meets a run-time error.
    const UnrolledInstance* get(const InstanceBoxes::Key& key, NodeId select, uint32_t depth,
                                const double* frame, uint64_t path);
    const UnrolledInstance* get(NodeId select, uint32_t depth, const double* frame, uint64_t path);
    // The instance if it is expanded already (counted as a use), else nullptr: no note,
    // no expansion.
    const UnrolledInstance* built(const InstanceBoxes::Key& key, NodeId select, uint32_t depth);
    // get() for an instance that built() has just not found (the walk asks built() first,
    // then tests the instance's box): its meeting, which leaves a note or expands it, without
    // looking for it as a built one again. The same result as get(). A shadow ray's meeting
    // counts a third of another ray's (see Notes above).
    const UnrolledInstance* meet(const InstanceBoxes::Key& key, NodeId select, uint32_t depth,
                                 const double* frame, uint64_t path, bool shadow = false);

    UnrolledInstance::Scratch& scratch() { return scratch_; }
    uint64_t expansions() const { return expansions_; }  // made by this thread
    UnrollCache& cache() { return cache_; }

  private:
    friend class Pin;
    void pinOnce() {  // (before the first look-up in a Pin scope)
        if (pinned_) return;
        cache_.retired_.pin(*slot_);
        pinned_ = true;
    }
    const UnrolledInstance* expand(Shard& s, Entry& e, const InstanceBoxes::Key& key, size_t y,
                                   NodeId select, uint32_t depth, const double* frame,
                                   uint64_t path);
    void used(size_t y);
    void missed(size_t y);

    UnrollCache& cache_;
    DeferredFree::Slot* slot_;
    uint32_t scopes_ = 0;  // nested Pin scopes
    bool pinned_ = false;
    std::vector<uint32_t> uses_;    // per (module, depth): not yet added to the cache's
    std::vector<uint32_t> misses_;  // (the same, of meetings a larger budget would expand)
    uint64_t expansions_ = 0;
    UnrolledInstance::Scratch scratch_;
};

// The instances a reader (nullptr: none) hands out while a Pin lives stay valid until it
// ends (scopes nest). The reader pins itself at its first look-up in the scope, so that a
// ray that never asks for an expanded instance costs nothing.
class UnrollCache::Pin {
  public:
    explicit Pin(Reader* r) : r_(r) {
        if (r_) ++r_->scopes_;
    }
    ~Pin() {
        if (!r_ || --r_->scopes_ > 0 || !r_->pinned_) return;
        r_->cache_.retired_.unpin(*r_->slot_);
        r_->pinned_ = false;
    }
    Pin(const Pin&) = delete;
    Pin& operator=(const Pin&) = delete;

  private:
    Reader* r_;
};

}  // namespace pcsg::tracer
