// Expanded instances: the tracer's lazily filled, memory-bounded cache of small sub-graph
// instances unrolled into flat arrays (the seed paper's future-work idea of keeping
// states of the graph, as a lazily filled cache of expanded sub-graph instances bounded
// in memory).
//
// Deep in a recursion the graph walk spends its time on bookkeeping, not geometry: each
// ray that reaches a flower head evaluates the selection and the C-node of every petal
// again, rebuilds every parameter-dependent matrix and walks a chain of 21 S-nodes. An
// expanded instance does that once: the instance's primitives and ∪ ∩ \ nodes in flat
// arrays, each with the exact box of what it holds and with the inverse matrices the
// graph walk would apply on the way to it (the same matrices, fused the same way, applied
// in the same order), so a ray finds the same surface, with the same t and normal bit
// for bit, as the graph walk would. Whether an instance was expanded therefore never
// changes an image, and the cache can keep whatever pays.
//
//  - Which instances: those at the depths where InstanceBoxes has seen sub-graphs of a
//    few dozen to a thousand node visits (InstanceBoxes::unrollAt); the first S-node of
//    such a depth on a ray's path is expanded with everything below it.
//  - When: an instance is expanded the second time a thread meets it (the first time
//    only leaves a note), so that instances a single ray passes do not pay for it; and a
//    thread stops expanding at a depth where the expansions are not used several times
//    each (a terrain's sub-triangles, each seen by a few rays only).
//  - Where: per thread (no locks), least recently used first out, within a byte budget.
//  - Materials and tie-break keys depend on where an instance is used, not on what it
//    is: a primitive without a paint above it inside the instance takes the caller's
//    material (and the frame of the caller's paint node, for patterns), and each hit's
//    instance path is replayed from the S-node's path. An instance with a paint node
//    whose material has a pattern inside is not expanded: the graph walk records that
//    node's frame.
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <unordered_map>
#include <vector>

#include "geometry.h"
#include "graph.h"
#include "instance_boxes.h"
#include "operators.h"

namespace pcsg::tracer {

class TraceScene;

class UnrolledInstance {
  public:
    static constexpr uint32_t kInherit = UINT32_MAX;  // material: the caller's

    enum class Kind : uint8_t { Solid, Triangle, Operator };

    struct Node {
        Kind kind;
        CsgOp op = CsgOp::Union;  // operators
        PrimitiveKind prim = PrimitiveKind::Empty;
        uint32_t material = kInherit;            // primitives: the innermost paint inside
        uint32_t firstMatrix = 0, matrices = 0;  // inverse matrices applied on entering
        uint32_t first = 0, count = 0;           // operators: children; primitives: args
        uint32_t firstChoice = 0, choices = 0;   // the path from the S-node (hit sources)
        uint32_t bvh = kNone;                    // unions: the root of their first-hit BVH
        Box box;  // what the node holds, in the frame it is entered from, padded
    };

    // First hits through nested unions: the operands of a union and of the unions nested in
    // it (each operand with the matrices on its way, so the arithmetic stays the same) in a
    // bounding-volume hierarchy, because the derivation nests them as the rules do (a
    // flower's 21 petals as a chain 21 unions deep). Spans still follow the derivation.
    // A node holds the boxes of its two children side by side, so that one SSE2 operation
    // tests an axis of both; child c is another node (bvh_[child[c]]) or, with kLeaf set,
    // an operand (nodes_[child[c] & ~kLeaf]) entered through the chain of matrices link[c]
    // (links_; kNone: none) and then its own.
    static constexpr uint32_t kLeaf = 1u << 31;
    struct BvhNode {
        double lo[3][2], hi[3][2];
        uint32_t child[2], link[2];
    };

    // Where an instance is used: the S-node's instance path, the material above it and the
    // tracer's handle on its paint node's frame (PathState::paint).
    struct Use {
        uint64_t path;
        uint32_t material;
        uint32_t paint;
    };

    // A step of the chains of matrices of BVH operands: links_[parent]'s chain, then
    // matrices_[matrix] (parent kNone: the chain starts at the union).
    struct Link {
        uint32_t parent, matrix;
    };

    // Scratch space of one thread (stacks of the walk; the ray of each link, valid in the
    // walk of one BVH, the one with its stamp).
    struct Scratch {
        std::vector<std::pair<double, uint32_t>> order;
        std::vector<Span> spans;
        struct Linked {
            uint64_t stamp = 0;
            LocalRay ray{{}, {}};
        };
        std::vector<Linked> linked;
        uint64_t stamp = 0;
        uint64_t visits = 0;
    };

