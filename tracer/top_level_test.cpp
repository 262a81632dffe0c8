// The two-level structure (top_level.h): for many random rays it finds the graph walk's
// hits exactly (t, normal, instance path, material, paint point), shadow rays included;
// copies share their instances, with the expansion cache; where the instances are all but
// unique (a terrain's patches) its cuts are deferred to the tracer, which still feeds the
// cache; it is refused where the part above the cuts is not all unions.
#include "top_level.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

#include "bounds.h"
#include "test_support.h"
#include "traversal.h"

namespace pcsg::tracer {
namespace {

using testing::compile;
using testing::eagerExpansion;
using testing::terrain;

// Flower heads (test_support.h's kFlower): painted petals, an unpainted centre that takes
// the material of each copy's paint node, copies under rotations and a shear.
const std::string kFlowers = std::string(testing::kFlower)
                                 .replace(std::string(testing::kFlower).find("{p = 21} F"), 10,
                                          "material red { color <1,0,0> }\n"
                                          "{p = 21} (F ∪ paint(red) move(1.2,0,0) rotx(30) F ∪ "
                                          "move(-1.2,0,0.3) zshear(0.2, 0.1) F ∪"
                                          " move(0,0,-1) uscale(0.7) F)");

// Two copies of one instance in the same place, in different materials: every hit is a tie
// in t that the instance path decides.
const char* kTwins = R"(
material red { color <1,0,0> }
material blue { color <0,0,1> }
{n = 3} (paint(blue) T ∪ paint(red) T ∪ move(0,0,-2) plane)
T if(n > 0, 2, 1)
1: T -> sphere
2: T -> {n = n-1} (move(1,0,0) uscale(0.5) T ∪ move(-1,0,0) uscale(0.5) T)
)";

// Instances whose root union has a matrix and a paint of its own above it (each level
// turned and painted green below the copies' blue and red): an Instance node must enter
// them through firstAt, which applies both, not straight into the union's hierarchy.
const char* kTurnedRoots = R"(
material red { color <1,0,0> }
material blue { color <0,0,1> }
material green { color <0,1,0> }
{n = 4} (paint(blue) T ∪ move(0.3,0,0) paint(red) T ∪ move(0,0,-2) plane)
T if(n > 0, 2, 1)
1: T -> sphere
2: T -> {n = n-1} paint(green) rotz(25) (move(1,0,0) uscale(0.5) T ∪ move(-1,0,0) uscale(0.5) T ∪
                                            move(0,1,0) uscale(0.4) T ∪ move(0,0,1) uscale(0.3) T ∪
                                            move(0,-1,0.5) uscale(0.3) T)
)";

// A difference above the recursion: no top level, the walk as before.
const std::string kCsgAbove = std::string(testing::kSierpinski)
                                  .replace(std::string(testing::kSierpinski).find("{c = 4} S"), 9,
                                           "{c = 4} S \\ move(0,0,0.5) uscale(0.4) sphere");

// Every instance unique (h differs in each, and the sub-graph reads it), as a terrain's
// patches: nothing to share, so no top level.
const char* kUnique = R"(
{n = 5; h = 1} T
T if(n > 0, 2, 1)
1: T -> move(0,0,h*0.01) scale(1.5, 20, 20) sphere
2: T -> {n = n-1; h = 2*h} move(1,0,0) uscale(0.5) T ∪ {n = n-1; h = 2*h+1} move(-1,0,0) uscale(0.5) T
)";

// kUnique painted: copies in two materials above the cuts (red and the default), unique too.
const char* kUniquePainted = R"(
material red { color <1,0,0> }
{n = 5; h = 1} (paint(red) T ∪ {h = h + 64} move(0,0,-1.5) T)
T if(n > 0, 2, 1)
1: T -> move(0,0,h*0.01) scale(1.5, 20, 20) sphere
2: T -> {n = n-1; h = 2*h} move(1,0,0) uscale(0.5) T ∪ {n = n-1; h = 2*h+1} move(-1,0,0) uscale(0.5) T
)";

