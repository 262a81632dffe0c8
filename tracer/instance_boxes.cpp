// Exact boxes of S-node instances: see instance_boxes.h.
#include "instance_boxes.h"

#include <tbb/spin_rw_mutex.h>

#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <unordered_map>

#include "key_slots.h"
#include "outward_float.h"
#include "primitives.h"
#include "thread_pool.h"

namespace pcsg::tracer {

namespace {

// SplitMix64's finaliser: parameter values are often dyadic fractions whose low bits
// are all zero, which a multiplicative hash alone would not spread.
inline uint64_t mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// A box as the table stores it (floats, rounded outwards). Every instance box is rounded
// so, stored or not, so that a box built from inner boxes is the same number whether
// they came from the table or were computed again.
inline Box storable(const Box& b) {
    if (b.isEmpty()) return Box::empty();
    Box r;
    for (int j = 0; j < 3; ++j) {
        r.lo[j] = castDown(b.lo[j]);
        r.hi[j] = castUp(b.hi[j]);
    }
    return r;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// The table: shards of open-addressing arrays, each behind a reader-writer lock.

class InstanceBoxes::Table {
  public:
    // 40 bytes: 96 bits of the key (its `a`, never 0, and half of its `b`), 4-byte aligned.
    struct Slot {
        uint32_t a0 = 0, a1 = 0, b1 = 0;  // a0 == 0 && a1 == 0: empty
        float lo[3], hi[3];
        uint32_t weight = 0;

        bool empty() const { return a0 == 0 && a1 == 0; }
        bool holds(const Key& k) const {
            return a0 == static_cast<uint32_t>(k.a) && a1 == static_cast<uint32_t>(k.a >> 32) &&
                   b1 == static_cast<uint32_t>(k.b >> 32);
        }
        // Where its probe begins: bits of `a` above the shard's.
        size_t home(size_t mask) const {
            return ((static_cast<size_t>(a1) << 32 | a0) >> 6) & mask;
        }
    };
    static_assert(sizeof(Slot) == 40);
    static size_t home(const Key& k, size_t mask) { return (k.a >> 6) & mask; }

    explicit Table(size_t maxBytes) : maxBytes_(maxBytes) {}

    bool find(const Key& k, Stored& out) const {
        const Shard& s = shard(k);
        tbb::spin_rw_mutex::scoped_lock lock(s.mutex, /*write=*/false);
        if (s.slots.empty()) return false;
        const size_t mask = s.slots.size() - 1;
        for (size_t i = home(k, mask);; i = (i + 1) & mask) {
            const Slot& slot = s.slots[i];
            if (slot.empty()) return false;
            if (slot.holds(k)) {
                for (int j = 0; j < 3; ++j) {
                    out.box.lo[j] = slot.lo[j];
                    out.box.hi[j] = slot.hi[j];
                }
                out.weight = slot.weight;
                return true;
            }
        }
    }

    void insert(const Key& k, const Stored& st) {
        Shard& s = shard(k);
        tbb::spin_rw_mutex::scoped_lock lock(s.mutex, /*write=*/true);
        if ((s.count + 1) * 4 > s.slots.size() * 3 && !grow(s)) return;
        const size_t mask = s.slots.size() - 1;
        for (size_t i = home(k, mask);; i = (i + 1) & mask) {
            Slot& slot = s.slots[i];
            if (slot.holds(k)) return;  // another thread was first
            if (slot.empty()) {
                slot.a0 = static_cast<uint32_t>(k.a);
                slot.a1 = static_cast<uint32_t>(k.a >> 32);
                slot.b1 = static_cast<uint32_t>(k.b >> 32);
                for (int j = 0; j < 3; ++j) {  // (exact: the box is storable())
                    slot.lo[j] = static_cast<float>(st.box.lo[j]);
                    slot.hi[j] = static_cast<float>(st.box.hi[j]);
                }
                slot.weight = static_cast<uint32_t>(std::min<uint64_t>(st.weight, UINT32_MAX));
                ++s.count;
                entries_.fetch_add(1, std::memory_order_relaxed);
                return;
            }
        }
    }

    uint64_t entries() const { return entries_.load(std::memory_order_relaxed); }
    uint64_t bytes() const { return bytes_.load(std::memory_order_relaxed); }
    bool full() const { return full_.load(std::memory_order_relaxed); }

  private:
    static constexpr size_t kShards = 64;
    struct alignas(64) Shard {
        mutable tbb::spin_rw_mutex mutex;
        std::vector<Slot> slots;  // size 0 or a power of two
        size_t count = 0;
    };

    Shard& shard(const Key& k) { return shards_[k.a % kShards]; }
    const Shard& shard(const Key& k) const { return shards_[k.a % kShards]; }

    // Doubles a shard's array (under its write lock), within the byte limit.
    bool grow(Shard& s) {
        const size_t size = s.slots.empty() ? 64 : s.slots.size() * 2;
        const size_t added = (size - s.slots.size()) * sizeof(Slot);
        size_t now = bytes_.load(std::memory_order_relaxed);
        do {
            if (now + added > maxBytes_) {
                full_.store(true, std::memory_order_relaxed);
                return false;
            }
        } while (!bytes_.compare_exchange_weak(now, now + added, std::memory_order_relaxed));
        std::vector<Slot> old = std::move(s.slots);
        s.slots.assign(size, Slot{});
        const size_t mask = size - 1;
        for (const Slot& o : old) {
            if (o.empty()) continue;
            size_t i = o.home(mask);
            while (!s.slots[i].empty()) i = (i + 1) & mask;
            s.slots[i] = o;
        }
        return true;
    }

    const size_t maxBytes_;
    Shard shards_[kShards];
    std::atomic<uint64_t> entries_{0}, bytes_{0};
    std::atomic<bool> full_{false};
};

// ---------------------------------------------------------------------------------------
// Unrolling one instance: a sink of the shared walk that unites primitive boxes.

struct BoxResult {
    Box box;
    uint64_t weight = 0;
};

// The same, with the count of the expanded sub-tree (the prefill's: subtree_count.h).
struct CountedBoxResult {
    Box box;
    uint64_t weight = 0;
    SubtreeCount count;
};

template <class R>
class BoxSinkOf {
  public:
    using Result = R;
    static constexpr bool kLocalSelectFrames = true;
    static constexpr bool kCounts = std::is_same_v<R, CountedBoxResult>;

    explicit BoxSinkOf(const InstanceBoxes& boxes) : boxes_(boxes) {}

    void reset() {
        visits_ = 0;
        starts_.clear();
        counted_ = true;
    }
    // Counting: whether the walk since reset() counted everything below it itself (no
    // stored box stood for a part): then its count is whole, and its visits are those
    // of the walk without memo.
    bool counted() const { return counted_; }

    Result nothing() const { return {}; }
    void visit() { ++visits_; }

    // An S-node instance met inside the one being unrolled. Where no instance of its
    // S-node and depth was ever stored, the table is not asked (nor its key computed):
    // the instances there are small, and most of all those met (a terrain's triangles).
    bool lookup(NodeId n, uint32_t depth, const double* frame, uint64_t path, Result& out) {
        if (!boxes_.mayHold(n, depth + 1)) {
            starts_.push_back({visits_, false, {}});
            return false;
        }
        InstanceBoxes::Stored s;
        const InstanceBoxes::Key k = boxes_.keyOf(n, frame, path);
        if (boxes_.find(n, k, s)) {
            out.box = s.box;
            out.weight = s.weight;
            visits_ += s.weight;  // it stands for that many visits
            counted_ = false;
            return true;
        }
        starts_.push_back({visits_, true, k});
        return false;
    }
    void store(NodeId n, uint32_t depth, const double* frame, uint64_t path, Result& r) {
        // Every visit below this S-node, including the ones its stored parts stand for.
        const Open open = starts_.back();
        starts_.pop_back();
        r.weight = visits_ - open.visits;
        r.box = storable(r.box);
        if (r.weight < boxes_.opt_.minWeight) return;
        const InstanceBoxes::Key k = open.keyed ? open.key : boxes_.keyOf(n, frame, path);
        boxes_.insert(n, k, InstanceBoxes::Stored{r.box, r.weight});
        boxes_.held(n, depth + 1);
    }

    Result toParent(const Affine& m, const Result& local) const {
        Result r = local;
        r.box = transformBox(m, local.box);
        return r;
    }

    Result primitive(PrimitiveKind kind, const Affine& world, uint32_t, const double* args,
                     uint32_t argc) const {
        Result r;
        if constexpr (kCounts) r.count = countPrimitive(kind, argc);
        if (kind == PrimitiveKind::Empty) return r;
        r.box = transformBox(world, primitiveBox(kind, args));
        r.weight = 1;
        return r;
    }

    void beginOperator(WalkEntry&) {}

    Result endOperator(CsgOp op, const Result* r, uint32_t n, const WalkEntry&) const {
        Result out;
        out.box = csgBox(op, n, [&](uint32_t i) { return r[i].box; });
        if constexpr (kCounts)
            out.count =
                countOperator(op, n, [&](uint32_t i) -> const SubtreeCount& { return r[i].count; });
        return out;
    }

  private:
    const InstanceBoxes& boxes_;
    uint64_t visits_ = 0;
    bool counted_ = true;
    struct Open {
        uint64_t visits;  // visits_ when the S-node instance began
        bool keyed;       // whether `key` was computed
        InstanceBoxes::Key key;
    };
    std::vector<Open> starts_;  // the open S-node instances, innermost last
};

using BoxSink = BoxSinkOf<BoxResult>;

template <class Sink>
struct WorkerOf {
    explicit WorkerOf(const InstanceBoxes& boxes, const Semantics& sem)
        : sink(boxes), walker(sem, sink) {}
    Sink sink;
    Walker<Sink> walker;
};

class InstanceBoxes::Worker : public WorkerOf<BoxSink> {
  public:
    explicit Worker(const InstanceBoxes& boxes)
        : WorkerOf<BoxSink>(boxes, boxes.sem_), recent_(kRecent) {}

    // The thread's last boxes, direct-mapped by key: an instance's box is a function of
    // its key, so a hit is the number the table (or an unrolling) would give, found
    // without the table's shared lock; the box comes padded, as box() returns it.
    struct Recent {
        Key key;  // key.a == 0: empty (no key has a == 0)
        Stored stored;
        Box padded;
    };
    Recent& recent(const Key& k) { return recent_[k.b & (kRecent - 1)]; }

  private:
    static constexpr size_t kRecent = 512;
    std::vector<Recent> recent_;
};

// The prefill's: counts what it unrolls (InstanceBoxes::prefill).
class InstanceBoxes::CountingWorker : public WorkerOf<BoxSinkOf<CountedBoxResult>> {
  public:
    explicit CountingWorker(const InstanceBoxes& boxes)
        : WorkerOf<BoxSinkOf<CountedBoxResult>>(boxes, boxes.sem_) {}
};

// ---------------------------------------------------------------------------------------

namespace {
// The modules' dependencies, with the key slots narrowed to the parameters that tell
// their instances apart.
std::vector<ModuleDependencies> narrowedDependencies(const Graph& g, const FixedSlots& fixed) {
    std::vector<ModuleDependencies> deps = moduleDependencies(g);
    narrowKeySlots(g, fixed, deps);
    return deps;
}
}  // namespace

InstanceKeys::InstanceKeys(const Graph& g, const std::vector<ModuleDependencies>& deps)
    : plans_(g.nodes.size()) {
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        if (g.nodes[n].kind != NodeKind::Select) continue;
        const ModuleDependencies& d = deps[g.nodes[n].payload];
        plans_[n] = Plan{static_cast<uint32_t>(slots_.size()),
                         static_cast<uint32_t>(d.reads.size()), d.usesPath};
        slots_.insert(slots_.end(), d.reads.begin(), d.reads.end());
    }
}

// Two lanes of xxHash64's round (acc = rotl(acc + v * P2, 31) * P1), each with its own
// constants, finished with SplitMix64's finaliser: one multiplication per value on each
// lane's dependency chain, where a full finaliser per value took three. The node's slots
// come from its plan (no look-up of its module's dependencies), two per loop: the same
// keys as hashing them one by one.
InstanceKeys::Key InstanceKeys::of(NodeId select, const double* frame, uint64_t path) const {
    constexpr uint64_t P1 = 0x9e3779b185ebca87ULL, P2 = 0xc2b2ae3d27d4eb4fULL;
    constexpr uint64_t P3 = 0x165667b19e3779f9ULL, P4 = 0x85ebca77c2b2ae63ULL;
    const Plan& p = plans_[select];
    uint64_t a = 0x84222325cbf29ce4ULL ^ (select * P1), b = 0x2545f4914f6cdd1dULL + select * P3;
    auto round = [&](uint64_t v) {
        a = std::rotl(a + v * P2, 31) * P1;
        b = std::rotl(b + v * P4, 29) * P3;
    };
    const Slot* s = slots_.data() + p.first;
    uint32_t left = p.count;
    for (; left >= 2; left -= 2, s += 2) {
        round(std::bit_cast<uint64_t>(frame[s[0]]));
        round(std::bit_cast<uint64_t>(frame[s[1]]));
    }
    if (left) round(std::bit_cast<uint64_t>(frame[*s]));
    if (p.usesPath) round(path);
    a = mix(a ^ (p.count + (p.usesPath ? 1 : 0)));
    b = mix(b ^ std::rotl(a, 32));
    return {a | 1, b};  // a != 0: never the empty slot
}

InstanceBoxes::InstanceBoxes(const Graph& g, const Bounds& bounds,
                             const InstanceBoxOptions& options)
    : InstanceBoxes(g, bounds, options, FixedSlots(g)) {}

InstanceBoxes::InstanceBoxes(const Graph& g, const Bounds& bounds,
                             const InstanceBoxOptions& options, const FixedSlots& fixed)
    : g_(g),
      sem_(g),
      bounds_(bounds),
      opt_(options),
      deps_(narrowedDependencies(g, fixed)),
      keys_(g, deps_),
      table_(std::make_unique<Table>(options.maxBytes)),
      sequence_(options.sequence),
      lasting_(g.modules.size(), 0),
      levels_(g.scene.settings.maxDepth + 2) {
    if (sequence_ && &sequence_->g_ != &g)
        throw std::logic_error("InstanceBoxes: the sequence's boxes belong to another graph");
    for (size_t m = 0; m < lasting_.size() && sequence_; ++m)
        lasting_[m] = deps_[m].analysed && !deps_[m].usesTime;
    const size_t n = g.modules.size() * static_cast<size_t>(levels_);
    decision_ = std::make_unique<std::atomic<uint8_t>[]>(n);
    expand_ = std::make_unique<std::atomic<uint8_t>[]>(n);
    stored_ = std::make_unique<std::atomic<uint8_t>[]>(n);
    tried_ = std::make_unique<std::atomic<uint32_t>[]>(n);
    paid_ = std::make_unique<std::atomic<uint32_t>[]>(n);
    minWeight_ = std::make_unique<std::atomic<uint64_t>[]>(n);
    maxWeight_ = std::make_unique<std::atomic<uint64_t>[]>(n);
    for (size_t i = 0; i < n; ++i) {
        // Modules whose dependencies could not be analysed cannot be keyed: static only.
        const bool analysed = deps_[i / levels_].analysed;
        decision_[i].store(analysed ? 0 : 2, std::memory_order_relaxed);
        expand_[i].store(0, std::memory_order_relaxed);
        stored_[i].store(0, std::memory_order_relaxed);
        tried_[i].store(0, std::memory_order_relaxed);
        paid_[i].store(0, std::memory_order_relaxed);
        minWeight_[i].store(UINT64_MAX, std::memory_order_relaxed);
        maxWeight_[i].store(0, std::memory_order_relaxed);
    }
}

InstanceBoxes::~InstanceBoxes() = default;

InstanceBoxes::WorkerPtr InstanceBoxes::makeWorker() const {
    return WorkerPtr(new Worker(*this));
}

void InstanceBoxes::WorkerDeleter::operator()(Worker* w) const {
    delete w;
}

bool InstanceBoxes::mayHold(NodeId select, uint32_t depth) const {
    if (depth >= levels_) return true;
    const size_t i = levelIndex(select, depth);
    return stored_[i].load(std::memory_order_relaxed) != 0;
}

void InstanceBoxes::held(NodeId select, uint32_t depth) const {
    if (depth >= levels_) return;
    const size_t i = levelIndex(select, depth);
    if (stored_[i].load(std::memory_order_relaxed) == 0)
        stored_[i].store(1, std::memory_order_relaxed);
}

uint64_t InstanceBoxes::unrollWeight(NodeId select, uint32_t depth) const {
    if (depth >= levels_) return 0;
    const size_t i = levelIndex(select, depth);
    return maxWeight_[i].load(std::memory_order_relaxed);
}

InstanceBoxes::Table& InstanceBoxes::tableOf(NodeId select) const {
    return lasting_[g_.nodes[select].payload] ? *sequence_->table_ : *table_;
}
bool InstanceBoxes::find(NodeId select, const Key& k, Stored& out) const {
    return tableOf(select).find(k, out);
}
void InstanceBoxes::insert(NodeId select, const Key& k, const Stored& s) const {
    tableOf(select).insert(k, s);
}

// The trial of exact boxes at (module, depth): do they pay?
void InstanceBoxes::record(NodeId select, uint32_t depth, const Stored& s) const {
    const size_t i = levelIndex(select, depth);
    if (decision_[i].load(std::memory_order_relaxed) != 0) return;
    bool pays = false;
    if (s.weight >= opt_.minWeight) {
        const Box& fixed = bounds_.select(g_, select, depth);
        if (s.box.isEmpty() && !fixed.isEmpty()) pays = true;
        for (int a = 0; a < 3 && !pays; ++a) {
            const double exact = s.box.hi[a] - s.box.lo[a], whole = fixed.hi[a] - fixed.lo[a];
            pays = !std::isfinite(whole) || exact < opt_.gain * whole;
        }
    }
    if (pays) paid_[i].fetch_add(1, std::memory_order_relaxed);
    uint64_t seen = minWeight_[i].load(std::memory_order_relaxed);
    while (s.weight < seen && !minWeight_[i].compare_exchange_weak(seen, s.weight)) {
    }
    seen = maxWeight_[i].load(std::memory_order_relaxed);
    while (s.weight > seen && !maxWeight_[i].compare_exchange_weak(seen, s.weight)) {
    }
    const uint32_t tried = tried_[i].fetch_add(1, std::memory_order_relaxed) + 1;
    if (tried >= opt_.trial) {
        const uint32_t paid = paid_[i].load(std::memory_order_relaxed);
        const bool expand = minWeight_[i].load(std::memory_order_relaxed) >= opt_.minExpandWeight &&
                            maxWeight_[i].load(std::memory_order_relaxed) <= opt_.maxUnrollWeight;
        expand_[i].store(expand ? 1 : 0, std::memory_order_relaxed);
        decision_[i].store(paid * 2 >= tried ? 1 : 2, std::memory_order_relaxed);
    }
}

Box InstanceBoxes::box(Worker& w, const Key& k, NodeId select, uint32_t depth, const double* frame,
                       uint64_t path) const {
    Worker::Recent& r = w.recent(k);
    if (r.key == k) {
        record(select, depth, r.stored);
        return r.padded;
    }
    Stored s;
    if (!find(select, k, s)) s = unroll(w, select, depth, frame, path);
    record(select, depth, s);
    r = {k, s, paddedBox(s.box)};
    return r.padded;
}

InstanceBoxes::Stored InstanceBoxes::unroll(Worker& w, NodeId select, uint32_t depth,
                                            const double* frame, uint64_t path) const {
    computed_.fetch_add(1, std::memory_order_relaxed);
    w.sink.reset();
    WalkStart start;
    start.node = select;
    start.frame = frame;
    start.path = path;
    start.depth = depth > 0 ? depth - 1 : 0;  // the walk counts this S-node itself
    const BoxResult r = w.walker.run(start, /*annotateStart=*/false);
    return Stored{r.box, r.weight};
}

// ---------------------------------------------------------------------------------------
// Filling ahead of need.

struct InstanceBoxes::Seed {
    NodeId node;
    uint32_t depth;
    uint64_t path;
    std::vector<double> frame;
};

namespace {
struct StopSeeding {};
}  // namespace

// A walk from the start that collects the distinct S-node instances at one depth (and
// goes no deeper), within a visit limit.
class SeedSink {
  public:
    struct Result {};
    SeedSink(const InstanceBoxes& boxes, uint32_t depth, uint64_t maxVisits)
        : boxes_(boxes), depth_(depth), maxVisits_(maxVisits) {}

