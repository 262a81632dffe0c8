// Rays walk the cyclic graph directly, by the one semantics (eval.h): S-nodes select a
// rule, C-nodes compute a new parameter frame for their subtree, T-nodes map the ray into
// their child's frame by the inverse of their matrix, paint nodes set the material,
// operators combine their children. The graph is never expanded.
//
//  - The ray's direction is not normalised in child frames, so its parameter t is the same
//    number in every frame of the graph: distances compare across the whole walk.
//  - Normals travel back up: each T-node on the way back multiplies the normal found
//    below it by the transpose of its inverse matrix (the paper's matrix chain, kept on
//    the call stack), so a normal arrives in world space correctly even through mirrors
//    and shears.
//  - First hit (camera, shadow and reflection rays): a union visits its children front to
//    back by the entry of the ray into their hyper-bounding boxes and stops at the first
//    child whose box starts beyond the nearest hit found so far. Only intersections and
//    differences compute full span lists (span_list.h) of their operands, restricted to
//    the window of t that still matters.
//  - Hyper-bounding boxes (bounds.h) are tested at every S-node (with its per-depth box)
//    and for every operand of an operator, in every cycle. Where the static boxes are
//    loose, an S-node also tests the exact box of the instance at hand
//    (instance_boxes.h: a lazily filled, memory-bounded cache).
//  - Small instances that rays keep meeting are expanded once per thread
//    (unrolled_instances.h) and traced as flat arrays with the same matrices, so the
//    walk below them finds the same surfaces bit for bit without re-evaluating them.
//  - Above the depth where instances are expanded, once the cache knows that depth, a ray
//    is traced through the two-level structure of top_level.h instead of the walk: an
//    expansion of the graph from the axiom whose leaves are the copies of shared expanded
//    instances (the same matrices, the same surfaces bit for bit), or, where instances
//    are unique (a terrain's patches), whose leaves are deferred to this walk: the walk
//    resumes at such an S-node from the state stored there (Tracer::firstDeferred).
//  - Pattern space (docs/language.md section 10): a pattern lives in the frame of the paint
//    node that applied it. Where a paint node's material has a pattern (only then), the
//    walk records the ray as that node's frame sees it, and the hit's point in that frame
//    is that ray at the hit's t (the same number in every frame): no matrix products on
//    the way, and a scene without patterns records nothing.
//  - Ties: of two surfaces at exactly the same distance, the one with the smaller
//    instance path wins, whatever the order the walk found them in. So the image does
//    not depend on which boxes culled what (and the instance boxes' decisions depend on
//    the order threads fill the cache).
//  - Memory per ray: parameter frames come from a per-thread stack of blocks, span lists
//    from a per-thread vector used as a stack; nothing is allocated per ray once these
//    have grown to the scene's needs.
//  - Recursion: one C++ call per node visit. The depth of the walk is bounded by
//    (max_depth + 1) times the longest S-free path of the graph (recursionBound()); the
//    renderer runs the walk on threads whose stacks are sized from that bound
//    (stackBytesNeeded()), and a guard at every S-node turns a stack that would still run
//    out into a clear error instead of a crash.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "bounds.h"
#include "eval.h"
#include "graph.h"
#include "instance_boxes.h"
#include "last_occluder.h"
#include "operand_boxes.h"
#include "operators.h"
#include "primitives.h"
#include "semantics.h"
#include "step_memo.h"
#include "top_level.h"
#include "unroll_cache.h"
#include "unrolled_instances.h"