// kUnique with a pattern below the cuts: the walk records the frames of paint nodes, which a
// deferred node's walk, started below the root, does not see whole: no top level.
const char* kUniqueBumpy = R"(
material bumpy { color <1,0,0>  normal { bumps 0.5 scale 0.1 } }
{n = 5; h = 1} T
T if(n > 0, 2, 1)
1: T -> paint(bumpy) move(0,0,h*0.01) scale(1.5, 20, 20) sphere
2: T -> {n = n-1; h = 2*h} move(1,0,0) uscale(0.5) T ∪ {n = n-1; h = 2*h+1} move(-1,0,0) uscale(0.5) T
)";

struct Result {
    size_t copies = 0, instances = 0, deferred = 0, hits = 0;
    uint64_t expansionsAfter = 0;  // made while the rays were fired through the top level
    uint64_t expansions = 0;       // made in all
    size_t interiors = 0;          // hits whose interior is a paint node's (transparency)
    size_t painted = 0;            // hits with a point in their paint node's frame (patterns)
    bool built = false;
};

// Fires n random rays at the scene: first through the walk (so that the expansion cache
// learns where it expands), then builds the top level and fires them again, comparing
// every first hit and shadow ray with a scene that only walks the graph. `expansionBytes`:
// the budget of the expansion cache (and of the top level).
Result compareRays(const std::string& text, const std::vector<Vec3>& o, const std::vector<Vec3>& d,
                   size_t expansionBytes, const InstanceBoxOptions& options) {
    Result out;
    auto c = compile(text);
    if (!c->graph) return out;
    const Graph& g = *c->graph;
    TraceScene plain(g, computeBounds(g), true, options);
    plain.expansionBytes = 0;
    TraceScene twoLevel(g, computeBounds(g), true, options);
    twoLevel.expansionBytes = expansionBytes;
    Tracer a(plain), b(twoLevel);
    const int n = static_cast<int>(o.size());
    SurfaceHit warm;
    // (shadow rays too: the walk's last occluder then holds a copy it tried in vain, which
    // must not be skipped later when a walk below the top level meets it)
    for (int round = 0; round < 2; ++round)
        for (int i = 0; i < n; ++i) {
            b.firstHit(o[i], d[i], 1e-4, 1e7, warm);
            if (round == 1) b.anyHit(o[i], d[i], 1e-4, 1e7);
        }
    const TopLevel* top = twoLevel.buildTopLevel();
    out.built = top != nullptr;
    if (top) out.copies = top->copies(), out.instances = top->instances();
    if (top) out.deferred = top->deferred();
    const uint64_t expansionsBefore = b.expansions();
    for (int i = 0; i < n; ++i) {
        SurfaceHit ha, hb;
        const bool fa = a.firstHit(o[i], d[i], 1e-4, 1e7, ha);
        EXPECT_EQ(b.firstHit(o[i], d[i], 1e-4, 1e7, hb), fa) << "ray " << i;
        EXPECT_EQ(b.anyHit(o[i], d[i], 1e-4, 1e7), fa) << "ray " << i;
        if (fa) {  // shadow rays that end just before the surface, at it and just past it
            for (const double end : {ha.t * (1 - 1e-9), ha.t, std::nextafter(ha.t, 2 * ha.t)})
                EXPECT_EQ(b.anyHit(o[i], d[i], 1e-4, end), a.anyHit(o[i], d[i], 1e-4, end))
                    << "ray " << i << " ending at " << end;
        }
        if (!fa) continue;
        ++out.hits;
        EXPECT_EQ(ha.t, hb.t) << "ray " << i;
        EXPECT_EQ(ha.normal, hb.normal) << "ray " << i;
        EXPECT_EQ(ha.path, hb.path) << "ray " << i;
        EXPECT_EQ(ha.material, hb.material) << "ray " << i;
        EXPECT_EQ(ha.painted, hb.painted) << "ray " << i;
        EXPECT_EQ(ha.interior, hb.interior) << "ray " << i;
        out.interiors += ha.interior != 0;
        if (ha.painted) {
            ++out.painted;
            EXPECT_EQ(ha.paintPoint, hb.paintPoint) << "ray " << i;
        }
    }
    out.expansionsAfter = b.expansions() - expansionsBefore;
    out.expansions = b.expansions();
    return out;
}

// compareRays with n random rays from in front of the scene towards the box of half-size
// `spread` around (0, 0, 0.5).
Result compareWithGraphWalk(const std::string& text, int n, double spread,
                            size_t expansionBytes = 16u << 20,
                            const InstanceBoxOptions& options = eagerExpansion()) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<Vec3> o, d;
    for (int i = 0; i < n; ++i) {
        o.push_back({u(rng) * 5, -6 + u(rng), u(rng) * 5});
        const Vec3 target{u(rng) * spread, u(rng) * spread, u(rng) * spread + 0.5};
        d.push_back(normalize(target - o.back()));
    }
    return compareRays(text, o, d, expansionBytes, options);
}

