// Exact boxes of S-node instances: the tracer's lazily filled, memory-bounded cache of
// what sub-graph instances hold (the seed paper's future-work "state grid", reduced to
// what culling needs).
//
// The hyper-bounding boxes (bounds.h) hold for every instance of a node at once. Where
// the instances differ a lot, they are loose: the terrain's heights travel in parameters,
// so the static box of every sub-triangle spans the whole terrain's height, and a ray
// that grazes the terrain enters thousands of them. The box of one instance, though, is
// a function of the instance alone: of its S-node, the values of the parameters its
// sub-graph reads (less those key_slots.h shows cannot differ between its instances)
// and, when the sub-graph calls rand() or choose(), its instance path (walk.h's
// ModuleDependencies). So the tracer asks this cache for an instance's box.
// A miss unrolls the instance through the shared walk (compiler/walk.h: the same code
// the expander uses), uniting the boxes of its primitives; the S-node instances met on
// the way are looked up and stored too, so filling the boxes of a whole object costs one
// expansion of it, not one per level.
//
//  - Boxes are composed level by level: an instance's box is built from the boxes of
//    the S-node instances inside it, each mapped by the matrices between the two
//    S-nodes. That is exact for translations and scales, and for rotations encloses the
//    rotated box. Every instance box is rounded outwards to floats (as the table stores
//    it), so it is the same number whether the inner boxes came from the cache or were
//    computed again: culling never depends on the cache's history.
//  - Only instances whose sub-graph took at least `minWeight` node visits to unroll are
//    stored (smaller ones are cheaper to recompute than to keep); the table stops
//    growing at `maxBytes`. Keys are 128-bit hashes of the instance (the table keeps 96
//    bits of them: 40 bytes an entry).
//  - Per (module, depth) the cache watches whether the exact boxes are worth it: when
//    the first instances at a depth are all small, or all about as large as the static
//    box there (a contractive system like the Sierpinski tetrahedron, whose static boxes
//    are already exact), that depth goes back to the static box alone. Culling with a
//    looser box is still sound and the tracer breaks ties between equally near hits by
//    their instance path, so images do not depend on these decisions.
//  - Filled ahead of need (prefill): before the first tile, the instances at the
//    shallowest depth where there are a few dozen of them are unrolled in parallel, so
//    that a large object's boxes are in the table when the first rays arrive (before,
//    every thread's first ray unrolled the same top instance, the whole terrain, at once).
//  - Thread-safe: shards with reader-writer locks; any number of tracers share one.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "bounds.h"
#include "fixed_slots.h"
#include "geometry.h"
#include "graph.h"
#include "semantics.h"
#include "subtree_count.h"
#include "walk.h"

namespace pcsg::tracer {

class SequenceInstanceBoxes;

// The keys of S-node instances: an instance is its S-node, the values of the parameters
// its sub-graph reads (ModuleDependencies::reads, as narrowKeySlots leaves them) and, when
// it calls rand() or choose(), its instance path, hashed to 128 bits. The walk makes one
// per S-node visit at a used depth, so the slots to hash are laid out per node, in one
// array, rather than found through the node's module and its dependencies each time.
class InstanceKeys {
  public:
    struct Key {
        uint64_t a = 0, b = 0;
        bool operator==(const Key&) const = default;
    };
    InstanceKeys(const Graph& g, const std::vector<ModuleDependencies>& deps);
    Key of(NodeId select, const double* frame, uint64_t path) const;

