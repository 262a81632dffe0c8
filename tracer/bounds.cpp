// Hyper-bounding boxes: see bounds.h for the method.
#include "bounds.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <optional>

#include "interval.h"
#include "primitives.h"

namespace pcsg::tracer {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// What the forward pass records per (node, depth) for the box pass.
struct Level {
    std::vector<uint8_t> reached;               // per node
    std::vector<IntervalAffine> matrix;         // per non-constant T-node
    std::vector<uint8_t> matrixOk;              // the matrix could be evaluated
    std::vector<std::array<Interval, 9>> args;  // per non-constant primitive
    std::vector<uint8_t> argsOk;
    std::vector<std::vector<uint32_t>> rules;  // per S-node (module index)
    std::vector<uint8_t> mayFail;              // per module: its selection may be an error
};

class Analysis {
  public:
    Analysis(const Graph& g, const BoundsOptions& opt) : g_(g), opt_(opt), n_(g.nodes.size()) {}

    Bounds run() {
        Bounds out;
        out.node.assign(n_, Box::everything());
        if (g_.axiom == kNone || g_.axiom >= n_ || !topologicalOrder()) {
            out.infiniteNodes = static_cast<uint32_t>(n_);
            return out;
        }
        indexNodes();
        const uint64_t maxDepth = g_.scene.settings.maxDepth;
        const uint64_t byBudget = std::max<uint64_t>(2, opt_.maxStates / std::max<size_t>(n_, 1));
        levels_ = static_cast<uint32_t>(std::min<uint64_t>(maxDepth + 1, byBudget));
        summary_ = levels_ <= maxDepth;

        forward();
        if (summary_) summaryFixpoint();
        backward(out);
        if (opt_.pad)
            for (Box& b : out.node) b = padded(b);
        if (opt_.pad)
            for (Box& b : out.depthBox) b = padded(b);
        out.summaryFrom = summary_ ? levels_ : 0;
        for (const Box& b : out.node)
            if (!b.isEmpty() && !b.isBounded()) ++out.infiniteNodes;
        return out;
    }

  private:
    const Graph& g_;
    BoundsOptions opt_;
    size_t n_;
    std::vector<NodeId> topo_;              // parents before children, edges into S-nodes ignored
    std::vector<int32_t> tIndex_, pIndex_;  // compact indices of non-constant T / primitives
    size_t tCount_ = 0, pCount_ = 0;
    uint32_t levels_ = 0;
    bool summary_ = false;
    std::vector<Level> level_;

    // Summary states (depths >= levels_).
    std::vector<std::optional<AbstractFrame>> sum_;
    Level sumRec_;
    std::vector<Box> sumBox_;

    bool isSelect(NodeId n) const { return g_.nodes[n].kind == NodeKind::Select; }
    uint32_t moduleOf(NodeId n) const { return g_.nodes[n].payload; }

    // Kahn's algorithm on the graph without the edges into S-nodes (S-nodes are the only
    // targets of back edges, so what remains is acyclic).
    bool topologicalOrder() {
        std::vector<uint32_t> indeg(n_, 0);
        for (NodeId n = 0; n < n_; ++n)
            for (uint32_t i = 0; i < g_.nodes[n].childCount; ++i) {
                const NodeId c = g_.child(n, i);
                if (!isSelect(c)) ++indeg[c];
            }
        std::deque<NodeId> q;
        for (NodeId n = 0; n < n_; ++n)
            if (indeg[n] == 0) q.push_back(n);
        while (!q.empty()) {
            const NodeId n = q.front();
            q.pop_front();
            topo_.push_back(n);
            for (uint32_t i = 0; i < g_.nodes[n].childCount; ++i) {
                const NodeId c = g_.child(n, i);
                if (!isSelect(c) && --indeg[c] == 0) q.push_back(c);
            }
        }
        return topo_.size() == n_;
    }

    void indexNodes() {
        tIndex_.assign(n_, -1);
        pIndex_.assign(n_, -1);
        for (NodeId n = 0; n < n_; ++n) {
            const Node& node = g_.nodes[n];
            if (node.kind == NodeKind::Transform && !g_.transforms[node.payload].constant)
                tIndex_[n] = static_cast<int32_t>(tCount_++);
            if (node.kind == NodeKind::Primitive && !g_.primitives[node.payload].constant)
                pIndex_[n] = static_cast<int32_t>(pCount_++);
        }
    }