namespace pcsg::tracer {

struct SurfaceHit {
    double t = 0;
    Vec3 normal;  // world space, outward from the solid hit, not normalised
    uint32_t material = 0;
    // Materials with a pattern (TraceScene::paintFrames): the hit point in the frame of the
    // paint node that applied the material.
    bool painted = false;
    Vec3 paintPoint;
    // Materials with a normal pattern (TraceScene::kPaintMap): the map of points from the
    // world into the paint node's frame, owned by the tracer and valid until its next
    // walk (a pointer, so that rays of scenes without patterns carry no matrix).
    const Affine* paintMap = nullptr;
    // Scenes with transparency (TraceScene::interiors): the object whose interior the
    // surface is in (transparency.h), the paint node instance that applied its material (a
    // hash of the node and its instance path; 0: under no paint node).
    uint64_t interior = 0;
    uint64_t path = 0;  // the instance path of the surface (what breaks ties in t)
};

// The graph with everything the walk precomputes once: its semantics (with the fused
// chains of constant T-nodes), boxes, the recursion bound.
class TraceScene {
  public:
    TraceScene(const Graph& g, Bounds bounds, bool useInstanceBoxes = true,
               const InstanceBoxOptions& instanceBoxOptions = {});

    const Graph& graph() const { return g_; }
    const Bounds& bounds() const { return bounds_; }

    // The largest number of nested node visits a walk can make (see above).
    uint64_t recursionBound() const { return recursionBound_; }
    // Stack bytes a thread needs to walk this graph (with a generous margin).
    size_t stackBytesNeeded() const;

    // Tests turn culling off to check that it never changes a result.
    bool useBounds = true;

    // The exact boxes of instances (nullptr: static boxes only).
    const InstanceBoxes* instanceBoxes() const { return instanceBoxes_.get(); }

    // Expanded instances (unrolled_instances.h): one cache shared by all the tracers of
    // this scene (unroll_cache.h) holds at most this many bytes; 0 turns them off.
    size_t expansionBytes = 16u << 20;
    // Where that cache's budget starts (it grows toward expansionBytes where a larger one
    // saves expansions, unroll_cache.h); at expansionBytes, every expansion that fits it
    // is kept from the start.
    size_t expansionStartBytes = UnrollCache::kStartBytes;
    // That cache, made by the first tracer that asks for it (with expansionBytes then).
    UnrollCache& expansionCache() const;
    // The budget that cache reached (it starts small and grows, unroll_cache.h); 0 if
    // it was never made.
    size_t expansionBudget() const;

    // Each tracer remembers the results of C- and T-steps (compiler/step_memo.h) in a table
    // of at most 2^stepMemoLog2 entries (it starts within 128 KB and grows while it misses
    // often); 0 turns it off.
    uint32_t stepMemoLog2 = 12;

    // The two-level structure (top_level.h): built where it pays, in a budget of its own
    // as large as the expansion cache's (expansionBytes 0 turns it off too).
    bool twoLevel = true;
    // First-hit rays cull a union's operands by their boxes per instance of the S-node
    // whose rule is the union (operand_boxes.h) where the instance boxes are used; false:
    // by the operands' static boxes alone (tests compare the two).
    bool operandBoxes = true;
    // It, once built (nullptr: not yet, or refused).
    const TopLevel* topLevel() const { return top_.load(std::memory_order_acquire); }
    // Builds it now, unless another thread is building it or it was tried `maxTries` times
    // already; returns it (nullptr: refused or not built). The tracers call it once the
    // cache has seen enough rays to know where it expands; tests call it directly.
    const TopLevel* buildTopLevel(uint32_t maxTries = 4) const;
    // Tests: called by buildTopLevel between its first look for a built top level and its
    // lock, where another tracer may build and publish one.
    std::function<void()> beforeTopLock;

    // What entering each node means (with the fused chains of constant T-nodes).
    const Semantics& semantics() const { return sem_; }

    // Per material: whether a hit needs the point in its paint node's frame (its pigment
    // has a pattern: kPaintPoint), and the map into that frame too (its normal has a
    // pattern: kPaintMap). Empty: none does, and the walk records no frames.
    std::vector<uint8_t> paintFrames;
    // kPaintInterior: every material, in scenes with transparency (`interiors`), so that a
    // hit knows its paint node instance (SurfaceHit::interior).
    static constexpr uint8_t kPaintPoint = 1, kPaintMap = 2, kPaintInterior = 4;
    bool paintMaps = false;  // some material needs kPaintMap
    bool interiors = false;  // some material may let light through
    // Per node: a union's operands that its first hit looks at before the others
    // (firstOfUnion's `lead`, bit i: operand i): those that are one primitive without
    // arguments below paint nodes and constant T-nodes, in a union that has other operands
    // too (a plane beside a terrain). Their hit is cheap and narrows the window of the rest.
    std::vector<uint32_t> unionLeads;
    bool paintMapOf(uint32_t material) const {
        return material < paintFrames.size() && (paintFrames[material] & kPaintMap);
    }
    bool paintFrameOf(uint32_t material) const {
        return material < paintFrames.size() && paintFrames[material];
    }