  private:
    struct Plan {
        uint32_t first = 0;  // the node's slots are slots_[first, first + count)
        uint32_t count = 0;
        bool usesPath = false;
    };
    std::vector<Plan> plans_;  // per node (S-nodes only)
    std::vector<Slot> slots_;
};

struct InstanceBoxOptions {
    size_t maxBytes = 64u << 20;  // the table's size limit
    // Store instances whose unrolling took this many visits (the terrain: its instances
    // of 64 triangles and more; those of 16 are 75% of the entries and paid nothing).
    uint64_t minWeight = 200;
    // Per (module, depth): decide after this many computed instances whether exact boxes
    // pay there.
    uint32_t trial = 24;
    // An exact box "pays" when it is smaller than the static box by this factor along
    // some axis.
    double gain = 0.8;
    // Depths whose instances all took between these many visits to unroll are worth
    // expanding (unrolled_instances.h). The upper limit only bounds the candidates: the
    // expansion cache (unroll_cache.h) keeps to the instances that fit its byte budget.
    uint64_t minExpandWeight = 12;
    uint64_t maxUnrollWeight = 1u << 20;
    // The frames of a sequence share the boxes that do not change with the time (see
    // SequenceInstanceBoxes); null: every box in this cache's own table.
    std::shared_ptr<SequenceInstanceBoxes> sequence;
};

struct InstanceBoxStats {
    uint64_t entries = 0;
    uint64_t bytes = 0;
    uint64_t computed = 0;  // instances unrolled on a miss
    bool full = false;      // the table reached maxBytes
};

class InstanceBoxes {
  public:
    InstanceBoxes(const Graph& g, const Bounds& bounds, const InstanceBoxOptions& options = {});
    // With the graph's fixed slots already found (TraceScene's, which its memo plan uses).
    InstanceBoxes(const Graph& g, const Bounds& bounds, const InstanceBoxOptions& options,
                  const FixedSlots& fixed);
    ~InstanceBoxes();
    InstanceBoxes(const InstanceBoxes&) = delete;
    InstanceBoxes& operator=(const InstanceBoxes&) = delete;

    // Whether exact boxes are used for this S-node at this depth (see above). (Inline, as
    // unrollAt: the walk asks at every S-node of every ray.)
    bool useAt(NodeId select, uint32_t depth) const {
        return depth < levels_ &&
               decision_[levelIndex(select, depth)].load(std::memory_order_relaxed) != 2;
    }
    // Whether the instances of this S-node at this depth are worth expanding: decided
    // with useAt, from the sizes of the first instances met there.
    bool unrollAt(NodeId select, uint32_t depth) const {
        return depth < levels_ &&
               expand_[levelIndex(select, depth)].load(std::memory_order_relaxed) != 0;
    }
    uint64_t maxUnrollWeight() const { return opt_.maxUnrollWeight; }
    // The visits the heaviest instance of this S-node at this depth took to unroll, of
    // those met so far (0: none), for the expansion cache's estimate of their bytes.
    uint64_t unrollWeight(NodeId select, uint32_t depth) const;

    // An instance: its S-node, the values of the parameters its sub-graph reads and, when
    // it calls rand() or choose(), its instance path, hashed to 128 bits.
    using Key = InstanceKeys::Key;
    Key keyOf(NodeId select, const double* frame, uint64_t path) const {
        return keys_.of(select, frame, path);
    }

    // What a thread needs to unroll instances (the walk's stacks): one per thread.
    class Worker;
    struct WorkerDeleter {
        void operator()(Worker* w) const;
    };
    using WorkerPtr = std::unique_ptr<Worker, WorkerDeleter>;
    WorkerPtr makeWorker() const;

    // The box of the S-node instance (select, frame, path) in the S-node's own frame,
    // padded like every box the tracer tests. Throws RuntimeError (without this S-node
    // in its module path: the caller adds it) when unrolling meets a run-time error.
    Box box(Worker& w, NodeId select, uint32_t depth, const double* frame, uint64_t path) const {
        return box(w, keyOf(select, frame, path), select, depth, frame, path);
    }
    // The same, with the instance's key computed by the caller.
    Box box(Worker& w, const Key& k, NodeId select, uint32_t depth, const double* frame,
            uint64_t path) const;

    // Fills the table ahead of need, in parallel on the calling thread's oneTBB pool: the
    // S-node instances at the shallowest depth below `start` (the axiom) where there are
    // enough of them to share out, each unrolled on a thread of its own, so that the
    // first rays find the boxes of a large object (a terrain) in the table instead of
    // all unrolling the same top instance at once. Their boxes are the numbers the rays'
    // misses would compute. A run-time error stops it quietly (the render meets the error
    // itself), and so does `cancel`. Does not take part in the trials of useAt/unrollAt.
    // The unrolling counts the expansion on the way (subtree_count.h): returns the counts
    // of the instances it unrolled, for countExpansion (CountOptions::known), so that the
    // primitive count need only walk the levels above them; null when there are none.
    std::shared_ptr<const KnownCounts> prefill(NodeId start,
                                               const std::atomic<bool>* cancel = nullptr) const;