    Level newLevel() const {
        Level l;
        l.reached.assign(n_, 0);
        l.matrix.resize(tCount_);
        l.matrixOk.assign(tCount_, 0);
        l.args.resize(pCount_);
        l.argsOk.assign(pCount_, 0);
        l.rules.resize(g_.modules.size());
        l.mayFail.assign(g_.modules.size(), 0);
        return l;
    }

    AbstractFrame initialFrame() const { return AbstractFrame(g_.slotCount()); }
    const TimeRange* time() const { return opt_.time ? &*opt_.time : nullptr; }

    // Evaluates a reached node in a state, records what the box pass needs, and calls
    // `push(child, state)` for every child it may reach.
    template <class Push>
    void process(NodeId n, const AbstractFrame& st, Level& rec, Push push) {
        const Node& node = g_.nodes[n];
        rec.reached[n] = 1;
        switch (node.kind) {
            case NodeKind::Select: {
                bool fails = false;
                auto rules = reachableRules(g_, n, st, &fails, time());
                if (fails) rec.mayFail[moduleOf(n)] = 1;
                for (uint32_t r : rules) push(g_.child(n, r), st);
                auto& dst = rec.rules[moduleOf(n)];
                for (uint32_t r : rules)
                    if (std::find(dst.begin(), dst.end(), r) == dst.end()) dst.push_back(r);
                return;
            }
            case NodeKind::Calc: {
                AbstractFrame out;
                if (applyCalcInterval(g_, n, st, out, time())) push(g_.child(n), out);
                return;
            }
            case NodeKind::Transform: {
                const int32_t ti = tIndex_[n];
                if (ti < 0) {
                    push(g_.child(n), st);
                    return;
                }
                IntervalAffine m;
                if (!transformInterval(g_, n, st, m, time())) return;
                if (rec.matrixOk[ti]) {
                    for (int i = 0; i < 3; ++i) {
                        for (int j = 0; j < 3; ++j)
                            rec.matrix[ti].l[i][j] = join(rec.matrix[ti].l[i][j], m.l[i][j]);
                        rec.matrix[ti].t[i] = join(rec.matrix[ti].t[i], m.t[i]);
                    }
                } else {
                    rec.matrix[ti] = m;
                    rec.matrixOk[ti] = 1;
                }
                push(g_.child(n), st);
                return;
            }
            case NodeKind::Paint:
                push(g_.child(n), st);
                return;
            case NodeKind::Operator:
                for (uint32_t i = 0; i < node.childCount; ++i) push(g_.child(n, i), st);
                return;
            case NodeKind::Primitive: {
                const int32_t pi = pIndex_[n];
                if (pi < 0) return;
                std::array<Interval, 9> a;
                if (!primitiveArgsInterval(g_, n, st, a.data(), time())) return;
                const uint32_t count = g_.primitives[node.payload].argCount;
                if (rec.argsOk[pi]) {
                    for (uint32_t i = 0; i < count; ++i)
                        rec.args[pi][i] = join(rec.args[pi][i], a[i]);
                } else {
                    rec.args[pi] = a;
                    rec.argsOk[pi] = 1;
                }
                return;
            }
        }
    }

    static void joinState(std::optional<AbstractFrame>& dst, const AbstractFrame& st) {
        if (!dst)
            dst = st;
        else
            joinInto(*dst, st);
    }

    // Exact states per depth, level by level: the non-S nodes of a level in topological
    // order, the S-children going to the next level (or to the summary).
    void forward() {
        const uint64_t maxDepth = g_.scene.settings.maxDepth;
        std::vector<std::optional<AbstractFrame>> cur(n_), next(n_);
        if (summary_) sum_.assign(n_, std::nullopt);
        const uint32_t axiomDepth = isSelect(g_.axiom) ? 1 : 0;
        if (axiomDepth <= maxDepth) {
            if (axiomDepth < levels_)
                (axiomDepth == 0 ? cur : next)[g_.axiom] = initialFrame();
            else
                sum_[g_.axiom] = initialFrame();
        }
        level_.reserve(levels_);
        for (uint32_t d = 0; d < levels_; ++d) {
            level_.push_back(newLevel());
            Level& rec = level_.back();
            if (d > 0) {
                cur.swap(next);
                for (auto& s : next) s.reset();
            }
            for (NodeId n : topo_) {
                if (!cur[n]) continue;
                const AbstractFrame st = std::move(*cur[n]);
                cur[n].reset();
                process(n, st, rec, [&](NodeId c, const AbstractFrame& s) {
                    if (!isSelect(c)) {
                        joinState(cur[c], s);
                    } else if (d + 1 <= maxDepth) {
                        if (d + 1 < levels_)
                            joinState(next[c], s);
                        else
                            joinState(sum_[c], s);
                    }
                });
            }
        }
    }

