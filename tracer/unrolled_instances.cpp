// Expanded instances: see unrolled_instances.h.
#include "unrolled_instances.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <type_traits>

#include "bounds.h"
#include "bvh_slabs.h"
#include "eval.h"
#include "eval_core.h"
#include "flat_index.h"
#include "map_ray.h"
#include "outward_float.h"
#include "transparency.h"
#include "traversal.h"

namespace pcsg::tracer {

namespace {

constexpr uint32_t kRuleBit = 1u << 31;

bool isUnion(const UnrolledInstance::Node& n) {
    return n.kind == UnrolledInstance::Kind::Operator && n.op == CsgOp::Union;
}

// A surface's paint handle while an instance's search runs: node n of the instance, whose
// interior resolvePaint() finds (the walk's own handles are small numbers).
constexpr uint32_t kNodePaint = 1u << 30;

// The expansion took more visits than its depth promised, or met a paint node it leaves
// to the graph walk (paintNode): leave it all to the walk.
struct TooLarge {};

}  // namespace

// ---------------------------------------------------------------------------------------
// Building: a walk of the graph below one S-node instance that takes the tracer's steps
// (semantics.h: the same selections, C-nodes and T-node inverses, fused along constant
// chains), in the same order, and keeps what it meets in flat arrays.

// The arrays of the expansions one thread builds. An expansion grows these (they keep
// their capacity from one expansion to the next) and copies them out at their final
// sizes: its own arrays, grown by doubling from nothing and shrunk to fit, had been a few
// dozen allocations and copies per expansion, and each freed array of 64 KB or more a
// malloc_consolidate.
struct BuildArrays {
    std::vector<UnrolledInstance::Node> nodes;
    std::vector<uint32_t> children, matrixRefs, choices;
    std::vector<Affine> matrices;
    std::vector<double> args;
    std::vector<UnrolledInstance::BvhNode> bvh;
    std::vector<UnrolledInstance::Link> links;
    std::vector<UnrolledInstance::PaintAt> paints;
    // The unroller's indices of the matrices and links (kept, emptied, with their slots).
    FlatIndex matrixIndex, linkIndex;

    // The unroller's stacks: they are empty between its steps, so that what a thread keeps
    // of them is their room (its expansions' hierarchies had grown them from nothing, a
    // dozen allocations and copies each).
    struct Stacks {
        // An operand of a union's BVH: the node, the chain of matrices (links_) from the
        // union's frame into the frame of the node's own union (kNone: the same frame), and
        // its box in the union's frame.
        struct Item {
            uint32_t node, link;
            Box box;
        };
        // A part of a union's hierarchy as its derivation nests it: an operand (kLeaf,
        // entered through `link`) or a node of `binary`, with its box and the binary
        // levels below it (child kNone: nothing).
        struct Part {
            uint32_t child = kNone, link = kNone;
            Box box;
            uint32_t height = 0;
        };
        // A node of the binary hierarchy that collapse() turns into four-wide nodes: child
        // c is another binary node or (kLeaf) an operand, as in BvhNode.
        struct Binary {
            Box box[2];
            uint32_t child[2], link[2];
        };
        std::vector<uint32_t> kids;  // operands of the operators being built
        std::vector<Item> items;     // the operands of the BVHs being built
        std::vector<Part> parts;     // collect()'s parts of the unions being collected
        std::vector<Binary> binary;  // the hierarchy being built

        template <class F>
        void each(F&& f) {
            f(kids), f(items), f(parts), f(binary);
        }
    } stacks;
    bool lent = false;
};

namespace {

// The thread's array b after an expansion that used `used` of it: kept for the next one,
// unless it is far larger than that (a one-off: a larger level tried, a build refused at
// its visit limit), which would otherwise stay with the thread for the rest of the run.
constexpr size_t kKeptSlack = 4, kKeptFreely = 64 * 1024;

BuildArrays& threadArrays() {
    thread_local BuildArrays a;
    return a;
}

// The thread's index after an expansion: emptied and kept for the next one, unless far
// larger than the entries this one stored (as giveBack() keeps arrays).
void giveBack(FlatIndex& index, bool keep) {
    if (keep && (index.bytes() <= kKeptFreely || index.slots() <= 2 * kKeptSlack * index.size())) {
        index.clear();
        return;
    }
    index.release();
}

template <class V>
void giveBack(V& b, size_t used, bool keep) {
    const size_t bytes = b.capacity() * sizeof(typename V::value_type);
    if (keep && (bytes <= kKeptFreely || b.capacity() <= kKeptSlack * used)) {
        b.clear();
        return;
    }
    V().swap(b);
}

// Room for a primitive's spans, left unwritten: intersectSolid writes every span it
// returns whole (Boundary{t, n, 0}), and zeroing the room first cost ~16 instructions a
// primitive tested.
union SpanRoom {
    SpanRoom() {}
    Span s[kMaxPrimitiveSpans];
};

// Room for a forward map's product, left unwritten until the product is (an Affine starts
// as the identity: nine stores at each of the unroller's steps, most of which multiply
// nothing). Affine is trivially copyable: assigning the member begins its lifetime.
union AffineRoom {
    AffineRoom() {}
    Affine m;
};

}  // namespace

class Unroller {
  public:
    Unroller(const TraceScene& scene, UnrolledInstance& out, uint64_t maxVisits,
             UnrolledInstance::Cuts* cuts = nullptr)
        : scene_(scene),
          sem_(scene.semantics()),
          g_(scene.graph()),
          out_(out),
          maxVisits_(maxVisits),
          cuts_(cuts),
          paintFrames_(!scene.paintFrames.empty()) {}

    void run(NodeId select, uint32_t depth, const double* frame, uint64_t path) {
        double* root = pushFrame();
        std::copy(frame, frame + g_.slotCount(), root);
        const uint32_t rule = selectRule(g_, select, EvalState{frame, path});
        choices_.push_back(kRuleBit | rule);
        base_ = depth;
        const PathState s{root, pathRule(path, rule), depth, UnrolledInstance::kInherit};
        const Lent lent(*this);
        finish(build(g_.child(select, rule), s, 0, nullptr));
    }

    // The whole graph from the axiom, in the walk's state at the root (expandTop).
    void runTop() {
        double* root = pushFrame();
        initFrame(g_, root);
        const PathState s{root, kRootPath, 0, UnrolledInstance::kInherit};
        const Lent lent(*this, /*keep=*/false);
        finish(build(g_.axiom, s, 0, nullptr));
    }

  private:
    // Applies f(the thread's array, the expansion's) to each array of an expansion.
    template <class F>
    static void eachArray(BuildArrays& b, UnrolledInstance& x, F&& f) {
        f(b.nodes, x.nodes_);
        f(b.children, x.children_);
        f(b.matrices, x.matrices_);
        f(b.matrixRefs, x.matrixRefs_);
        f(b.args, x.args_);
        f(b.choices, x.choices_);
        f(b.bvh, x.bvh_);
        f(b.links, x.links_);
        f(b.paints, x.paints_);
    }

