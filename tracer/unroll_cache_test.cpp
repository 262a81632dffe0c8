// The shared cache of expanded instances (unroll_cache.h): threads asking for the same
// instance get one object, built once; the cache stays within its byte budget whatever
// the threads do; an instance evicted while a reader is pinned stays intact until the
// reader unpins; tracers on several threads find the same hits as the graph walk; an
// instance larger than its share of the budget is refused and the level below it is
// expanded instead; levels of large instances that do not stay, and levels whose
// instances are rebuilt after eviction, stop expanding; the budget starts small and grows
// only where a larger one would have saved expansions.
#include "unroll_cache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <thread>

#include "bounds.h"
#include "test_support.h"
#include "traversal.h"

namespace pcsg::tracer {
namespace {

using testing::compile;
using testing::eagerExpansion;

using testing::kFlower;

const std::string kPlant = testing::branchingPlant(6);

// The flower's S-node and the frame of its instance with p petals.
struct Flower {
    explicit Flower(const Graph& graph) : g(graph), frame(g.slotCount()) {
        std::vector<double> root(g.slotCount());
        initFrame(g, root.data());
        applyCalc(g, g.axiom, EvalState{root.data(), kRootPath}, frame.data());
        select = g.child(g.axiom);
        for (size_t k = 0; k < frame.size(); ++k)
            if (frame[k] == 21) slot = k;
    }
    const UnrolledInstance* get(UnrollCache::Reader& r, double petals, uint32_t depth = 1) {
        frame[slot] = petals;
        return r.get(select, depth, frame.data(), kRootPath);
    }
    const Graph& g;
    std::vector<double> frame;
    NodeId select = kNone;
    size_t slot = SIZE_MAX;
};

// The bytes of the flower's instance with p petals, expanded alone.
size_t flowerBytes(const TraceScene& scene, Flower& f, double p) {
    f.frame[f.slot] = p;
    return UnrolledInstance::expand(scene, f.select, 1, f.frame.data(), kRootPath, 1u << 20)
        ->bytes();
}

// The nearest hit of a ray through an instance, to compare instances by what they hold.
Hit hitOf(const UnrolledInstance& x, UnrollCache::Reader& r) {
    Hit h;
    double tmax = 1e9;
    x.first(LocalRay{{0.1, -5, 0}, Vec3{0, 1, 0}}, 1e-6, tmax, h, {kRootPath, 0, 0}, false,
            r.scratch());
    return h;
}

TEST(UnrollCache, ThreadsAskingForOneInstanceGetOneObjectBuiltOnce) {
    auto c = compile(kFlower);
    ASSERT_TRUE(c->graph);
    TraceScene scene(*c->graph, computeBounds(*c->graph), true, eagerExpansion());
    UnrollCache cache(scene, 64u << 20);
    constexpr int kThreads = 4;
    std::vector<const UnrolledInstance*> got(kThreads, nullptr);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            Flower f(*c->graph);
            UnrollCache::Reader reader(cache);
            // nullptr while it is a note or in construction elsewhere: asked again until
            // it is built (a loaded machine, or a sanitizer's, may keep the builder from
            // running for a long while: no count of tries, only a guard against a hang)
            const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(2);
            while (!got[t] && std::chrono::steady_clock::now() < give_up) {
                {
                    const UnrollCache::Pin pin(&reader);
                    got[t] = f.get(reader, 21);
                }
                if (!got[t]) std::this_thread::yield();
            }
        });
    for (auto& t : threads) t.join();
    ASSERT_NE(got[0], nullptr);
    for (int t = 1; t < kThreads; ++t) EXPECT_EQ(got[t], got[0]) << "thread " << t;
    EXPECT_EQ(cache.expansions(), 1u);
}