    // Depths from levels_ on share one state per node: a fixpoint with widening.
    void summaryFixpoint() {
        sumRec_ = newLevel();
        std::vector<uint32_t> updates(n_, 0);
        std::vector<uint8_t> queued(n_, 0);
        std::deque<NodeId> q;
        for (NodeId n = 0; n < n_; ++n)
            if (sum_[n]) {
                q.push_back(n);
                queued[n] = 1;
            }
        Level scratch = newLevel();
        while (!q.empty()) {
            const NodeId n = q.front();
            q.pop_front();
            queued[n] = 0;
            const AbstractFrame st = *sum_[n];
            process(n, st, scratch, [&](NodeId c, const AbstractFrame& s) {
                bool changed;
                if (!sum_[c]) {
                    sum_[c] = s;
                    changed = true;
                } else {
                    const AbstractFrame before = *sum_[c];
                    changed = joinInto(*sum_[c], s);
                    if (changed && ++updates[c] > 4) sum_[c] = widen(before, *sum_[c]);
                }
                if (changed && !queued[c]) {
                    q.push_back(c);
                    queued[c] = 1;
                }
            });
        }
        // Record from the final states.
        for (NodeId n = 0; n < n_; ++n)
            if (sum_[n]) process(n, *sum_[n], sumRec_, [](NodeId, const AbstractFrame&) {});
    }

    Box primitiveBoxAt(NodeId n, const Level& rec) const {
        const Node& node = g_.nodes[n];
        const Primitive& p = g_.primitives[node.payload];
        if (p.constant) return primitiveBox(p.kind, p.values.data());
        const int32_t pi = pIndex_[n];
        if (!rec.argsOk[pi]) return Box::empty();
        const auto& a = rec.args[pi];
        auto mag = [](const Interval& v) { return std::max(std::fabs(v.lo), std::fabs(v.hi)); };
        if (p.kind == PrimitiveKind::Torus) {
            const double e = mag(a[0]) + mag(a[1]), r = mag(a[1]);
            return Box{{-e, -e, -r}, {e, e, r}};
        }
        if (p.kind == PrimitiveKind::Triangle) {
            Box b;
            for (int k = 0; k < 3; ++k) {
                b.extend(Vec3{a[3 * k].lo, a[3 * k + 1].lo, a[3 * k + 2].lo});
                b.extend(Vec3{a[3 * k].hi, a[3 * k + 1].hi, a[3 * k + 2].hi});
            }
            return b;
        }
        return primitiveBox(p.kind, nullptr);
    }

    // One application of the box equations at node n, with children's boxes from `child`.
    template <class ChildBox>
    Box apply(NodeId n, const Level& rec, ChildBox child) const {
        const Node& node = g_.nodes[n];
        switch (node.kind) {
            case NodeKind::Primitive:
                return primitiveBoxAt(n, rec);
            case NodeKind::Select: {
                // A run-time error is "there" too: a ray that reaches it must meet it.
                if (rec.mayFail[moduleOf(n)]) return Box::everything();
                Box b;
                for (uint32_t r : rec.rules[moduleOf(n)]) b = unite(b, child(g_.child(n, r)));
                return b;
            }
            case NodeKind::Calc:
            case NodeKind::Paint:
                return child(g_.child(n));
            case NodeKind::Transform: {
                const Box c = child(g_.child(n));
                const int32_t ti = tIndex_[n];
                if (ti < 0) return pcsg::transformBox(g_.transforms[node.payload].matrix, c);
                if (!rec.matrixOk[ti]) return Box::empty();
                return tracer::transformBox(rec.matrix[ti], c);
            }
            case NodeKind::Operator:
                return csgBox(node.op(), node.childCount,
                              [&](uint32_t i) { return child(g_.child(n, i)); });
        }
        return Box::everything();
    }

