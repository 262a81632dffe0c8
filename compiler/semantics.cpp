// Entering a node of the cyclic graph: see semantics.h.
#include "semantics.h"

#include <bit>

#include "primitive_table.h"

namespace pcsg {

namespace {
constexpr uint32_t kMaxFused = 64;  // T-nodes fused into one step at most
}  // namespace

Semantics::Semantics(const Graph& g)
    : g_(g), maxDepth_(g.scene.settings.maxDepth), fused_(g.nodes.size()) {
    const size_t n = g.nodes.size();
    auto constantT = [&](NodeId m) {
        return g.nodes[m].kind == NodeKind::Transform && g.transforms[g.nodes[m].payload].constant;
    };
    for (NodeId m = 0; m < n; ++m) {
        if (!constantT(m)) continue;
        // The chain of constant T-nodes below m: M_m M_c1 ... M_ck, and its inverse
        // M_ck^-1 ... M_c1^-1 M_m^-1. A chain is cut after kMaxFused nodes (the next step
        // fuses the rest), so that a graph of one long chain is prepared in linear time.
        Fused& f = fused_[m];
        f.forward = g.transforms[g.nodes[m].payload].matrix;
        f.inverse = f.forward.inverse();
        f.forward = Affine::identity() * f.forward;
        NodeId c = g.child(m);
        for (uint32_t k = 1; constantT(c) && k < kMaxFused; ++k) {
            const Affine& mc = g.transforms[g.nodes[c].payload].matrix;
            f.forward = f.forward * mc;
            f.inverse = mc.inverse() * f.inverse;
            ++f.length;
            c = g.child(c);
        }
        f.target = c;
    }
}

void Semantics::transformStep(NodeId n, const PathState& s, StepScratch& scratch,
                              Step& step) const {
    StepScratch::Matrices& m = scratch.matrices.emplace();
    if (scratch.memo) {
        scratch.memo->transform(n, EvalState{s.frame, s.path}, m.forward, m.inverse);
    } else if (scratch.forwardOnly) {
        m.forward = transformMatrix(g_, n, EvalState{s.frame, s.path});
    } else {
        transformPair(g_, n, EvalState{s.frame, s.path}, m.forward, m.inverse);
    }
    step.child = g_.child(n);
    step.forward = &m.forward;
    step.inverse = scratch.forwardOnly && !scratch.memo ? nullptr : &m.inverse;
}

Affine Semantics::forwardThrough(const Affine& outer, NodeId n, const Step& st) const {
    if (fused_[n].target == kNone) return outer * *st.forward;
    Affine m = outer;
    for (NodeId k = n; k != st.child; k = g_.child(k))
        m = m * g_.transforms[g_.nodes[k].payload].matrix;
    return m;
}

bool Semantics::identityTimesIsExact(const Affine& m) {
    constexpr uint64_t kMinusZero = uint64_t{1} << 63, kExponent = uint64_t{0x7ff} << 52;
    bool exact = true;
    auto check = [&](double x) {
        const uint64_t b = std::bit_cast<uint64_t>(x);
        exact = exact && b != kMinusZero && (b & kExponent) != kExponent;
    };
    for (const auto& row : m.l)
        for (double x : row) check(x);
    check(m.t.x), check(m.t.y), check(m.t.z);
    return exact;
}

uint32_t Semantics::primitiveArgs(NodeId n, const PathState& s, double* out) const {
    const uint32_t count = primitiveArgCount(g_.primitives[g_.nodes[n].payload].kind);
    if (count) pcsg::primitiveArgs(g_, n, EvalState{s.frame, s.path}, out);
    return count;
}

}  // namespace pcsg
