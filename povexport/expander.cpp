// The expander and the counting pass: one explicit-stack walker over the graph that
// follows the one semantics of eval.h, with two sinks (build the tree, or count it).
#include "expander.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <unordered_map>

#include <fmt/format.h>

#include "eval.h"

namespace pcsg {

// ---------------------------------------------------------------------------------------
// Sizes.

namespace {

constexpr uint64_t kSat = UINT64_MAX;
constexpr uint64_t addSat(uint64_t a, uint64_t b) { return a > kSat - b ? kSat : a + b; }
constexpr uint64_t mulSat(uint64_t a, uint64_t b) {
    return (a != 0 && b > kSat / a) ? kSat : a * b;
}

// The argument values a primitive kind stores in the tree.
uint32_t storedArgs(PrimitiveKind k) {
    switch (k) {
        case PrimitiveKind::Torus: return 2;
        case PrimitiveKind::Triangle: return 9;
        default: return 0;
    }
}

}  // namespace

size_t ExpandedTree::bytes() const {
    return sizeof(ExpandedTree) + nodes.size() * sizeof(TreeNode) +
           children.size() * sizeof(uint32_t) + primitives.size() * sizeof(TreePrimitive) +
           args.size() * sizeof(double);
}

size_t ExpansionCount::treeBytes() const {
    uint64_t b = sizeof(ExpandedTree);
    b = addSat(b, mulSat(nodes, sizeof(TreeNode)));
    b = addSat(b, mulSat(nodes > 0 ? nodes - 1 : 0, sizeof(uint32_t)));  // every non-root node is one child
    b = addSat(b, mulSat(primitives, sizeof(TreePrimitive)));
    b = addSat(b, mulSat(args, sizeof(double)));
    return static_cast<size_t>(b);
}

BudgetError::BudgetError(std::string message, uint64_t limit_, std::optional<uint64_t> needed_)
    : std::runtime_error(std::move(message)), limit(limit_), needed(needed_) {}

// ---------------------------------------------------------------------------------------
// The walker.

namespace {

// One node being visited: the traversal state the one semantics carries down.
struct Entry {
    NodeId node;
    uint32_t depth;       // S-nodes passed on the path before this node
    uint32_t material;    // the innermost paint so far (0: default)
    uint32_t next;        // progress: operators: children begun; unary nodes: 1 once entered
    size_t frame;         // offset of the incoming parameter frame in the arena
    size_t resultBase;    // size of the result stack when an operator began
    uint64_t path;        // the instance path
    Affine world;         // maps this node's frame to world coordinates
    size_t mark[4];       // the sink's bookkeeping for operators
};

// Sink interface (static): Result; visit(); lookup()/store() for S-nodes; primitive();
// beginOperator(); endOperator().
template <class Sink>
class Walker {
public:
    using Result = typename Sink::Result;

    Walker(const Graph& g, Sink& sink)
        : g_(g), sink_(sink), frameSize_(std::max<size_t>(g.slotCount(), 1)) {}

    Result run() {
        if (g_.axiom == kNone || g_.axiom >= g_.nodes.size()) return sink_.nothing();
        arena_.assign(frameSize_, 0.0);
        initFrame(g_, arena_.data());
        Entry root{};
        root.node = g_.axiom;
        root.path = kRootPath;
        root.world = Affine::identity();
        stack_.push_back(root);
        try {
            while (!stack_.empty()) step();
        } catch (RuntimeError& e) {
            // The module path: every S-node on the stack, innermost first, so that
            // enterModule (which prepends) leaves the outermost first.
            for (auto it = stack_.rbegin(); it != stack_.rend(); ++it)
                if (g_.nodes[it->node].kind == NodeKind::Select)
                    e.enterModule(g_.modules[g_.nodes[it->node].payload].name);
            throw;
        }
        return results_.back();
    }

private:
    void pushChild(const Entry& parent, NodeId child) {
        Entry c = parent;
        c.node = child;
        c.next = 0;
        stack_.push_back(c);
    }