    // A candidate summary box, enlarged a little so that a converging iteration becomes a
    // post-fixpoint.
    static Box enlarged(const Box& b) { return growBox(b, 1e-6, 1e-9); }

    void summaryBoxes() {
        sumBox_.assign(n_, Box::empty());
        auto child = [&](NodeId c) { return sumBox_[c]; };
        for (int it = 0; it < opt_.iterations; ++it) {
            bool changed = false;
            for (auto i = topo_.rbegin(); i != topo_.rend(); ++i) {
                const NodeId n = *i;
                if (!sum_[n]) continue;
                const Box b = unite(sumBox_[n], apply(n, sumRec_, child));
                if (!(b == sumBox_[n])) {
                    sumBox_[n] = b;
                    changed = true;
                }
            }
            if (!changed) return;  // an exact fixpoint
        }
        for (NodeId n = 0; n < n_; ++n) sumBox_[n] = enlarged(sumBox_[n]);
        // Accept only a post-fixpoint: F(B) within B at every node; give up (infinite)
        // where that fails, and check again, until it holds everywhere.
        for (size_t round = 0; round <= n_ + 1; ++round) {
            bool ok = true;
            for (NodeId n = 0; n < n_; ++n) {
                if (!sum_[n]) continue;
                const Box f = apply(n, sumRec_, child);
                if (!sumBox_[n].contains(f)) {
                    sumBox_[n] = Box::everything();
                    ok = false;
                }
            }
            if (ok) return;
        }
        for (NodeId n = 0; n < n_; ++n)
            if (sum_[n]) sumBox_[n] = Box::everything();
    }

    void backward(Bounds& out) {
        const uint64_t maxDepth = g_.scene.settings.maxDepth;
        if (summary_) summaryBoxes();
        const size_t modules = g_.modules.size();
        out.levels = levels_;
        out.depthBox.assign(modules * levels_, Box::empty());
        std::vector<Box> node(n_, Box::empty());
        std::vector<Box> cur(n_, Box::empty());
        for (uint32_t d = levels_; d-- > 0;) {
            const Level& rec = level_[d];
            std::fill(cur.begin(), cur.end(), Box::empty());
            auto child = [&](NodeId c) -> Box {
                if (!isSelect(c)) return cur[c];
                if (d + 1 > maxDepth) return Box::everything();  // the max_depth error
                if (d + 1 >= levels_) return summary_ ? sumBox_[c] : Box::empty();
                return out.depthBox[static_cast<size_t>(moduleOf(c)) * levels_ + d + 1];
            };
            for (auto i = topo_.rbegin(); i != topo_.rend(); ++i) {
                const NodeId n = *i;
                if (!rec.reached[n]) continue;
                cur[n] = apply(n, rec, child);
                node[n] = unite(node[n], cur[n]);
                if (isSelect(n))
                    out.depthBox[static_cast<size_t>(moduleOf(n)) * levels_ + d] = cur[n];
            }
        }
        if (summary_)
            for (NodeId n = 0; n < n_; ++n)
                if (sum_[n]) node[n] = unite(node[n], sumBox_[n]);
        out.node = std::move(node);
    }

    // Padding against rounding: relative to the box's size and position.
    static Box padded(const Box& b) { return paddedBox(b); }
};

}  // namespace

// b enlarged on every finite side by rel * (finite extent) + abs * max(|ends|, 1).
Box growUnboundedBox(const Box& b, double rel, double abs) {
    Box r = b;
    for (int i = 0; i < 3; ++i) {
        const double lo = b.lo[i], hi = b.hi[i];
        const double extent = std::isfinite(hi - lo) ? hi - lo : 0.0;
        double big = 1.0;
        if (std::isfinite(lo)) big = std::max(big, std::fabs(lo));
        if (std::isfinite(hi)) big = std::max(big, std::fabs(hi));
        const double m = rel * extent + abs * big;
        r.lo[i] = lo - m;  // infinite ends stay infinite
        r.hi[i] = hi + m;
    }
    return r;
}

Bounds computeBounds(const Graph& g, const BoundsOptions& options) {
    return Analysis(g, options).run();
}

}  // namespace pcsg::tracer
