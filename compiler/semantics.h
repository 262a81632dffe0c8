// What it means to enter a node of the cyclic graph: the one step that every walker takes,
// whatever it walks for (docs/language.md sections 3 to 6).
//
// A walker carries a PathState down the graph: the parameter frame, the instance path, the
// S-node depth, the innermost material and, where patterns need it, a handle on the frame
// of the paint node that set that material. Entering a node gives the node to go on to and
// the state there:
//
//  - an S-node checks max_depth, selects its rule (the instance path records which) and
//    leads to the rule's body one level deeper;
//  - a C-node computes a new frame (into storage the walker provides) for its operand;
//  - a T-node leads to its operand through its matrix; a chain of T-nodes whose arguments
//    are all constants counts as one step with the chain's product and its inverse,
//    computed once here;
//  - a paint node sets the material and clears the paint frame; a walker that shades
//    patterns (docs/language.md section 10: a pattern lives in the frame of the paint node
//    that applied it) then records that node's frame its own way and puts its handle in
//    `paint`. Walkers that only need geometry leave it 0 and pay nothing;
//  - an operator's operand i gets the instance path extended by i (operand());
//  - a primitive's arguments come from primitiveArgs().
//
// The walkers decide only how to recurse: the explicit-stack walk of compiler/walk.h (the
// exporter's expansion and the tracer's instance boxes), the tracer's recursion with a ray
// (tracer/traversal.cpp) and the tracer's unrolled instances (tracer/unrolled_instances.cpp).
// Because all of them take this step, an unrolled instance meets the same matrices, frames
// and paths as the walk, and hits the same surfaces bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <type_traits>
#include <vector>

#include "eval.h"
#include "graph.h"
#include "step_memo.h"

namespace pcsg {

struct PathState {
    const double* frame = nullptr;  // Graph::slotCount() values
    uint64_t path = kRootPath;      // the instance path (docs/language.md section 6)
    uint32_t depth = 0;             // S-nodes passed on the way here
    uint32_t material = 0;          // the innermost paint so far (0: the default)
    uint32_t paint = 0;  // the walker's handle on that paint node's frame (0: not recorded)
};

// Where entering a unary node (S, C, T, paint) leads.
struct Step {
    NodeId child = kNone;             // the node to go on to
    PathState state;                  // the state there
    uint32_t rule = kNone;            // S-nodes: the rule taken (0-based)
    const Affine* forward = nullptr;  // T-nodes: maps `child`'s frame into this node's
    const Affine* inverse = nullptr;  // T-nodes: the inverse of `forward` (see forwardOnly)
};

// Storage a walker lends to enter(): the new frame of a C-node (Graph::slotCount() values,
// not the incoming frame) and the matrices of a T-node that depends on parameters (made
// only then: the walk takes a step per node of every ray).
// A walker may also lend its StepMemo (step_memo.h), which remembers the results of C-
// and T-steps by what they read. A walker that maps only forwards (walk.h: world matrices,
// never rays) sets forwardOnly: a T-step without a memo then leaves `inverse` null instead
// of inverting a matrix nobody reads.
struct StepScratch {
    struct Matrices {
        Affine forward, inverse;
    };
    // Room for a T-node's matrices, made by emplace() only when the step needs them (not a
    // std::optional: GCC 12 zero-fills an optional's 192 bytes on construction, and every
    // node visit of every ray makes a StepScratch). emplace() leaves them unwritten: every
    // T-step writes `forward` whole, and `inverse` whole unless it leaves Step::inverse
    // null (Matrices() wrote two identities first: 1.2% of the terrain's instructions).
    // Matrices, an aggregate, is an implicit-lifetime type: the bytes' array begun by the
    // placement new holds it from then on.
    class MatrixRoom {
      public:
        MatrixRoom() {}
        Matrices& emplace() {
            return *std::launder(
                reinterpret_cast<Matrices*>(new (room_) std::byte[sizeof(Matrices)]));
        }

      private:
        static_assert(std::is_aggregate_v<Matrices> && std::is_trivially_destructible_v<Matrices>);
        alignas(Matrices) std::byte room_[sizeof(Matrices)];
    };
    double* frame = nullptr;
    MatrixRoom matrices;
    StepMemo* memo = nullptr;
    bool forwardOnly = false;
};

class Semantics {
  public:
    explicit Semantics(const Graph& g);

    const Graph& graph() const { return g_; }