  private:
    friend class Tracer;
    TraceScene(const Graph& g, Bounds bounds, bool useInstanceBoxes,
               const InstanceBoxOptions& instanceBoxOptions, const FixedSlots& fixed);
    void markPaintFrames();
    void markUnionLeads();
    const Graph& g_;
    Semantics sem_;
    StepMemoPlan memoPlan_;
    Bounds bounds_;
    uint64_t recursionBound_ = 0;
    std::unique_ptr<InstanceBoxes> instanceBoxes_;
    mutable std::once_flag expansionOnce_;
    mutable std::unique_ptr<UnrollCache> expansionCache_;
    mutable std::mutex topMutex_;  // held while building the top level
    mutable std::unique_ptr<TopLevel> topOwned_;
    mutable std::atomic<const TopLevel*> top_{nullptr};
    mutable uint32_t topTries_ = 0;  // (under topMutex_)
};

// The stack ran out although the walk stays within max_depth (the thread's stack is
// smaller than stackBytesNeeded()).
class StackExhausted : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// Per-thread walker: reuse one for all the rays of a thread. (It walks the Deferred nodes
// of a top level too, as the walker of its expansions' scratch space.)
class Tracer final : private UnrolledInstance::Walker {
  public:
    explicit Tracer(const TraceScene& scene);
    ~Tracer();

    // The nearest surface with tmin < t < tmax along origin + t dir (dir in world space;
    // t is the distance when dir has unit length). Throws RuntimeError (with its module
    // path) or StackExhausted.
    bool firstHit(const Vec3& origin, const Vec3& dir, double tmin, double tmax, SurfaceHit& hit);

    // Any surface with tmin < t < tmax (shadow rays): stops at the first one found.
    bool anyHit(const Vec3& origin, const Vec3& dir, double tmin, double tmax);

    // Node visits, of the graph and of expanded instances.
    uint64_t nodeVisits() const {
        return visits_ + (expansion_ ? expansion_->scratch().visits : 0);
    }
    // Instances this tracer expanded, and what the shared cache of them holds now.
    uint64_t expansions() const { return expansion_ ? expansion_->expansions() : 0; }
    size_t expansionCacheBytes() const { return expansion_ ? expansion_->cache().bytes() : 0; }
    size_t expansionCacheEntries() const { return expansion_ ? expansion_->cache().entries() : 0; }
    // Shadow rays answered by the copy of an instance that stopped an earlier one.
    uint64_t shadowShortcuts() const { return occluder_.stopped(); }
    // The lowest stack address a walk reached (for the stack-size test).
    uintptr_t stackLowWater() const { return lowWater_; }

  private:
    using Ctx = PathState;

    // Parameter frames: a stack of fixed-size blocks (addresses stay valid while deeper
    // frames are pushed).
    class FrameStack {
      public:
        explicit FrameStack(size_t frameSize);
        double* push() {  // (inline: once per C-node visit)
            if (slot_ == perBlock_) nextBlock();
            ++used_;
            return block_ + slot_++ * frameSize_;
        }
        void pop() {
            --used_;
            if (--slot_ == 0) previousBlock();
        }
        void reset() { used_ = 0, slot_ = perBlock_, block_ = nullptr; }

      private:
        void nextBlock();
        void previousBlock();
        size_t frameSize_, perBlock_;
        std::vector<std::unique_ptr<double[]>> blocks_;
        size_t used_ = 0;
        // The block of the top frame and the frames in it (with no frame: none, and
        // perBlock_, so that the first push moves to block 0).
        double* block_ = nullptr;
        size_t slot_;
    };