TEST(UnrollCache, AnInstanceEvictedWhileInUseStaysIntactUntilItsReaderUnpins) {
    auto c = compile(kFlower);
    ASSERT_TRUE(c->graph);
    TraceScene scene(*c->graph, computeBounds(*c->graph), true, eagerExpansion());
    Flower fa(*c->graph), fb(*c->graph);
    ASSERT_NE(fa.slot, SIZE_MAX);
    // Room for the whole flower (within its share), not for it and all the smaller ones.
    UnrollCache cache(scene, 8 * (flowerBytes(scene, fa, 21) + 256));
    UnrollCache::Reader a(cache);
    auto b = std::make_unique<UnrollCache::Reader>(cache);
    const UnrolledInstance* x = nullptr;
    {
        const UnrollCache::Pin pin(&a);
        for (int i = 0; i < 2 && !x; ++i) x = fa.get(a, 21);
        ASSERT_NE(x, nullptr);
        const Hit before = hitOf(*x, a);
        ASSERT_TRUE(before.valid);
        const Box box = x->box();
        // Another reader fills the cache: the instance leaves it, but is not freed. (At three
        // depths, each with flowers of its own: a depth stops after half the budget's worth
        // of large instances.)
        for (uint32_t depth = 2; depth <= 4; ++depth)
            for (int p = 1; p < 21; ++p)
                for (int i = 0; i < 2; ++i) {
                    const UnrollCache::Pin pinB(b.get());
                    fb.get(*b, p + depth / 4.0, depth);
                }
        EXPECT_GT(cache.retiredBytes(), 0u);
        const Hit after = hitOf(*x, a);  // (ASan: a use after free if it had been freed)
        EXPECT_EQ(after.t, before.t);
        EXPECT_EQ(after.key, before.key);
        EXPECT_EQ(x->box().lo.x, box.lo.x);
        EXPECT_EQ(x->box().hi.z, box.hi.z);
    }
    b.reset();  // (a reader leaving frees what no pinned reader holds)
    EXPECT_EQ(cache.retiredBytes(), 0u);
}

// The flower's scene, its instances and a cache that holds eight of them, read by r.
struct FlowerCache {
    explicit FlowerCache(const Graph& g)
        : scene(g, computeBounds(g), true, eagerExpansion()),
          f(g),
          cache(scene,
                f.slot == SIZE_MAX ? size_t{1} << 20 : 8 * (flowerBytes(scene, f, 21) + 256)),
          r(cache) {}
    TraceScene scene;
    Flower f;
    UnrollCache cache;
    UnrollCache::Reader r;
};

TEST(UnrollCache, BuiltFindsTheBuiltInstancesAndItsFilterForgetsTheEvictedOnes) {
    auto c = compile(kFlower);
    ASSERT_TRUE(c->graph);
    FlowerCache fc(*c->graph);
    TraceScene& scene = fc.scene;
    Flower& f = fc.f;
    UnrollCache& cache = fc.cache;
    UnrollCache::Reader& r = fc.r;
    ASSERT_NE(f.slot, SIZE_MAX);
    f.frame[f.slot] = 21;
    const InstanceBoxes::Key k = scene.instanceBoxes()->keyOf(f.select, f.frame.data(), kRootPath);
    const UnrolledInstance* x = nullptr;
    {
        const UnrollCache::Pin pin(&r);
        EXPECT_FALSE(cache.mayBeBuilt(k));
        EXPECT_EQ(r.built(k, f.select, 1), nullptr);
        EXPECT_EQ(r.meet(k, f.select, 1, f.frame.data(), kRootPath), nullptr);  // a note
        x = r.meet(k, f.select, 1, f.frame.data(), kRootPath);  // expanded at the second
        ASSERT_NE(x, nullptr);
        EXPECT_TRUE(cache.mayBeBuilt(k));
        EXPECT_EQ(r.built(k, f.select, 1), x);
        EXPECT_EQ(r.meet(k, f.select, 1, f.frame.data(), kRootPath), x);
    }
    // Others fill the cache (as in the test above, but never with 21 petals: keys hold no
    // depth): the flower leaves it, and the filter no longer holds it.
    for (uint32_t depth = 2; depth <= 4; ++depth)
        for (int p = 1; p < 21; ++p)
            for (int i = 0; i < 2; ++i) {
                const UnrollCache::Pin pin(&r);
                f.get(r, p + depth / 8.0, depth);
            }
    ASSERT_EQ(cache.share(k), nullptr);  // (evicted: not built, whatever its level does)
    EXPECT_FALSE(cache.mayBeBuilt(k));
}

