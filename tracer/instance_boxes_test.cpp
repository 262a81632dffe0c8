// The exact boxes of S-node instances (instance_boxes.h): every primitive of an instance
// lies inside the instance's box, whatever the cache held; culling with them never
// changes a hit; the table stays within its byte limit.
#include "instance_boxes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <random>

#include "expander.h"
#include "key_slots.h"
#include "outward_float.h"
#include "primitives.h"
#include "test_support.h"
#include "traversal.h"

namespace pcsg::tracer {
namespace {

using testing::compile;
using testing::expectSameBoxes;

// Systems whose instances differ a lot: parameter-dependent rotations and scales, CSG,
// random heights (rand(x) and rand()), choose().
const char* kTree = R"(
{n = 7; a = 30} T
T if(n > 0, 2, 1)
1: T -> scale(0.1, 0.1, 1) cylinder
2: T -> scale(0.1, 0.1, 1) cylinder ∪
        {n = n-1; a = a + 7} move(0,0,1) rotz(137) (rotx(a) uscale(0.7) T ∪ roty(-a) uscale(0.6) T)
)";

const char* kTerrain = R"(
{ cnt = 5; delta = 0.5; x1 = 0; y1 = 0; z1 = 0; z2 = 0.1; z3 = -0.1 } T
T if(cnt > 0, 2, 1)
1: T -> move(0,0,z1) zshear(z2-z1, z3-z1) tri1
2: T -> {cnt = cnt-1; z2 = (z1+z2)/2 + (rand(x1*7+y1*3) - 0.5)*delta; delta = delta*0.5}
          scale(0.5,0.5,1) T ∪
        {cnt = cnt-1; x1 = x1 + 0.5; z3 = (z1+z3)/2 + (rand(x1*5+y1*11) - 0.5)*delta; delta = delta*0.5}
          move(0.5,0,0) scale(0.5,0.5,1) T ∪
        {cnt = cnt-1; y1 = y1 + 0.5; z1 = z1 + rand()*delta; delta = delta*0.5}
          move(0,0.5,0) scale(0.5,0.5,1) T
)";

const char* kCsgPlant = R"(
settings { seed 5 }
{n = 5} P
P if(n > 0, choose(0.6, 0.4) + 1, 1)
1: P -> (sphere \ move(0.6,0,0) sphere) ∩ uscale(0.9) cube
2: P -> cylinder ∪ {n = n-1} move(0,0,1) rotz(rand()*360) roty(25) uscale(0.8) P
3: P -> torus(1, 0.2) ∪ {n = n-1} move(0,0,0.5) rotx(40) uscale(0.7) P ∪
        {n = n-1} move(0,0,0.5) rotx(-40) uscale(0.6) P
)";

// Walks the expansion (recursively: small systems only) and, at every S-node instance,
// asks `boxes` for its exact box; every primitive must lie inside the boxes of all the
// S-node instances above it (each in its own frame). Returns the number of checks.
class SoundnessWalk {
  public:
    SoundnessWalk(const Graph& g, const InstanceBoxes& boxes)
        : g_(g), boxes_(boxes), worker_(boxes.makeWorker()) {}

    size_t run() {
        std::vector<double> frame(g_.slotCount());
        initFrame(g_, frame.data());
        walk(g_.axiom, frame, kRootPath, 0, Affine::identity(), 0);
        return checks_;
    }

  private:
    struct Open {
        Box box;
        Affine toWorld;  // the S-node's frame to the world
    };