    // The thread's BuildArrays lent to the expansion being built (when no other on this
    // thread has them), and taken back when it is done: the expansion's arrays are copied
    // out at their final sizes, or, should the build throw, given up; the unroller's
    // indices are emptied. Unless `keep`, the thread's arrays are freed then (a top level:
    // built once, and larger than the expansions, which would keep its size for good).
    class Lent {
      public:
        explicit Lent(Unroller& u, bool keep = true)
            : u_(u), x_(u.out_), b_(threadArrays()), mine_(!b_.lent), keep_(keep) {
            if (!mine_) return;
            b_.lent = true;
            eachArray(b_, x_, [](auto& b, auto& x) {
                b.clear();
                x.swap(b);
            });
            std::swap(u_.matrixIndex_, b_.matrixIndex);
            std::swap(u_.linkIndex_, b_.linkIndex);
            b_.stacks.each([](auto& v) { v.clear(); });  // (a build that threw left some)
            std::swap(u_.stacks_, b_.stacks);
        }
        ~Lent() {
            if (!mine_) {
                eachArray(b_, x_, [](auto&, auto& x) { x.shrink_to_fit(); });
                return;
            }
            const bool done = std::uncaught_exceptions() == 0;
            eachArray(b_, x_, [done, keep = keep_](auto& b, auto& x) {
                b.swap(x);
                if (done) x.assign(b.begin(), b.end());
                giveBack(b, b.size(), keep);
            });
            std::swap(u_.matrixIndex_, b_.matrixIndex);
            std::swap(u_.linkIndex_, b_.linkIndex);
            giveBack(b_.matrixIndex, keep_);
            giveBack(b_.linkIndex, keep_);
            std::swap(u_.stacks_, b_.stacks);
            b_.stacks.each([keep = keep_](auto& v) { giveBack(v, 0, keep); });  // (<= 64 KB)
            b_.lent = false;
        }
        Lent(const Lent&) = delete;
        Lent& operator=(const Lent&) = delete;

      private:
        Unroller& u_;
        UnrolledInstance& x_;
        BuildArrays& b_;
        const bool mine_, keep_;
    };

    using Node = UnrolledInstance::Node;
    using Kind = UnrolledInstance::Kind;
    using BvhNode = UnrolledInstance::BvhNode;

    // The expansion's root and hierarchy; its arrays go out at their final sizes when the
    // Lent arrays are given back.
    void finish(uint32_t root) {
        out_.root_ = root;
        if (out_.root_ != kNone) hierarchy(out_.root_);
        out_.rootBvh_ = kNone;
        if (root != kNone) {
            const Node& r = out_.nodes_[root];
            if (isUnion(r) && r.matrices == 0 && !r.looseInBvh &&
                r.material == UnrolledInstance::kInherit)
                out_.rootBvh_ = r.bvh;
        }
        out_.linkSlots_ = static_cast<uint32_t>(out_.links_.size());
        for (const UnrolledInstance::Reference& x : out_.instances_)
            out_.linkSlots_ = std::max(out_.linkSlots_, x.instance->linkSlots_);
        out_.instances_.shrink_to_fit();
    }

    // Builds what node n holds in state s; returns its index, or kNone when it holds
    // nothing. The inverse matrices in pending_[pendingBase..] and the forward map `edge`
    // lead from the frame of the last operator above (or the S-node) to n's frame.
    uint32_t build(NodeId n, const PathState& s, size_t pendingBase, const Affine* edge) {
        if (++visits_ > maxVisits_) pastVisitLimit();
        switch (g_.nodes[n].kind) {
            case NodeKind::Operator:
                return buildOperator(n, s, pendingBase, edge);
            case NodeKind::Primitive:
                return buildPrimitive(n, s, pendingBase, edge);
            case NodeKind::Select:
                return buildSelect(n, s, pendingBase, edge);
            default:
                return buildUnary(n, s, pendingBase, edge);
        }
    }

    // Past maxVisits_: the end of the build, unless a top level's cuts allow more.
    [[gnu::noinline]] void pastVisitLimit() const {
        if (!(cuts_ && visits_ <= cuts_->maxVisits())) throw TooLarge{};
    }

    // An S-node: a cut (expandTop) or its step, and its module on the path of a run-time
    // error from below. (Out of line: build(), taken at every node, is then only a switch
    // whose cases jump to their builders, with no frame of its own.)
    [[gnu::noinline]] uint32_t buildSelect(NodeId n, const PathState& s, size_t pendingBase,
                                           const Affine* edge) {
        try {
            if (cuts_) {
                const uint32_t depth = sem_.selectDepth(n, s);
                if (const UnrolledInstance* x = cuts_->cut(n, s, depth))
                    return buildReference(*x, s, pendingBase, edge);
                Box box;
                InstanceBoxes::Key key;
                if (cuts_->defer(n, s, depth, box, key))
                    return buildDeferred(n, s, depth, box, key, pendingBase, edge);
            }
            return buildUnary(n, s, pendingBase, edge);
        } catch (RuntimeError& e) {
            e.enterModule(g_.modules[g_.nodes[n].payload].name);
            throw;
        }
    }

    // S, C, T and paint nodes: the one step of semantics.h, as the tracer's walk takes it.
    uint32_t buildUnary(NodeId n, const PathState& s, size_t pendingBase, const Affine* edge) {
        const NodeKind kind = g_.nodes[n].kind;
        StepScratch scratch;
        if (kind == NodeKind::Calc) {
            scratch.frame = pushFrame();
        }
        Step st = sem_.enter(n, s, scratch);
        if (kind == NodeKind::Paint && paintFrames_) paintNode(n, st.state);
        if (kind == NodeKind::Select) {
            out_.levels_ = std::max(out_.levels_, st.state.depth - base_);
            choices_.push_back(kRuleBit | st.rule);
        }
        if (st.inverse) pending_.push_back(inverseIndex(n, *st.inverse));
        // (from the identity: the step's own matrix where that is exact, Semantics' rule)
        AffineRoom composed;
        const Affine* next = edge;
        if (st.forward)
            next =
                edge ? &(composed.m = *edge * *st.forward) : &sem_.fromIdentity(n, st, composed.m);
        const uint32_t r = build(st.child, st.state, pendingBase, next);
        if (st.inverse) pending_.pop_back();
        if (kind == NodeKind::Select) choices_.pop_back();
        if (kind == NodeKind::Calc) --framesUsed_;
        return r;
    }

    uint32_t buildOperator(NodeId n, const PathState& s, size_t pendingBase, const Affine* edge) {
        const ::pcsg::Node& node = g_.nodes[n];
        const CsgOp op = node.op();
        if (cuts_ && op != CsgOp::Union) throw TooLarge{};  // (a top level holds unions only)
        // This operator's operands are kids_[base..] (one stack for all operators).
        const size_t base = kids_.size();
        const size_t mark = pending_.size();
        for (uint32_t i = 0; i < node.childCount; ++i) {
            choices_.push_back(i);
            const uint32_t c = build(g_.child(n, i), Semantics::operand(s, i), mark, nullptr);
            choices_.pop_back();
            if (c == kNone) {
                if (!emptyOperandEmptiesAll(op, i)) continue;
                kids_.resize(base);
                return kNone;
            }
            kids_.push_back(c);
        }
        if (kids_.size() == base) return kNone;
        Box inside = out_.nodes_[kids_[base]].box;
        for (size_t k = base + 1; k < kids_.size(); ++k) {
            const Box& b = out_.nodes_[kids_[k]].box;
            if (op == CsgOp::Union) inside.extend(b);
            if (op == CsgOp::Intersection) inside = intersect(inside, b);
        }
        Node x = emit(Kind::Operator, s, pendingBase, edge, inside);
        x.op = op;
        x.first = static_cast<uint32_t>(out_.children_.size());
        x.count = static_cast<uint32_t>(kids_.size() - base);
        out_.children_.insert(out_.children_.end(), kids_.begin() + base, kids_.end());
        kids_.resize(base);
        if (op != CsgOp::Union) setChoices(x);
        out_.nodes_.push_back(x);
        return static_cast<uint32_t>(out_.nodes_.size() - 1);
    }