    InstanceBoxStats stats() const;

  private:
    template <class>
    friend class BoxSinkOf;
    friend class SeedSink;
    friend class SequenceInstanceBoxes;
    struct Seed;
    class CountingWorker;
    std::vector<Seed> seedsAt(NodeId start, uint32_t depth, uint64_t maxVisits) const;
    std::vector<Seed> prefillSeeds(NodeId start) const;
    std::optional<KnownSubtree> unrollCounting(CountingWorker& w, const Seed& sd) const;
    struct Stored {
        Box box;
        uint64_t weight = 0;
    };
    class Table;

    Stored unroll(Worker& w, NodeId select, uint32_t depth, const double* frame,
                  uint64_t path) const;
    // The table that holds the instances of this S-node's module: the sequence's when its
    // sub-graph reads no time, else this cache's own.
    Table& tableOf(NodeId select) const;
    bool find(NodeId select, const Key& k, Stored& out) const;
    void insert(NodeId select, const Key& k, const Stored& s) const;
    // Whether an instance of this S-node at this depth was ever stored (then the table
    // may hold the one asked for), and the note that one was.
    bool mayHold(NodeId select, uint32_t depth) const;
    void held(NodeId select, uint32_t depth) const;
    void record(NodeId select, uint32_t depth, const Stored& s) const;
    // The index of (module, depth < levels_) in the per-level arrays below.
    size_t levelIndex(NodeId select, uint32_t depth) const {
        return static_cast<size_t>(g_.nodes[select].payload) * levels_ + depth;
    }

    const Graph& g_;
    Semantics sem_;
    const Bounds& bounds_;
    InstanceBoxOptions opt_;
    std::vector<ModuleDependencies> deps_;
    InstanceKeys keys_;  // after deps_: made from them, narrowed
    std::unique_ptr<Table> table_;
    std::shared_ptr<SequenceInstanceBoxes> sequence_;
    std::vector<uint8_t> lasting_;  // per module: its boxes go to the sequence's table
    mutable std::atomic<uint64_t> computed_{0};

    // Per (module, depth < levels_): 0 undecided, 1 use exact boxes, 2 static only;
    // whether to expand; whether an instance was ever stored; and the trial counters.
    uint32_t levels_ = 0;
    mutable std::unique_ptr<std::atomic<uint8_t>[]> decision_, expand_, stored_;
    mutable std::unique_ptr<std::atomic<uint32_t>[]> tried_, paid_;
    mutable std::unique_ptr<std::atomic<uint64_t>[]> minWeight_, maxWeight_;
};

// The boxes a sequence's frames share (tools/cli/render_command.cpp's runFrames): an
// instance of a module whose sub-graph reads neither `clock` nor `frame`
// (ModuleDependencies::usesTime) unrolls to the same primitives in every frame, so its box
// and weight are the same numbers in every frame, and its key (which holds no time) is
// exact across them. The frames' InstanceBoxes store such instances here and find what
// earlier frames computed; instances of modules that read the time stay in each frame's
// own table. For one graph (only its time changes between frames); thread-safe; at most
// maxBytes, beside each frame's own table.
class SequenceInstanceBoxes {
  public:
    SequenceInstanceBoxes(const Graph& g, size_t maxBytes);
    ~SequenceInstanceBoxes();
    SequenceInstanceBoxes(const SequenceInstanceBoxes&) = delete;
    SequenceInstanceBoxes& operator=(const SequenceInstanceBoxes&) = delete;

    uint64_t entries() const;
    uint64_t bytes() const;

  private:
    friend class InstanceBoxes;
    const Graph& g_;
    std::unique_ptr<InstanceBoxes::Table> table_;
};

}  // namespace pcsg::tracer