    void step() {
        Entry& e = stack_.back();
        const Node& node = g_.nodes[e.node];
        switch (node.kind) {
            case NodeKind::Select: {
                if (e.next == 0) {
                    sink_.visit();
                    const EvalState st{arena_.data() + e.frame, e.path};
                    Result memo;
                    if (sink_.lookup(e.node, e.depth, st.frame, memo)) {
                        results_.push_back(memo);
                        stack_.pop_back();
                        return;
                    }
                    const uint32_t depth = e.depth + 1;
                    checkDepth(g_, e.node, depth, st);
                    const uint32_t rule = selectRule(g_, e.node, st);
                    e.next = 1;
                    Entry c = e;
                    c.node = g_.child(e.node, rule);
                    c.next = 0;
                    c.depth = depth;
                    c.path = pathRule(e.path, rule);
                    stack_.push_back(c);
                } else {
                    sink_.store(e.node, e.depth, arena_.data() + e.frame, results_.back());
                    stack_.pop_back();
                }
                return;
            }
            case NodeKind::Calc: {
                if (e.next == 0) {
                    sink_.visit();
                    const size_t off = arena_.size();
                    arena_.resize(off + frameSize_);
                    Entry& cur = stack_.back();
                    applyCalc(g_, cur.node, {arena_.data() + cur.frame, cur.path},
                              arena_.data() + off);
                    cur.next = 1;
                    Entry c = cur;
                    c.node = g_.child(cur.node);
                    c.next = 0;
                    c.frame = off;
                    stack_.push_back(c);
                } else {
                    // Frames are released in stack order: the child's is the last one.
                    arena_.resize(arena_.size() - frameSize_);
                    stack_.pop_back();
                }
                return;
            }
            case NodeKind::Transform: {
                if (e.next == 0) {
                    sink_.visit();
                    const Affine m = transformMatrix(g_, e.node, {arena_.data() + e.frame, e.path});
                    e.next = 1;
                    Entry c = e;
                    c.node = g_.child(e.node);
                    c.next = 0;
                    c.world = e.world * m;
                    stack_.push_back(c);
                } else {
                    stack_.pop_back();
                }
                return;
            }
            case NodeKind::Paint: {
                if (e.next == 0) {
                    sink_.visit();
                    e.next = 1;
                    Entry c = e;
                    c.node = g_.child(e.node);
                    c.next = 0;
                    c.material = node.payload;
                    stack_.push_back(c);
                } else {
                    stack_.pop_back();
                }
                return;
            }
            case NodeKind::Union:
            case NodeKind::Intersection:
            case NodeKind::Difference: {
                if (e.next == 0) {
                    sink_.visit();
                    e.resultBase = results_.size();
                    sink_.beginOperator(e);
                }
                if (e.next < node.childCount) {
                    const uint32_t i = e.next++;
                    Entry c = e;
                    c.node = g_.child(e.node, i);
                    c.next = 0;
                    c.path = pathChild(e.path, i);
                    stack_.push_back(c);
                    return;
                }
                const TreeKind kind = node.kind == NodeKind::Union          ? TreeKind::Union
                                      : node.kind == NodeKind::Intersection ? TreeKind::Intersection
                                                                            : TreeKind::Difference;
                const size_t base = e.resultBase;
                const Result r = sink_.endOperator(kind, results_.data() + base,
                                                   static_cast<uint32_t>(results_.size() - base), e);
                results_.resize(base);
                results_.push_back(r);
                stack_.pop_back();
                return;
            }
            case NodeKind::Primitive: {
                sink_.visit();
                const Primitive& p = g_.primitives[node.payload];
                double args[9] = {};
                const uint32_t argc = storedArgs(p.kind);
                if (argc) primitiveArgs(g_, e.node, {arena_.data() + e.frame, e.path}, args);
                results_.push_back(sink_.primitive(p.kind, e.world, e.material, args, argc));
                stack_.pop_back();
                return;
            }
        }
    }