    uint32_t buildPrimitive(NodeId n, const PathState& s, size_t pendingBase, const Affine* edge) {
        const PrimitiveKind kind = g_.primitives[g_.nodes[n].payload].kind;
        if (kind == PrimitiveKind::Empty) return kNone;
        double args[9] = {};
        const uint32_t argc = sem_.primitiveArgs(n, s, args);
        Node x = emit(isTriangle(kind) ? Kind::Triangle : Kind::Solid, s, pendingBase, edge,
                      primitiveBox(kind, args));
        x.prim = kind;
        x.first = static_cast<uint32_t>(out_.args_.size());
        x.count = argc;
        out_.args_.insert(out_.args_.end(), args, args + argc);
        setChoices(x);
        out_.nodes_.push_back(x);
        return static_cast<uint32_t>(out_.nodes_.size() - 1);
    }

    // A cut (expandTop): the expanded instance x of the S-node instance entered in state s.
    uint32_t buildReference(const UnrolledInstance& x, const PathState& s, size_t pendingBase,
                            const Affine* edge) {
        if (x.empty()) return kNone;
        Node r = emit(Kind::Instance, s, pendingBase, edge, x.box());
        r.first = static_cast<uint32_t>(out_.instances_.size());
        out_.instances_.push_back({&x, s.path});
        out_.nodes_.push_back(r);
        return static_cast<uint32_t>(out_.nodes_.size() - 1);
    }

    // A deferred cut (expandTop): the S-node instance entered in state s, whose box in its
    // own frame is `box`, stays the tracer's to walk.
    uint32_t buildDeferred(NodeId n, const PathState& s, uint32_t depth, const Box& box,
                           const InstanceBoxes::Key& key, size_t pendingBase, const Affine* edge) {
        if (box.isEmpty()) return kNone;
        Node r = emit(Kind::Deferred, s, pendingBase, edge, box);
        r.first = static_cast<uint32_t>(out_.deferred_.size());
        const auto frame = static_cast<uint32_t>(out_.deferredFrames_.size());
        out_.deferred_.push_back({n, depth, s.depth, frame, s.path, key});
        out_.deferredFrames_.insert(out_.deferredFrames_.end(), s.frame, s.frame + g_.slotCount());
        out_.nodes_.push_back(r);
        return static_cast<uint32_t>(out_.nodes_.size() - 1);
    }

    // A node entered through the matrices pending_[pendingBase..], holding `inside` (in
    // its own frame).
    Node emit(Kind kind, const PathState& s, size_t pendingBase, const Affine* edge,
              const Box& inside) {
        Node x{};
        x.kind = kind;
        x.material = s.material;
        x.paintAt = s.paint == 0 ? kNone : s.paint - 1;
        x.firstMatrix = static_cast<uint32_t>(out_.matrixRefs_.size());
        x.matrices = static_cast<uint32_t>(pending_.size() - pendingBase);
        out_.matrixRefs_.insert(out_.matrixRefs_.end(), pending_.begin() + pendingBase,
                                pending_.end());
        x.box = inside.isEmpty() ? Box::empty()
                                 : paddedBox(edge ? transformBox(*edge, inside) : inside);
        return x;
    }

    // The index in out_.matrices_ of the inverse matrix of the T-step at n. A constant
    // T-node's step (a fused chain) always gives the same matrix: its index is looked up
    // once per expansion (constIndex_, direct-mapped by node) instead of hashed again at
    // each of the node's steps.
    uint32_t inverseIndex(NodeId n, const Affine& inverse) {
        const ::pcsg::Node& node = g_.nodes[n];
        if (node.kind != NodeKind::Transform || !g_.transforms[node.payload].constant)
            return matrixIndex(inverse);
        ConstIndex& c = constIndex_[n % kConstIndexSlots];
        if (c.node != n) c = {n, matrixIndex(inverse)};
        return c.index;
    }

    // The index of matrix m in out_.matrices_, where each matrix is stored once (the same
    // bits: the nodes that use it apply the very numbers the walk would).
    uint32_t matrixIndex(const Affine& m) {
        static_assert(sizeof(Affine) == 12 * sizeof(double));
        // (the twelve words in their order in memory, read in place: no copy to the stack)
        uint64_t h = 0x9e3779b97f4a7c15ULL;
        for (const auto& row : m.l)
            for (double v : row) h = (h ^ std::bit_cast<uint64_t>(v)) * 0xff51afd7ed558ccdULL;
        for (int a = 0; a < 3; ++a)
            h = (h ^ std::bit_cast<uint64_t>(m.t[a])) * 0xff51afd7ed558ccdULL;
        const auto [at, inserted] =
            matrixIndex_.tryEmplace(h, static_cast<uint32_t>(out_.matrices_.size()));
        if (!inserted && std::memcmp(&out_.matrices_[at], &m, sizeof m) == 0) return at;
        out_.matrices_.push_back(m);
        return static_cast<uint32_t>(out_.matrices_.size() - 1);
    }

    // --- the first-hit BVHs of unions ---

    // Flattening stops where an operand would need more matrices than this on its way
    // (linkedRay recurses once per matrix). The chains' links are shared and each link's
    // ray is computed once per walk, so a longer chain costs only the links a ray meets:
    // at 12 the growing tree's crown, three or four matrices a level, was cut every few
    // levels into a BVH of its own, entered through the leaf's box in the outer frame
    // (a box of a box) and walked again; at 32 its expansion is one hierarchy.
    static constexpr uint32_t kMaxChain = 32;
    // Unions of this many operands (after flattening) or fewer get no BVH.
    static constexpr size_t kFewItems = 4;

    using Item = BuildArrays::Stacks::Item;
    using Part = BuildArrays::Stacks::Part;
    using Binary = BuildArrays::Stacks::Binary;

    // The operands of union u and of the unions nested in it, each entered from u's frame
    // through the chain of matrices of the unions on its way (`link`, a path in the tree
    // links_ whose branches the operands share), then its own, with its box mapped into u's
    // frame. `link` (`length` matrices) leads from the outermost union into u's frame
    // (kNone: u is outermost) and `toU` maps points the other way. Returns the hierarchy
    // the derivation gives them (in binary_): each nested union's parts paired up.
    Part collect(uint32_t u, const Affine& toU, uint32_t link, uint32_t length,
                 std::vector<Item>& items) {
        const uint32_t first = out_.nodes_[u].first, count = out_.nodes_[u].count;
        const size_t base = parts_.size();
        const bool loose = link != kNone && !scaledPermutation(toU);  // (the same for all)
        for (uint32_t i = 0; i < count; ++i) {
            const uint32_t c = out_.children_[first + i];
            const Node& child = out_.nodes_[c];
            if (child.box.isEmpty()) continue;  // holds nothing a ray can hit
            if (isUnion(child) && length + child.matrices <= kMaxChain) {
                uint32_t l = link;
                Affine to = toU;
                for (uint32_t k = 0; k < child.matrices; ++k) {
                    l = linkTo(l, out_.matrixRefs_[child.firstMatrix + k]);
                    to = to * inverseOf(out_.matrixRefs_[child.firstMatrix + k]);
                }
                const Part inner = collect(c, to, l, length + child.matrices, items);
                if (inner.child != kNone) parts_.push_back(inner);
                continue;
            }
            if (isUnion(child)) ++beyondChain_;  // (an operand here: a hierarchy of its own)
            const Box box =
                link == kNone ? child.box : growBox(transformBox(toU, child.box), 1e-7, 1e-9);
            out_.nodes_[c].looseInBvh = loose;
            items.push_back({c, link, box});
            parts_.push_back({c | UnrolledInstance::kLeaf, link, box, 0});
        }
        const Part whole = pairUp(base, parts_.size());
        parts_.resize(base);
        return whole;
    }