    // `checkFrom`: the S-node instances open_[checkFrom..] must hold the primitives below;
    // the ones above an intersection or difference need only hold what it keeps, so a
    // primitive below may stick out of them.
    void walk(NodeId n, const std::vector<double>& frame, uint64_t path, uint32_t depth,
              const Affine& world, size_t checkFrom) {
        const Node& node = g_.nodes[n];
        const EvalState st{frame.data(), path};
        switch (node.kind) {
            case NodeKind::Select: {
                ++depth;
                open_.push_back({boxes_.box(*worker_, n, depth, frame.data(), path), world});
                const uint32_t r = selectRule(g_, n, st);
                walk(g_.child(n, r), frame, pathRule(path, r), depth, world, checkFrom);
                open_.pop_back();
                break;
            }
            case NodeKind::Calc: {
                std::vector<double> next(g_.slotCount());
                applyCalc(g_, n, st, next.data());
                walk(g_.child(n), next, path, depth, world, checkFrom);
                break;
            }
            case NodeKind::Transform:
                walk(g_.child(n), frame, path, depth, world * transformMatrix(g_, n, st),
                     checkFrom);
                break;
            case NodeKind::Paint:
                walk(g_.child(n), frame, path, depth, world, checkFrom);
                break;
            case NodeKind::Operator:
                for (uint32_t i = 0; i < node.childCount; ++i)
                    walk(g_.child(n, i), frame, pathChild(path, i), depth, world,
                         node.is(CsgOp::Union) ? checkFrom : open_.size());
                break;
            case NodeKind::Primitive: {
                const Primitive& p = g_.primitives[node.payload];
                if (p.kind == PrimitiveKind::Empty) break;
                double args[9] = {};
                if (primitiveArgCount(p.kind)) primitiveArgs(g_, n, st, args);
                Vec3 corners[3];
                const bool triangle = isTriangle(p.kind);
                if (triangle) triangleCorners(p.kind, args, corners);
                const Box own = primitiveBox(p.kind, args);
                for (size_t k = checkFrom; k < open_.size(); ++k) {
                    const Open& o = open_[k];
                    const Affine toS = o.toWorld.inverse() * world;
                    auto check = [&](const Vec3& c) {
                        if (!isFinite(c)) return;
                        const Vec3 q = toS.point(c);
                        ++checks_;
                        EXPECT_TRUE(o.box.contains(q))
                            << "a primitive at (" << q.x << ", " << q.y << ", " << q.z
                            << ") outside its instance's box";
                    };
                    if (triangle) {
                        for (const Vec3& c : corners) check(c);
                    } else {
                        for (int k = 0; k < 8; ++k)
                            check(Vec3{k & 1 ? own.hi.x : own.lo.x, k & 2 ? own.hi.y : own.lo.y,
                                       k & 4 ? own.hi.z : own.lo.z});
                    }
                }
                break;
            }
        }
    }

    const Graph& g_;
    const InstanceBoxes& boxes_;
    InstanceBoxes::WorkerPtr worker_;
    std::vector<Open> open_;
    size_t checks_ = 0;
};

// Exact boxes at every depth, whatever the trial would decide.
InstanceBoxOptions always() {
    InstanceBoxOptions o;
    o.trial = UINT32_MAX;
    o.minWeight = 1;
    return o;
}

// As always(), but nothing is ever stored: every box is computed on its own.
InstanceBoxOptions storingNothing() {
    InstanceBoxOptions o = always();
    o.maxBytes = 0;
    return o;
}

TEST(InstanceBoxes, EveryPrimitiveLiesInsideTheBoxOfEachInstanceAboveIt) {
    for (const char* text : {testing::kSierpinski, kTree, kTerrain, kCsgPlant}) {
        auto c = compile(text);
        ASSERT_TRUE(c->graph);
        const Bounds bounds = computeBounds(*c->graph);
        const InstanceBoxes boxes(*c->graph, bounds, always());
        EXPECT_GT(SoundnessWalk(*c->graph, boxes).run(), 100u);
        EXPECT_GT(boxes.stats().entries, 0u);
    }
}

TEST(InstanceBoxes, TheBoxDoesNotDependOnWhatTheCacheHeld) {
    for (const char* text : {kTree, kTerrain, kCsgPlant}) {
        auto c = compile(text);
        ASSERT_TRUE(c->graph);
        const Graph& g = *c->graph;
        const Bounds bounds = computeBounds(g);
        const InstanceBoxes cold(g, bounds, storingNothing()), warm(g, bounds, always());
        auto coldWorker = cold.makeWorker(), warmWorker = warm.makeWorker();
        // The axiom's S-node instance, after its inner instances are in the warm cache.
        std::vector<double> frame(g.slotCount());
        initFrame(g, frame.data());
        const NodeId calc = g.axiom, s = g.child(calc);
        ASSERT_EQ(g.nodes[calc].kind, NodeKind::Calc);
        ASSERT_EQ(g.nodes[s].kind, NodeKind::Select);
        std::vector<double> f(g.slotCount());
        applyCalc(g, calc, EvalState{frame.data(), kRootPath}, f.data());
        const Box first = warm.box(*warmWorker, s, 1, f.data(), kRootPath);
        const Box again = warm.box(*warmWorker, s, 1, f.data(), kRootPath);
        const Box computed = cold.box(*coldWorker, s, 1, f.data(), kRootPath);
        EXPECT_EQ(first, again);
        EXPECT_EQ(first, computed);
        EXPECT_EQ(cold.stats().entries, 0u);
        EXPECT_GT(warm.stats().entries, 0u);
        EXPECT_TRUE(first.isBounded());
    }
}

