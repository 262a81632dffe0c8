// The expander and the counting pass: two sinks (build the tree, or count it) of the
// shared walk over the graph (compiler/walk.h), which follows the one semantics of eval.h.
#include "expander.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <unordered_map>

#include "eval.h"
#include "walk.h"

namespace pcsg {

// ---------------------------------------------------------------------------------------
// Sizes.

namespace {

constexpr uint64_t kSat = UINT64_MAX;
constexpr uint64_t addSat(uint64_t a, uint64_t b) {
    return a > kSat - b ? kSat : a + b;
}
constexpr uint64_t mulSat(uint64_t a, uint64_t b) {
    return (a != 0 && b > kSat / a) ? kSat : a * b;
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
    b = addSat(b, mulSat(nodes > 0 ? nodes - 1 : 0,
                         sizeof(uint32_t)));  // every non-root node is one child
    b = addSat(b, mulSat(primitives, sizeof(TreePrimitive)));
    b = addSat(b, mulSat(args, sizeof(double)));
    return static_cast<size_t>(b);
}

BudgetError::BudgetError(std::string message, uint64_t limit_, std::optional<uint64_t> needed_)
    : std::runtime_error(std::move(message)), limit(limit_), needed(needed_) {}

namespace {

// ---------------------------------------------------------------------------------------
// The counting sink.

using Count = SubtreeCount;

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

    // With `known`, the counts found before are taken where they stand, and the count
    // stops (complete = false) as soon as the walk without them and without the memo
    // would have made more than maxVisits visits (see countExpansion).
    CountSink(const Graph& g, uint64_t maxVisits, const KnownCounts* known)
        : g_(g),
          maxVisits_(maxVisits),
          known_(known),
          deps_(moduleDependencies(g)),
          modules_(deps_.size()) {
        for (size_t m = 0; m < deps_.size(); ++m)
            modules_[m].memoisable = deps_[m].analysed && !deps_[m].usesPath;
    }

    Result nothing() const { return Count{}; }
    uint64_t visits() const { return visits_; }

    void visit() {
        if (++visits_ > maxVisits_) throw StopCounting{};
        addWhole(1);
    }

    bool lookup(NodeId n, uint32_t depth, const double* frame, uint64_t path, Count& out) {
        if (known_ && knownBelow(n, depth, frame, path, out)) return true;
        if (memoised(n, depth, frame, out)) return true;
        opened_.push_back(whole_);
        return false;
    }
    void store(NodeId n, uint32_t depth, const double* frame, uint64_t, const Count& c) {
        const uint64_t below = whole_ - opened_.back();
        opened_.pop_back();
        if (memo_.size() >= kMaxMemo || !makeKey(n, depth, frame)) return;
        memo_.emplace(key_, Memo{c, below});
    }

    Count primitive(PrimitiveKind kind, const Affine&, uint32_t, const double*, uint32_t argc) {
        return countPrimitive(kind, argc);
    }

    void beginOperator(WalkEntry&) {}

    Count endOperator(CsgOp op, const Count* r, uint32_t n, const WalkEntry&) {
        return countOperator(op, n, [&](uint32_t i) -> const Count& { return r[i]; });
    }

  private:
    // The visits of the walk without memo and known counts, which stops a count with
    // known counts at the work limit.
    void addWhole(uint64_t n) {
        whole_ = addSat(whole_, n);
        if (known_ && whole_ > maxVisits_) throw StopCounting{};
    }

    // An instance counted before (the instance-box fill): its count, without walking
    // below it.
    bool knownBelow(NodeId n, uint32_t depth, const double* frame, uint64_t path, Count& out) {
        KnownSubtree k;
        if (!known_->find(n, depth, frame, path, k)) return false;
        addWhole(k.visits);
        visits_ = addSat(visits_, k.visits);
        out = k.count;
        return true;
    }

    bool memoised(NodeId n, uint32_t depth, const double* frame, Count& out) {
        if (!makeKey(n, depth, frame)) return false;
        ModuleMemo& s = modules_[g_.nodes[n].payload];
        // A module whose parameter frames never repeat (a terrain's coordinates) is not
        // worth the hashing: stop memoising it when hardly anything was found.
        if (++s.lookups == 4096 && s.hits * 64 < s.lookups) s.memoisable = false;
        const auto it = memo_.find(key_);
        if (it == memo_.end()) return false;
        ++s.hits;
        out = it->second.count;
        addWhole(it->second.whole);
        return true;
    }

    bool makeKey(NodeId n, uint32_t depth, const double* frame) {
        const uint32_t m = g_.nodes[n].payload;
        if (!modules_[m].memoisable) return false;
        key_.clear();
        key_.push_back((static_cast<uint64_t>(n) << 32) | depth);
        for (Slot slot : deps_[m].reads) key_.push_back(std::bit_cast<uint64_t>(frame[slot]));
        return true;
    }