    // out_.matrices_[matrix].inverse(), computed once per matrix met (the unions of a
    // terrain patch enter their operands through the same few constant matrices).
    const Affine& inverseOf(uint32_t matrix) {
        InverseSlot& s = inverses_[matrix % kInverseSlots];
        if (s.matrix != matrix) s = {matrix, out_.matrices_[matrix].inverse()};
        return s.inverse;
    }

    // Whether m maps boxes to boxes (each row of its linear part has at most one nonzero
    // entry): else the box of a mapped box is larger than what it holds.
    static bool scaledPermutation(const Affine& m) {
        for (const auto& row : m.l)
            if ((row[0] != 0) + (row[1] != 0) + (row[2] != 0) > 1) return false;
        return true;
    }

    // The binary hierarchy over parts_[begin, end) in their order, halved at the middle.
    Part pairUp(size_t begin, size_t end) {
        if (begin == end) return Part{};
        if (end - begin == 1) return parts_[begin];
        if (end - begin == 2) return joined(parts_[begin], parts_[begin + 1]);  // (no copies)
        const size_t mid = begin + (end - begin) / 2;
        const Part first = pairUp(begin, mid);  // (first: its nodes come first in binary_)
        const Part second = pairUp(mid, end);
        return joined(first, second);
    }

    // The binary node over two parts, appended to binary_.
    Part joined(const Part& a, const Part& b) {
        Binary x;
        x.box[0] = a.box, x.child[0] = a.child, x.link[0] = a.link;
        x.box[1] = b.box, x.child[1] = b.child, x.link[1] = b.link;
        binary_.push_back(x);
        return {static_cast<uint32_t>(binary_.size() - 1), kNone, unite(a.box, b.box),
                1 + std::max(a.height, b.height)};
    }

    // The link that applies out_.matrices_[matrix] after the chain `parent`.
    uint32_t linkTo(uint32_t parent, uint32_t matrix) {
        const uint64_t key = (static_cast<uint64_t>(parent) << 32) | matrix;
        const auto [at, added] =
            linkIndex_.tryEmplace(key, static_cast<uint32_t>(out_.links_.size()));
        if (added) out_.links_.push_back({parent, matrix});
        return at;
    }

    // Builds the BVHs of the unions that first hits reach through n: one operand per leaf.
    // Where the derivation nests the operands about as deep as median splits would (a
    // terrain patch's four sub-triangles per level), its nesting is the hierarchy, built
    // without sorting; otherwise (a flower's chain of petals) median splits make it.
    void hierarchy(uint32_t n) {
        if (!isUnion(out_.nodes_[n])) return;
        const size_t begin = items_.size();  // (its operands: items_[begin, end))
        const uint32_t beyond = beyondChain_;
        binary_.clear();
        const Part derived = collect(n, Affine::identity(), kNone, 0, items_);
        const size_t end = items_.size();
        if (end - begin > kFewItems) {  // (else the union's own operands will do)
            const uint32_t balanced = std::bit_width(end - begin - 1) + 1;
            uint32_t root = derived.child;
            if (derived.height > balanced) {
                binary_.clear();
                root = split(items_, begin, end);
            }
            out_.nodes_[n].bvh = collapse(root);
            out_.bvhLeaves_ += static_cast<uint32_t>(end - begin);
        }
        // The unions beyond the chain limit, if collect() met any (a call per leaf, then a
        // test per leaf, only looked for them).
        if (beyondChain_ != beyond)
            for (size_t k = begin; k < end; ++k)
                if (isUnion(out_.nodes_[items_[k].node])) hierarchy(items_[k].node);
        items_.resize(begin);
    }

    // The binary hierarchy over items[begin, end) (two or more), in binary_: halves at the
    // median of the items' centres along the axis where the centres spread widest. Returns
    // its root.
    uint32_t split(std::vector<Item>& items, size_t begin, size_t end) {
        Box centres;
        for (size_t k = begin; k < end; ++k) centres.extend(items[k].box.center());
        int axis = -1;
        double widest = 0;
        for (int a = 0; a < 3; ++a) {
            const double w = centres.hi[a] - centres.lo[a];
            if (std::isfinite(w) && w > widest) widest = w, axis = a;
        }
        const size_t mid = begin + (end - begin) / 2;
        // (a box unbounded both ways along the axis has a NaN centre: taken as 0, so that
        // the order stays strict and weak)
        auto centre = [axis](const Item& i) {
            const double c = i.box.center()[axis];
            return c == c ? c : 0.0;
        };
        if (axis >= 0)
            std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                             [&](const Item& a, const Item& b) { return centre(a) < centre(b); });
        const uint32_t index = static_cast<uint32_t>(binary_.size());
        binary_.emplace_back();
        const size_t bounds[3] = {begin, mid, end};
        for (int c = 0; c < 2; ++c) {
            Box box;
            for (size_t k = bounds[c]; k < bounds[c + 1]; ++k) box.extend(items[k].box);
            uint32_t child = 0, link = kNone;
            if (bounds[c + 1] - bounds[c] == 1) {
                child = items[bounds[c]].node | UnrolledInstance::kLeaf;
                link = items[bounds[c]].link;
            } else {
                child = split(items, bounds[c], bounds[c + 1]);
            }
            Binary& b = binary_[index];
            b.box[c] = box;
            b.child[c] = child;
            b.link[c] = link;
        }
        return index;
    }

    // The four-wide node of binary node `root`: its two children, and in their place the
    // children of the inner one with the largest box while there is room. Returns its
    // index in out_.bvh_.
    uint32_t collapse(uint32_t root) {
        struct Slot {
            uint32_t child, link;
            Box box;
        };
        Slot slots[4];
        int n = 0;
        for (int c = 0; c < 2; ++c)
            slots[n++] = {binary_[root].child[c], binary_[root].link[c], binary_[root].box[c]};
        while (n < 4) {
            int open = -1;
            double largest = 0;
            for (int k = 0; k < n; ++k) {
                if (slots[k].child & UnrolledInstance::kLeaf) continue;
                const double area = halfArea(slots[k].box);
                if (open < 0 || area > largest) open = k, largest = area;
            }
            if (open < 0) break;
            const Binary& b = binary_[slots[open].child];
            slots[n++] = {b.child[1], b.link[1], b.box[1]};
            slots[open] = {b.child[0], b.link[0], b.box[0]};
        }
        const uint32_t index = static_cast<uint32_t>(out_.bvh_.size());
        out_.bvh_.emplace_back();
        double lo[3][4] = {}, hi[3][4] = {};  // (an empty slot: 0 to 0, never entered)
        for (int k = 0; k < 4; ++k) {
            uint32_t child = kNone, link = kNone;
            if (k < n) {
                for (int a = 0; a < 3; ++a) lo[a][k] = slots[k].box.lo[a];
                for (int a = 0; a < 3; ++a) hi[a][k] = slots[k].box.hi[a];
                link = slots[k].link;
                child = (slots[k].child & UnrolledInstance::kLeaf) ? slots[k].child
                                                                   : collapse(slots[k].child);
            }
            out_.bvh_[index].child[k] = child;
            out_.bvh_[index].link[k] = link;
        }
        BvhNode& b = out_.bvh_[index];
        for (int a = 0; a < 3; ++a) {
            floatsBelow(lo[a], b.lo[a]);
            floatsAbove(hi[a], b.hi[a]);
        }
        return index;
    }