    Result nothing() const { return {}; }
    void visit() {
        if (++visits_ > maxVisits_) throw StopSeeding{};
    }
    bool lookup(NodeId n, uint32_t depth, const double* frame, uint64_t path, Result&) {
        if (depth + 1 < depth_) return false;
        if (!boxes_.useAt(n, depth + 1)) return true;  // (an unanalysed module: not keyed)
        const InstanceBoxes::Key k = boxes_.keyOf(n, frame, path);
        for (const InstanceBoxes::Key& seen : keys_)
            if (seen == k) return true;
        keys_.push_back(k);
        const size_t slots = boxes_.g_.slotCount();
        seeds.push_back({n, depth + 1, path, std::vector<double>(frame, frame + slots)});
        if (seeds.size() > kMaxSeeds) throw StopSeeding{};
        return true;
    }
    void store(NodeId, uint32_t, const double*, uint64_t, const Result&) {}
    Result primitive(PrimitiveKind, const Affine&, uint32_t, const double*, uint32_t) const {
        return {};
    }
    void beginOperator(WalkEntry&) {}
    Result endOperator(CsgOp, const Result*, uint32_t, const WalkEntry&) const { return {}; }

    static constexpr size_t kMaxSeeds = 4096;
    std::vector<InstanceBoxes::Seed> seeds;

