// The one walk that unrolls the cyclic graph: an explicit-stack traversal of every path
// from a start node, each step the one step of semantics.h (selection, C-nodes, T-node
// matrices, paint, instance paths and rand()). What it produces is up to a sink:
//
//  - povexport/expander.cpp: the expanded CSG tree, and the counting pass that sizes it;
//  - tracer/instance_boxes.cpp: the exact bounding box of one S-node instance.
//
// Paint frames (PathState::paint) stay 0 here: the exporter writes a texture where its
// paint node is, so POV-Ray evaluates a pattern in that node's frame itself.
//
// No recursion on the C++ stack, whatever the graph's depth: max_depth bounds the
// S-node depth, and between two S-nodes a path is acyclic, so the walk's own stack is
// bounded by (max_depth + 1) * nodes.
//
// Sink interface (static):
//   using Result;                        // what a sub-walk yields
//   Result nothing();                    // the result of an empty walk
//   void visit();                        // called once per node visit (work limits)
//   bool lookup(NodeId, uint32_t depth, const double* frame, uint64_t path, Result&);
//   void store(NodeId, uint32_t depth, const double* frame, uint64_t path, const Result&);
//                                        // memoisation of S-node instances
//   Result primitive(PrimitiveKind, const Affine& world, uint32_t material,
//                    const double* args, uint32_t argc);
//   void beginOperator(WalkEntry&);
//   Result endOperator(CsgOp, const Result* operands, uint32_t n, const WalkEntry&);
// and optionally, to see every S-node instance in its own frame:
//   static constexpr bool kLocalSelectFrames = true;
//   Result toParent(const Affine& selectToParent, const Result& local);
// and optionally, to see where paint nodes stand (the exporter's textures on unions):
//   void paint(uint32_t material, const Affine& world, Result& r);
//                         // r: the result of the paint's operand; world: the paint's frame
// With kLocalSelectFrames the walk restarts `world` at the identity below each S-node,
// lookup/store see results in the S-node's own frame, and toParent maps them into the
// frame of the node that reached the S-node.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>
#include <type_traits>
#include <vector>

#include "eval.h"
#include "graph.h"
#include "semantics.h"

namespace pcsg {

// One node being visited: the traversal state the one semantics carries down.
struct WalkEntry {
    NodeId node;
    uint32_t depth;     // S-nodes passed on the path before this node
    uint32_t material;  // the innermost paint so far (0: default)
    uint32_t next;      // progress: operators: children begun; unary nodes: 1 once entered
    size_t frame;       // offset of the incoming parameter frame in the arena
    size_t resultBase;  // size of the result stack when an operator began
    uint64_t path;      // the instance path
    Affine world;       // maps this node's frame to the start node's frame
    bool identity;      // world is Affine::identity() as the walk set it (no T-step since)
    size_t mark[4];     // the sink's bookkeeping for operators
};

// Where a walk starts: the axiom with an empty frame, or any node with a given state.
struct WalkStart {
    NodeId node = kNone;
    const double* frame = nullptr;  // g.slotCount() values; nullptr: every slot unassigned
    uint64_t path = kRootPath;
    uint32_t depth = 0;
    uint32_t material = 0;
};

template <class Sink>
class Walker {
  public:
    using Result = typename Sink::Result;

    Walker(const Semantics& sem, Sink& sink)
        : g_(sem.graph()),
          sem_(sem),
          sink_(sink),
          frameSize_(std::max<size_t>(sem.graph().slotCount(), 1)) {}

    // Walks everything below the axiom.
    Result run() {
        WalkStart s;
        s.node = g_.axiom;
        return run(s);
    }

    // Walks everything below `start`. A RuntimeError gets the module path of the S-nodes
    // on the walk's stack (the start node included when `annotateStart`).
    Result run(const WalkStart& start, bool annotateStart = true) {
        stack_.clear();
        results_.clear();
        if (start.node == kNone || start.node >= g_.nodes.size()) return sink_.nothing();
        if (arena_.size() < frameSize_) arena_.resize(frameSize_);
        arenaTop_ = frameSize_;
        std::fill_n(arena_.begin(), frameSize_, 0.0);
        if (start.frame)
            std::copy(start.frame, start.frame + g_.slotCount(), arena_.begin());
        else
            initFrame(g_, arena_.data());
        stack_.emplace_back();
        WalkEntry& root = stack_.back().get();
        root = WalkEntry{};
        root.node = start.node;
        root.depth = start.depth;
        root.material = start.material;
        root.path = start.path;
        root.world = Affine::identity();
        root.identity = true;
        try {
            while (!stack_.empty()) step();
        } catch (RuntimeError& e) {
            // Every S-node on the stack, innermost first, so that enterModule (which
            // prepends) leaves the outermost first.
            for (size_t i = stack_.size(); i-- > (annotateStart ? 0 : 1);)
                if (g_.nodes[stack_[i].get().node].kind == NodeKind::Select)
                    e.enterModule(g_.modules[g_.nodes[stack_[i].get().node].payload].name);
            throw;
        }
        return results_.back();
    }