    // The half surface of a box (NaN or infinite when it is unbounded: opened last or
    // first, which only orders the hierarchy).
    static double halfArea(const Box& b) {
        const Vec3 e = b.hi - b.lo;
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }

    // A paint node whose material needs its instance (transparency's interiors: the node
    // and the choices that lead to it) or its frame (a pigment pattern: the inverse
    // matrices on the way to it, all of pending_) is recorded for the surfaces below it.
    // The map from the world into its frame (a normal pattern) is the graph walk's, and so
    // is every such paint node of a top level (its Instance and Deferred nodes would not
    // pass it on).
    void paintNode(NodeId n, PathState& s) {
        s.paint = 0;
        const uint32_t m = s.material;
        if (!scene_.paintFrameOf(m)) return;
        const uint8_t marks = scene_.paintFrames[m];
        if (cuts_ || (marks & TraceScene::kPaintMap)) throw TooLarge{};
        UnrolledInstance::PaintAt at{n, static_cast<uint32_t>(choices_.size())};
        if (marks & TraceScene::kPaintPoint) {
            at.point = true;
            at.firstMatrix = static_cast<uint32_t>(out_.matrixRefs_.size());
            at.matrices = static_cast<uint32_t>(pending_.size());
            out_.matrixRefs_.insert(out_.matrixRefs_.end(), pending_.begin(), pending_.end());
        }
        out_.paints_.push_back(at);
        s.paint = static_cast<uint32_t>(out_.paints_.size());
    }

    void setChoices(Node& x) {
        x.firstChoice = static_cast<uint32_t>(out_.choices_.size());
        x.choices = static_cast<uint32_t>(choices_.size());
        out_.choices_.insert(out_.choices_.end(), choices_.begin(), choices_.end());
    }

    const TraceScene& scene_;
    const Semantics& sem_;
    const Graph& g_;
    UnrolledInstance& out_;
    const uint64_t maxVisits_;
    UnrolledInstance::Cuts* const cuts_;  // expandTop's (else null)
    const bool paintFrames_;
    uint64_t visits_ = 0;
    uint32_t base_ = 0;
    // Parameter frames, a stack (addresses stay valid while deeper ones are pushed).
    // (The allocation out of line: a C-step then takes the frame inline.)
    double* pushFrame() {
        if (framesUsed_ == frames_.size()) addFrame();
        return frames_[framesUsed_++].get();
    }
    [[gnu::noinline]] void addFrame() {
        frames_.push_back(std::make_unique<double[]>(std::max<size_t>(g_.slotCount(), 1)));
    }
    std::vector<std::unique_ptr<double[]>> frames_;
    size_t framesUsed_ = 0;
    std::vector<uint32_t> pending_;  // matrices (indices in out_.matrices_)
    FlatIndex matrixIndex_;          // by the bits' hash
    // inverseIndex()'s constant T-nodes met (node kNone: a free slot).
    static constexpr size_t kConstIndexSlots = 16;
    struct ConstIndex {
        NodeId node = kNone;
        uint32_t index = 0;
    };
    ConstIndex constIndex_[kConstIndexSlots];
    // inverseOf()'s inverses, direct-mapped by matrix index (matrix kNone: a free slot).
    static constexpr size_t kInverseSlots = 16;
    struct InverseSlot {
        uint32_t matrix = kNone;
        Affine inverse;
    };
    InverseSlot inverses_[kInverseSlots];
    std::vector<uint32_t> choices_;
    FlatIndex linkIndex_;       // linkTo()'s links by (parent, matrix)
    uint32_t beyondChain_ = 0;  // unions collect() left as operands (beyond kMaxChain)
    // (the thread's, while it lends its arrays)
    BuildArrays::Stacks stacks_;
    std::vector<uint32_t>& kids_ = stacks_.kids;
    std::vector<Item>& items_ = stacks_.items;
    std::vector<Part>& parts_ = stacks_.parts;
    std::vector<Binary>& binary_ = stacks_.binary;
};

// ---------------------------------------------------------------------------------------
// Tracing: Tracer::first and Tracer::spans on the flat arrays.

size_t UnrolledInstance::bytes() const {
    return sizeof(*this) + nodes_.capacity() * sizeof(Node) +
           children_.capacity() * sizeof(uint32_t) + matrices_.capacity() * sizeof(Affine) +
           matrixRefs_.capacity() * sizeof(uint32_t) + args_.capacity() * sizeof(double) +
           choices_.capacity() * sizeof(uint32_t) + bvh_.capacity() * sizeof(BvhNode) +
           links_.capacity() * sizeof(Link) + instances_.capacity() * sizeof(Reference) +
           deferred_.capacity() * sizeof(Deferred) + deferredFrames_.capacity() * sizeof(double) +
           paints_.capacity() * sizeof(PaintAt);
}

std::vector<std::vector<uint32_t>> UnrolledInstance::bvhLeafGroups() const {
    std::vector<std::vector<uint32_t>> groups;
    for (const BvhNode& b : bvh_) {
        std::vector<uint32_t>& leaves = groups.emplace_back();
        for (const uint32_t c : b.child)
            if (c != kNone && (c & kLeaf)) leaves.push_back(c & ~kLeaf);
    }
    return groups;
}

size_t UnrolledInstance::looseOperands() const {
    return static_cast<size_t>(
        std::count_if(nodes_.begin(), nodes_.end(), [](const Node& n) { return n.looseInBvh; }));
}

namespace {

// FNV-1a over the bytes of values without padding.
struct Digest {
    uint64_t h = 0xcbf29ce484222325ULL;
    template <class T>
    void add(const T& v) {
        static_assert(std::has_unique_object_representations_v<T> || std::is_floating_point_v<T>);
        unsigned char bytes[sizeof(T)];
        std::memcpy(bytes, &v, sizeof v);
        for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ULL;
    }
    template <class T>
    void addAll(const std::vector<T>& v) {
        add(v.size());
        for (const T& x : v) add(x);
    }
};

}  // namespace