// In a scene with transparency every surface records the paint node instance that applied
// its material (its interior). The instances below such paint nodes are expanded, and each
// of their surfaces gives the interior the walk gives: a union painted as a whole one, each
// path to a paint node its own. (The top level stays the walk's there: its Deferred and
// Instance nodes do not carry paint nodes.)
TEST(TopLevel, ATransparentScenesExpandedInstancesGiveTheWalksInteriors) {
    const Result r = compareWithGraphWalk(R"(
material glass { pigment { color rgbf <0.8, 1, 0.9, 0.85> } interior { ior 1.45 } }
material amber { pigment { color rgbt <1, 0.7, 0.3, 0.6> } interior { ior 1.2 } }
{n = 3} S
S if(n > 0, 2, 1)
1: S -> paint(glass) (sphere ∪ move(0.6, 0, 0) uscale(0.8) sphere) ∪
        move(0, 0.3, 0.2) paint(amber) uscale(0.5) sphere ∪ cube
2: S -> move(-1, 0, 0.4) uscale(0.6) {n = n - 1} S ∪ move(1, 0, 0.4) uscale(0.6) {n = n - 1} S ∪
        move(0, 0, 1) uscale(0.6) paint(glass) {n = n - 1} S
)",
                                          2000, 1.5);
    EXPECT_GT(r.expansions, 0u);
    EXPECT_GT(r.hits, 200u);
    EXPECT_GT(r.interiors, 100u);
    EXPECT_FALSE(r.built);
}

// A pigment pattern needs the hit point in its paint node's frame. Instances with such
// paint nodes inside are expanded, each surface keeping the inverse matrices from the
// S-node to its paint node, and give the walk's points bit for bit, whatever the
// transformations between them.
TEST(TopLevel, PatternsPaintedInsideExpandedInstancesGetTheWalksPoints) {
    const Result r = compareWithGraphWalk(R"(
material marble { pigment { marble turbulence 0.5 scale 0.3 } }
material stripes { pigment { gradient x color_map { [0 color <1, 0, 0>] [1 color <0, 0, 1>] } } }
{n = 3} M
M if(n > 0, 2, 1)
1: M -> paint(marble) cube ∪ move(0, 0, 1.2) paint(stripes) rotz(30) uscale(0.5) sphere
2: M -> {n = n - 1} (move(-0.7, 0, 0) uscale(0.45) M ∪ move(0.7, 0, 0) rotx(20) uscale(0.45) M ∪
                     move(0, 0.7, 0) paint(stripes) scale(0.4, 0.5, 0.45) M)
)",
                                          2000, 1.2);
    EXPECT_GT(r.expansions, 0u);
    EXPECT_GT(r.hits, 200u);
    EXPECT_GT(r.painted, 200u);
    EXPECT_FALSE(r.built);
}

// A top level holds no paint node that records its frame or instance: its Instance and
// Deferred nodes would not pass it on to the surfaces below them, so it is the walk's (a
// marble Menger sponge, painted at the axiom: its copies of the expanded cubes are walked).
TEST(TopLevel, APaintNodeThatRecordsItsFrameAboveTheCopiesLeavesThemToTheWalk) {
    std::string text = R"(
material marble { pigment { marble turbulence 0.5 scale 0.3 } }
paint(marble) {n = 3} M
M if(n > 0, 2, 1)
1: M -> cube
2: M -> {n = n - 1} ()";
    const char* sep = "";
    for (int x = -1; x <= 1; ++x)  // (the 20 cubes of the Menger sponge's rule)
        for (int y = -1; y <= 1; ++y)
            for (int z = -1; z <= 1; ++z) {
                if ((x == 0) + (y == 0) + (z == 0) >= 2) continue;
                text += sep + ("move(" + std::to_string(x) + "*2/3, " + std::to_string(y) +
                               "*2/3, " + std::to_string(z) + "*2/3) uscale(1/3) M");
                sep = " ∪ ";
            }
    const Result r = compareWithGraphWalk(text + ")\n", 2000, 1.0);
    EXPECT_GT(r.hits, 200u);
    EXPECT_GT(r.painted, 200u);
    EXPECT_FALSE(r.built);
}