    bool first(NodeId n, const LocalRay& r, const Ctx& c, double tmin, double& tmax, Hit& hit,
               const OperandBoxes::Entry* operands = nullptr);
    bool firstOfPrimitive(NodeId n, const LocalRay& r, const Ctx& c, double tmin, double& tmax,
                          Hit& hit);
    bool firstOfSolid(NodeId n, const LocalRay& r, const Ctx& c, double tmin, double& tmax,
                      Hit& hit);
    size_t spans(NodeId n, const LocalRay& r, const Ctx& c, double tmin, double tmax);
    bool staticCulled(NodeId n, const LocalRay& r, uint32_t depth, double& t0, double& t1);
    bool exactCulled(NodeId n, const LocalRay& r, const Ctx& c, uint32_t depth, double t0,
                     double t1, std::optional<InstanceBoxes::Key>& key);
    const UnrolledInstance* builtAt(NodeId n, const Ctx& c, uint32_t depth,
                                    std::optional<InstanceBoxes::Key>& key);
    const UnrolledInstance* unrolledAt(NodeId n, const Ctx& c, uint32_t depth,
                                       std::optional<InstanceBoxes::Key>& key);
    const OperandBoxes::Entry* operandBoxesOf(NodeId select, const InstanceBoxes::Key& key,
                                              uint32_t depth, const Step& st);
    Box operandBox(NodeId u, uint32_t i, const Ctx& cu);
    template <bool kOperands, class Below, class Unrolled, class TransformBack>
    auto unary(NodeId n, const LocalRay& r, const Ctx& c, double tmin, double tmax, Below below,
               Unrolled unrolled, TransformBack transformBack);
    bool walk(const Vec3& origin, const Vec3& dir, double tmin, double tmax, SurfaceHit& hit);
    void resetWalk();
    bool firstDeferred(const UnrolledInstance::Deferred& d, const double* frame, const LocalRay& r,
                       double tmin, double& tmax, Hit& hit, uint32_t material) override;
    const TopLevel* topLevel();
    void checkStack() {  // (inline: once per S-node visit)
        const auto here = reinterpret_cast<uintptr_t>(__builtin_frame_address(0));
        if (here < lowWater_) lowWater_ = here;
        if (here < stackLimit_) checkStackLimit(here);
    }
    [[gnu::noinline]] void checkStackLimit(uintptr_t here);
    Affine paintMapHere(uint32_t material) const;

    const TraceScene& scene_;
    const Graph& g_;
    FrameStack frames_;
    InstanceBoxes::WorkerPtr boxWorker_;
    std::unique_ptr<StepMemo> memo_;  // null: scene_.stepMemoLog2 is 0
    OperandBoxes operandBoxes_;
    std::unique_ptr<UnrollCache::Reader> expansion_;
    std::vector<double> rootFrame_;
    std::vector<Span> spans_;
    std::vector<std::pair<double, uint32_t>> order_;
    std::vector<LocalRay>
        paintRays_;  // the ray in the frame of each paint node (PathState::paint - 1)
    std::vector<uint64_t> paintInteriors_;  // and that paint node instance's interior
    // With TraceScene::paintMaps: the inverse matrices of the T-nodes above the node being
    // visited, outermost first, and the map from the world into each paint node's frame
    // (beside paintRays_; identity where the material has no normal pattern).
    // (also in shadow rays' walks, for occluder_)
    std::vector<const Affine*> inverses_;
    std::vector<Affine> paintMaps_;
    LastOccluder occluder_;  // shadow rays: the copy of an instance that stopped the last one
    bool anyHit_ = false;
    uint64_t visits_ = 0;
    // Rays that entered the scene's box by the walk, the count at which to try to build the
    // top level next, and the expansion cache's count of expansions at the last try.
    uint64_t walks_ = 0, nextTopTry_ = kWalksBeforeTop, expansionsTried_ = 0;
    static constexpr uint64_t kWalksBeforeTop = 2048;
    uintptr_t stackLimit_ = UINTPTR_MAX;  // not yet known (0: unknown to the system)
    uintptr_t lowWater_ = UINTPTR_MAX;
};

}  // namespace pcsg::tracer