    // The nearest surface with tmin < t < tmax (or at tmax, winning the tie) in the
    // instance, the ray in the S-node's frame; `hit.normal` comes back in that frame.
    bool first(const LocalRay& r, double tmin, double& tmax, Hit& hit, const Use& use, bool anyHit,
               Scratch& s) const;
    // The instance's span list, appended to `spans` (normals in the S-node's frame).
    size_t spans(const LocalRay& r, double tmin, double tmax, std::vector<Span>& spans,
                 const Use& use, Scratch& s) const;

    const Box& box() const { return nodes_[root_].box; }
    bool empty() const { return root_ == kNone; }
    // S-nodes nested below the instance's own (the expansion is used only where the
    // deepest of them stays within max_depth).
    uint32_t levels() const { return levels_; }
    size_t bytes() const;
    // The nodes of the first-hit hierarchies, leaves included.
    size_t bvhNodes() const { return bvh_.empty() ? 0 : 2 * bvh_.size() + 1; }

  private:
    friend class Unroller;

    bool firstAt(uint32_t n, const LocalRay& r, double tmin, double& tmax, Hit& hit, const Use& use,
                 bool anyHit, Scratch& s) const;
    size_t spansAt(uint32_t n, const LocalRay& r, double tmin, double tmax,
                   std::vector<Span>& spans, const Use& use, Scratch& s) const;
    bool firstOfNodes(const uint32_t* list, uint32_t count, const LocalRay& r, double tmin,
                      double& tmax, Hit& hit, const Use& use, bool anyHit, Scratch& s) const;
    const LocalRay& linkedRay(uint32_t l, const LocalRay& r, uint64_t stamp, Scratch& s) const;
    bool firstBvh(uint32_t root, const LocalRay& r, double tmin, double& tmax, Hit& hit,
                  const Use& use, bool anyHit, Scratch& s) const;
    LocalRay enter(const Node& node, const LocalRay& r) const;
    Vec3 leave(const Node& node, Vec3 normal) const;
    uint64_t keyOf(const Node& node, uint64_t path) const;

    std::vector<Node> nodes_;
    std::vector<uint32_t> children_;
    std::vector<Affine> matrices_;
    std::vector<double> args_;
    std::vector<uint32_t> choices_;  // bit 31: a rule of an S-node, else an operand
    std::vector<BvhNode> bvh_;
    std::vector<Link> links_;
    uint32_t root_ = kNone;
    uint32_t levels_ = 0;
};

// One thread's cache of expanded instances.
class UnrollCache {
  public:
    UnrollCache(const TraceScene& scene, size_t maxBytes);
    ~UnrollCache();

    // The expanded instance of the S-node instance (select, frame, path) at `depth`, or
    // nullptr (not worth expanding yet, or too large). Throws RuntimeError (without this
    // S-node in its module path) when unrolling meets a run-time error.
    const UnrolledInstance* get(NodeId select, uint32_t depth, const double* frame, uint64_t path);
    // The same, with the instance's key (InstanceBoxes::keyOf) computed by the caller.
    const UnrolledInstance* get(const InstanceBoxes::Key& key, NodeId select, uint32_t depth,
                                const double* frame, uint64_t path);

    // The instance if it is expanded already (counted as a use), else nullptr: no note,
    // no expansion.
    const UnrolledInstance* built(const InstanceBoxes::Key& key, NodeId select, uint32_t depth);

    UnrolledInstance::Scratch& scratch() { return scratch_; }
    uint64_t expansions() const { return expansions_; }
    size_t bytes() const { return bytes_; }
    size_t entries() const { return lru_.size(); }

  private:
    struct Entry {
        InstanceBoxes::Key key;
        std::unique_ptr<UnrolledInstance> instance;  // nullptr: met once, or too large
        bool tooLarge = false;
        size_t bytes = 0;
    };
    struct KeyHash {
        size_t operator()(const InstanceBoxes::Key& k) const { return static_cast<size_t>(k.b); }
    };

    void evict();

    // Per (module, depth): expansions made, and uses of them.
    struct Yield {
        uint64_t built = 0, used = 0;
        bool off = false;
    };
    const TraceScene& scene_;
    size_t maxBytes_;
    std::vector<Yield> yield_;
    uint32_t levels_;
    size_t bytes_ = 0;
    uint64_t expansions_ = 0;
    std::list<Entry> lru_;  // most recently used first
    std::unordered_map<InstanceBoxes::Key, std::list<Entry>::iterator, KeyHash> index_;
    UnrolledInstance::Scratch scratch_;
};

}  // namespace pcsg::tracer