// The box of an instance whose rule is move() zshear() of a primitive without arguments
// is the rule's: the primitive's own box (primitiveBox) mapped by the product of the two
// matrices, rounded outwards to floats, mapped by the instance's identity and padded, bit
// for bit, for every such kind (the walk's sink keeps their own boxes in a table).
TEST(InstanceBoxes, ABoxOfAPrimitiveWithoutArgumentsIsTheRulesBitForBit) {
    size_t kinds = 0;
    for (const PrimitiveInfo& p : kPrimitiveTable) {
        if (p.args != 0 || p.kind == PrimitiveKind::Empty) continue;
        ++kinds;
        const std::string text = std::string("{z = 0.25; a = 0.5; b = -0.75} P\nP 1\n") +
                                 "1: P -> move(0.5, 0, z) zshear(a, b) " + p.name + "\n";
        auto c = compile(text.c_str());
        ASSERT_TRUE(c->graph) << p.name;
        const Graph& g = *c->graph;
        const Bounds bounds = computeBounds(g);
        const InstanceBoxes boxes(g, bounds, always());
        auto worker = boxes.makeWorker();
        std::vector<double> frame(g.slotCount()), f(g.slotCount());
        initFrame(g, frame.data());
        const NodeId calc = g.axiom, s = g.child(calc);
        ASSERT_EQ(g.nodes[s].kind, NodeKind::Select) << p.name;
        applyCalc(g, calc, EvalState{frame.data(), kRootPath}, f.data());
        const double moved[] = {0.5, 0, 0.25}, sheared[] = {0.5, -0.75};
        const Affine world =
            makeTransform(TransformOp::Move, moved) * makeTransform(TransformOp::ZShear, sheared);
        const Box local = transformBox(world, primitiveBox(p.kind, nullptr));
        Box rounded;
        for (int j = 0; j < 3; ++j)
            rounded.lo[j] = castDown(local.lo[j]), rounded.hi[j] = castUp(local.hi[j]);
        const Box want = paddedBox(transformBox(Affine::identity(), rounded));
        const Box got = boxes.box(*worker, s, 1, f.data(), kRootPath);
        for (int j = 0; j < 3; ++j) {
            EXPECT_EQ(std::bit_cast<uint64_t>(got.lo[j]), std::bit_cast<uint64_t>(want.lo[j]))
                << p.name << " axis " << j;
            EXPECT_EQ(std::bit_cast<uint64_t>(got.hi[j]), std::bit_cast<uint64_t>(want.hi[j]))
                << p.name << " axis " << j;
        }
    }
    EXPECT_EQ(kinds, 8u);
}

// Every S-node instance of a small system (node, depth, frame, path), by a recursive walk.
struct SelectInstance {
    NodeId node;
    uint32_t depth;
    std::vector<double> frame;
    uint64_t path;
};

void collectInstances(const Graph& g, NodeId n, uint32_t depth, const std::vector<double>& frame,
                      uint64_t path, std::vector<SelectInstance>& out) {
    const Node& node = g.nodes[n];
    if (node.kind == NodeKind::Select) {
        out.push_back({n, depth + 1, frame, path});
        const uint32_t r = selectRule(g, n, EvalState{frame.data(), path});
        collectInstances(g, g.child(n, r), depth + 1, frame, pathRule(path, r), out);
    } else if (node.kind == NodeKind::Calc) {
        std::vector<double> next(g.slotCount());
        applyCalc(g, n, EvalState{frame.data(), path}, next.data());
        collectInstances(g, g.child(n), depth, next, path, out);
    } else if (node.kind == NodeKind::Operator) {
        for (uint32_t i = 0; i < node.childCount; ++i)
            collectInstances(g, g.child(n, i), depth, frame, pathChild(path, i), out);
    } else if (node.kind != NodeKind::Primitive) {
        collectInstances(g, g.child(n), depth, frame, path, out);
    }
}