    const Graph& g_;
    Sink& sink_;
    const size_t frameSize_;
    std::vector<Entry> stack_;
    std::vector<double> arena_;
    std::vector<Result> results_;
};

// ---------------------------------------------------------------------------------------
// Which S-nodes may be memoised while counting, and on which parameters they depend.

struct SelectInfo {
    bool memoisable = false;
    std::vector<Slot> reads;  // the slots any expression below reads, ascending
    uint64_t lookups = 0, hits = 0;
};

void exprInfo(const Graph& g, ExprId id, bool& usesPath, std::vector<uint8_t>& readSet) {
    if (id == kNone || id >= g.exprs.size()) return;
    const Expr& e = g.exprs[id];
    if (e.usesPath) usesPath = true;
    for (uint32_t pc = e.begin; pc < e.end; ++pc) {
        const Instr& in = g.code[pc];
        if (in.op == Op::Load && in.a < readSet.size()) readSet[in.a] = 1;
        // Belt and braces: an expression that says it does not use the path but calls
        // rand() or choose() still does.
        if (in.op == Op::Rand0 || in.op == Op::Choose) usesPath = true;
    }
}

void nodeInfo(const Graph& g, NodeId n, bool& usesPath, std::vector<uint8_t>& readSet) {
    const Node& node = g.nodes[n];
    switch (node.kind) {
        case NodeKind::Select: {
            const Module& m = g.modules[node.payload];
            exprInfo(g, m.select, usesPath, readSet);
            for (ExprId c : m.conditions) exprInfo(g, c, usesPath, readSet);
            break;
        }
        case NodeKind::Calc: {
            const Calc& c = g.calcs[node.payload];
            for (uint32_t i = 0; i < c.count; ++i)
                exprInfo(g, g.assignments[c.first + i].value, usesPath, readSet);
            break;
        }
        case NodeKind::Transform: {
            const Transform& t = g.transforms[node.payload];
            if (!t.constant)
                for (uint32_t i = 0; i < t.argCount; ++i)
                    exprInfo(g, g.args[t.firstArg + i], usesPath, readSet);
            break;
        }
        case NodeKind::Primitive: {
            const Primitive& p = g.primitives[node.payload];
            if (!p.constant)
                for (uint32_t i = 0; i < p.argCount; ++i)
                    exprInfo(g, g.args[p.firstArg + i], usesPath, readSet);
            break;
        }
        default: break;
    }
}

// One depth-first search per module over everything reachable from its S-node. When
// that would be too much work (a huge graph with many modules), nothing is memoised:
// the count stays correct, only slower.
std::vector<SelectInfo> analyseSelects(const Graph& g) {
    std::vector<SelectInfo> info(g.modules.size());
    const uint64_t work = mulSat(g.modules.size(), g.nodes.size() + g.edges.size());
    if (work > 50'000'000) return info;
    std::vector<uint32_t> seen(g.nodes.size(), UINT32_MAX);
    std::vector<uint8_t> readSet(g.slotCount());
    std::vector<NodeId> todo;
    for (uint32_t m = 0; m < g.modules.size(); ++m) {
        const NodeId start = g.modules[m].node;
        if (start == kNone || start >= g.nodes.size()) continue;
        std::fill(readSet.begin(), readSet.end(), 0);
        bool usesPath = false;
        todo.assign(1, start);
        seen[start] = m;
        while (!todo.empty()) {
            const NodeId n = todo.back();
            todo.pop_back();
            nodeInfo(g, n, usesPath, readSet);
            const Node& node = g.nodes[n];
            for (uint32_t i = 0; i < node.childCount; ++i) {
                const NodeId c = g.child(n, i);
                if (c < g.nodes.size() && seen[c] != m) {
                    seen[c] = m;
                    todo.push_back(c);
                }
            }
        }
        info[m].memoisable = !usesPath;
        for (Slot s = 0; s < readSet.size(); ++s)
            if (readSet[s]) info[m].reads.push_back(s);
    }
    return info;
}

// ---------------------------------------------------------------------------------------
// The counting sink.

struct Count {
    uint64_t prims = 0, nodes = 0, args = 0;
    bool empty = true;
};

Count plus(Count a, const Count& b) {
    a.prims = addSat(a.prims, b.prims);
    a.nodes = addSat(a.nodes, b.nodes);
    a.args = addSat(a.args, b.args);
    return a;
}

struct StopCounting {};

struct KeyHash {
    // SplitMix64's finaliser per word: parameter values are often dyadic fractions whose
    // low bits are all zero, which a multiplicative hash alone would not spread.
    static uint64_t mix(uint64_t z) {
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }
    size_t operator()(const std::vector<uint64_t>& k) const {
        uint64_t h = 0x84222325cbf29ce4ULL;
        for (uint64_t v : k) h = mix(h ^ v);
        return static_cast<size_t>(h);
    }
};

class CountSink {
public:
    using Result = Count;
    static constexpr size_t kMaxMemo = 1 << 18;

    CountSink(const Graph& g, uint64_t maxVisits)
        : g_(g), maxVisits_(maxVisits), selects_(analyseSelects(g)) {}