TEST(TopLevel, SierpinskiCopiesShareTheirInstanceAndHitTheWalksSurfaces) {
    // (a budget too small for the whole: the cache expands the instances of a deeper level)
    const Result r = compareWithGraphWalk(testing::sierpinski(5), 3000, 1.0, 256u << 10);
    ASSERT_TRUE(r.built);
    EXPECT_GE(r.copies, 16u);
    EXPECT_EQ(r.instances, 1u);  // one instance per depth
    EXPECT_GT(r.hits, 300u);
}

// Copies of an instance with glass or a pigment pattern painted inside it: the top level
// refers to the instance, and each surface painted there gets the interior and the point
// the walk gives, from the copy's instance path and its ray in the copy's frame.
TEST(TopLevel, CopiesOfInstancesPaintedInsideGetTheWalksInteriorsAndPoints) {
    for (const char* material : {"pigment { color rgbf <0.8, 1, 0.9, 0.85> } interior { ior 1.4 }",
                                 "pigment { marble turbulence 0.4 scale 0.2 }"}) {
        std::string text = testing::sierpinski(5);
        const size_t leaf = text.find("tetrahedron");
        ASSERT_NE(leaf, std::string::npos);
        text.insert(leaf, "paint(m) ");
        text = "material m { " + std::string(material) + " }\n" + text;
        const Result r = compareWithGraphWalk(text, 3000, 1.0, 256u << 10);
        ASSERT_TRUE(r.built) << material;
        EXPECT_GE(r.copies, 16u);
        EXPECT_GT(r.hits, 300u);
        EXPECT_GT(r.interiors + r.painted, 300u) << material;
    }
}

TEST(TopLevel, CopiesBeyondTheVisitsOfAFewHundredAreNotRefused) {
    // (only small instances are expanded, those of a deep level: thousands of copies, whose
    // top level takes more than kMaxVisits visits above them)
    InstanceBoxOptions small = eagerExpansion();
    small.maxUnrollWeight = 200;
    const Result r = compareWithGraphWalk(testing::sierpinski(8), 3000, 1.0, 16u << 20, small);
    ASSERT_TRUE(r.built);
    EXPECT_GT(r.copies, TopLevel::kMaxVisits / 4);
    EXPECT_EQ(r.instances, 1u);
    EXPECT_GT(r.hits, 300u);
}

TEST(TopLevel, FlowersInheritTheirCopiesMaterialsAndHitTheWalksSurfaces) {
    const Result r = compareWithGraphWalk(kFlowers, 1500, 1.5);
    ASSERT_TRUE(r.built);
    EXPECT_GE(r.copies, 4u);
    EXPECT_GT(r.hits, 200u);
}

TEST(TopLevel, TiesBetweenCopiesGoByTheInstancePathAsInTheWalk) {
    const Result r = compareWithGraphWalk(kTwins, 1500, 1.5);
    ASSERT_TRUE(r.built);
    EXPECT_GT(r.hits, 300u);
}

TEST(TopLevel, InstancesWithTheirOwnMatricesAndPaintAtTheRootHitTheWalksSurfaces) {
    const Result r = compareWithGraphWalk(kTurnedRoots, 1500, 1.5);
    ASSERT_TRUE(r.built);
    EXPECT_GE(r.copies, 2u);
    EXPECT_GT(r.hits, 300u);
}

TEST(TopLevel, UniqueInstancesAreDeferredToTheWalkAndHitItsSurfaces) {
    // (a budget that holds only the deeper levels: many copies, each its own instance)
    const Result r = compareWithGraphWalk(kUnique, 1500, 1.5, 64u << 10);
    ASSERT_TRUE(r.built);
    EXPECT_EQ(r.instances, 0u);
    EXPECT_GE(r.deferred, 4u);
    EXPECT_EQ(r.copies, 0u);  // (a deferred cut is no copy of a shared instance)
    EXPECT_GT(r.hits, 300u);
}

TEST(TopLevel, DeferredNodesTakeTheirCopiesMaterials) {
    const Result r = compareWithGraphWalk(kUniquePainted, 1500, 1.5, 64u << 10);
    ASSERT_TRUE(r.built);
    EXPECT_GE(r.deferred, 8u);
    EXPECT_GT(r.hits, 300u);
}