  private:
    const InstanceBoxes& boxes_;
    const uint32_t depth_;
    const uint64_t maxVisits_;
    uint64_t visits_ = 0;
    std::vector<InstanceBoxes::Key> keys_;
};

std::vector<InstanceBoxes::Seed> InstanceBoxes::seedsAt(NodeId start, uint32_t depth,
                                                        uint64_t maxVisits) const {
    SeedSink sink(*this, depth, maxVisits);
    Walker<SeedSink> walker(sem_, sink);
    WalkStart from;
    from.node = start;
    try {
        walker.run(from);
    } catch (const StopSeeding&) {
        return {};
    } catch (const RuntimeError&) {
        return {};
    }
    return std::move(sink.seeds);
}

// The instances to fill ahead: enough to share out among the threads, found by a walk of
// the levels above them (a few thousand visits at most).
std::vector<InstanceBoxes::Seed> InstanceBoxes::prefillSeeds(NodeId start) const {
    constexpr size_t kEnough = 64;
    constexpr uint64_t kMaxVisits = 1u << 20;
    std::vector<Seed> seeds;
    for (uint32_t depth = 1; depth + 1 < levels_ && seeds.size() < kEnough; ++depth) {
        std::vector<Seed> deeper = seedsAt(start, depth, kMaxVisits);
        if (deeper.size() <= seeds.size()) break;
        seeds = std::move(deeper);
    }
    return seeds;
}

// Unrolls a seed as a miss would, counting its expansion on the way: its count, when the
// walk counted everything below it itself (see BoxSinkOf::counted).
std::optional<KnownSubtree> InstanceBoxes::unrollCounting(CountingWorker& w, const Seed& sd) const {
    computed_.fetch_add(1, std::memory_order_relaxed);
    w.sink.reset();
    WalkStart start;
    start.node = sd.node;
    start.frame = sd.frame.data();
    start.path = sd.path;
    start.depth = sd.depth > 0 ? sd.depth - 1 : 0;  // the walk counts this S-node itself
    const CountedBoxResult r = w.walker.run(start, /*annotateStart=*/false);
    if (!w.sink.counted() || sd.depth == 0) return std::nullopt;
    return KnownSubtree{r.count, r.weight};
}

namespace {

// The counts of the instances the prefill unrolled, for the primitive count (a
// KnownCounts for countExpansion): found by their keys, at the one depth of the seeds.
class PrefillCounts : public KnownCounts {
  public:
    PrefillCounts(const InstanceKeys& keys, uint32_t depth) : keys_(keys), depth_(depth) {}