    Result nothing() const { return Count{}; }
    uint64_t visits() const { return visits_; }

    void visit() {
        if (++visits_ > maxVisits_) throw StopCounting{};
    }

    bool lookup(NodeId n, uint32_t depth, const double* frame, Count& out) {
        if (!makeKey(n, depth, frame)) return false;
        SelectInfo& s = selects_[g_.nodes[n].payload];
        // A module whose parameter frames never repeat (a terrain's coordinates) is not
        // worth the hashing: stop memoising it when hardly anything was found.
        if (++s.lookups == 4096 && s.hits * 64 < s.lookups) s.memoisable = false;
        const auto it = memo_.find(key_);
        if (it == memo_.end()) return false;
        ++s.hits;
        out = it->second;
        return true;
    }
    void store(NodeId n, uint32_t depth, const double* frame, const Count& c) {
        if (memo_.size() >= kMaxMemo || !makeKey(n, depth, frame)) return;
        memo_.emplace(key_, c);
    }

    Count primitive(PrimitiveKind kind, const Affine&, uint32_t, const double*, uint32_t argc) {
        if (kind == PrimitiveKind::Empty) return Count{};
        return Count{1, 1, argc, false};
    }

    void beginOperator(Entry&) {}

    Count endOperator(TreeKind kind, const Count* r, uint32_t n, const Entry&) {
        Count sum;
        uint32_t kept = 0;
        if (kind == TreeKind::Intersection) {
            for (uint32_t i = 0; i < n; ++i)
                if (r[i].empty) return Count{};
        }
        if (kind == TreeKind::Difference && (n == 0 || r[0].empty)) return Count{};
        for (uint32_t i = 0; i < n; ++i) {
            if (r[i].empty) continue;
            sum = plus(sum, r[i]);
            ++kept;
        }
        if (kept == 0) return Count{};
        sum.empty = false;
        if (kept >= 2) sum.nodes = addSat(sum.nodes, 1);
        return sum;
    }

private:
    bool makeKey(NodeId n, uint32_t depth, const double* frame) {
        const SelectInfo& s = selects_[g_.nodes[n].payload];
        if (!s.memoisable) return false;
        key_.clear();
        key_.push_back((static_cast<uint64_t>(n) << 32) | depth);
        for (Slot slot : s.reads) key_.push_back(std::bit_cast<uint64_t>(frame[slot]));
        return true;
    }

    const Graph& g_;
    uint64_t maxVisits_;
    uint64_t visits_ = 0;
    std::vector<SelectInfo> selects_;
    std::vector<uint64_t> key_;
    std::unordered_map<std::vector<uint64_t>, Count, KeyHash> memo_;
};

// ---------------------------------------------------------------------------------------
// The building sink.

struct OverBudget {};

class TreeSink {
public:
    using Result = uint32_t;  // a node id, or kNone for nothing

    TreeSink(ExpandedTree& t, uint64_t maxNodes) : t_(t), maxNodes_(maxNodes) {}

    Result nothing() const { return kNone; }
    void visit() {}
    bool lookup(NodeId, uint32_t, const double*, Result&) { return false; }
    void store(NodeId, uint32_t, const double*, Result) {}

    Result primitive(PrimitiveKind kind, const Affine& world, uint32_t material,
                     const double* args, uint32_t argc) {
        if (kind == PrimitiveKind::Empty) return kNone;
        reserveNode();
        TreePrimitive p;
        p.toWorld = world;
        p.material = material;
        p.kind = kind;
        if (argc) {
            p.firstArg = static_cast<uint32_t>(t_.args.size());
            t_.args.insert(t_.args.end(), args, args + argc);
        }
        t_.nodes.push_back({TreeKind::Primitive, static_cast<uint32_t>(t_.primitives.size()), 0});
        t_.primitives.push_back(p);
        return static_cast<uint32_t>(t_.nodes.size() - 1);
    }

    void beginOperator(Entry& e) {
        e.mark[0] = t_.nodes.size();
        e.mark[1] = t_.children.size();
        e.mark[2] = t_.primitives.size();
        e.mark[3] = t_.args.size();
    }