  private:
    static constexpr bool localSelectFrames() {
        if constexpr (requires { Sink::kLocalSelectFrames; })
            return Sink::kLocalSelectFrames;
        else
            return false;
    }

    PathState stateOf(const WalkEntry& e) const {
        return PathState{arena_.data() + e.frame, e.path, e.depth, e.material};
    }

    // The result of an S-node instance (in its own frame when localSelectFrames) as the
    // node above it sees it.
    Result fromSelect(const WalkEntry& e, const Result& r) {
        if constexpr (localSelectFrames())
            return sink_.toParent(e.world, r);
        else
            return r;
    }

    void step() {
        WalkEntry& e = stack_.back().get();
        switch (g_.nodes[e.node].kind) {
            case NodeKind::Operator:
                return stepOperator(e);
            case NodeKind::Primitive:
                return stepPrimitive(e);
            default:
                return e.next == 0 ? enterUnary(e) : leaveUnary(e);
        }
    }

    // An S-node instance the sink has memoised: its result, without walking below.
    bool memoised(const WalkEntry& e) {
        Result memo;
        if (!sink_.lookup(e.node, e.depth, arena_.data() + e.frame, e.path, memo)) return false;
        Result r = fromSelect(e, memo);
        stack_.pop_back();
        results_.push_back(r);
        return true;
    }

    // S, C, T and paint nodes on the way down: the one step of semantics.h.
    void enterUnary(WalkEntry& e) {
        // Every graph node the step passes counts (a sink's work limits and weights).
        for (uint32_t k = sem_.nodesInStep(e.node); k-- > 0;) sink_.visit();
        const NodeKind kind = g_.nodes[e.node].kind;
        if (kind == NodeKind::Select && memoised(e)) return;
        StepScratch scratch;
        scratch.forwardOnly = true;  // (world matrices only: no T-node's inverse is read)
        size_t frame = e.frame;
        if (kind == NodeKind::Calc) {
            frame = pushFrame();
            scratch.frame = arena_.data() + frame;
        }
        const Step st = sem_.enter(e.node, stateOf(e), scratch);
        e.next = 1;
        const NodeId n = e.node;
        // The child's entry is written field by field, its world once (not a copy of e's
        // 168 bytes whose world a T- or S-step then overwrites).
        const size_t parent = stack_.size() - 1;
        stack_.emplace_back();  // (unwritten; e may move: only stack_[parent] is read below)
        const WalkEntry& p = stack_[parent].get();
        WalkEntry& c = stack_.back().get();
        c.node = st.child;
        c.depth = st.state.depth;
        c.material = st.state.material;
        c.next = 0;
        c.frame = frame;
        c.resultBase = p.resultBase;
        c.path = st.state.path;
        // (one by one: std::copy_n made a call to memmove of 32 bytes)
        c.mark[0] = p.mark[0], c.mark[1] = p.mark[1], c.mark[2] = p.mark[2], c.mark[3] = p.mark[3];
        childWorld(p, c, kind, n, st);
    }

    // The world of c, entered from p by the step st of the unary node n.
    void childWorld(const WalkEntry& p, WalkEntry& c, NodeKind kind, NodeId n, const Step& st) {
        if (kind == NodeKind::Select && localSelectFrames()) {
            c.world = Affine::identity();
            c.identity = true;
        } else if (!st.forward) {
            c.world = p.world;
            c.identity = p.identity;
        } else if (!p.identity) {
            c.world = sem_.forwardThrough(p.world, n, st);
            c.identity = false;
        } else {
            // (from the identity: the step's own matrix where that is exact, else the
            // product, written into c.world itself)
            const Affine& w = sem_.fromIdentity(n, st, c.world);
            if (&w != &c.world) c.world = w;
            c.identity = false;
        }
    }