// A worker recalls the boxes it computed last (by key, in a small direct-mapped table):
// asked again in any order, it gives what a fresh worker of a fresh cache computes.
TEST(InstanceBoxes, AWorkersRecalledBoxesAreTheComputedOnes) {
    for (const char* text : {kTree, kTerrain}) {
        auto c = compile(text);
        ASSERT_TRUE(c->graph);
        const Graph& g = *c->graph;
        const Bounds bounds = computeBounds(g);
        std::vector<double> frame(g.slotCount());
        initFrame(g, frame.data());
        std::vector<SelectInstance> all;
        collectInstances(g, g.axiom, 0, frame, kRootPath, all);
        ASSERT_GT(all.size(), 200u);  // enough that keys share the worker's slots
        const InstanceBoxes boxes(g, bounds, always());
        auto w = boxes.makeWorker();
        std::mt19937 rng(11);
        for (int round = 0; round < 3; ++round) {
            std::shuffle(all.begin(), all.end(), rng);
            for (const SelectInstance& i : all) {
                const InstanceBoxes fresh(g, bounds, storingNothing());
                auto fw = fresh.makeWorker();
                const Box expected = fresh.box(*fw, i.node, i.depth, i.frame.data(), i.path);
                ASSERT_EQ(boxes.box(*w, i.node, i.depth, i.frame.data(), i.path), expected);
            }
        }
    }
}

TEST(InstanceBoxes, FillingAheadStoresTheBoxesTheMissesWouldCompute) {
    for (const char* text : {kTree, kTerrain, kCsgPlant}) {
        auto c = compile(text);
        ASSERT_TRUE(c->graph);
        const Graph& g = *c->graph;
        const Bounds bounds = computeBounds(g);
        const InstanceBoxes cold(g, bounds, storingNothing()), filled(g, bounds, always());
        filled.prefill(g.axiom);
        if (text == kTerrain) {  // (the tree's instances of a depth are all alike: one each)
            const InstanceBoxStats ahead = filled.stats();
            EXPECT_GT(ahead.entries, 0u);
            EXPECT_GT(ahead.computed, 1u);  // several instances, shared out
        }
        expectSameBoxes(g, filled, cold);
    }
}

TEST(InstanceBoxes, FillingAheadStopsQuietlyAtARunTimeError) {
    // The rule number 3 of a module with two rules, deep inside: the fill stores what it
    // finished and leaves the error to the render, which asks for the box and gets it.
    auto c = compile(R"(
{ n = 6 } T
T if(n > 0, 2, if(n < -5, 1, 3))
1: T -> sphere
2: T -> {n = n-1} uscale(0.5) T ∪ {n = n-1} move(1,0,0) uscale(0.5) T
)");
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const Bounds bounds = computeBounds(g);
    const InstanceBoxes boxes(g, bounds, always());
    EXPECT_NO_THROW(boxes.prefill(g.axiom));
    auto w = boxes.makeWorker();
    std::vector<double> frame(g.slotCount()), f(g.slotCount());
    initFrame(g, frame.data());
    applyCalc(g, g.axiom, EvalState{frame.data(), kRootPath}, f.data());
    EXPECT_THROW(boxes.box(*w, g.child(g.axiom), 1, f.data(), kRootPath), RuntimeError);
}

// The terrain again, with heights that depend on the coordinates alone (rand(x)): the
// count memoises its module (and finds nothing to reuse).
const char* kTerrainByCoordinates = R"(
{ cnt = 5; delta = 0.5; x1 = 0; y1 = 0; z1 = 0; z2 = 0.1; z3 = -0.1 } T
T if(cnt > 0, 2, 1)
1: T -> move(0,0,z1) zshear(z2-z1, z3-z1) tri1
2: T -> {cnt = cnt-1; z2 = (z1+z2)/2 + (rand(x1*7+y1*3) - 0.5)*delta; delta = delta*0.5}
          scale(0.5,0.5,1) T ∪
        {cnt = cnt-1; x1 = x1 + 0.5; z3 = (z1+z3)/2 + (rand(x1*5+y1*11) - 0.5)*delta}
          move(0.5,0,0) scale(0.5,0.5,1) T ∪
        {cnt = cnt-1; y1 = y1 + 0.5; z1 = z1 + rand(x1+y1*13)*delta; delta = delta*0.5}
          move(0,0.5,0) (scale(0.5,0.5,1) T ∪ move(0.1,0.1,0) uscale(0.05) sphere)
)";

