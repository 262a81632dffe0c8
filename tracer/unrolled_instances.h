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
//  - When: an instance is expanded the second time it is met, by any thread (the first
//    time only leaves a note; a shadow ray's meeting counts a third of one, unroll_cache.h),
//    so that instances a single ray passes do not pay for it; and
//    expansion stops at a depth where the expansions are not used several times each (a
//    terrain's sub-triangles, each seen by a few rays only).
//  - Where: in one cache shared by the tracer threads (unroll_cache.h), within a byte
//    budget for all of them.
//  - Materials and tie-break keys depend on where an instance is used, not on what it
//    is: a primitive without a paint above it inside the instance takes the caller's
//    material (and the frame of the caller's paint node, for patterns), and each hit's
//    instance path is replayed from the S-node's path. A paint node inside an instance
//    whose material needs its instance (transparency's interiors) or its frame (a
//    pigment pattern) is kept for the surfaces below it (paints_: the node, the choices
//    that lead to it, the inverse matrices on the way), and a hit there gets its interior
//    and its point in that frame as the walk would give them (resolvePaint). One whose
//    normal pattern needs the map from the world into that frame is not expanded: the
//    graph walk records it, and so does a top level's every such paint node.
//  - Two levels (top_level.h): an expansion of the whole graph from the axiom may stop at
//    S-node instances and refer to expanded instances of their own instead (a node of
//    kind Instance: the S-node's matrices and material as for a primitive, and its
//    instance path, computed once, since the top level is traced from the root only; the
//    instance referred to replays its hits' paths from that path), so that the copies of
//    one instance share its arrays; or at S-node instances it leaves to the tracer (a
//    node of kind Deferred, with the S-node's parameters and path: Walker).
#pragma once