// A shadow ray's meeting counts a third of another ray's: a camera ray's note and two
// shadow rays leave a note; six shadow rays, or two other rays, expand the instance.
TEST(UnrollCache, AShadowRaysMeetingCountsAThirdOfOne) {
    auto c = compile(kFlower);
    ASSERT_TRUE(c->graph);
    FlowerCache fc(*c->graph);
    ASSERT_NE(fc.f.slot, SIZE_MAX);
    const UnrollCache::Pin pin(&fc.r);
    auto meet = [&fc](double petals, bool shadow) {
        Flower& f = fc.f;
        f.frame[f.slot] = petals;
        const InstanceBoxes::Key k =
            fc.scene.instanceBoxes()->keyOf(f.select, f.frame.data(), kRootPath);
        return fc.r.meet(k, f.select, 1, f.frame.data(), kRootPath, shadow);
    };
    EXPECT_EQ(meet(21, false), nullptr);
    EXPECT_EQ(meet(21, true), nullptr);
    EXPECT_EQ(meet(21, true), nullptr);
    EXPECT_NE(meet(21, false), nullptr);
    for (int ray = 0; ray < 5; ++ray) EXPECT_EQ(meet(20, true), nullptr) << "shadow ray " << ray;
    EXPECT_NE(meet(20, true), nullptr);
    EXPECT_EQ(meet(19, false), nullptr);
    EXPECT_NE(meet(19, false), nullptr);
    EXPECT_EQ(fc.cache.expansions(), 3u);
}

TEST(UnrollCache, TracersOnSeveralThreadsStayWithinOneBudgetAndFindTheGraphWalksHits) {
    auto c = compile(kPlant);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    TraceScene plain(g, computeBounds(g), true, eagerExpansion());
    plain.expansionBytes = 0;
    TraceScene shared(g, computeBounds(g), true, eagerExpansion());
    shared.expansionBytes = 24 * 1024;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<Vec3> o, d;
    for (int i = 0; i < 3000; ++i) {
        o.push_back(Vec3{u(rng) * 5, -6 + u(rng), u(rng) * 5});
        d.push_back(normalize(Vec3{u(rng) * 1.5, u(rng) * 1.5, u(rng) * 1.5 + 1.5} - o.back()));
    }
    std::vector<SurfaceHit> expected(o.size());
    std::vector<char> found(o.size());
    Tracer walk(plain);
    for (size_t i = 0; i < o.size(); ++i)
        found[i] = walk.firstHit(o[i], d[i], 1e-4, 1e7, expected[i]);
    constexpr int kThreads = 3;
    std::vector<int> mismatches(kThreads, 0);
    std::vector<uint64_t> expansions(kThreads, 0);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            Tracer tracer(shared);
            for (int round = 0; round < 3; ++round)
                for (size_t k = 0; k < o.size(); ++k) {
                    const size_t i = (k * (t + 1) + round * 977) % o.size();
                    SurfaceHit h;
                    const bool f = tracer.firstHit(o[i], d[i], 1e-4, 1e7, h);
                    if (f != bool(found[i]) ||
                        (f && (h.t != expected[i].t || h.material != expected[i].material ||
                               h.normal.x != expected[i].normal.x)))
                        ++mismatches[t];
                }
            expansions[t] = tracer.expansions();
        });
    for (auto& t : threads) t.join();
    uint64_t total = 0;
    for (int t = 0; t < kThreads; ++t) {
        EXPECT_EQ(mismatches[t], 0) << "thread " << t;
        total += expansions[t];
    }
    const UnrollCache& cache = shared.expansionCache();
    EXPECT_GT(total, 0u);
    EXPECT_EQ(total, cache.expansions());
    EXPECT_GT(cache.bytes(), 0u);
    EXPECT_LE(cache.bytes(), cache.maxBytes()) << cache.entries() << " entries";
    EXPECT_EQ(cache.retiredBytes(), 0u);  // the tracers are gone: nothing is held
}