// Counts the known counts the count took.
class CountingKnown : public KnownCounts {
  public:
    explicit CountingKnown(const KnownCounts& k) : known_(k) {}
    bool find(NodeId n, uint32_t depth, const double* frame, uint64_t path,
              KnownSubtree& out) const override {
        const bool found = known_.find(n, depth, frame, path, out);
        if (found) ++taken;
        return found;
    }
    mutable uint64_t taken = 0;

  private:
    const KnownCounts& known_;
};

void expectSameCount(const ExpansionCount& a, const ExpansionCount& b) {
    EXPECT_EQ(a.complete, b.complete);
    if (!a.complete || !b.complete) return;
    EXPECT_EQ(a.primitives, b.primitives);
    EXPECT_EQ(a.nodes, b.nodes);
    EXPECT_EQ(a.args, b.args);
}

TEST(InstanceBoxes, FillingAheadCountsWhatTheCountCounts) {
    for (const char* text :
         {testing::kSierpinski, kTree, kTerrain, kTerrainByCoordinates, kCsgPlant}) {
        auto c = compile(text);
        ASSERT_TRUE(c->graph);
        const Graph& g = *c->graph;
        const Bounds bounds = computeBounds(g);
        const InstanceBoxes boxes(g, bounds);
        const std::shared_ptr<const KnownCounts> known = boxes.prefill(g.axiom);
        const ExpansionCount whole = countExpansion(g);
        // (The others' instances at a depth are alike, or few: no fill ahead.)
        if (text == kTerrain || text == kTerrainByCoordinates) {
            ASSERT_TRUE(known);
        }
        if (!known) continue;
        CountingKnown taken(*known);
        CountOptions co;
        co.known = &taken;
        expectSameCount(countExpansion(g, co), whole);
        EXPECT_GT(taken.taken, 1u);  // the levels below were not walked again
        // At the work limit: stopped exactly where the count without them stops.
        for (uint64_t limit : {whole.visits - 1, whole.visits, whole.visits / 3}) {
            co.maxVisits = limit;
            CountOptions alone;
            alone.maxVisits = limit;
            expectSameCount(countExpansion(g, co), countExpansion(g, alone));
        }
    }
}

TEST(InstanceBoxes, TheCountWithTheFillsCountsMeetsTheSameFirstError) {
    // A run-time error (rule 3 of two) in some of the instances the fill unrolls, not in
    // the first: the fill counts the others, and the count meets the error the count
    // without them meets first, with the same module path.
    auto c = compile(R"(
{ n = 6; x = 0 } T
T if(n > 0, 2, if(x > 10, 3, 1))
1: T -> sphere
2: T -> {n = n-1} uscale(0.5) T ∪ {n = n-1; x = x + 1} move(1,0,0) uscale(0.5) T ∪
        {n = n-1; x = x + 3} move(0,1,0) uscale(0.5) T
)");
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const Bounds bounds = computeBounds(g);
    const InstanceBoxes boxes(g, bounds);
    const std::shared_ptr<const KnownCounts> known = boxes.prefill(g.axiom);
    ASSERT_TRUE(known);
    std::string alone, with;
    try {
        countExpansion(g);
    } catch (const RuntimeError& e) {
        alone = e.format(g);
    }
    CountingKnown taken(*known);
    CountOptions co;
    co.known = &taken;
    try {
        countExpansion(g, co);
    } catch (const RuntimeError& e) {
        with = e.format(g);
    }
    EXPECT_NE(alone, "");
    EXPECT_EQ(with, alone);
    EXPECT_GT(taken.taken, 0u);
}

TEST(InstanceBoxes, TheTableStaysWithinItsByteLimit) {
    auto c = compile(kTerrain);
    ASSERT_TRUE(c->graph);
    const Bounds bounds = computeBounds(*c->graph);
    InstanceBoxOptions small = always();
    small.maxBytes = 16 * 1024;
    const InstanceBoxes boxes(*c->graph, bounds, small);
    EXPECT_GT(SoundnessWalk(*c->graph, boxes).run(), 100u);  // sound when full, too
    const InstanceBoxStats st = boxes.stats();
    EXPECT_LE(st.bytes, small.maxBytes);
    EXPECT_TRUE(st.full);
    EXPECT_GT(st.entries, 0u);
}