#include <cstdint>
#include <memory>
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

    // Instance: another expanded instance (instances_[first]), entered at its S-node
    // (expandTop's only). Deferred: an S-node instance not expanded here (deferred_[first]),
    // which the tracer tracing the top level walks or finds expanded (expandTop's only).
    enum class Kind : uint8_t { Solid, Triangle, Operator, Instance, Deferred };

    struct Node {
        Kind kind;
        CsgOp op = CsgOp::Union;  // operators
        PrimitiveKind prim = PrimitiveKind::Empty;
        // An operand of a BVH whose box there is the box of its box through a chain with
        // rotations (looser than its own): the walk tests its own box, in the frame of
        // the link's ray, before entering it.
        bool looseInBvh = false;
        uint32_t material = kInherit;            // primitives: the innermost paint inside
        uint32_t firstMatrix = 0, matrices = 0;  // inverse matrices applied on entering
                                                 // (matrixRefs_[firstMatrix..])
        uint32_t first = 0, count = 0;           // operators: children; primitives: args
        uint32_t firstChoice = 0, choices = 0;   // the path from the S-node (hit sources)
        uint32_t bvh = kNone;                    // unions: the root of their first-hit BVH
        // Surfaces painted inside the instance by a paint node that records its instance
        // (transparency's interiors) or its frame (a pigment pattern): that paint node,
        // paints_[paintAt] (kNone: none, or the material is the caller's).
        uint32_t paintAt = kNone;
        Box box;  // what the node holds, in the frame it is entered from, padded
    };

    // The paint handle of a surface painted inside an expansion (Hit::paint,
    // Boundary::paint): its interior is Scratch::interiors[paint & ~kScratchPaint] and
    // its point in the paint node's frame Scratch::points[...], kept till the end of the
    // ray's walk; the walk's own handles are small numbers.
    static constexpr uint32_t kScratchPaint = 1u << 31;

    // First hits through nested unions: the operands of a union and of the unions nested in
    // it (each operand with the matrices on its way, so the arithmetic stays the same) in a
    // bounding-volume hierarchy, because the derivation nests them as the rules do (a
    // flower's 21 petals as a chain 21 unions deep). Spans still follow the derivation.
    // A node holds the boxes of up to four children side by side, in floats rounded
    // outwards (boxes only cull: a larger box never changes a hit), so that a node is two
    // cache lines and one SSE register holds an axis of all four; child c is another
    // node (bvh_[child[c]]), or, with kLeaf set, an operand (nodes_[child[c] & ~kLeaf])
    // entered through the chain of matrices link[c] (links_; kNone: none) and then its
    // own, or kNone: an empty slot (after the used ones).
    static constexpr uint32_t kLeaf = 1u << 31;
    struct alignas(64) BvhNode {
        float lo[3][4], hi[3][4];
        uint32_t child[4], link[4];
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

    // A paint node whose instance the surfaces below it record (Node::paintAt): the node,
    // how many of a surface's choices lead to it, and, where its material has a pigment
    // pattern, the inverse matrices on the way to it from the instance's S-node
    // (matrixRefs_[firstMatrix..]), which map a ray into the paint node's frame.
    struct PaintAt {
        NodeId node;
        uint32_t prefix;
        uint32_t firstMatrix = 0, matrices = 0;
        bool point = false;
    };

    // A Deferred node's S-node instance: the S-node, its depth (Semantics::selectDepth) and
    // the walk's state there (the parameters at deferredFrames_[frame..], the instance path,
    // the S-nodes passed), and its instance key.
    struct Deferred {
        NodeId select;
        uint32_t depth, stateDepth;
        uint32_t frame;
        uint64_t path;
        InstanceBoxes::Key key;
    };
    // What traces a Deferred node's instance: the tracer whose scratch space this is (it
    // finds the instance expanded in its cache, or walks the graph below the S-node). The
    // ray is in the S-node's frame; the hit's normal comes back in that frame.
    class Walker {
      public:
        virtual bool firstDeferred(const Deferred& d, const double* frame, const LocalRay& r,
                                   double tmin, double& tmax, Hit& hit, uint32_t material) = 0;

      protected:
        ~Walker() = default;
    };

    // Scratch space of one thread (stacks of the walk; the ray of each link, valid in the
    // walk of one BVH, the one with its stamp; the walker of Deferred nodes).
    struct Scratch {
        Walker* walker = nullptr;
        std::vector<std::pair<double, uint32_t>> order;
        std::vector<Span> spans;
        struct Linked {
            uint64_t stamp = 0;
            LocalRay ray{{}, {}};
        };
        std::vector<Linked> linked;
        std::vector<uint64_t> interiors;  // of the surfaces painted inside (kScratchPaint)
        std::vector<Vec3> points;         // and their points in the paint node's frame
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

    // Expands the S-node instance (select, frame, path) at `depth`: nullptr when the
    // expansion takes more than `maxVisits` node visits or meets a paint node whose
    // normal pattern needs the map into the node's frame (the graph walk records it).
    // Throws RuntimeError (without this S-node in its module path) when unrolling meets a
    // run-time error.
    static std::unique_ptr<UnrolledInstance> expand(const TraceScene& scene, NodeId select,
                                                    uint32_t depth, const double* frame,
                                                    uint64_t path, uint64_t maxVisits);

    // Where an expansion of the whole graph (expandTop) stops: the expanded instance to
    // refer to for the S-node `select` entered in state `s` at `depth` (it must outlive the
    // expansion), nullptr to expand the S-node in place; throws Refused to give up. Where
    // it gives none, `defer` may stop there with a Deferred node (true: its box in the
    // S-node's frame and its key in `box` and `key`). And the node visits the expansion may
    // take, asked again each time it passes them (so that the cuts met so far may raise
    // them).
    struct Refused {};
    class Cuts {
      public:
        virtual const UnrolledInstance* cut(NodeId select, const PathState& s, uint32_t depth) = 0;
        virtual bool defer(NodeId, const PathState&, uint32_t, Box&, InstanceBoxes::Key&) {
            return false;
        }
        virtual uint64_t maxVisits() const = 0;

      protected:
        ~Cuts() = default;
    };
    // The whole graph from the axiom, cut where `cuts` says: nullptr when it takes more
    // than `cuts.maxVisits()` node visits, meets an operator other than a union, a paint
    // node whose pattern needs the node's frame, or is refused. Throws RuntimeError when
    // unrolling meets a run-time error. Traced with first() and Use{kRootPath, 0, 0}.
    static std::unique_ptr<UnrolledInstance> expandTop(const TraceScene& scene, Cuts& cuts);
    // The bytes of the build arrays the calling thread keeps between its expansions (they
    // keep their capacity, unless far larger than the last expansion needed).
    static size_t keptBuildBytes();

    const Box& box() const { return nodes_[root_].box; }
    size_t deferredNodes() const { return deferred_.size(); }
    bool empty() const { return root_ == kNone; }
    // S-nodes nested below the instance's own (the expansion is used only where the
    // deepest of them stays within max_depth).
    uint32_t levels() const { return levels_; }
    size_t bytes() const;
    // The nodes of the first-hit hierarchies, leaves included.
    size_t bvhNodes() const { return bvh_.size() + bvhLeaves_; }
    // The operands each node of the first-hit hierarchies holds directly (their indices in
    // the instance's nodes, in the order of the node's slots), node by node: which the
    // hierarchy groups together (tests).
    std::vector<std::vector<uint32_t>> bvhLeafGroups() const;
    // The operands whose own box is tested before they are entered (Node::looseInBvh).
    size_t looseOperands() const;
    // A hash of the expansion's arrays, field by field (nodes, children, matrices and their
    // references, arguments, choices, hierarchy, links): expansions built by different code
    // compare equal only when they hold the same values bit for bit (tests).
    uint64_t digest() const;

  private:
    friend class Unroller;

    bool firstAt(uint32_t n, const LocalRay& r, double tmin, double& tmax, Hit& hit, const Use& use,
                 bool anyHit, Scratch& s) const;
    struct Reference;
    bool firstInDeferred(const Node& node, const LocalRay& r, double tmin, double& tmax, Hit& hit,
                         uint32_t material, Scratch& s) const;
    bool firstInInstance(const Reference& ref, const LocalRay& r, double tmin, double& tmax,
                         Hit& hit, const Use& inside, bool anyHit, Scratch& s) const;
    size_t spansAt(uint32_t n, const LocalRay& r, double tmin, double tmax,
                   std::vector<Span>& spans, const Use& use, Scratch& s) const;
    bool firstOfNodes(const uint32_t* list, uint32_t count, const LocalRay& r, double tmin,
                      double& tmax, Hit& hit, const Use& use, bool anyHit, Scratch& s) const;
    const LocalRay& linkedRay(uint32_t l, const LocalRay& r, uint64_t stamp, Scratch& s) const;
    bool firstInSolid(const Node& node, const Vec3& o, const Vec3& d, double tmin, double& tmax,
                      Hit& hit, const Use& use, bool anyHit) const;
    bool firstLeaf(const Node& node, const LocalRay& r, double tmin, double& tmax, Hit& hit,
                   const Use& use, bool anyHit, Scratch& s) const;
    bool firstBvh(uint32_t root, const LocalRay& r, double tmin, double& tmax, Hit& hit,
                  const Use& use, bool anyHit, Scratch& s) const;
    LocalRay enter(const Node& node, const LocalRay& r) const;
    Vec3 leave(const Node& node, Vec3 normal) const;
    uint64_t replayChoices(const Node& node, uint64_t path, uint32_t count) const;
    uint64_t keyOf(const Node& node, uint64_t path) const;
    uint32_t paintOf(const Node& node, const Use& use) const;
    void settlePaint(Hit& hit, uint64_t path, const LocalRay& r, bool anyHit, Scratch& s) const;
    void resolvePaint(uint32_t& paint, uint64_t path, const LocalRay& r, double t,
                      Scratch& s) const;

    std::vector<Node> nodes_;
    std::vector<uint32_t> children_;
    std::vector<Affine> matrices_;      // each inverse matrix met, once
    std::vector<uint32_t> matrixRefs_;  // the nodes' matrices (indices in matrices_)
    std::vector<double> args_;
    std::vector<uint32_t> choices_;  // bit 31: a rule of an S-node, else an operand
    std::vector<BvhNode> bvh_;
    std::vector<Link> links_;
    std::vector<PaintAt> paints_;
    // Instance nodes: the instance and the S-node's instance path (from the root).
    struct Reference {
        const UnrolledInstance* instance;
        uint64_t path;
    };
    std::vector<Reference> instances_;
    // Deferred nodes: their S-node instances, and the parameters of each (slotCount() a
    // node).
    std::vector<Deferred> deferred_;
    std::vector<double> deferredFrames_;
    uint32_t linkSlots_ = 0;  // Scratch::linked entries needed, instances referred to included
    uint32_t root_ = kNone;
    // The root's first-hit hierarchy when firstAt(root_) would do nothing but walk it (a
    // union with one, without matrices, own box test or material): an Instance node
    // referring to this instance walks it directly, one call and one copy of the ray less
    // for each copy entered. Else kNone.
    uint32_t rootBvh_ = kNone;
    uint32_t levels_ = 0;
    uint32_t bvhLeaves_ = 0;
};

}  // namespace pcsg::tracer
