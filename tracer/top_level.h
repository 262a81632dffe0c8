// The two-level structure (as Embree's instancing): above the depth where instances are
// expanded (unrolled_instances.h), a ray no longer walks the cyclic graph (S-node
// culling, instance keys, cache look-ups, C-node memo, T-node maps: ~160 instructions a
// node visit) but one expansion of the whole graph from the axiom whose leaves are the
// copies of expanded instances, each a chain of inverse matrices and a reference to the
// one UnrolledInstance its copies share, under the expansions' own four-wide BVH over the
// copies' boxes in the top frame.
//
//  - One mechanism: the top level is an UnrolledInstance (expandTop) whose nodes of kind
//    Instance refer to the expanded instances this class holds: the expansion cache's own
//    where it has built them (UnrollCache::share: each exists once, and lives on here
//    when the cache evicts it), else expanded here. Above the cuts it takes
//    the graph walk's steps (semantics.h) in the same order, so a copy's ray is mapped by
//    the same matrices, in the same order, as the walk maps it; a hit's path is the
//    top level's path to the S-node followed by the instance's own; materials are
//    inherited from the paint nodes above as the walk gives them. Images do not change.
//  - Where it cuts: at the first S-node on a path where the tracer would hand the ray to
//    an expanded instance (InstanceBoxes::unrollAt) and the expansion cache has built
//    instances of that (module, depth) without refusing one as too large; elsewhere it
//    expands in place. Copies are shared by their instance key (and depth).
//  - When it is refused (then tried with deferred cuts, below): an operator other than a
//    union above the cuts, a paint node whose material needs its frame or its instance
//    (a pattern, transparency: Instance and Deferred nodes would not pass it on), a level
//    where the cache stopped expanding, more than half as many instances as copies (a
//    terrain's patches: every instance unique), more than `maxBytes` in all (top and instances),
//    more node visits above the cuts than kMaxVisits and a few per copy met (see below),
//    an instance whose deepest S-node passes max_depth, or a run-time error (the walk
//    raises it where a ray meets it). Not tried again with deferred cuts: a dry run refused
//    while its copies were many and their instances few (a larger instance will do).
//  - Deferred cuts (unique instances: a terrain's patches, a conifer's branches): the same
//    expansion, cut at the first S-node on a path where the tracer would hand the ray to an
//    expanded instance and the cache expands that depth (for any module, and has not
//    stopped for this one), whether or not it has built this instance. The cut is a node
//    of kind Deferred: the S-node, its state (the parameters, copied; the instance path;
//    the depth) and its key, under the instance's exact box (InstanceBoxes). A ray that
//    meets its box is handed to the tracer (Tracer::firstDeferred), which does there what
//    the walk does at that S-node once its boxes let the ray through: the cache's
//    expansion (a meeting as the walk's, so the cache goes on learning and expanding), or
//    the walk below it. So a ray reaches the patch it meets through one hierarchy instead
//    of the walk of every level above it (the terrain: 50 M node visits at 640x480 became
//    7 M). Refused where a paint node's material needs its frame (the walk below a
//    deferred node does not have the matrices above it), where the cache expands nowhere,
//    or past maxBytes / kBytesPerDeferredVisit node visits or `maxBytes`. A run-time error
//    below a cut refuses it too: the exact box of the cut's instance unrolls all of it and
//    meets the error (so a walk below a deferred node never raises one without the
//    modules above its cut in its path).
//  - When it is built: by TraceScene::buildTopLevel, which a tracer calls once the
//    expansion cache has seen a few thousand rays enter the scene (so that the cuts are
//    known); per TraceScene, so per frame of a sequence. Immutable once built.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "unroll_cache.h"
#include "unrolled_instances.h"

namespace pcsg::tracer {

class TopLevel {
  public:
    // Node visits above the cuts before the top level is refused: kMaxVisits, and
    // kVisitsPerCopy more for each copy met so far, but no more than one per
    // kBudgetPerVisit bytes of the budget (32,768 in 16 MB: Sierpinski order 12's 4,096
    // copies take ~20,000; the top level's arrays take ~60 bytes a visit, twice that
    // while they grow, so that a try refused for its size, order 13 and up, holds ~4 MB
    // at most: 65,536 gave order 13 a top level, and orders 14 to 16 5 to 8 MB more peak
    // RSS for the tries). A terrain's dry runs, which find no cuts, stop at kMaxVisits
    // (4 tries of ~2 M instructions).
    static constexpr uint64_t kMaxVisits = 1u << 13;
    static constexpr uint64_t kVisitsPerCopy = 16;
    static constexpr uint64_t kBudgetPerVisit = 512;
    // Copies met by a refused dry run above which larger instances would help (see build).
    static constexpr uint64_t kManyCopies = 1024;

    // The top level of the scene, cut where `cache` expands, or nullptr (refused, see
    // above). `manyCopies` (if given) tells whether it was refused while its copies were
    // many and their instances few: cut at larger instances, it would hold fewer copies.
    // Throws RuntimeError when unrolling meets a run-time error.
    static std::unique_ptr<TopLevel> build(const TraceScene& scene, const UnrollCache& cache,
                                           size_t maxBytes, bool* manyCopies = nullptr);

    // The nearest surface as Tracer::first from the axiom finds it (world ray). With
    // deferred() nodes, `s` must be the scratch of a tracer's expansion cache reader (its
    // walker walks them).
    bool first(const LocalRay& r, double tmin, double& tmax, Hit& hit, bool anyHit,
               UnrolledInstance::Scratch& s) const {
        return top_->first(r, tmin, tmax, hit, {kRootPath, 0, 0}, anyHit, s);
    }

    size_t bytes() const { return bytes_; }    // the top level and the instances it holds
    size_t copies() const { return copies_; }  // of shared instances (none: deferred cuts)
    size_t instances() const { return owned_.size(); }
    // Instances it holds that the expansion cache had built (and shares with it).
    size_t sharedInstances() const { return shared_; }
    const UnrolledInstance& instance(size_t i) const { return *owned_[i]; }

    // Deferred nodes (the top level of a scene whose instances are all but unique).
    size_t deferred() const { return top_ ? top_->deferredNodes() : 0; }

  private:
    class Cuts;
    class DeferredCuts;
    // The node visits of a top level with deferred cuts: one per this many bytes of the
    // budget (262,144 in 16 MB; the terrain's top level, 8,192 cuts, takes 3.6 MB).
    static constexpr size_t kBytesPerDeferredVisit = 64;
    static std::unique_ptr<TopLevel> buildDeferred(const TraceScene& scene,
                                                   const UnrollCache& cache, size_t maxBytes);
    // The instances the copies refer to: the expansion cache's where it had built them
    // (which stay valid here when the cache evicts them), else the top level's own.
    std::vector<std::shared_ptr<const UnrolledInstance>> owned_;
    std::unique_ptr<UnrolledInstance> top_;
    size_t bytes_ = 0, copies_ = 0, shared_ = 0;
};

}  // namespace pcsg::tracer