    const Graph& g_;
    uint64_t maxVisits_;
    const KnownCounts* known_;
    uint64_t visits_ = 0;
    uint64_t whole_ = 0;            // visits without memo and known counts
    std::vector<uint64_t> opened_;  // whole_ where each open S-node instance began
    // Memoised per (S-node, depth, the values of the slots its sub-graph reads); only
    // modules whose sub-graphs do not depend on the instance path.
    struct ModuleMemo {
        bool memoisable = false;
        uint64_t lookups = 0, hits = 0;
    };
    std::vector<ModuleDependencies> deps_;
    std::vector<ModuleMemo> modules_;
    std::vector<uint64_t> key_;
    struct Memo {
        Count count;
        uint64_t whole;  // the visits below without memo
    };
    std::unordered_map<std::vector<uint64_t>, Memo, KeyHash> memo_;
};

// ---------------------------------------------------------------------------------------
// The building sink.

struct OverBudget {};

class TreeSink {
  public:
    using Result = uint32_t;  // a node id, or kNone for nothing

    TreeSink(const Graph& g, ExpandedTree& t, uint64_t maxNodes)
        : g_(g), t_(t), maxNodes_(maxNodes) {}

    Result nothing() const { return kNone; }
    void visit() {}
    bool lookup(NodeId, uint32_t, const double*, uint64_t, Result&) { return false; }
    void store(NodeId, uint32_t, const double*, uint64_t, Result) {}

    Result primitive(PrimitiveKind kind, const Affine& world, uint32_t material, const double* args,
                     uint32_t argc) {
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
        t_.nodes.push_back({true, CsgOp::Union, static_cast<uint32_t>(t_.primitives.size()), 0});
        t_.primitives.push_back(p);
        return static_cast<uint32_t>(t_.nodes.size() - 1);
    }

    void beginOperator(WalkEntry& e) {
        e.mark[0] = t_.nodes.size();
        e.mark[1] = t_.children.size();
        e.mark[2] = t_.primitives.size();
        e.mark[3] = t_.args.size();
    }

    Result endOperator(CsgOp op, const uint32_t* r, uint32_t n, const WalkEntry& e) {
        if (csgHoldsNothing(op, n, [&](uint32_t i) { return r[i] == kNone; })) return discard(e);
        uint32_t kept = 0, last = kNone;
        for (uint32_t i = 0; i < n; ++i)
            if (r[i] != kNone) ++kept, last = r[i];
        if (kept == 1) return op == CsgOp::Difference ? r[0] : last;
        reserveNode();
        const uint32_t first = static_cast<uint32_t>(t_.children.size());
        for (uint32_t i = 0; i < n; ++i)
            if (r[i] != kNone) t_.children.push_back(r[i]);
        t_.nodes.push_back({false, op, first, kept});
        return static_cast<uint32_t>(t_.nodes.size() - 1);
    }

    // The innermost paint wins: a node that has a texture keeps it. A texture with a
    // pattern keeps the paint node's frame (`world`), where POV-Ray must evaluate it.
    void paint(uint32_t material, const Affine& world, uint32_t& r) {
        if (r == kNone || t_.nodes[r].texture != kNone) return;
        t_.nodes[r].texture = material;
        const Material& m = g_.materials[material];
        if (m.pigment.pattern.kind != PatternKind::Plain || m.normal.kind != NormalKind::None) {
            t_.nodes[r].textureFrame = static_cast<uint32_t>(t_.textureFrames.size());
            t_.textureFrames.push_back(world);
        }
    }

  private:
    void reserveNode() {
        if (t_.nodes.size() >= maxNodes_) throw OverBudget{};
    }
    // An operator that turned out empty: drop everything its operands built.
    Result discard(const WalkEntry& e) {
        t_.nodes.resize(e.mark[0]);
        t_.children.resize(e.mark[1]);
        t_.primitives.resize(e.mark[2]);
        t_.args.resize(e.mark[3]);
        return kNone;
    }

    const Graph& g_;
    ExpandedTree& t_;
    uint64_t maxNodes_;
};

std::string countText(uint64_t n) {
    return n == kSat ? std::string("more than 1.8e19") : fmt::format("{}", n);
}

}  // namespace

// ---------------------------------------------------------------------------------------

namespace {

ExpansionCount countWith(const Graph& g, uint64_t maxVisits, const KnownCounts* known) {
    CountSink sink(g, maxVisits, known);
    const Semantics sem(g);
    Walker<CountSink> walker(sem, sink);
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

}  // namespace

// With known counts, the count is what the count without them would be: the same
// figures (memo and known counts are exact) and the same first error (the parts they
// stand for hold none, and the walk's order is the same), provided the count without
// them completes too, which it does when the walk without memo stays within the limit
// (the memo only saves visits). Otherwise it is counted again without them.
ExpansionCount countExpansion(const Graph& g, const CountOptions& options) {
    if (options.known) {
        const ExpansionCount out = countWith(g, options.maxVisits, options.known);
        if (out.complete) return out;
    }
    return countWith(g, options.maxVisits, nullptr);
}

ExpandedTree expand(const Graph& g, const ExpandOptions& options) {
    // Node ids are 32-bit.
    const uint64_t maxNodes = std::min<uint64_t>(options.maxNodes, UINT32_MAX - 1);
    // The counting pass may work somewhat longer than the expansion would (so that an
    // expansion over budget can say exactly how large it would be): a few seconds at most.
    const uint64_t visits =
        options.countVisits
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
    TreeSink sink(g, tree, maxNodes);
    const Semantics sem(g);
    Walker<TreeSink> walker(sem, sink);
    try {
        tree.root = walker.run();
        if (tree.root != kNone && tree.nodes[tree.root].texture == kNone)
            tree.nodes[tree.root].texture = 0;
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