TEST(UnrollCache, AnInstanceLargerThanItsShareIsRefusedAndTheLevelBelowIsExpandedInstead) {
    auto c = compile(testing::kSierpinski);  // order 4
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    TraceScene plain(g, computeBounds(g), true, eagerExpansion());
    plain.expansionBytes = 0;
    TraceScene scene(g, computeBounds(g), true, eagerExpansion());
    // The budget's share holds the instance at depth 2 (order 3), twice over, not the one
    // at depth 1 (four times as large): the margin leaves room for the cache's estimate of
    // a level's size before its first expansion.
    auto [select, frame] = testing::axiomInstance(g);
    const auto order = std::find(frame.begin(), frame.end(), 4.0);
    ASSERT_NE(order, frame.end());
    auto bytesAt = [&](double c) {
        *order = c;
        return UnrolledInstance::expand(scene, select, 1, frame.data(), kRootPath, 1u << 20)
            ->bytes();
    };
    const size_t whole = bytesAt(4), quarter = bytesAt(3);
    scene.expansionBytes = 8 * 2 * quarter;
    ASSERT_GT(whole, scene.expansionBytes / 8);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    Tracer walk(plain), tracer(scene);
    int mismatches = 0;
    for (int i = 0; i < 3000; ++i) {
        const Vec3 o{u(rng) * 5, -6 + u(rng), u(rng) * 5};
        const Vec3 d = normalize(Vec3{u(rng), u(rng), u(rng)} - o);
        for (int round = 0; round < 2; ++round) {
            SurfaceHit a, b;
            const bool fa = walk.firstHit(o, d, 1e-4, 1e7, a);
            const bool fb = tracer.firstHit(o, d, 1e-4, 1e7, b);
            if (fa != fb || (fa && (a.t != b.t || a.normal.x != b.normal.x))) ++mismatches;
        }
    }
    EXPECT_EQ(mismatches, 0);
    const UnrollCache& cache = scene.expansionCache();
    const UnrollCache::Level one = cache.level(select, 1), two = cache.level(select, 2);
    EXPECT_TRUE(one.off);
    EXPECT_EQ(one.built, 0u);
    EXPECT_FALSE(two.off);
    EXPECT_EQ(two.built, 1u);  // (one instance: the four at depth 2 are alike)
    EXPECT_GT(cache.bytes(), quarter);
    EXPECT_LE(cache.bytes(), cache.maxBytes());
}

TEST(UnrollCache, ALevelWhoseLargeInstancesDoNotStayStopsExpanding) {
    auto c = compile(kFlower);
    ASSERT_TRUE(c->graph);
    TraceScene scene(*c->graph, computeBounds(*c->graph), true, eagerExpansion());
    Flower f(*c->graph);
    ASSERT_NE(f.slot, SIZE_MAX);
    // Flowers of 21 petals (20.001, 20.002, ...: each an instance of its own), each a 40th of
    // the budget: large (over a 64th), and 60 of them hold more than half the budget.
    const size_t each = flowerBytes(scene, f, 20.5);
    UnrollCache cache(scene, 40 * each);
    UnrollCache::Reader reader(cache);
    uint64_t built = 0, refusedAfterStop = 0;
    for (int i = 1; i <= 60; ++i) {
        const UnrollCache::Pin pin(&reader);
        const double p = 20 + i / 1000.0;
        const bool wasOff = cache.level(f.select, 1).off;
        f.get(reader, p);
        const UnrolledInstance* x = f.get(reader, p);
        if (x) ++built;
        if (wasOff && !x) ++refusedAfterStop;
        EXPECT_LE(cache.bytes(), cache.maxBytes()) << "flower " << i;
    }
    const UnrollCache::Level level = cache.level(f.select, 1);
    EXPECT_TRUE(level.off);
    EXPECT_EQ(level.built, built);
    EXPECT_GE(built, 20u);  // half the budget's worth was built, not much more
    EXPECT_LE(built, 22u);
    EXPECT_EQ(refusedAfterStop, 60 - built);
    EXPECT_EQ(level.refused, 0u);
}

TEST(UnrollCache, ALevelWhoseInstancesAreRebuiltAfterEvictionStopsExpanding) {
    auto c = compile(kFlower);
    ASSERT_TRUE(c->graph);
    TraceScene scene(*c->graph, computeBounds(*c->graph), true, eagerExpansion());
    Flower f(*c->graph);
    ASSERT_NE(f.slot, SIZE_MAX);
    // Small flowers of 2 petals (1.001, 1.002, ...), well used, but half as many again as
    // the cache holds, met again and again.
    const size_t each = flowerBytes(scene, f, 1.5);
    UnrollCache cache(scene, 100 * (each + 128));
    UnrollCache::Reader reader(cache);
    int pass = 0;
    for (; pass < 6 && !cache.level(f.select, 1).off; ++pass)
        for (int i = 1; i <= 150; ++i)
            for (int use = 0; use < 8; ++use) {
                const UnrollCache::Pin pin(&reader);
                f.get(reader, 1 + i / 1000.0);
                EXPECT_LE(cache.bytes(), cache.maxBytes());
            }
    const UnrollCache::Level level = cache.level(f.select, 1);
    EXPECT_TRUE(level.off);
    EXPECT_GE(pass, 2) << level.built << " " << level.rebuilt;  // (the first pass builds each once)
    EXPECT_GT(level.rebuilt * 3, level.built - level.rebuilt);
    EXPECT_EQ(level.refused, 0u);
}