    // The depth an S-node instance has when entered from state s; throws the max_depth
    // RuntimeError when it is beyond settings max_depth. Walkers that cull before they
    // select call this first, so that culling can never hide the error.
    uint32_t selectDepth(NodeId select, const PathState& s) const {
        if (s.depth >= maxDepth_) checkDepth(g_, select, s.depth + 1, EvalState{s.frame, s.path});
        return s.depth + 1;
    }

    // Enters the unary node n from state s. Throws RuntimeError (without module path: the
    // walker adds it as the error passes its S-nodes). Inline: the tracer takes this step
    // at every node of every ray.
    Step enter(NodeId n, const PathState& s, StepScratch& scratch) const {
        const Node& node = g_.nodes[n];
        Step step;
        step.state = s;
        switch (node.kind) {
            case NodeKind::Select:
                step.state.depth = selectDepth(n, s);
                step.rule = scratch.memo ? scratch.memo->select(n, EvalState{s.frame, s.path})
                                         : selectRule(g_, n, EvalState{s.frame, s.path});
                step.state.path = pathRule(s.path, step.rule);
                step.child = g_.child(n, step.rule);
                break;
            case NodeKind::Calc:
                if (scratch.memo)
                    scratch.memo->calc(n, EvalState{s.frame, s.path}, scratch.frame);
                else
                    applyCalc(g_, n, EvalState{s.frame, s.path}, scratch.frame);
                step.state.frame = scratch.frame;
                step.child = g_.child(n);
                break;
            case NodeKind::Transform:
                if (fused_[n].target == kNone) {
                    transformStep(n, s, scratch, step);
                    break;
                }
                step.child = fused_[n].target;
                step.forward = &fused_[n].forward;
                step.inverse = &fused_[n].inverse;
                break;
            case NodeKind::Paint:
                step.state.material = node.payload;
                step.state.paint = 0;
                step.child = g_.child(n);
                break;
            case NodeKind::Operator:
            case NodeKind::Primitive:
                break;  // not unary: operand() and primitiveArgs()
        }
        return step;
    }

    // outer * (the matrix of the T-step `st` taken at n), multiplied T-node by T-node along a
    // fused chain, so that a world matrix is the same product whether or not the chain's
    // T-nodes were folded into constants.
    Affine forwardThrough(const Affine& outer, NodeId n, const Step& st) const;

    // forwardThrough(Affine::identity(), n, st) bit for bit, without the product where it is
    // the step's own matrix (a world that restarts at the identity below an S-node: the
    // prefill's walk, an expansion's build): returns *st.forward itself then, else writes
    // the product into `room` and returns it. The one rule: a fused chain's matrix is that
    // product (the constructor multiplies it out from the identity the same way); a
    // parameter T-node's M is identity * M where M holds no -0 (+0 + -0 is +0) and no
    // infinity or NaN (0 * inf is NaN), else it is multiplied.
    const Affine& fromIdentity(NodeId n, const Step& st, Affine& room) const {
        if (fused_[n].target != kNone || identityTimesIsExact(*st.forward)) return *st.forward;
        return room = forwardThrough(Affine::identity(), n, st);
    }
    // Whether identity * m has m's bits (the test fromIdentity makes).
    static bool identityTimesIsExact(const Affine& m);

    // The state of operand i of an operator.
    static PathState operand(const PathState& s, uint32_t i) {
        return PathState{s.frame, pathChild(s.path, i), s.depth, s.material, s.paint};
    }

    // A primitive's argument values in state s, into out[0..8]; returns their number
    // (torus 2, triangle 9, tri1/tri2 and the solids without arguments 0).
    uint32_t primitiveArgs(NodeId n, const PathState& s, double* out) const;

    // The graph nodes one step from n passes: the T-nodes of a fused chain of constant
    // T-nodes, else 1.
    uint32_t nodesInStep(NodeId n) const {
        return fused_[n].target == kNone ? 1 : fused_[n].length;
    }

  private:
    // A T-node whose matrix depends on parameters: computed now, into `scratch`.
    void transformStep(NodeId n, const PathState& s, StepScratch& scratch, Step& step) const;

    struct Fused {
        NodeId target = kNone;
        uint32_t length = 1;  // T-nodes in the chain
        Affine forward, inverse;
    };
    const Graph& g_;
    uint32_t maxDepth_;
    std::vector<Fused> fused_;  // per node
};

}  // namespace pcsg