TEST(TopLevel, APatternBelowUniqueInstancesLeavesThemToTheWalk) {
    const Result r = compareWithGraphWalk(kUniqueBumpy, 1500, 1.5, 64u << 10);
    EXPECT_FALSE(r.built);
    EXPECT_GT(r.hits, 300u);
}

// The terrain's patches: one deferred node each where the cache expands them, whose rays
// still meet them in the cache (and expand those met twice).
TEST(TopLevel, TerrainPatchesAreDeferredAndStillExpandedByTheCache) {
    const std::string text = terrain(6);
    ASSERT_FALSE(text.empty());
    // A camera's rays (as the scene's, rows of neighbours that meet the same patches).
    std::vector<Vec3> o, d;
    for (int y = 0; y < 80; ++y)
        for (int x = 0; x < 80; ++x) {
            o.push_back({-0.75, -1.05, 1.0});
            d.push_back(normalize(Vec3{0.2 + x / 60.0, 0.2 + y / 60.0, -0.05} - o.back()));
        }
    const Result r = compareRays(text, o, d, 1u << 20, InstanceBoxOptions{});
    ASSERT_TRUE(r.built);
    EXPECT_GE(r.deferred, 32u);
    EXPECT_GT(r.expansionsAfter, 0u);
    EXPECT_GT(r.hits, 1000u);
}

TEST(TopLevel, ADifferenceAboveTheInstancesFallsBackToTheWalk) {
    const Result r = compareWithGraphWalk(kCsgAbove, 1500, 1.0);
    EXPECT_FALSE(r.built);
    EXPECT_GT(r.hits, 300u);
}

// n random rays (origins o, directions d) from in front of the scene towards its middle.
void fan(uint64_t seed, int n, std::vector<Vec3>& o, std::vector<Vec3>& d) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < n; ++i) {
        o.push_back({u(rng) * 5, -6 + u(rng), u(rng) * 5});
        d.push_back(normalize(Vec3{u(rng), u(rng), u(rng) + 0.5} - o.back()));
    }
}

// The first hits of rays from the origins o in the directions d through the top level alone.
std::vector<Hit> hitsOf(const TopLevel& top, const std::vector<Vec3>& o,
                        const std::vector<Vec3>& d) {
    UnrolledInstance::Scratch scratch;
    std::vector<Hit> hits(o.size());
    for (size_t i = 0; i < o.size(); ++i) {
        double tmax = 1e7;
        top.first(LocalRay{o[i], d[i]}, 1e-4, tmax, hits[i], false, scratch);
    }
    return hits;
}

// The rays (o, d) traced twice through the scene, so that its expansion cache expands
// what they meet twice.
void warmUp(const TraceScene& scene, const std::vector<Vec3>& o, const std::vector<Vec3>& d) {
    Tracer warm(scene);
    SurfaceHit h;
    for (int round = 0; round < 2; ++round)
        for (size_t i = 0; i < o.size(); ++i) warm.firstHit(o[i], d[i], 1e-4, 1e7, h);
}

TEST(TopLevel, CopiesReferToTheCachesInstanceWhichLivesOnWithTheTopLevel) {
    auto c = compile(testing::sierpinski(5));
    ASSERT_TRUE(c->graph);
    auto scene =
        std::make_unique<TraceScene>(*c->graph, computeBounds(*c->graph), true, eagerExpansion());
    scene->expansionBytes = 256u << 10;  // (the cache expands a level below the top)
    std::vector<Vec3> o, d;
    fan(5, 2000, o, d);
    warmUp(*scene, o, d);
    const auto one = TopLevel::build(*scene, scene->expansionCache(), scene->expansionBytes);
    const auto two = TopLevel::build(*scene, scene->expansionCache(), scene->expansionBytes);
    ASSERT_TRUE(one && two);
    ASSERT_EQ(one->instances(), 1u);
    EXPECT_EQ(one->sharedInstances(), 1u);
    // Both top levels refer to the one object the cache built, not to copies of their own.
    EXPECT_EQ(&one->instance(0), &two->instance(0));
    const std::vector<Hit> before = hitsOf(*one, o, d);
    scene.reset();  // the cache goes, and what it held (ASan: a use after free if freed)
    const std::vector<Hit> after = hitsOf(*one, o, d);
    size_t hits = 0;
    for (size_t i = 0; i < o.size(); ++i) {
        EXPECT_EQ(after[i].valid, before[i].valid) << "ray " << i;
        if (!before[i].valid) continue;
        ++hits;
        EXPECT_EQ(after[i].t, before[i].t) << "ray " << i;
        EXPECT_EQ(after[i].key, before[i].key) << "ray " << i;
    }
    EXPECT_GT(hits, 300u);
}