    Result endOperator(TreeKind kind, const uint32_t* r, uint32_t n, const Entry& e) {
        if (kind == TreeKind::Intersection) {
            for (uint32_t i = 0; i < n; ++i)
                if (r[i] == kNone) return discard(e);
        }
        if (kind == TreeKind::Difference && (n == 0 || r[0] == kNone)) return discard(e);
        uint32_t kept = 0, last = kNone;
        for (uint32_t i = 0; i < n; ++i)
            if (r[i] != kNone) ++kept, last = r[i];
        if (kept == 0) return kNone;
        if (kept == 1) return kind == TreeKind::Difference ? r[0] : last;
        reserveNode();
        const uint32_t first = static_cast<uint32_t>(t_.children.size());
        for (uint32_t i = 0; i < n; ++i)
            if (r[i] != kNone) t_.children.push_back(r[i]);
        t_.nodes.push_back({kind, first, kept});
        return static_cast<uint32_t>(t_.nodes.size() - 1);
    }

private:
    void reserveNode() {
        if (t_.nodes.size() >= maxNodes_) throw OverBudget{};
    }
    // An operator that turned out empty: drop everything its operands built.
    Result discard(const Entry& e) {
        t_.nodes.resize(e.mark[0]);
        t_.children.resize(e.mark[1]);
        t_.primitives.resize(e.mark[2]);
        t_.args.resize(e.mark[3]);
        return kNone;
    }

    ExpandedTree& t_;
    uint64_t maxNodes_;
};

std::string countText(uint64_t n) {
    return n == kSat ? std::string("more than 1.8e19") : fmt::format("{}", n);
}

}  // namespace

// ---------------------------------------------------------------------------------------

ExpansionCount countExpansion(const Graph& g, const CountOptions& options) {
    CountSink sink(g, options.maxVisits);
    Walker<CountSink> walker(g, sink);
    ExpansionCount out;
    try {
        const Count c = walker.run();
        out.primitives = c.prims;
        out.nodes = c.nodes;
        out.args = c.args;
        out.complete = true;
    } catch (const StopCounting&) {
        out.complete = false;
    }
    out.visits = sink.visits();
    return out;
}

ExpandedTree expand(const Graph& g, const ExpandOptions& options) {
    // Node ids are 32-bit.
    const uint64_t maxNodes = std::min<uint64_t>(options.maxNodes, UINT32_MAX - 1);
    // The counting pass may work somewhat longer than the expansion would (so that an
    // expansion over budget can say exactly how large it would be): a few seconds at most.
    const uint64_t visits = options.countVisits
                                ? options.countVisits
                                : std::max<uint64_t>(addSat(mulSat(maxNodes, 16), 1'000'000), 100'000'000);

    // First count (cheap where memoisable): an expansion over budget fails before it
    // allocates anything, with the exact figure, and one within budget gets its arrays
    // sized exactly.
    const ExpansionCount count = countExpansion(g, {visits});
    if (count.complete && count.nodes > maxNodes)
        throw BudgetError(
            fmt::format("the expanded tree would need {} nodes ({} primitives), more than the "
                        "node budget of {} (raise it with --max-nodes, or lower the scene's "
                        "recursion depth)",
                        countText(count.nodes), countText(count.primitives), maxNodes),
            maxNodes, count.nodes == kSat ? std::nullopt : std::optional<uint64_t>(count.nodes));

    ExpandedTree tree;
    if (count.complete) {
        tree.nodes.reserve(count.nodes);
        tree.children.reserve(count.nodes > 0 ? count.nodes - 1 : 0);
        tree.primitives.reserve(count.primitives);
        tree.args.reserve(count.args);
    }
    TreeSink sink(tree, maxNodes);
    Walker<TreeSink> walker(g, sink);
    try {
        tree.root = walker.run();
    } catch (const OverBudget&) {
        if (count.complete)
            throw BudgetError(
                fmt::format("the expansion needs more than the node budget of {} while building "
                            "operands that an intersection or difference then discards as empty "
                            "(the finished tree would have {} nodes); raise --max-nodes",
                            maxNodes, count.nodes),
                maxNodes, std::nullopt);
        throw BudgetError(
            fmt::format("the expanded tree needs more than the node budget of {} nodes (counting "
                        "gave up after {} graph visits, so the exact need is unknown); raise it "
                        "with --max-nodes, or lower the scene's recursion depth",
                        maxNodes, count.visits),
            maxNodes, std::nullopt);
    }
    return tree;
}

}  // namespace pcsg