    void add(const InstanceBoxes::Key& k, const KnownSubtree& s) { known_.emplace(k, s); }
    bool empty() const { return known_.empty(); }

    bool find(NodeId select, uint32_t depth, const double* frame, uint64_t path,
              KnownSubtree& out) const override {
        if (depth + 1 != depth_) return false;
        const auto it = known_.find(keys_.of(select, frame, path));
        if (it == known_.end()) return false;
        out = it->second;
        return true;
    }

  private:
    struct KeyHash {
        size_t operator()(const InstanceBoxes::Key& k) const { return static_cast<size_t>(k.b); }
    };
    const InstanceKeys keys_;
    const uint32_t depth_;  // the seeds' (S-nodes passed, this one included)
    std::unordered_map<InstanceBoxes::Key, KnownSubtree, KeyHash> known_;
};

}  // namespace

std::shared_ptr<const KnownCounts> InstanceBoxes::prefill(NodeId start,
                                                          const std::atomic<bool>* cancel) const {
    const std::vector<Seed> seeds = prefillSeeds(start);
    if (seeds.size() < 2) return nullptr;
    std::vector<std::optional<KnownSubtree>> counted(seeds.size());
    std::vector<std::unique_ptr<CountingWorker>> workers(parallelSlots());
    std::atomic<bool> stop{false};
    parallelFor(seeds.size(), [&](size_t i, int slot) {
        if (stop.load(std::memory_order_relaxed) ||
            (cancel && cancel->load(std::memory_order_relaxed)))
            return;
        const Seed& sd = seeds[i];
        Stored s;
        if (find(sd.node, keyOf(sd.node, sd.frame.data(), sd.path), s)) return;
        if (!workers[slot]) workers[slot] = std::make_unique<CountingWorker>(*this);
        try {
            counted[i] = unrollCounting(*workers[slot], sd);
        } catch (const RuntimeError&) {
            stop = true;
        }
    });
    auto known = std::make_shared<PrefillCounts>(keys_, seeds.front().depth);
    for (size_t i = 0; i < seeds.size(); ++i)
        if (counted[i] && seeds[i].depth == seeds.front().depth)
            known->add(keyOf(seeds[i].node, seeds[i].frame.data(), seeds[i].path), *counted[i]);
    if (known->empty()) return nullptr;
    return known;
}

// With a sequence's table: its entries too (what this frame could find).
InstanceBoxStats InstanceBoxes::stats() const {
    InstanceBoxStats st;
    st.entries = table_->entries();
    st.bytes = table_->bytes();
    st.computed = computed_.load(std::memory_order_relaxed);
    st.full = table_->full();
    if (sequence_) {
        st.entries += sequence_->table_->entries();
        st.bytes += sequence_->table_->bytes();
        st.full = st.full || sequence_->table_->full();
    }
    return st;
}

SequenceInstanceBoxes::SequenceInstanceBoxes(const Graph& g, size_t maxBytes)
    : g_(g), table_(std::make_unique<InstanceBoxes::Table>(maxBytes)) {}

SequenceInstanceBoxes::~SequenceInstanceBoxes() = default;

uint64_t SequenceInstanceBoxes::entries() const {
    return table_->entries();
}
uint64_t SequenceInstanceBoxes::bytes() const {
    return table_->bytes();
}

}  // namespace pcsg::tracer