uint64_t UnrolledInstance::digest() const {
    Digest d;
    d.add(nodes_.size());
    for (const Node& n : nodes_) {
        d.add(static_cast<uint32_t>(n.kind) | static_cast<uint32_t>(n.op) << 8 |
              static_cast<uint32_t>(n.prim) << 16 | static_cast<uint32_t>(n.looseInBvh) << 24);
        for (uint32_t v : {n.material, n.firstMatrix, n.matrices, n.first, n.count, n.firstChoice,
                           n.choices, n.bvh})
            d.add(v);
        for (int a = 0; a < 3; ++a) d.add(n.box.lo[a]), d.add(n.box.hi[a]);
    }
    d.addAll(children_);
    d.add(matrices_.size());
    for (const Affine& m : matrices_) {
        for (const auto& row : m.l)
            for (double v : row) d.add(v);
        for (int a = 0; a < 3; ++a) d.add(m.t[a]);
    }
    d.addAll(matrixRefs_);
    d.addAll(args_);
    d.addAll(choices_);
    d.add(bvh_.size());
    for (const BvhNode& b : bvh_)
        for (int k = 0; k < 4; ++k) {
            for (int a = 0; a < 3; ++a) d.add(b.lo[a][k]), d.add(b.hi[a][k]);
            d.add(b.child[k]), d.add(b.link[k]);
        }
    d.add(links_.size());
    for (const Link& l : links_) d.add(l.parent), d.add(l.matrix);
    // (only where there are some: the digests of other expansions stay what they were)
    if (!paints_.empty()) {
        d.add(paints_.size());
        for (const PaintAt& p : paints_)
            d.add(p.node), d.add(p.prefix), d.add(p.firstMatrix), d.add(p.matrices),
                d.add(static_cast<uint32_t>(p.point));
        for (const Node& n : nodes_) d.add(n.paintAt);
    }
    if (!deferred_.empty()) d.add(deferred_.size());
    for (const Deferred& x : deferred_) {
        for (uint32_t v : {x.select, x.depth, x.stateDepth, x.frame}) d.add(v);
        for (uint64_t v : {x.path, x.key.a, x.key.b}) d.add(v);
    }
    if (!deferredFrames_.empty()) d.addAll(deferredFrames_);
    for (uint32_t v : {root_, rootBvh_, levels_, bvhLeaves_, linkSlots_}) d.add(v);
    return d.h;
}

LocalRay UnrolledInstance::enter(const Node& node, const LocalRay& r) const {
    if (node.matrices == 0) return r;  // (with its reciprocals, if computed)
    return mapRay(matrices_.data(), matrixRefs_.data() + node.firstMatrix, node.matrices, r);
}

Vec3 UnrolledInstance::leave(const Node& node, Vec3 normal) const {
    for (uint32_t k = node.matrices; k-- > 0;)
        normal = matrices_[matrixRefs_[node.firstMatrix + k]].transposedVector(normal);
    return normal;
}

// The ray r (in the frame of the union whose BVH is being walked, at `stamp`) mapped
// through the chain of matrices of link l, as enter() maps it one matrix after the other:
// each link's ray is computed once per walk and shared by the copies below it.
const LocalRay& UnrolledInstance::linkedRay(uint32_t l, const LocalRay& r, uint64_t stamp,
                                            Scratch& s) const {
    Scratch::Linked& e = s.linked[l];
    if (e.stamp == stamp) return e.ray;
    const Link& link = links_[l];
    const LocalRay& from = link.parent == kNone ? r : linkedRay(link.parent, r, stamp, s);
    e.ray = mapRay(matrices_[link.matrix], from);
    e.stamp = stamp;
    return e.ray;
}

// The instance path after the first `count` of the node's choices, from `path` at the
// S-node. (The mixers inline: a hit replays a dozen choices.)
inline uint64_t UnrolledInstance::replayChoices(const Node& node, uint64_t path,
                                                uint32_t count) const {
    for (uint32_t k = 0; k < count; ++k) {
        const uint32_t c = choices_[node.firstChoice + k];
        path = (c & kRuleBit) ? pathRuleInline(path, c & ~kRuleBit) : pathChildInline(path, c);
    }
    return path;
}

uint64_t UnrolledInstance::keyOf(const Node& node, uint64_t path) const {
    return replayChoices(node, path, node.choices);
}

bool UnrolledInstance::first(const LocalRay& r, double tmin, double& tmax, Hit& hit, const Use& use,
                             bool anyHit, Scratch& s) const {
    if (root_ == kNone) return false;
    double t0 = tmin, t1 = tmax;
    if (!clipToBox(nodes_[root_].box, r, t0, t1)) return false;
    // (instances referred to need theirs too: no resizing while a link's ray is in use)
    if (s.linked.size() < linkSlots_) s.linked.resize(linkSlots_);
    if (!firstAt(root_, r, tmin, tmax, hit, use, anyHit, s)) return false;
    settlePaint(hit, use.path, r, anyHit, s);
    return true;
}

size_t UnrolledInstance::spans(const LocalRay& r, double tmin, double tmax,
                               std::vector<Span>& spans, const Use& use, Scratch& s) const {
    if (root_ == kNone) return 0;
    double t0 = tmin, t1 = tmax;
    if (!clipToBox(nodes_[root_].box, r, t0, t1)) return 0;
    const size_t count = spansAt(root_, r, tmin, tmax, spans, use, s);
    if (!paints_.empty())
        for (size_t k = spans.size() - count; k < spans.size(); ++k) {
            Span& sp = spans[k];
            if (sp.in.paint & kNodePaint) resolvePaint(sp.in.paint, use.path, r, sp.in.t, s);
            if (sp.out.paint & kNodePaint) resolvePaint(sp.out.paint, use.path, r, sp.out.t, s);
        }
    return count;
}

// The paint handle of a surface of `node`: the caller's where the node inherits its
// material; else, where a paint node inside the instance recorded its instance, the node
// itself (kNodePaint, until first() or spans() resolve it with the instance's path).
uint32_t UnrolledInstance::paintOf(const Node& node, const Use& use) const {
    if (node.material == kInherit) return use.paint;
    if (node.paintAt == kNone) return 0;
    return kNodePaint | static_cast<uint32_t>(&node - nodes_.data());
}

// The hit of a search of this instance (from the instance path `path` at its S-node, the
// ray r in the S-node's frame): a surface painted inside it resolved (resolvePaint), or,
// for a shadow ray, whose hit is only its existence, no paint at all.
void UnrolledInstance::settlePaint(Hit& hit, uint64_t path, const LocalRay& r, bool anyHit,
                                   Scratch& s) const {
    if (!(hit.paint & kNodePaint)) return;
    if (anyHit)
        hit.paint = 0;
    else
        resolvePaint(hit.paint, path, r, hit.t, s);
}

// A surface's paint handle kNodePaint | n becomes its interior (the paint node and the
// instance path that reached it) and its point at t in the paint node's frame (the ray r,
// in the S-node's frame, through the same matrices), as the graph walk records them, kept
// in the scratch space till the end of the ray's walk (kScratchPaint).
void UnrolledInstance::resolvePaint(uint32_t& paint, uint64_t path, const LocalRay& r, double t,
                                    Scratch& s) const {
    const Node& node = nodes_[paint & ~kNodePaint];
    const PaintAt& at = paints_[node.paintAt];
    s.interiors.push_back(paintInteriorOf(replayChoices(node, path, at.prefix), at.node));
    Vec3 point{};
    if (at.point) {
        const LocalRay p =
            mapRay(matrices_.data(), matrixRefs_.data() + at.firstMatrix, at.matrices, r);
        point = p.o + p.d * t;
    }
    s.points.push_back(point);
    paint = kScratchPaint | static_cast<uint32_t>(s.interiors.size() - 1);
}