// Sierpinski order 5, whose expansion cache expands a level below the top, and the rays
// (o, d) of a fan through it.
class TopLevelOfOrder5 : public ::testing::Test {
  protected:
    void SetUp() override {
        c_ = compile(testing::sierpinski(5));
        ASSERT_TRUE(c_->graph);
        scene_ = std::make_unique<TraceScene>(*c_->graph, computeBounds(*c_->graph), true,
                                              eagerExpansion());
        scene_->expansionBytes = 256u << 10;
        fan(17, 2000, o, d);
    }
    std::unique_ptr<testing::Compiled> c_;
    std::unique_ptr<TraceScene> scene_;
    std::vector<Vec3> o, d;
};

// A tracer that finds no top level and then takes the lock after another has built and
// published one returns that one and does not build another: building again freed the
// published top level while other tracers traced it (a rare crash of frame sequences on
// two threads).
TEST_F(TopLevelOfOrder5, APublishedTopLevelIsNotBuiltAgain) {
    TraceScene& scene = *scene_;
    scene.twoLevel = false;  // (the warm-up's tracer builds none)
    warmUp(scene, o, d);
    scene.twoLevel = true;
    ASSERT_EQ(scene.topLevel(), nullptr);
    const TopLevel* other = nullptr;
    bool first = true;
    scene.beforeTopLock = [&] {  // another tracer builds it, between this one's look and lock
        if (!std::exchange(first, false)) return;
        other = scene.buildTopLevel();
    };
    const TopLevel* mine = scene.buildTopLevel();
    ASSERT_TRUE(other);
    EXPECT_EQ(mine, other);
    EXPECT_EQ(scene.topLevel(), other);
    const std::vector<Hit> hits = hitsOf(*other, o, d);  // (ASan: a use after free if freed)
    EXPECT_TRUE(std::any_of(hits.begin(), hits.end(), [](const Hit& x) { return x.valid; }));
}

// Shadow rays through the copies and their shared instance (which stop at their first
// surface and leave the hit's key and normal unset): one that ends at the first hit's t
// meets nothing (a surface at tmax only wins a tie with a hit already found), one that
// ends a step further meets it, and first hits traced after them are what they were.
TEST_F(TopLevelOfOrder5, ShadowRaysThroughCopiesEndAtTheFirstHit) {
    TraceScene& scene = *scene_;
    warmUp(scene, o, d);
    const TopLevel* top = scene.buildTopLevel();
    ASSERT_TRUE(top);
    const std::vector<Hit> before = hitsOf(*top, o, d);
    UnrolledInstance::Scratch scratch;
    size_t hits = 0;
    for (size_t i = 0; i < o.size(); ++i) {
        const LocalRay r{o[i], d[i]};
        Hit any;
        double end = 1e7;
        EXPECT_EQ(top->first(r, 1e-4, end, any, true, scratch), before[i].valid) << "ray " << i;
        if (!before[i].valid) continue;
        ++hits;
        end = before[i].t;
        EXPECT_FALSE(top->first(r, 1e-4, end, any = Hit{}, true, scratch)) << "ray " << i;
        end = std::nextafter(before[i].t, 1e7);
        EXPECT_TRUE(top->first(r, 1e-4, end, any = Hit{}, true, scratch)) << "ray " << i;
    }
    EXPECT_GT(hits, 300u);
    const std::vector<Hit> after = hitsOf(*top, o, d);
    for (size_t i = 0; i < o.size(); ++i) {
        ASSERT_EQ(after[i].valid, before[i].valid) << "ray " << i;
        if (!before[i].valid) continue;
        EXPECT_EQ(after[i].t, before[i].t) << "ray " << i;
        EXPECT_EQ(after[i].normal, before[i].normal) << "ray " << i;
        EXPECT_EQ(after[i].key, before[i].key) << "ray " << i;
    }
}

}  // namespace
}  // namespace pcsg::tracer