TEST(InstanceBoxes, TerrainInstancesAreMuchTighterThanTheStaticBoxes) {
    // The reason they exist: a sub-triangle's static box spans all the terrain's heights.
    // Go down the first operand of every union to the S-node instance at depth 4.
    auto c = compile(kTerrain);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const Bounds bounds = computeBounds(g);
    const InstanceBoxes boxes(g, bounds, always());
    auto w = boxes.makeWorker();
    std::vector<double> frame(g.slotCount()), next(g.slotCount());
    initFrame(g, frame.data());
    uint64_t path = kRootPath;
    uint32_t depth = 0;
    for (NodeId n = g.axiom;;) {
        const Node& node = g.nodes[n];
        if (node.kind == NodeKind::Select) {
            ++depth;
            if (depth == 4) {
                const Box exact = boxes.box(*w, n, depth, frame.data(), path);
                const Box& fixed = bounds.select(g, n, depth);
                EXPECT_LT(exact.hi.z - exact.lo.z, 0.5 * (fixed.hi.z - fixed.lo.z));
                EXPECT_LE(exact.hi.x - exact.lo.x, fixed.hi.x - fixed.lo.x + 1e-6);
                return;
            }
            const uint32_t r = selectRule(g, n, EvalState{frame.data(), path});
            path = pathRule(path, r);
            n = g.child(n, r);
        } else if (node.kind == NodeKind::Calc) {
            applyCalc(g, n, EvalState{frame.data(), path}, next.data());
            frame.swap(next);
            n = g.child(n);
        } else if (node.is(CsgOp::Union)) {
            path = pathChild(path, 0);
            n = g.child(n, 0);
        } else {
            ASSERT_NE(node.kind, NodeKind::Primitive) << "the terrain ended above depth 4";
            n = g.child(n);
        }
    }
}

// Random rays from around the object: the nearest hit (t, normal, material) is the same
// bit for bit with static boxes, with exact instance boxes at every depth, and with no
// culling at all.
TEST(InstanceBoxes, CullingWithThemNeverChangesAHit) {
    for (const char* text : {testing::kSierpinski, kTree, kTerrain, kCsgPlant}) {
        auto c = compile(text);
        ASSERT_TRUE(c->graph);
        const Graph& g = *c->graph;
        TraceScene none(g, computeBounds(g), false), fixed(g, computeBounds(g), false),
            exact(g, computeBounds(g), true, always());
        none.useBounds = false;
        Tracer tn(none), tf(fixed), te(exact);
        std::mt19937_64 rng(42);
        std::uniform_real_distribution<double> u(-1, 1);
        int hits = 0;
        for (int i = 0; i < 3000; ++i) {
            const Vec3 o{u(rng) * 4, u(rng) * 4, u(rng) * 4 + 1};
            const Vec3 target{u(rng) * 1.5, u(rng) * 1.5, u(rng) * 2 + 0.5};
            const Vec3 d = normalize(target - o);
            SurfaceHit a, b, e;
            const bool ha = tn.firstHit(o, d, 1e-4, 1e7, a);
            const bool hb = tf.firstHit(o, d, 1e-4, 1e7, b);
            const bool he = te.firstHit(o, d, 1e-4, 1e7, e);
            ASSERT_EQ(ha, hb) << "ray " << i;
            ASSERT_EQ(ha, he) << "ray " << i;
            EXPECT_EQ(te.anyHit(o, d, 1e-4, 1e7), ha) << "ray " << i;
            if (!ha) continue;
            ++hits;
            EXPECT_EQ(a.t, e.t) << "ray " << i;
            EXPECT_EQ(a.normal, e.normal) << "ray " << i;
            EXPECT_EQ(a.material, e.material) << "ray " << i;
            EXPECT_EQ(a.t, b.t) << "ray " << i;
        }
        EXPECT_GT(hits, 50);
        EXPECT_LT(te.nodeVisits(), tn.nodeVisits());
    }
}