// A solid primitive's first boundary after tmin that is nearer than the hit so far (or at
// tmax, winning the tie), the ray (o, d) in its frame: its normal left in that frame.
[[gnu::always_inline]] inline bool UnrolledInstance::firstInSolid(const Node& node, const Vec3& o,
                                                                  const Vec3& d, double tmin,
                                                                  double& tmax, Hit& hit,
                                                                  const Use& use,
                                                                  bool anyHit) const {
    SpanRoom room;
    Span* sp = room.s;
    const int count = intersectSolid(node.prim, args_.data() + node.first, o, d, sp);
    for (int k = 0; k < count; ++k) {
        const Boundary* b =
            sp[k].in.t > tmin ? &sp[k].in : (sp[k].out.t > tmin ? &sp[k].out : nullptr);
        if (!b) continue;
        // (the key is replayed only for a tie or a new nearest hit)
        if (!(b->t < tmax) && !(b->t == tmax && hit.valid && keyOf(node, use.path) < hit.key))
            return false;
        const bool inherit = node.material == kInherit;
        // (a shadow ray's hit is only its existence: no key, no normal to map back)
        hit = Hit{b->t,
                  b->normal,
                  inherit ? use.material : node.material,
                  true,
                  anyHit ? 0 : keyOf(node, use.path),
                  paintOf(node, use)};
        tmax = b->t;
        return true;
    }
    return false;
}

// A solid or an Instance node met in a hierarchy (its box there its own), as firstAt would
// enter it, without firstAt's dispatch, and a solid without matrices without a copy of the
// ray.
bool UnrolledInstance::firstLeaf(const Node& node, const LocalRay& r, double tmin, double& tmax,
                                 Hit& hit, const Use& use, bool anyHit, Scratch& s) const {
    ++s.visits;
    const bool solid = node.kind == Kind::Solid;
    if (solid && node.matrices == 0)
        return firstInSolid(node, r.o, r.d, tmin, tmax, hit, use, anyHit);
    // (a copy all the same for an instance: its walk may reuse the slot of r's link)
    const LocalRay rr =
        node.matrices == 0
            ? r
            : mapRay(matrices_.data(), matrixRefs_.data() + node.firstMatrix, node.matrices, r);
    bool found;
    if (solid) {
        found = firstInSolid(node, rr.o, rr.d, tmin, tmax, hit, use, anyHit);
    } else {
        const bool inherit = node.material == kInherit;
        const Reference& x = instances_[node.first];
        found = firstInInstance(
            x, rr, tmin, tmax, hit,
            Use{x.path, inherit ? use.material : node.material, inherit ? use.paint : 0}, anyHit,
            s);
    }
    if (found && !anyHit) hit.normal = leave(node, hit.normal);
    return found;
}

bool UnrolledInstance::firstAt(uint32_t n, const LocalRay& r, double tmin, double& tmax, Hit& hit,
                               const Use& use, bool anyHit, Scratch& s) const {
    ++s.visits;
    const Node& node = nodes_[n];
    if (node.looseInBvh) {  // (its own box is tighter than the one the BVH tested)
        double t0 = tmin, t1 = tmax;
        if (!clipToBox(node.box, r, t0, t1)) return false;
    }
    const LocalRay rr = enter(node, r);
    const uint32_t material = node.material == kInherit ? use.material : node.material;
    const uint32_t paint = paintOf(node, use);
    bool found = false;
    switch (node.kind) {
        case Kind::Solid:
            found = firstInSolid(node, rr.o, rr.d, tmin, tmax, hit, use, anyHit);
            break;
        case Kind::Triangle: {
            Vec3 corners[3];
            triangleCorners(node.prim, args_.data() + node.first, corners);
            Boundary b;
            if (intersectTriangle(corners[0], corners[1], corners[2], rr.o, rr.d, tmin,
                                  std::nextafter(tmax, std::numeric_limits<double>::infinity()),
                                  b) &&
                (b.t < tmax || (b.t == tmax && hit.valid && keyOf(node, use.path) < hit.key))) {
                hit = Hit{b.t, b.normal, material, true, anyHit ? 0 : keyOf(node, use.path), paint};
                tmax = b.t;
                found = true;
            }
            break;
        }
        case Kind::Instance:
            found = firstInInstance(instances_[node.first], rr, tmin, tmax, hit,
                                    Use{instances_[node.first].path, material, paint}, anyHit, s);
            break;
        case Kind::Deferred:
            found = firstInDeferred(node, rr, tmin, tmax, hit, material, s);
            break;
        case Kind::Operator:
            if (node.op != CsgOp::Union) {
                std::vector<Span>& buffer = s.spans;
                const size_t base = buffer.size();
                const size_t count = spansAt(n, r, tmin, tmax, buffer, use, s);
                // spansAt left the normals in the frame this node is entered from.
                found = boundaryHit(buffer, base, count, tmin, tmax, keyOf(node, use.path), hit);
                buffer.resize(base);
                if (found) tmax = hit.t;
                return found;
            }
            if (node.bvh != kNone) {
                found = firstBvh(node.bvh, rr, tmin, tmax, hit, use, anyHit, s);
                break;
            }
            found = firstOfNodes(children_.data() + node.first, node.count, rr, tmin, tmax, hit,
                                 use, anyHit, s);
            break;
    }
    if (found && !anyHit) hit.normal = leave(node, hit.normal);
    return found;
}

// An Instance node's instance, the ray in its S-node's frame: first() without its clip to
// the instance's box (this node's box, which holds it, has been met, and boxes only cull;
// first() on the top level has sized s.linked for the instances too), and straight into
// the root's hierarchy where firstAt(root_) would only walk it; a surface painted inside it
// resolved as first() resolves it. (Out of line: firstAt, the primitives' walk too, stays
// as small as it was.)
[[gnu::noinline]] bool UnrolledInstance::firstInInstance(const Reference& ref, const LocalRay& r,
                                                         double tmin, double& tmax, Hit& hit,
                                                         const Use& inside, bool anyHit,
                                                         Scratch& s) const {
    const UnrolledInstance& x = *ref.instance;
    const auto search = [&] {
        if (x.rootBvh_ != kNone) {
            ++s.visits;  // (as firstAt(root_) counts it)
            return x.firstBvh(x.rootBvh_, r, tmin, tmax, hit, inside, anyHit, s);
        }
        return x.root_ != kNone && x.firstAt(x.root_, r, tmin, tmax, hit, inside, anyHit, s);
    };
    if (x.paints_.empty()) return search();  // (nothing painted inside: tail calls)
    const bool found = search();
    if (found) x.settlePaint(hit, inside.path, r, anyHit, s);
    return found;
}

// A Deferred node's instance, the ray in its S-node's frame: the walker's (the tracer's).
// (Out of line, as firstInInstance.)
[[gnu::noinline]] bool UnrolledInstance::firstInDeferred(const Node& node, const LocalRay& r,
                                                         double tmin, double& tmax, Hit& hit,
                                                         uint32_t material, Scratch& s) const {
    const Deferred& d = deferred_[node.first];
    return s.walker->firstDeferred(d, deferredFrames_.data() + d.frame, r, tmin, tmax, hit,
                                   material);
}

// The first hit among the nodes list[0..count), all entered from the same frame, as the
// operands of a union.
bool UnrolledInstance::firstOfNodes(const uint32_t* list, uint32_t count, const LocalRay& r,
                                    double tmin, double& tmax, Hit& hit, const Use& use,
                                    bool anyHit, Scratch& s) const {
    return firstOfUnion(
        count, tmin, tmax, hit, anyHit, s.order,
        [&](uint32_t i, double& t0) {
            double t1 = tmax;
            return clipToBox(nodes_[list[i]].box, r, t0, t1);
        },
        [&](uint32_t i, double& best, Hit& h) {
            return firstAt(list[i], r, tmin, best, h, use, anyHit, s);
        });
}

