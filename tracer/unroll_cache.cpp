// The shared cache of expanded instances: see unroll_cache.h.
#include "unroll_cache.h"

#include <tbb/spin_rw_mutex.h>

#include <algorithm>
#include <deque>
#include <unordered_map>

#include "traversal.h"

namespace pcsg::tracer {

namespace {

struct KeyHash {
    size_t operator()(const InstanceBoxes::Key& k) const { return static_cast<size_t>(k.b); }
};

// What a note costs (the entry, the map's node, its key in the eviction queue).
constexpr size_t kNoteBytes = 128;
// Uses a reader counts before adding them to the cache's figures.
constexpr uint32_t kUseBatch = 32;
// Expansions at a (module, depth) that are used less than kUses times each on average
// (judged from kTrial expansions on) do not pay.
constexpr uint64_t kTrial = 64, kUses = 4;
// One instance takes at most 1/kShare of the budget; instances above 1/kLarge of it are
// large (see unroll_cache.h). Where a third (1/kRebuilds) of the expansions at a level are
// rebuilds of evicted instances, the level thrashes.
constexpr size_t kShare = 8, kLarge = 64;
constexpr uint64_t kRebuilds = 3;
// A level whose instances are too large for the budget reached (not for the maximum) gets
// the budget it needs once they have been met kMisses times and kStandIns expansions at
// other levels stood in for them: a tree whose levels are one instance each is served by
// one smaller expansion below (and the top level's copies of it), and stays small; one whose
// smaller instances are many and distinct (a tree whose branches sway each in its own way)
// gains from the larger ones.
constexpr uint64_t kMisses = 256, kStandIns = 4;
// An evicted instance met again grows the budget only while such meetings are at least
// 1/kGhostRate of the instances evicted so far: where they are fewer (a terrain's patches,
// met again mostly far apart), the growth would buy few expansions for its bytes.
constexpr uint64_t kGhostRate = 8;
// A note's meetings, weighed: another ray's counts kMeeting, a shadow ray's kShadowMeeting;
// the instance is expanded once they add up to two of the others' (kExpandAt).
constexpr uint8_t kMeeting = 3, kShadowMeeting = 1, kExpandAt = 2 * kMeeting;
// The bytes per node visit of an expansion: the estimate before the first one, and the
// fewest, which bounds the visits of one (an expansion that reaches the limit is refused).
constexpr double kFirstBytesPerVisit = 64;
constexpr size_t kMinBytesPerVisit = 32;

}  // namespace

struct UnrollCache::Entry {
    enum class State : uint8_t { Note, Building, Built, TooLarge };
    State state = State::Note;                         // (written under the shard's write lock)
    std::atomic<bool> referenced{false};               // used since the eviction hand passed
    std::shared_ptr<const UnrolledInstance> instance;  // Built (shared with a top level)
    size_t bytes = kNoteBytes;
    uint8_t met = 0;   // a note's meetings so far, weighed (kMeeting, kShadowMeeting)
    size_t ghost = 0;  // a note left by an instance that was built and evicted: its bytes
};

struct alignas(64) UnrollCache::Shard {
    mutable tbb::spin_rw_mutex mutex;
    std::unordered_map<InstanceBoxes::Key, Entry, KeyHash> map;
};

struct UnrollCache::Yield {
    std::atomic<uint64_t> built{0}, used{0}, rebuilt{0}, refused{0};
    std::atomic<uint64_t> largeBytes{0};  // of the large instances built
    std::atomic<bool> off{false};
    // The budget at which its instances were predicted too large (0: never): they are tried
    // again once the budget has grown past it.
    std::atomic<size_t> tooLargeAt{0};
    std::atomic<size_t> want{0};      // the bytes of such an instance (predicted or built)
    std::atomic<uint64_t> missed{0};  // meetings of its instances since
    std::atomic<size_t> grew{0};      // what the budget grew by for it (misses)
    bool skipped(size_t budget) const {
        return off.load(std::memory_order_relaxed) ||
               tooLargeAt.load(std::memory_order_relaxed) >= budget;
    }
};

UnrollCache::UnrollCache(const TraceScene& scene, size_t maxBytes, size_t startBytes)
    : scene_(scene),
      maxBytes_(maxBytes),
      startBytes_(std::min(maxBytes, startBytes)),
      budget_(startBytes_),
      levels_(scene.graph().scene.settings.maxDepth + 2),
      shards_(std::make_unique<Shard[]>(kShards)),
      builtFilter_(std::make_unique<std::atomic<uint32_t>[]>(kFilterSlots)),
      yield_(std::make_unique<Yield[]>(scene.graph().modules.size() * levels_)) {}

UnrollCache::~UnrollCache() = default;

UnrollCache::Shard& UnrollCache::shardOf(const InstanceBoxes::Key& k) const {
    return shards_[k.a % kShards];
}

size_t UnrollCache::maxInstanceBytes() const {
    return budget() / kShare;
}

// An evicted instance's ghost is being expanded again (under its shard's write lock).
void UnrollCache::unghost(Entry& e) {
    ghostBytes_.fetch_sub(e.ghost, std::memory_order_relaxed);
    e.ghost = 0;
}

// Grows the budget to `bytes` (at most the maximum), if it is less; returns the growth.
size_t UnrollCache::growTo(size_t bytes) {
    size_t b = budget();
    const size_t want = std::min(maxBytes_, bytes);
    while (b < want && !budget_.compare_exchange_weak(b, want, std::memory_order_relaxed)) {
    }
    return b < want ? want - b : 0;
}

// Expansion stops at a level; the budget grown for its misses goes back (to the start at
// least): the larger instances it waited for did not pay.
void UnrollCache::turnOff(Yield& yield) {
    if (yield.off.exchange(true, std::memory_order_relaxed)) return;
    const size_t grew = yield.grew.exchange(0, std::memory_order_relaxed);
    size_t b = budget();
    while (grew > 0 && b > startBytes_ &&
           !budget_.compare_exchange_weak(b, std::max(startBytes_, b - std::min(b, grew)),
                                          std::memory_order_relaxed)) {
    }
}

// Grows the budget to hold one instance of a waiting level (and a quarter more); what it
// grew by goes back if expansion stops there (turnOff).
size_t UnrollCache::growFor(Yield& yield) {
    const size_t g = growTo(kShare * yield.want.load(std::memory_order_relaxed) * 5 / 4);
    yield.grew.fetch_add(g, std::memory_order_relaxed);
    return g;
}

// The waiting levels are those whose instances the budget reached does not hold
// (waitForRoom set their `want`, within the maximum's share).
size_t UnrollCache::growForWaitingLevel() {
    const size_t budget = this->budget();
    Yield* smallest = nullptr;
    for (size_t y = 0; y < scene_.graph().modules.size() * levels_; ++y) {
        Yield& yield = yield_[y];
        const size_t want = yield.want.load(std::memory_order_relaxed);
        if (!yield.off.load(std::memory_order_relaxed) && yield.skipped(budget) && want > 0 &&
            (!smallest || want < smallest->want.load(std::memory_order_relaxed)))
            smallest = &yield;
    }
    return smallest ? growFor(*smallest) : 0;
}

// An evicted instance is met again while its ghost is there: whether such meetings are
// frequent enough, of all the evictions so far, for a larger budget to pay.
bool UnrollCache::ghostsPay() {
    const uint64_t hits = ghostHits_.fetch_add(1, std::memory_order_relaxed) + 1;
    return hits * kGhostRate >= evicted_.load(std::memory_order_relaxed);
}

// Grows the budget by `bytes` (an evicted instance met again), up to the maximum; false
// when it is at the maximum already.
bool UnrollCache::grow(size_t bytes) {
    size_t b = budget();
    while (b < maxBytes_ && !budget_.compare_exchange_weak(b, std::min(maxBytes_, b + bytes),
                                                           std::memory_order_relaxed)) {
    }
    return b < maxBytes_;
}

UnrollCache::Level UnrollCache::level(NodeId select, uint32_t depth) const {
    if (depth >= levels_) return {};
    const Yield& y = yield_[yieldIndex(select, depth)];
    return {y.built.load(std::memory_order_relaxed), y.rebuilt.load(std::memory_order_relaxed),
            y.refused.load(std::memory_order_relaxed), y.off.load(std::memory_order_relaxed)};
}

size_t UnrollCache::yieldIndex(NodeId select, uint32_t depth) const {
    return static_cast<size_t>(scene_.graph().nodes[select].payload) * levels_ + depth;
}

// Second chance (CLOCK): entries used since the hand last passed them (and those in
// construction) go to the back of the queue; the others leave, until the cache fits.
// One evicting thread at a time (the queue's mutex, then a shard's lock).
void UnrollCache::evict() {
    std::vector<std::shared_ptr<const UnrolledInstance>> out;
    size_t freed = 0;
    {
        std::lock_guard<std::mutex> hand(queueMutex_);
        for (size_t turns = 2 * queue_.size(); turns > 0 && !queue_.empty(); --turns) {
            if (bytes_.load(std::memory_order_relaxed) <= budget()) break;
            const InstanceBoxes::Key k = queue_.front();
            queue_.pop_front();
            Shard& s = shardOf(k);
            tbb::spin_rw_mutex::scoped_lock lock(s.mutex, /*write=*/true);
            const auto it = s.map.find(k);
            if (it == s.map.end()) continue;  // (never: a key is queued while it is stored)
            Entry& e = it->second;
            if (e.state == Entry::State::Building ||
                e.referenced.exchange(false, std::memory_order_relaxed)) {
                queue_.push_back(k);
                continue;
            }
            if (e.instance) {  // leaves a ghost behind (a later expansion is a rebuild)
                filterAdd(k, -1);
                freed += e.bytes;
                out.push_back(std::move(e.instance));
                bytes_.fetch_sub(e.bytes, std::memory_order_relaxed);
                ghostBytes_.fetch_add(e.ghost = e.bytes, std::memory_order_relaxed);
                evicted_.fetch_add(1, std::memory_order_relaxed);
                e.bytes = 0;  // (a ghost's few bytes are not counted)
                e.state = Entry::State::Note;
                e.met = kMeeting;  // (met again, it is expanded again)
                e.referenced.store(true, std::memory_order_relaxed);  // (a second round)
                queue_.push_back(k);
                continue;
            }
            if (e.ghost > 0 && e.state == Entry::State::Note) {
                // Ghosts stay while they are no more than the budget could still grow by.
                if (ghostBytes_.load(std::memory_order_relaxed) <= maxBytes_ - budget()) {
                    queue_.push_back(k);
                    continue;
                }
                ghostBytes_.fetch_sub(e.ghost, std::memory_order_relaxed);
            }
            bytes_.fetch_sub(e.bytes, std::memory_order_relaxed);
            entries_.fetch_sub(1, std::memory_order_relaxed);
            s.map.erase(it);
        }
    }
    if (out.empty() && retired_.pendingBytes() > 0) retired_.reclaim();
    retired_.retire(out, freed);
}

// ---------------------------------------------------------------------------------------

UnrollCache::Reader::Reader(UnrollCache& cache)
    : cache_(cache),
      slot_(cache.retired_.join()),
      uses_(cache.scene_.graph().modules.size() * cache.levels_, 0),
      misses_(uses_.size(), 0) {}

UnrollCache::Reader::~Reader() {
    for (size_t y = 0; y < uses_.size(); ++y)
        if (uses_[y]) cache_.yield_[y].used.fetch_add(uses_[y], std::memory_order_relaxed);
    cache_.retired_.leave(slot_);
}

void UnrollCache::Reader::used(size_t y) {
    if (++uses_[y] < kUseBatch) return;
    cache_.yield_[y].used.fetch_add(uses_[y], std::memory_order_relaxed);
    uses_[y] = 0;
}

// A meeting at level y that the budget reached does not let it expand: where a larger budget
// would, once its instances have been met kMisses times and the cache has made kStandIns
// expansions below such levels, the budget grows to hold one of them (and a quarter more).
void UnrollCache::Reader::missed(size_t y) {
    Yield& yield = cache_.yield_[y];
    if (yield.off.load(std::memory_order_relaxed) || ++misses_[y] < kUseBatch) return;
    const uint64_t n = yield.missed.fetch_add(misses_[y], std::memory_order_relaxed) + misses_[y];
    misses_[y] = 0;
    if (n >= kMisses && cache_.expansions() >= kStandIns) cache_.growFor(yield);
}

const UnrolledInstance* UnrollCache::Reader::built(const InstanceBoxes::Key& key, NodeId select,
                                                   uint32_t depth) {
    if (depth >= cache_.levels_ || cache_.entries() == 0) return nullptr;
    const size_t y = cache_.yieldIndex(select, depth);
    if (cache_.yield_[y].skipped(cache_.budget()) || !cache_.mayBeBuilt(key)) return nullptr;
    Shard& s = cache_.shardOf(key);
    pinOnce();
    tbb::spin_rw_mutex::scoped_lock lock(s.mutex, /*write=*/false);
    const auto it = s.map.find(key);
    if (it == s.map.end() || it->second.state != Entry::State::Built) return nullptr;
    Entry& e = it->second;
    if (!e.referenced.load(std::memory_order_relaxed))
        e.referenced.store(true, std::memory_order_relaxed);
    used(y);
    return e.instance.get();
}

std::shared_ptr<const UnrolledInstance> UnrollCache::share(const InstanceBoxes::Key& key) const {
    Shard& s = shardOf(key);
    tbb::spin_rw_mutex::scoped_lock lock(s.mutex, /*write=*/false);
    const auto it = s.map.find(key);
    if (it == s.map.end() || it->second.state != Entry::State::Built) return nullptr;
    return it->second.instance;
}

const UnrolledInstance* UnrollCache::Reader::get(NodeId select, uint32_t depth, const double* frame,
                                                 uint64_t path) {
    return get(cache_.scene_.instanceBoxes()->keyOf(select, frame, path), select, depth, frame,
               path);
}

const UnrolledInstance* UnrollCache::Reader::get(const InstanceBoxes::Key& key, NodeId select,
                                                 uint32_t depth, const double* frame,
                                                 uint64_t path) {
    if (const UnrolledInstance* x = built(key, select, depth)) return x;
    return meet(key, select, depth, frame, path);
}

const UnrolledInstance* UnrollCache::Reader::meet(const InstanceBoxes::Key& key, NodeId select,
                                                  uint32_t depth, const double* frame,
                                                  uint64_t path, bool shadow) {
    if (depth >= cache_.levels_) return nullptr;
    const uint8_t weight = shadow ? kShadowMeeting : kMeeting;
    const size_t y = cache_.yieldIndex(select, depth);
    if (cache_.yield_[y].skipped(cache_.budget())) {
        missed(y);
        return nullptr;
    }
    Shard& s = cache_.shardOf(key);
    pinOnce();
    Entry* e = nullptr;
    bool inserted = false;
    {
        tbb::spin_rw_mutex::scoped_lock lock(s.mutex, /*write=*/true);
        const auto emplaced = s.map.try_emplace(key);
        const auto it = emplaced.first;
        inserted = emplaced.second;
        if (inserted) {  // the first meeting: only a note
            it->second.met = weight;
            cache_.bytes_.fetch_add(kNoteBytes, std::memory_order_relaxed);
            cache_.entries_.fetch_add(1, std::memory_order_relaxed);
        } else if (it->second.state == Entry::State::Built) {  // (built meanwhile)
            it->second.referenced.store(true, std::memory_order_relaxed);
            used(y);
            return it->second.instance.get();
        } else if (it->second.state == Entry::State::Note) {
            Entry& n = it->second;
            n.met = static_cast<uint8_t>(std::min<int>(kExpandAt, n.met + weight));
            if (n.met < kExpandAt) return nullptr;
            if (cache_.stopsAt(y, select, depth, n.ghost, uses_[y])) return nullptr;
            n.state = Entry::State::Building;  // met enough: expand
            if (n.ghost > 0) cache_.unghost(n);
            e = &n;
        }
    }
    if (!e) {
        if (inserted) {  // (queued after the shard's lock: the hand takes the queue first)
            std::lock_guard<std::mutex> hand(cache_.queueMutex_);
            cache_.queue_.push_back(key);
        }
        if (cache_.bytes() > cache_.budget()) cache_.evict();
        return nullptr;
    }
    return expand(s, *e, key, y, select, depth, frame, path);
}

// Expands the instance of entry e (in construction, so that it stays in its shard while
// no lock is held).
const UnrolledInstance* UnrollCache::Reader::expand(Shard& s, Entry& e,
                                                    const InstanceBoxes::Key& key, size_t y,
                                                    NodeId select, uint32_t depth,
                                                    const double* frame, uint64_t path) {
    std::unique_ptr<UnrolledInstance> x;
    try {
        const uint64_t maxVisits =
            std::min<uint64_t>(4 * cache_.scene_.instanceBoxes()->maxUnrollWeight(),
                               cache_.maxInstanceBytes() / kMinBytesPerVisit);
        x = UnrolledInstance::expand(cache_.scene_, select, depth, frame, path, maxVisits);
    } catch (...) {
        tbb::spin_rw_mutex::scoped_lock lock(s.mutex, /*write=*/true);
        e.state = Entry::State::Note;
        throw;
    }
    const UnrolledInstance* result = x.get();
    const size_t b = x ? x->bytes() + kNoteBytes : SIZE_MAX;
    {
        tbb::spin_rw_mutex::scoped_lock lock(s.mutex, /*write=*/true);
        if (b > cache_.maxInstanceBytes()) {  // (x, if any, is freed here: nobody has it)
            // (no x: it reached the visits the budget's share allows; a larger share may hold it)
            if (cache_.waitForRoom(cache_.yield_[y], x ? b : 2 * cache_.maxInstanceBytes())) {
                e.state = Entry::State::Note;
                return nullptr;
            }
            e.state = Entry::State::TooLarge;
            cache_.refuse(y);
            return nullptr;
        }
        cache_.bytes_.fetch_add(b - e.bytes, std::memory_order_relaxed);
        e.bytes = b;
        e.instance = std::move(x);
        e.referenced.store(true, std::memory_order_relaxed);  // (the one just built stays)
        e.state = Entry::State::Built;
        cache_.filterAdd(key, +1);
    }
    ++expansions_;
    cache_.expansions_.fetch_add(1, std::memory_order_relaxed);
    cache_.count(y, select, depth, b);
    used(y);
    if (cache_.bytes() > cache_.budget() || cache_.retiredBytes() > 0) cache_.evict();
    return result;
}

// Whether expansion stops at level y (select, depth), before the expansion of an instance
// met a second time (`ghost`: the bytes of the instance built and evicted before, else 0):
// its expansions are not used enough, or a third of them are rebuilds that the budget
// could not grow for, or its instances would not fit the budget reached (for now).
bool UnrollCache::stopsAt(size_t y, NodeId select, uint32_t depth, size_t ghost,
                          uint32_t pendingUses) {
    Yield& yield = yield_[y];
    const uint64_t b = yield.built.load(std::memory_order_relaxed);
    uint64_t rebuilt = yield.rebuilt.load(std::memory_order_relaxed);
    if (ghost > 0 && !(ghostsPay() && grow(ghost)))
        rebuilt = yield.rebuilt.fetch_add(1, std::memory_order_relaxed) + 1;
    const bool stop =
        b >= kTrial && (yield.used.load(std::memory_order_relaxed) + pendingUses < kUses * b ||
                        rebuilt * kRebuilds > b);
    if (stop) turnOff(yield);
    if (b > 0 || stop) return stop;
    const double bytes = predictedBytes(select, depth), share = maxBytes_ / kShare;
    if (bytes <= static_cast<double>(maxInstanceBytes())) return false;
    // Below the maximum, the level waits (for the maximum, where the estimate is above its
    // share: the estimate is rough); at the maximum, one that waited is tried where the
    // estimate before any expansion would have tried it (as it would have been, had the
    // budget been the maximum from the start), and the expansion's own size decides.
    if (budget() < maxBytes_)
        return waitForRoom(yield, static_cast<size_t>(std::min(bytes, share)));
    if (yield.tooLargeAt.load(std::memory_order_relaxed) > 0 &&
        predictedBytes(select, depth, kFirstBytesPerVisit) <= share)
        return false;
    turnOff(yield);
    return true;
}

// An instance of `bytes` at a level (yield) does not fit the budget reached: if it would fit
// the maximum, the level waits until the budget has grown for it (its instances' meetings
// meanwhile are misses, missed()); else false.
bool UnrollCache::waitForRoom(Yield& yield, size_t bytes) {
    if (bytes > maxBytes_ / kShare) return false;
    yield.want.store(bytes, std::memory_order_relaxed);
    yield.tooLargeAt.store(budget(), std::memory_order_relaxed);
    return true;
}

// The bytes of an instance at (select, depth), estimated from
// the weight of the heaviest met there and the bytes per visit of the expansions so far
// (at most maxPerVisit).
double UnrollCache::predictedBytes(NodeId select, uint32_t depth, double maxPerVisit) const {
    const uint64_t w = scene_.instanceBoxes()->unrollWeight(select, depth);
    const uint64_t bytes = builtBytes_.load(std::memory_order_relaxed);
    const uint64_t visits = builtWeight_.load(std::memory_order_relaxed);
    const double perVisit =
        visits > 0 ? static_cast<double>(bytes) / static_cast<double>(visits) : kFirstBytesPerVisit;
    return static_cast<double>(w) * std::min(perVisit, maxPerVisit);
}

// Counts an instance too large to keep at level y; stops expansion there when more than a
// quarter of its instances were.
void UnrollCache::refuse(size_t y) {
    Yield& yield = yield_[y];
    const uint64_t refused = yield.refused.fetch_add(1, std::memory_order_relaxed) + 1;
    if (refused * 4 > yield.built.load(std::memory_order_relaxed)) turnOff(yield);
}

// Counts an expansion of `bytes` at level y; stops expansion there when its large
// instances have been built for more bytes than half the budget.
void UnrollCache::count(size_t y, NodeId select, uint32_t depth, size_t bytes) {
    Yield& yield = yield_[y];
    yield.built.fetch_add(1, std::memory_order_relaxed);
    const uint64_t w = scene_.instanceBoxes()->unrollWeight(select, depth);
    if (w > 0) {
        builtBytes_.fetch_add(bytes, std::memory_order_relaxed);
        builtWeight_.fetch_add(w, std::memory_order_relaxed);
    }
    if (bytes <= maxBytes_ / kLarge) return;
    if (yield.largeBytes.fetch_add(bytes, std::memory_order_relaxed) + bytes > maxBytes_ / 2)
        turnOff(yield);
}

}  // namespace pcsg::tracer