// 150 small flowers in a cache whose budget starts with room for 40 of them and may grow
// to 1,000.
struct SmallFlowers {
    SmallFlowers()
        : c(compile(kFlower)),
          scene(*c->graph, computeBounds(*c->graph), true, eagerExpansion()),
          f(*c->graph),
          each(flowerBytes(scene, f, 1.5) + 256),
          cache(scene, 1000 * each, 40 * each),
          reader(cache) {}
    // Meets each flower `uses` times in a row; false if the cache went over its budget.
    bool pass(int uses) {
        bool within = true;
        for (int i = 1; i <= 150; ++i)
            for (int use = 0; use < uses; ++use) {
                const UnrollCache::Pin pin(&reader);
                f.get(reader, 1 + i / 1000.0);
                within = within && cache.bytes() <= cache.budget();
            }
        return within;
    }
    std::unique_ptr<testing::Compiled> c;
    TraceScene scene;
    Flower f;
    size_t each;
    UnrollCache cache;
    UnrollCache::Reader reader;
};

TEST(UnrollCache, TheBudgetGrowsForEvictedInstancesMetAgainUpToWhatTheyNeed) {
    SmallFlowers s;  // (met again and again)
    ASSERT_EQ(s.cache.budget(), 40 * s.each);
    uint64_t lastPass = 0;
    for (int pass = 0; pass < 5; ++pass) {
        const uint64_t before = s.cache.expansions();
        EXPECT_TRUE(s.pass(8)) << "pass " << pass;
        lastPass = s.cache.expansions() - before;
    }
    const UnrollCache::Level level = s.cache.level(s.f.select, 1);
    EXPECT_FALSE(level.off);  // (with a fixed budget of 40 it thrashes and stops)
    // Every rebuild grew the budget once they were an eighth of the evictions (the first
    // pass evicted 110 flowers, none met again yet; a few more went before the rate held).
    EXPECT_LE(level.rebuilt, 150u / 8);
    EXPECT_GT(s.cache.budget(), 150 * (s.each - 256));  // it holds them all now ...
    EXPECT_LT(s.cache.budget(), 300 * s.each);          // ... and not much more
    EXPECT_EQ(lastPass, 0u);
}

TEST(UnrollCache, InstancesNotMetAgainLeaveTheBudgetWhereItStarts) {
    SmallFlowers s;
    EXPECT_TRUE(s.pass(8));  // (each used eight times and then never again)
    EXPECT_EQ(s.cache.expansions(), 150u);
    EXPECT_EQ(s.cache.budget(), 40 * s.each);
    EXPECT_LE(s.cache.bytes(), 40 * s.each);  // (the maximum would have kept all 150)
}

// A stream of flowers, each met 8 times, where only every 16th new one brings back one
// evicted 60 flowers before: its ghost is there, but such meetings are fewer than an
// eighth of the evictions, so the budget stays where it starts (it grew by each before).
TEST(UnrollCache, EvictedInstancesMetAgainOnlyRarelyLeaveTheBudgetWhereItStarts) {
    SmallFlowers s;
    int again = 0;
    for (int i = 1; i <= 600; ++i) {
        for (int use = 0; use < 8; ++use) {
            const UnrollCache::Pin pin(&s.reader);
            s.f.get(s.reader, 1 + i / 1000.0);
        }
        if (i % 16 != 0 || i <= 60) continue;
        for (int use = 0; use < 8; ++use) {
            const UnrollCache::Pin pin(&s.reader);
            s.f.get(s.reader, 1 + (i - 60) / 1000.0);
        }
        ++again;
    }
    const UnrollCache::Level level = s.cache.level(s.f.select, 1);
    EXPECT_FALSE(level.off);
    EXPECT_EQ(level.rebuilt, static_cast<uint64_t>(again));  // (none grew the budget)
    EXPECT_EQ(s.cache.budget(), 40 * s.each);
}