// The boxes' rounding to floats (castDown, castUp: the cast, stepped without libm) gives the
// bits of the cast stepped by std::nextafter, the rounding the table's boxes had before:
// zeros, subnormals, the largest floats and infinities included.
TEST(InstanceBoxes, BoxesRoundToTheFloatsNextafterGives) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> mantissa(1, 2);
    std::uniform_int_distribution<int> exponent(-160, 160);
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> xs = {0.0,           -0.0,         1.0,           0.1,    -0.1,
                              1e-45,         -1e-45,       1e-50,         -1e-50, 3.4028234e38,
                              -3.4028234e38, 3.4028236e38, -3.4028236e38, 3.5e38, -3.5e38,
                              1e300,         -1e300,       inf,           -inf};
    for (int i = 0; i < 4000; ++i)
        xs.push_back((i % 2 ? -1 : 1) * std::ldexp(mantissa(rng), exponent(rng)));
    for (double x : xs) {
        const float f = static_cast<float>(x);
        const float down = static_cast<double>(f) > x ? std::nextafter(f, -INFINITY) : f;
        const float up = static_cast<double>(f) < x ? std::nextafter(f, INFINITY) : f;
        EXPECT_EQ(std::bit_cast<uint32_t>(castDown(x)), std::bit_cast<uint32_t>(down)) << x;
        EXPECT_EQ(std::bit_cast<uint32_t>(castUp(x)), std::bit_cast<uint32_t>(up)) << x;
    }
}

// The keys of instance_boxes.h's InstanceKeys: equal exactly when the instances are the
// same (the same S-node, the same values in the slots narrowKeySlots keeps and, where the
// module uses it, the same path). Modules that hash an odd and an even number of slots.
TEST(InstanceKeys, TwoInstancesHaveTheSameKeyExactlyWhenTheyAreTheSameInstance) {
    // S hashes n, a, b; P n, b and its path; Q n, a.
    auto c = compile(
        "{ a = 1; b = 2; n = 3 } S ∪ { a = 1; b = 2; n = 3 } P ∪ { a = 1; n = 3 } Q\n"
        "S if(n > 0, 1, 2)\n"
        "1: S -> { n = n - 1; a = a + b; b = b * 0.5 } move(a, b, 0) S\n"
        "2: S -> sphere\n"
        "P if(n > 0, 1, 2)\n"
        "1: P -> { n = n - 1; b = b * 0.5 } move(b, rand(), 0) P\n"
        "2: P -> sphere\n"
        "Q if(n > 0, 1, 2)\n"
        "1: Q -> { n = n - 1; a = a * 0.5 } move(a, 0, 0) Q\n"
        "2: Q -> sphere\n");
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    std::vector<ModuleDependencies> deps = moduleDependencies(g);
    narrowKeySlots(g, FixedSlots(g), deps);
    const InstanceKeys keys(g, deps);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> value(-4, 4);
    std::vector<double> frame(g.slotCount());
    for (double& v : frame) v = value(rng);
    std::vector<InstanceKeys::Key> seen;
    bool odd = false, even = false, path = false;
    for (const Module& m : g.modules) {
        const ModuleDependencies& d = deps[g.nodes[m.node].payload];
        (d.reads.size() % 2 ? odd : even) |= d.reads.size() >= 2;
        path |= d.usesPath;
        const InstanceKeys::Key k = keys.of(m.node, frame.data(), 5);
        for (const InstanceKeys::Key& other : seen) EXPECT_FALSE(k == other) << m.name;
        seen.push_back(k);
        std::vector<double> same = frame;  // a copy: the key reads values, not addresses
        EXPECT_EQ(keys.of(m.node, same.data(), 5), k) << m.name;
        for (Slot s = 0; s < frame.size(); ++s) {
            std::vector<double> changed = frame;
            changed[s] += 0.5;
            const bool read = std::find(d.reads.begin(), d.reads.end(), s) != d.reads.end();
            EXPECT_EQ(keys.of(m.node, changed.data(), 5) == k, !read) << m.name << " slot " << s;
        }
        EXPECT_EQ(keys.of(m.node, frame.data(), 6) == k, !d.usesPath) << m.name;
    }
    EXPECT_TRUE(odd && even && path);  // the loop's pairs, its last odd slot, the path
}

}  // namespace
}  // namespace pcsg::tracer