    // A C-node's new frame on the arena (not cleared: the C-step writes all of it); its offset.
    size_t pushFrame() {
        const size_t frame = arenaTop_;
        arenaTop_ += frameSize_;
        if (arenaTop_ > arena_.size()) arena_.resize(std::max(arenaTop_, 2 * arena_.size()));
        return frame;
    }

    // ... and on the way back up.
    void leaveUnary(WalkEntry& e) {
        const NodeKind kind = g_.nodes[e.node].kind;
        if (kind == NodeKind::Select) {
            sink_.store(e.node, e.depth, arena_.data() + e.frame, e.path, results_.back());
            results_.back() = fromSelect(e, results_.back());
        }
        if constexpr (requires(Sink & s, Result & r) { s.paint(uint32_t{}, e.world, r); }) {
            if (kind == NodeKind::Paint)
                sink_.paint(g_.nodes[e.node].payload, e.world, results_.back());
        }
        // Frames are released in stack order: the C-node's child's is the last one.
        if (kind == NodeKind::Calc) arenaTop_ -= frameSize_;
        stack_.pop_back();
    }

    void stepOperator(WalkEntry& e) {
        const Node& node = g_.nodes[e.node];
        if (e.next == 0) {
            sink_.visit();
            e.resultBase = results_.size();
            sink_.beginOperator(e);
        }
        if (e.next < node.childCount) {
            const uint32_t i = e.next++;
            const NodeId child = g_.child(e.node, i);
            const uint64_t path = Semantics::operand(stateOf(e), i).path;
            stack_.emplace_back(e);  // (a copy made in place: e may move)
            WalkEntry& c = stack_.back().get();
            c.node = child;
            c.next = 0;
            c.path = path;
            return;
        }
        const size_t base = e.resultBase;
        const Result r = sink_.endOperator(node.op(), results_.data() + base,
                                           static_cast<uint32_t>(results_.size() - base), e);
        results_.resize(base);
        results_.push_back(r);
        stack_.pop_back();
    }

    void stepPrimitive(WalkEntry& e) {
        sink_.visit();
        double args[9] = {};
        const uint32_t argc = sem_.primitiveArgs(e.node, stateOf(e), args);
        const PrimitiveKind kind = g_.primitives[g_.nodes[e.node].payload].kind;
        results_.push_back(sink_.primitive(kind, e.world, e.material, args, argc));
        stack_.pop_back();
    }

    const Graph& g_;
    const Semantics& sem_;
    Sink& sink_;
    const size_t frameSize_;
    // The stack's element: room for an entry that a new element leaves unwritten
    // (enterUnary writes every field; a WalkEntry made by its constructor would get its
    // world set to the identity first). WalkEntry, an aggregate, is an implicit-lifetime
    // type: the bytes' array begun by the placement new holds it (as StepScratch's room).
    class StackEntry {
      public:
        StackEntry() { new (room_) std::byte[sizeof(WalkEntry)]; }
        explicit StackEntry(const WalkEntry& w) { std::memcpy(room_, &w, sizeof(WalkEntry)); }
        WalkEntry& get() { return *std::launder(reinterpret_cast<WalkEntry*>(room_)); }

      private:
        static_assert(std::is_aggregate_v<WalkEntry> && std::is_trivially_copyable_v<WalkEntry>);
        alignas(WalkEntry) std::byte room_[sizeof(WalkEntry)];
    };
    std::vector<StackEntry> stack_;
    std::vector<double> arena_;  // the frames: [0, arenaTop_) in use
    size_t arenaTop_ = 0;
    std::vector<Result> results_;
};

// What the sub-graph below each module's S-node depends on: the parameter slots that
// any expression reachable from it reads, and whether it calls rand() or choose() (then
// its instances depend on the instance path too). Memoising S-node instances by these
// is exact: two instances of a module with the same values in `reads` (and, when
// `usesPath`, the same path) unroll to the same sub-tree.
struct ModuleDependencies {
    bool analysed = false;  // false: the graph was too large to analyse (memoise nothing)
    bool usesPath = false;
    // Reads `clock` or `frame` (Graph::time): its instances differ from frame to frame of a
    // sequence even with the same values in `reads`.
    bool usesTime = false;
    std::vector<Slot> reads;  // ascending
};

// One entry per module (Graph::modules).
std::vector<ModuleDependencies> moduleDependencies(const Graph& g);

}  // namespace pcsg