// Flowers of 21 petals (too large for the start's share, not for the maximum's), met
// `meetings` times each, after `standIns` small flowers were expanded at depth 3.
struct WaitingLevel {
    WaitingLevel(int standIns, int meetings)
        : c(compile(kFlower)),
          scene(*c->graph, computeBounds(*c->graph), true, eagerExpansion()),
          f(*c->graph),
          large(flowerBytes(scene, f, 20.5) + 256),
          cache(scene, 64 * large, 4 * large) {
        UnrollCache::Reader reader(cache);
        for (int i = 1; i <= standIns; ++i)
            for (int use = 0; use < 8; ++use) {
                const UnrollCache::Pin pin(&reader);
                f.get(reader, 1 + i / 1000.0, 3);
            }
        for (int m = 0; m < meetings; ++m) {
            const UnrollCache::Pin pin(&reader);
            if (f.get(reader, 20 + (m % 4) / 1000.0)) ++got;
        }
    }
    std::unique_ptr<testing::Compiled> c;
    TraceScene scene;
    Flower f;
    size_t large;
    UnrollCache cache;
    int got = 0;
};

TEST(UnrollCache, ALevelTooLargeForTheStartGetsTheBudgetOnceOtherExpansionsStandInForIt) {
    WaitingLevel w(8, 2000);
    EXPECT_GE(w.cache.budget(), 8 * w.large);
    EXPECT_LE(w.cache.budget(), 64 * w.large);
    const UnrollCache::Level level = w.cache.level(w.f.select, 1);
    EXPECT_FALSE(level.off);
    EXPECT_GE(level.built, 1u);
    EXPECT_GT(w.got, 0);
}

// The level the budget grew for stops (new flowers, each met once more after its
// expansion, until the level's expansions are used less than four times each on
// average): the budget goes back to where it started.
TEST(UnrollCache, TheBudgetGrownForALevelThatStopsGoesBack) {
    WaitingLevel w(8, 2000);
    ASSERT_GE(w.cache.budget(), 8 * w.large);
    UnrollCache::Reader reader(w.cache);
    for (int i = 1; i <= 2000 && !w.cache.level(w.f.select, 1).off; ++i)
        for (int meeting = 0; meeting < 2; ++meeting) {
            const UnrollCache::Pin pin(&reader);
            w.f.get(reader, 20 + (10 + i) / 1000.0);
        }
    EXPECT_TRUE(w.cache.level(w.f.select, 1).off);
    EXPECT_EQ(w.cache.budget(), 4 * w.large);
}

TEST(UnrollCache, ALevelTooLargeForTheStartWithNoStandInsLeavesTheBudgetSmall) {
    WaitingLevel w(1, 2000);  // (a tree whose levels are one instance each)
    EXPECT_EQ(w.cache.budget(), 4 * w.large);
    const UnrollCache::Level level = w.cache.level(w.f.select, 1);
    EXPECT_EQ(level.built, 0u);
    EXPECT_FALSE(level.off);  // (it still waits)
    EXPECT_EQ(w.got, 0);
}

// A top level refused for its many copies of small instances asks for the waiting level
// (TraceScene::buildTopLevel): the budget grows to hold its instances, and they expand.
TEST(UnrollCache, TheWaitingLevelGetsItsBudgetWhenAskedFor) {
    WaitingLevel w(1, 2000);
    ASSERT_EQ(w.cache.budget(), 4 * w.large);
    EXPECT_GT(w.cache.growForWaitingLevel(), 0u);
    EXPECT_GE(w.cache.budget(), 8 * w.large);
    EXPECT_LE(w.cache.budget(), 64 * w.large);
    UnrollCache::Reader reader(w.cache);
    int got = 0;
    for (int m = 0; m < 8; ++m) {
        const UnrollCache::Pin pin(&reader);
        if (w.f.get(reader, 20)) ++got;
    }
    EXPECT_GT(got, 0);
    EXPECT_GE(w.cache.level(w.f.select, 1).built, 1u);
}

TEST(UnrollCache, NoWaitingLevelNoGrowthWhenAskedFor) {
    WaitingLevel w(8, 0);  // (small flowers only: nothing waits)
    const size_t before = w.cache.budget();
    EXPECT_EQ(w.cache.growForWaitingLevel(), 0u);
    EXPECT_EQ(w.cache.budget(), before);
}

}  // namespace
}  // namespace pcsg::tracer