namespace {

// A child of a BVH node that firstBvh has still to visit (its entry in floats: the float
// test's own, or the doubles' rounded down, so that it is never later than the doubles';
// 16 bytes, moved as one).
struct alignas(16) Pending {
    uint32_t child, link;
    float t0;
};

// Pushes the children of b in `mask`, entered at t0[c], onto stack[top..]; returns the new
// top. For a first hit sorted, the farthest first (by insertion: at most four), so that the
// nearest is on top; a shadow ray may stop at any surface, so its children go unsorted.
[[gnu::always_inline]] inline int pushMet(const UnrolledInstance::BvhNode& b, int mask,
                                          const float t0[4], bool sorted, Pending* stack, int top) {
    const int base = top;
    for (; mask != 0; mask &= mask - 1) {
        const int c = __builtin_ctz(static_cast<unsigned>(mask));
        int k = top++;
        for (; sorted && k > base && stack[k - 1].t0 < t0[c]; --k) stack[k] = stack[k - 1];
        stack[k] = {b.child[c], b.link[c], t0[c]};
    }
    return top;
}

}  // namespace

// The first hit in a union's BVH: the nodes front to back by the ray's entry into them
// (a stack of the ones still to visit, nearer ones on top), each skipped once its entry
// lies beyond the nearest hit so far. (The order only saves work: a hit is the nearest
// (t, key) of all operands whose boxes the ray meets before it, whatever the order.)
bool UnrolledInstance::firstBvh(uint32_t root, const LocalRay& r, double tmin, double& tmax,
                                Hit& hit, const Use& use, bool anyHit, Scratch& s) const {
    // Deeper than any hierarchy of median splits, or of a derivation's nesting (hierarchy():
    // at most one level deeper), with four entries per level at most.
    constexpr int kStack = 4 * 32 + 4;
    Pending stack[kStack];
    int top = 0;
    Pending p = {root, kNone, floatBelow(tmin)};
    if (p.t0 > tmax) return false;
    const uint64_t stamp = ++s.stamp;
#if defined(__SSE2__)
    const FloatRay fr = floatRay(r, tmin);
#endif
    bool found = false;
    uint32_t foundLink = kNone;  // the nearest hit's link: its normal mapped back at the end
    for (;;) {
        if (p.child & kLeaf) {  // an operand: its box was the child's box
            const uint32_t n = p.child & ~kLeaf;
            const LocalRay& rr = p.link == kNone ? r : linkedRay(p.link, r, stamp, s);
            const Node& leaf = nodes_[n];
            if (!leaf.looseInBvh && (leaf.kind == Kind::Solid || leaf.kind == Kind::Instance)
                    ? firstLeaf(leaf, rr, tmin, tmax, hit, use, anyHit, s)
                    : firstAt(n, rr, tmin, tmax, hit, use, anyHit, s)) {
                if (anyHit) return true;
                foundLink = p.link;
                found = true;
            }
        } else {
            const BvhNode& b = bvh_[p.child];
            float t0[4];
#if defined(__SSE2__)
            int mask = fr.ok ? enterChildrenFloat(b, fr, tmax, t0)
                             : enterChildrenBelow(b, r, tmin, tmax, t0);
#else
            int mask = enterChildrenBelow(b, r, tmin, tmax, t0);
#endif
            const int base = top;
            top = pushMet(b, mask, t0, !anyHit, stack, top);
            // The nearest child met (on top) next, without the pops' test against tmax: the
            // node test met it within tmax (widened by at most its margin) and no hit has
            // moved tmax since; a box entered in vain costs work, never a hit.
            if (top > base) {
                p = stack[--top];
                continue;
            }
        }
        while (top > 0 && stack[top - 1].t0 > tmax) --top;  // (at tmax exactly: a tie)
        if (top == 0) break;
        p = stack[--top];
    }
    // (a nearer hit replaces the whole of hit.normal, so only the last one's is mapped)
    for (uint32_t l = foundLink; l != kNone; l = links_[l].parent)
        hit.normal = matrices_[links_[l].matrix].transposedVector(hit.normal);
    return found;
}

size_t UnrolledInstance::spansAt(uint32_t n, const LocalRay& r, double tmin, double tmax,
                                 std::vector<Span>& spans, const Use& use, Scratch& s) const {
    ++s.visits;
    const Node& node = nodes_[n];
    const LocalRay rr = enter(node, r);
    const size_t base = spans.size();
    size_t count = 0;
    switch (node.kind) {
        case Kind::Triangle:
            return 0;  // surfaces: never under ∩ or \ (the compiler checks)
        case Kind::Deferred:
            return 0;  // (top levels only, which hold unions and are traced by first())
        case Kind::Solid: {
            SpanRoom room;
            Span* sp = room.s;
            const int k = intersectSolid(node.prim, args_.data() + node.first, rr.o, rr.d, sp);
            const uint32_t material = node.material == kInherit ? use.material : node.material;
            for (int j = 0; j < k; ++j) {
                sp[j].in.material = sp[j].out.material = material;
                sp[j].in.paint = sp[j].out.paint = paintOf(node, use);
                spans.push_back(sp[j]);
            }
            count = static_cast<size_t>(k);
            break;
        }
        case Kind::Instance: {
            const Reference& x = instances_[node.first];
            count =
                x.instance->spans(rr, tmin, tmax, spans,
                                  {x.path, node.material == kInherit ? use.material : node.material,
                                   node.material == kInherit ? use.paint : 0},
                                  s);
            break;
        }
        case Kind::Operator: {
            count = combineOperands(
                node.op, node.count, spans, tmin, tmax,
                [&](uint32_t i, double lo, double hi) {
                    return clipToBox(nodes_[children_[node.first + i]].box, rr, lo, hi);
                },
                [&](uint32_t i, double lo, double hi) {
                    return spansAt(children_[node.first + i], rr, lo, hi, spans, use, s);
                });
            break;
        }
    }
    for (size_t k = base; k < base + count; ++k) {
        spans[k].in.normal = leave(node, spans[k].in.normal);
        spans[k].out.normal = leave(node, spans[k].out.normal);
    }
    return count;
}

// ---------------------------------------------------------------------------------------

std::unique_ptr<UnrolledInstance> UnrolledInstance::expand(const TraceScene& scene, NodeId select,
                                                           uint32_t depth, const double* frame,
                                                           uint64_t path, uint64_t maxVisits) {
    auto x = std::make_unique<UnrolledInstance>();
    Unroller builder(scene, *x, maxVisits);
    try {
        builder.run(select, depth, frame, path);
    } catch (const TooLarge&) {
        return nullptr;
    }
    return x;
}

size_t UnrolledInstance::keptBuildBytes() {
    BuildArrays& b = threadArrays();
    size_t bytes = 0;
    const auto add = [&bytes](const auto& v) {
        bytes += v.capacity() * sizeof(typename std::decay_t<decltype(v)>::value_type);
    };
    add(b.nodes), add(b.children), add(b.matrixRefs), add(b.choices);
    add(b.matrices), add(b.args), add(b.bvh), add(b.links), add(b.paints);
    b.stacks.each(add);
    return bytes + b.matrixIndex.bytes() + b.linkIndex.bytes();
}

std::unique_ptr<UnrolledInstance> UnrolledInstance::expandTop(const TraceScene& scene, Cuts& cuts) {
    if (scene.graph().axiom == kNone) return nullptr;
    auto x = std::make_unique<UnrolledInstance>();
    Unroller builder(scene, *x, cuts.maxVisits(), &cuts);
    try {
        builder.runTop();
    } catch (const TooLarge&) {
        return nullptr;
    } catch (const Refused&) {
        return nullptr;
    }
    return x;
}

}  // namespace pcsg::tracer
