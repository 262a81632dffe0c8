// The walk through the cyclic graph against a brute-force reference on the expanded tree.
//
// The reference expands the graph with test_support.h's Expander (every primitive instance
// with its toWorld matrix and the operators on its path), rebuilds the CSG tree of the
// operators from the paths, and for a ray:
//  - intersects the world ray with every instance in its object frame (primitives.h), so
//    the reference's t is the world parameter and its normal is the inverse transpose of
//    the instance's whole toWorld applied to the object's normal;
//  - takes the surfaces of a union as the surfaces of all its operands (a union reports
//    every surface, as POV-Ray's union does: the first one from outside is the entry);
//  - finds the surfaces of an intersection or difference by point classification: all the
//    boundaries of the primitives below it are candidates, and a candidate is a surface
//    where the membership of the CSG expression (insideSolid through ∪ ∩ \) changes from
//    one side to the other. That decides whether the ray enters or leaves there, and so
//    which way the outward normal must point (independently of span_list.h);
//  - the outward normal of a candidate is the primitive's, negated once for each
//    subtracted operand between the operator and the primitive.
// Tracer::firstHit must then give the nearest such surface (t, normal direction, material);
// anyHit must agree with its existence; and the same rays with culling turned off must
// give identical results, bit for bit.
#include "traversal.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bounds.h"
#include "primitives.h"
#include "sanitizer.h"
#include "test_support.h"

namespace pcsg::tracer {
namespace {

using testing::compile;

constexpr double kInf = std::numeric_limits<double>::infinity();

struct RefSurface {
    double t;
    Vec3 normal;  // unit; solids: outward; triangles: the inverse transpose of (b-a)x(c-a)
    uint32_t material;
    bool solid;
    int kind;         // 0: a solid under unions, 1: a surface of an intersection or difference,
                      // 2: a triangle
    bool entering;    // solids: the ray enters the solid (of the surface's owner) here
    Vec3 worldCross;  // triangles: (B-A)x(C-A) of the world corners, computed independently
};

// The expanded tree of a graph and the brute-force intersection of a ray with it.
class Reference {
  public:
    explicit Reference(const Graph& g) : g_(g) {
        testing::Expander expander(g, kLimit);
        const auto insts = expander.run();
        EXPECT_LT(insts.size(), kLimit) << "the test scene is too big for the reference";
        for (const auto& in : insts) {
            Inst inst;
            inst.kind = in.kind;
            std::copy(in.args.begin(), in.args.end(), inst.args);
            inst.toWorld = in.toWorld;
            inst.fromWorld = in.toWorld.inverse();
            inst.material = in.material;
            insts_.push_back(inst);
            const Box b = transformBox(inst.toWorld, primitiveBox(inst.kind, inst.args));
            if (b.isBounded()) {
                box_.extend(b);
                boxes_.push_back(b);
            }
            // Rebuild the operator tree: an operator occurrence is identified by its parent
            // occurrence and the operand of the parent the path continues into.
            int parent = -1;
            uint32_t key = 0;
            for (const auto& pn : in.path) {
                const Node& k = g.nodes[pn.node];
                if (k.kind != NodeKind::Operator) continue;
                int c = childOf(parent, key);
                if (c < 0) {
                    c = static_cast<int>(nodes_.size());
                    nodes_.push_back(RNode{k.kind, k.op(), pn.node, -1, {}});
                    setChild(parent, key, c);
                }
                parent = c;
                key = pn.childTaken;
            }
            const int leaf = static_cast<int>(nodes_.size());
            nodes_.push_back(
                RNode{NodeKind::Primitive, {}, in.node, static_cast<int>(insts_.size() - 1), {}});
            EXPECT_LT(childOf(parent, key), 0) << "two instances on one path";
            setChild(parent, key, leaf);
        }
    }

    size_t instances() const { return insts_.size(); }
    const Box& box() const { return box_; }
    // The world box of each bounded instance.
    const std::vector<Box>& instanceBoxes() const { return boxes_; }

    // Every surface along the whole line o + t d, in no particular order.
    std::vector<RefSurface> surfaces(const Vec3& o, const Vec3& d) const {
        std::vector<RefSurface> out;
        if (root_ >= 0) collectFirst(root_, o, d, out);
        return out;
    }

  private:
    static constexpr size_t kLimit = 20000;

    struct Inst {
        PrimitiveKind kind;
        double args[9] = {};
        Affine toWorld, fromWorld;
        uint32_t material;
    };
    struct RNode {
        NodeKind kind;
        CsgOp op;  // Operator
        NodeId graphNode;
        int inst;
        std::map<uint32_t, int> children;  // by operand index
    };
    struct Candidate {
        double t;
        Vec3 normal;  // world, outward for the expression (parity applied)
        uint32_t material;
    };

    const Graph& g_;
    std::vector<Inst> insts_;
    std::vector<RNode> nodes_;
    int root_ = -1;
    Box box_;
    std::vector<Box> boxes_;

    int childOf(int parent, uint32_t key) const {
        if (parent < 0) return root_;
        const auto it = nodes_[parent].children.find(key);
        return it == nodes_[parent].children.end() ? -1 : it->second;
    }
    void setChild(int parent, uint32_t key, int c) {
        if (parent < 0)
            root_ = c;
        else
            nodes_[parent].children[key] = c;
    }

    static Vec3 worldNormal(const Inst& in, const Vec3& n) {
        return in.fromWorld.transposedVector(n);
    }

    void collectFirst(int n, const Vec3& o, const Vec3& d, std::vector<RefSurface>& out) const {
        const RNode& node = nodes_[n];
        switch (node.kind) {
            case NodeKind::Primitive: {
                const Inst& in = insts_[node.inst];
                const Vec3 lo = in.fromWorld.point(o), ld = in.fromWorld.vector(d);
                if (isTriangle(in.kind)) {
                    Vec3 c[3];
                    triangleCorners(in.kind, in.args, c);
                    Boundary b;
                    if (!intersectTriangle(c[0], c[1], c[2], lo, ld, -kInf, kInf, b)) return;
                    const Vec3 a = in.toWorld.point(c[0]), bb = in.toWorld.point(c[1]),
                               cc = in.toWorld.point(c[2]);
                    out.push_back(RefSurface{b.t, normalize(worldNormal(in, b.normal)), in.material,
                                             false, 2, false, cross(bb - a, cc - a)});
                    return;
                }
                Span s[kMaxPrimitiveSpans];
                const int count = intersectSolid(in.kind, in.args, lo, ld, s);
                for (int k = 0; k < count; ++k)
                    for (const Boundary* b : {&s[k].in, &s[k].out})
                        if (std::isfinite(b->t))
                            out.push_back(RefSurface{b->t,
                                                     normalize(worldNormal(in, b->normal)),
                                                     in.material,
                                                     true,
                                                     0,
                                                     b == &s[k].in,
                                                     {}});
                return;
            }
            default: {
                if (node.kind == NodeKind::Operator && node.op == CsgOp::Union) {
                    for (const auto& [key, c] : node.children) collectFirst(c, o, d, out);
                    return;
                }
                std::vector<Candidate> cands;
                collectSolid(n, 1.0, o, d, cands);
                classify(n, cands, o, d, out);
                return;
            }
        }
    }

    // All finite boundaries of the primitives below n, with their outward normals for the
    // expression at the top (negated by each subtracted operand on the way).
    void collectSolid(int n, double parity, const Vec3& o, const Vec3& d,
                      std::vector<Candidate>& out) const {
        const RNode& node = nodes_[n];
        if (node.kind == NodeKind::Primitive) {
            const Inst& in = insts_[node.inst];
            EXPECT_FALSE(isTriangle(in.kind)) << "a triangle under an intersection or difference";
            Span s[kMaxPrimitiveSpans];
            const int count =
                intersectSolid(in.kind, in.args, in.fromWorld.point(o), in.fromWorld.vector(d), s);
            for (int k = 0; k < count; ++k)
                for (const Boundary* b : {&s[k].in, &s[k].out})
                    if (std::isfinite(b->t))
                        out.push_back(
                            Candidate{b->t, worldNormal(in, b->normal) * parity, in.material});
            return;
        }
        for (const auto& [key, c] : node.children)
            collectSolid(c, node.op == CsgOp::Difference && key > 0 ? -parity : parity, o, d, out);
    }

    bool inside(int n, const Vec3& p) const {
        const RNode& node = nodes_[n];
        if (node.kind == NodeKind::Primitive) {
            const Inst& in = insts_[node.inst];
            return insideSolid(in.kind, in.args, in.fromWorld.point(p));
        }
        switch (node.op) {
            case CsgOp::Union:
                for (const auto& [key, c] : node.children)
                    if (inside(c, p)) return true;
                return false;
            case CsgOp::Intersection:
                // An operand that expanded to nothing makes the intersection empty.
                if (node.children.size() != g_.nodes[node.graphNode].childCount) return false;
                for (const auto& [key, c] : node.children)
                    if (!inside(c, p)) return false;
                return true;
            case CsgOp::Difference: {
                const auto first = node.children.find(0);
                if (first == node.children.end() || !inside(first->second, p)) return false;
                for (const auto& [key, c] : node.children)
                    if (key > 0 && inside(c, p)) return false;
                return true;
            }
        }
        return false;
    }

    // The candidates where the membership of n changes are its surfaces.
    void classify(int n, std::vector<Candidate>& cands, const Vec3& o, const Vec3& d,
                  std::vector<RefSurface>& out) const {
        if (cands.empty()) return;
        std::sort(cands.begin(), cands.end(),
                  [](const Candidate& a, const Candidate& b) { return a.t < b.t; });
        // Groups of candidates at the same t (within rounding) are one boundary.
        std::vector<std::pair<size_t, size_t>> groups;
        for (size_t i = 0; i < cands.size();) {
            size_t j = i + 1;
            while (j < cands.size() &&
                   cands[j].t - cands[j - 1].t <= 1e-9 * (1 + std::fabs(cands[j].t)))
                ++j;
            groups.emplace_back(i, j);
            i = j;
        }
        auto at = [&](double t) { return inside(n, o + d * t); };
        bool before = at(cands.front().t - 1);
        for (size_t k = 0; k < groups.size(); ++k) {
            const auto [i, j] = groups[k];
            const double next = k + 1 < groups.size()
                                    ? 0.5 * (cands[j - 1].t + cands[groups[k + 1].first].t)
                                    : cands[j - 1].t + 1;
            const bool after = at(next);
            if (before != after)
                for (size_t m = i; m < j; ++m)
                    out.push_back(RefSurface{cands[m].t,
                                             normalize(cands[m].normal),
                                             cands[m].material,
                                             true,
                                             1,
                                             after,
                                             {}});
            before = after;
        }
    }
};

// A random ray aimed at the scene.
struct TestRay {
    Vec3 o, d;
    double tmin, tmax;
};

class RayGenerator {
  public:
    RayGenerator(const Box& box, const std::vector<Box>& parts, uint32_t seed)
        : box_(box), parts_(parts), rng_(seed) {}

    TestRay next() {
        const Vec3 c = box_.center();
        const double radius = 0.5 * length(box_.hi - box_.lo);
        // Most rays aim at a point of one instance's box, so that small parts get hit too.
        const Vec3 target = uni(0, 1) < 0.7 ? pointIn(parts_[index(parts_.size())]) : pointIn(box_);
        TestRay r;
        const double kind = uni(0, 1);
        if (kind < 0.6) {
            // From outside, through a point of the box: the camera rays.
            r.o = c + unitVector() * (radius * uni(1.2, 3));
            r.d = normalize(target - r.o);
            r.tmin = 1e-4;
            r.tmax = 1e7;
        } else if (kind < 0.8) {
            // From inside the box, in any direction: reflected rays, rays from inside solids.
            r.o = pointIn(box_);
            r.d = unitVector();
            r.tmin = 1e-4;
            r.tmax = 1e7;
        } else {
            // Segments, as shadow rays: the far end anywhere near the box.
            r.o = c + unitVector() * (radius * uni(1.2, 3));
            r.d = normalize(target - r.o);
            r.tmin = 1e-3;
            r.tmax = length(target - r.o) * uni(0.5, 1.5);
        }
        if (uni(0, 1) < 0.1) {
            // A direction of another length: t is then not the distance, but the same t
            // must come out everywhere.
            const double f = uni(0.3, 3);
            r.d = r.d * f;
            r.tmin /= f;
            r.tmax /= f;
        }
        return r;
    }

  private:
    Box box_;
    const std::vector<Box>& parts_;
    std::mt19937_64 rng_;

    double uni(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
    size_t index(size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(rng_); }
    Vec3 pointIn(const Box& b) {
        return {uni(b.lo.x, b.hi.x), uni(b.lo.y, b.hi.y), uni(b.lo.z, b.hi.z)};
    }
    Vec3 unitVector() {
        for (;;) {
            const Vec3 v{uni(-1, 1), uni(-1, 1), uni(-1, 1)};
            const double l = length(v);
            if (l > 0.1 && l <= 1) return v / l;
        }
    }
};

std::string vecText(const Vec3& v) {
    std::ostringstream s;
    s.precision(17);
    s << "<" << v.x << ", " << v.y << ", " << v.z << ">";
    return s.str();
}

std::string rayText(const TestRay& r) {
    std::ostringstream s;
    s.precision(17);
    s << "ray origin " << vecText(r.o) << " dir " << vecText(r.d) << " t in (" << r.tmin << ", "
      << r.tmax << ")";
    return s.str();
}

struct Tally {
    int rays = 0, hits = 0, ambiguous = 0, failures = 0;
    std::vector<std::string> messages;
    int kinds[3] = {};  // hits on solids under unions, on ∩/\ surfaces, on triangles

    void fail(const std::string& m) {
        ++failures;
        if (messages.size() < 6) messages.push_back(m);
    }
};

// Fires `count` rays at the scene and compares the tracer with the reference, with and
// without culling, and with and without the step memo (the plain walk has neither).
Tally compareWithReference(const char* text, int count, uint32_t seed) {
    Tally tally;
    auto c = compile(text);
    if (!c->graph) {
        tally.fail("does not compile");
        return tally;
    }
    const Graph& g = *c->graph;
    const Reference ref(g);
    if (ref.instances() == 0 || ref.box().isEmpty()) {
        tally.fail("the scene expands to nothing");
        return tally;
    }
    const TraceScene culled(g, computeBounds(g));
    TraceScene unculled(g, computeBounds(g));
    unculled.useBounds = false;
    unculled.stepMemoLog2 = 0;
    Tracer tracer(culled), plain(unculled);
    RayGenerator gen(ref.box(), ref.instanceBoxes(), seed);

    for (int i = 0; i < count; ++i) {
        const TestRay r = gen.next();
        ++tally.rays;
        SurfaceHit hit, hit2;
        const bool found = tracer.firstHit(r.o, r.d, r.tmin, r.tmax, hit);
        const bool any = tracer.anyHit(r.o, r.d, r.tmin, r.tmax);
        const bool found2 = plain.firstHit(r.o, r.d, r.tmin, r.tmax, hit2);
        const bool any2 = plain.anyHit(r.o, r.d, r.tmin, r.tmax);

        // Culling never changes a result.
        if (found != found2 || (found && (hit.t != hit2.t || !(hit.normal == hit2.normal) ||
                                          hit.material != hit2.material)))
            tally.fail(rayText(r) + ": culling or the step memo changes the hit (with both: " +
                       (found ? "t " + std::to_string(hit.t) : std::string("none")) +
                       ", without: " +
                       (found2 ? "t " + std::to_string(hit2.t) : std::string("none")) + ")");
        if (any != found || any2 != found2)
            tally.fail(rayText(r) + ": anyHit " + std::to_string(any) + " but firstHit " +
                       std::to_string(found));

        // The reference: the nearest surface in (tmin, tmax).
        const auto surfaces = ref.surfaces(r.o, r.d);
        double best = kInf;
        for (const auto& s : surfaces)
            if (s.t > r.tmin && s.t < r.tmax) best = std::min(best, s.t);
        const bool refFound = best < kInf;
        const double tol = 1e-9 * (1 + std::fabs(best));
        // A surface within rounding of either end of the interval may go either way.
        bool nearEnd = false;
        for (const auto& s : surfaces)
            if (std::fabs(s.t - r.tmin) <= 1e-9 * (1 + std::fabs(r.tmin)) ||
                std::fabs(s.t - r.tmax) <= 1e-9 * (1 + std::fabs(r.tmax)))
                nearEnd = true;
        if (nearEnd) {
            ++tally.ambiguous;
            continue;
        }
        if (found != refFound) {
            tally.fail(rayText(r) + ": tracer " +
                       (found ? "hits at t " + std::to_string(hit.t) : std::string("misses")) +
                       ", reference " +
                       (refFound ? "hits at t " + std::to_string(best) : std::string("misses")));
            continue;
        }
        if (!found) continue;
        ++tally.hits;
        if (std::fabs(hit.t - best) > tol) {
            std::ostringstream s;
            s.precision(17);
            s << rayText(r) << ": t " << hit.t << ", reference " << best;
            tally.fail(s.str());
            continue;
        }
        // The normal: finite, non-zero, unit after normalisation, the reference's direction.
        const double len = length(hit.normal);
        if (!(len > 0) || !std::isfinite(len)) {
            tally.fail(rayText(r) + ": degenerate normal " + vecText(hit.normal));
            continue;
        }
        const Vec3 n = hit.normal / len;
        if (std::fabs(length(n) - 1) > 1e-12) tally.fail(rayText(r) + ": normal not unit");
        // Any reference surface at the same t (edges: several) may be the one.
        bool matched = false;
        std::string seen;
        for (const auto& s : surfaces) {
            if (std::fabs(s.t - best) > tol) continue;
            seen += " " + vecText(s.normal) + " material " + std::to_string(s.material) + ";";
            if (s.material != hit.material || dot(n, s.normal) < 1 - 1e-9) continue;
            if (s.solid) {
                // Outward: against the ray where it enters, along it where it leaves
                // (unless the ray grazes the surface).
                const double cosine = dot(n, normalize(r.d));
                if (std::fabs(cosine) > 1e-6 && (cosine < 0) != s.entering) continue;
            } else if (std::fabs(dot(n, normalize(s.worldCross))) < 1 - 1e-9) {
                continue;  // not perpendicular to the world triangle
            }
            matched = true;
            ++tally.kinds[s.kind];
            break;
        }
        if (!matched)
            tally.fail(rayText(r) + ": t " + std::to_string(hit.t) + " normal " + vecText(n) +
                       " material " + std::to_string(hit.material) +
                       " matches no reference surface there:" + seen);
    }
    return tally;
}

// minHits: the least number of hits of each kind (solids under unions, surfaces of
// intersections and differences, triangles) the scene must get.
void expectAgreement(const char* text, int count, uint32_t seed, std::array<int, 3> minHits) {
    const Tally t = compareWithReference(text, count, seed);
    std::string all;
    for (const auto& m : t.messages) all += "\n  " + m;
    EXPECT_EQ(t.failures, 0) << t.failures << " of " << t.rays << " rays disagree:" << all;
    for (int k = 0; k < 3; ++k)
        EXPECT_GE(t.kinds[k], minHits[k]) << "too few hits of kind " << k << " to test anything";
    EXPECT_LE(t.ambiguous, t.rays / 100) << "too many rays end on a surface";
}

constexpr int kRays = kAddressSanitizer ? 400 : 3000;

// Mirrors (flipxz, flipyz, flipxy), a shear, rot about a slanted axis, matrix, rotations
// by parameters, all six solid primitives with a torus of parameter radius, paint at two
// levels (the innermost wins), one S-node with two rules and C-nodes: 384 instances.
const char* kTransforms = R"(
material red   { color <1,0,0> }
material green { color <0,1,0> }
material blue  { color <0,0,1> }
{n = 3; a = 20; s = 0.3} M
M if(n > 0, 2, 1)
1: M -> paint(red) rot(1, 1, 0, a) scale(0.4, 0.2, 0.3) cube ∪
        paint(blue) zshear(0.5, -0.3) move(0.5, 0, 0) uscale(s) sphere ∪
        move(0, 0, -0.6) rotx(a) torus(0.5, s*0.4) ∪
        move(-0.5, 0.2, 0) scale(0.3, 0.3, 0.5) cone ∪
        move(0.3, -0.5, 0) zshear(-0.4, 0.2) uscale(0.3) tetrahedron ∪
        move(0, 0.5, -0.3) rot(0, 1, 1, -a) scale(0.2, 0.2, 0.6) cylinder
2: M -> {n = n-1; a = a + 15; s = s*0.9} (
            flipxz move(0.8, 0.6, 0) rotz(a) uscale(0.6) M ∪
            flipyz move(0.7, 0.3, 0.2) uscale(0.55) M ∪
            paint(green) flipxy move(0, 0.5, 0.6) roty(a) uscale(0.5) M ∪
            matrix(1,0.2,0, 0,1,0.3, 0.1,0,1, 0,-0.6,-0.4) zshear(0.2, 0.1) uscale(0.5) M )
)";

// ∪ ∩ \ nested in each other, with S-nodes, C-nodes and T-nodes under intersections and
// differences (span lists through the whole graph), a half-space, mirrored and sheared
// operands, subtracted operands with their own material (cut faces), tori with parameter
// radii under ∪ and under \.
const char* kCsg = R"(
material red   { color <1,0,0> }
material green { color <0,1,0> }
material blue  { color <0,0,1> }
material gold  { color <1,0.8,0> }
{k = 2; r = 0.25} A
A if(k > 0, 2, 1)
1: A -> paint(red) (sphere \ move(0.5, 0, 0.3) uscale(0.7) paint(blue) cube) ∪ torus(1.2, r)
2: A -> paint(blue) torus(1.5, r) ∪
        (paint(green) cylinder ∩ move(0, 0, 0.5) rotx(20) sphere) ∪
        move(2.5, 0, 0) ((cube \ paint(red) flipxy move(0, 0, -0.5) uscale(0.8) cone) ∩
                         zshear(0.3, 0.2) uscale(1.2) sphere) ∪
        move(-2.5, 0, 0) (sphere \ (move(0.5, 0, 0) uscale(0.6) sphere ∪
                                    paint(gold) move(-0.5, 0, 0.2) uscale(0.6) sphere ∪
                                    rotx(90) move(0, 0, -1.5) scale(0.2, 0.2, 3) cylinder)) ∪
        move(0, 2.5, 0) uscale(0.8) (rotx(15) plane ∩ sphere ∩ {k2 = 3} B) ∪
        move(0, -2.5, 0) (cube \ {k2 = 2} flipxz B) ∪
        move(0, 0, -2) (torus(1, r) \ move(1, 0, 0) uscale(0.5) paint(gold) cube) ∪
        {k = k-1; r = r*0.8} move(0, 0, 2) rotz(40) uscale(0.6) A
B if(k2 > 0, 2, 1)
1: B -> uscale(0.45) sphere
2: B -> {k2 = k2 - 1} (move(0.5, 0, 0) uscale(0.7) B ∪ move(-0.5, 0, 0.1) rotz(30) uscale(0.7) B ∪
                       matrix(0.6,0,0, 0,0.6,0, 0.2,0,0.6, 0,0.5,0) B)
)";

// Triangles (tri1, tri2, triangle with parameter corners) under unions, sheared and
// mirrored, a stochastic module: choose() picks among three rules, rand() turns, tilts
// and lifts: every instance must make the same choices for every ray.
const char* kStochastic = R"(
settings { seed 7 }
material red   { color <1,0,0> }
material green { color <0,1,0> }
{n = 5; h = 0.2} P
P if(n > 0, choose(0.5, 0.3, 0.2) + 1, 1)
1: P -> paint(green) triangle(0,0,h, 1,0,0, 0,1,2*h) ∪ tri2
2: P -> tri1 ∪ paint(red) zshear(h, -h) tri2 ∪
        {n = n-1; h = h + rand()*0.3} move(0.3, 0.2, 0.4) rotz(rand()*90) flipxz uscale(0.8) P
3: P -> uscale(0.3) sphere ∪ {n = n-1} (
            move(0, 0, 0.5) rot(1, 0, 1, rand()*180) flipyz uscale(0.7) P ∪
            {h = -h} move(0.5, 0.5, 0.5) flipxy uscale(0.6) P )
4: P -> {n = n-2} matrix(1,0,0.3, 0,1,0, 0,0,1, 0,0,0.3) P ∪ move(0, 0, -0.5) scale(1, 1, 0.2) torus(0.5, 0.1 + rand()*0.2)
)";

TEST(Traversal, TransformsMirrorsAndShearsAgreeWithTheExpandedTree) {
    expectAgreement(kTransforms, kRays, 1, {kRays / 4, 0, 0});
}

TEST(Traversal, CsgAgreesWithTheExpandedTree) {
    expectAgreement(kCsg, kRays, 2, {kRays / 40, kRays / 4, 0});
}

TEST(Traversal, StochasticTrianglesAgreeWithTheExpandedTree) {
    expectAgreement(kStochastic, kRays, 3, {kRays / 20, 0, kRays / 8});
}

TEST(Traversal, SierpinskiAgreesWithTheExpandedTree) {
    // Constant T-chains (fused by TraceScene) and 256 tetrahedra touching at corners.
    expectAgreement(testing::kSierpinski, kRays, 4, {kRays / 4, 0, 0});
}

// Scenes whose answer can be stated: a union under a difference or an intersection whose
// first operand lies far from the ray (its box is culled) must keep its other operands.
struct StatedHit {
    const char* scene;
    Vec3 origin, dir;
    bool found;
    double t;
    Vec3 normal;  // direction only
};

void expectStated(const StatedHit& s) {
    auto c = compile(s.scene);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    for (bool useBounds : {true, false}) {
        TraceScene scene(g, computeBounds(g));
        scene.useBounds = useBounds;
        Tracer tracer(scene);
        SurfaceHit hit;
        const bool found = tracer.firstHit(s.origin, s.dir, 1e-4, 1e7, hit);
        EXPECT_EQ(found, s.found) << s.scene << "\nwith culling " << useBounds;
        EXPECT_EQ(tracer.anyHit(s.origin, s.dir, 1e-4, 1e7), s.found);
        if (!found || !s.found) continue;
        EXPECT_NEAR(hit.t, s.t, 1e-12) << s.scene << "\nwith culling " << useBounds;
        const Vec3 n = normalize(hit.normal);
        EXPECT_GT(dot(n, normalize(s.normal)), 1 - 1e-12)
            << s.scene << "\nwith culling " << useBounds << ": normal " << vecText(n);
    }
}

TEST(Traversal, UnionUnderDifferenceKeepsOperandsAfterACulledFirstOne) {
    // A ball with a spherical cavity of radius 0.5; the subtracted union's first operand
    // is far away at y = 5. From inside the shell at x = -0.75 towards +x, the first
    // surface is the cavity's wall at x = -0.5, facing +x (out of the solid, into the
    // cavity).
    expectStated({"sphere \\ (move(0, 5, 0) uscale(0.5) sphere ∪ uscale(0.5) sphere)",
                  {-0.75, 0, 0},
                  {1, 0, 0},
                  true,
                  0.25,
                  {1, 0, 0}});
    // From outside, through the cavity's side wall: enters the ball at x = -1.
    expectStated({"sphere \\ (move(0, 5, 0) uscale(0.5) sphere ∪ uscale(0.5) sphere)",
                  {-3, 0, 0},
                  {1, 0, 0},
                  true,
                  2,
                  {-1, 0, 0}});
}

TEST(Traversal, UnionUnderIntersectionKeepsOperandsAfterACulledFirstOne) {
    // The ball of radius 1 cut by (a far sphere ∪ a ball of radius 0.5): the small ball.
    expectStated({"sphere ∩ (move(0, 5, 0) uscale(0.5) sphere ∪ uscale(0.5) sphere)",
                  {-3, 0, 0},
                  {1, 0, 0},
                  true,
                  2.5,
                  {-1, 0, 0}});
    // And with the far operand second, which never was a problem.
    expectStated({"sphere ∩ (uscale(0.5) sphere ∪ move(0, 5, 0) uscale(0.5) sphere)",
                  {-3, 0, 0},
                  {1, 0, 0},
                  true,
                  2.5,
                  {-1, 0, 0}});
}

// A plane beside a recursive sub-graph that reaches above it: the union's leading operand
// (TraceScene::unionLeads) is the plane, whose hit narrows the walk of the tetrahedra.
const char* kSeaBeside = R"(
material sea  { color <0, 0, 1> }
material land { color <0, 1, 0> }
paint(sea) move(0, 0, 0.1) plane ∪ {n = 4} paint(land) move(0.2, 0.1, -0.6) S
S if(n > 0, 2, 1)
1: S -> tetrahedron
2: S -> {n = n-1} ( move(0.5, 0.5, 0.5) uscale(0.5) S ∪ move(-0.5, -0.5, 0.5) uscale(0.5) S ∪
                    move(0.5, -0.5, -0.5) uscale(0.5) S ∪ move(-0.5, 0.5, -0.5) uscale(0.5) S )
)";

TEST(Traversal, UnionLeadsAreThePrimitivesBesideSubGraphs) {
    auto c = compile(kSeaBeside);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const TraceScene scene(g, computeBounds(g));
    ASSERT_EQ(scene.unionLeads.size(), g.nodes.size());
    int unions = 0;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        const Node& node = g.nodes[n];
        if (node.kind != NodeKind::Operator) {
            EXPECT_EQ(scene.unionLeads[n], 0u);
            continue;
        }
        ++unions;
        if (node.childCount == 2)  // the axiom's: the plane (under paint and move) leads
            EXPECT_EQ(scene.unionLeads[n], 1u);
        else  // the rule's four S references: none
            EXPECT_EQ(scene.unionLeads[n], 0u);
    }
    EXPECT_EQ(unions, 2);
    // A union of primitives alone keeps its order by the boxes' entry: no leads. A T-node
    // with a parameter is no leaf (its matrix is evaluated).
    auto leadsOf = [](const char* text) {
        auto only = compile(text);
        EXPECT_TRUE(only->graph);
        const TraceScene sc(*only->graph, computeBounds(*only->graph));
        std::vector<uint32_t> leads;
        for (NodeId n = 0; n < only->graph->nodes.size(); ++n)
            if (only->graph->nodes[n].kind == NodeKind::Operator) leads.push_back(sc.unionLeads[n]);
        return leads;
    };
    EXPECT_EQ(leadsOf("sphere ∪ move(2, 0, 0) cube"), std::vector<uint32_t>{0});
    EXPECT_EQ(leadsOf("{a = rand()} (move(0, 0, a) sphere ∪ cube)"), std::vector<uint32_t>{2});
}

// The first hits (and any hits) of tracers a and b along the ray agree; a's first hit in `ha`,
// and whether there was one.
bool expectSameHits(Tracer& a, Tracer& b, const Vec3& o, const Vec3& d, SurfaceHit& ha) {
    const std::string ray = vecText(o) + " towards " + vecText(d);
    SurfaceHit hb;
    const bool fa = a.firstHit(o, d, 1e-4, 1e7, ha), fb = b.firstHit(o, d, 1e-4, 1e7, hb);
    EXPECT_EQ(fa, fb) << ray;
    EXPECT_EQ(a.anyHit(o, d, 1e-4, 1e7), b.anyHit(o, d, 1e-4, 1e7)) << ray;
    if (!fa || !fb) return false;
    EXPECT_EQ(ha.t, hb.t) << ray;
    EXPECT_EQ(ha.normal, hb.normal) << ray;
    EXPECT_EQ(ha.material, hb.material) << ray;
    EXPECT_EQ(ha.path, hb.path) << ray;
    return true;
}

TEST(Traversal, UnionLeadsGiveTheSameHitsWithFewerVisits) {
    auto c = compile(kSeaBeside);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    TraceScene led(g, computeBounds(g)), plain(g, computeBounds(g));
    plain.unionLeads.assign(g.nodes.size(), 0);
    led.expansionBytes = plain.expansionBytes = 0;  // (visits of the graph walk alone)
    Tracer a(led), b(plain);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int planeHits = 0, landHits = 0;
    for (int k = 0; k < kRays; ++k) {
        // (over the tetrahedra's square, x and y in [-0.8, 1.2] x [-0.9, 1.1] at the plane)
        const Vec3 o{0.2 + u(rng) * 1.5, 0.1 + u(rng) * 1.5, 2 + u(rng)};
        const Vec3 d =
            normalize(Vec3{u(rng) * 0.3 - (o.x - 0.2) * 0.2, u(rng) * 0.3 - (o.y - 0.1) * 0.2, -1});
        SurfaceHit ha;
        if (!expectSameHits(a, b, o, d, ha)) continue;
        ++(g.materials[ha.material].color.z == 1 ? planeHits : landHits);  // sea: blue
    }
    EXPECT_GT(planeHits, kRays / 4);
    EXPECT_GT(landHits, kRays / 20);
    // Rays that reach the plane beside or through the tetrahedra's boxes no longer walk
    // the tetrahedra below it.
    EXPECT_LT(a.nodeVisits(), b.nodeVisits() * 9 / 10);
}

// A terrain whose sub-triangles' operands are `C-node T-nodes S-node` chains (one of them
// rotated, one a union with a sphere, which keeps its static box), for the operands' boxes
// per instance (operand_boxes.h).
const char* kChainedTerrain = R"(
{ cnt = 6; delta = 0.5; x1 = 0; y1 = 0; z1 = 0; z2 = 0.1; z3 = -0.1 } T
T if(cnt > 0, 2, 1)
1: T -> move(0,0,z1) zshear(z2-z1, z3-z1) tri1
2: T -> {cnt = cnt-1; z2 = (z1+z2)/2 + (rand(x1*7+y1*3) - 0.5)*delta; delta = delta*0.5}
          scale(0.5,0.5,1) T ∪
        {cnt = cnt-1; x1 = x1 + 0.5; z3 = (z1+z3)/2 + (rand(x1*5+y1*11) - 0.5)*delta}
          move(0.5,0,0) scale(0.5,0.5,1) rotz(3) T ∪
        {cnt = cnt-1; x1 = x1 + 0.25; z1 = (z1+z2)/2 + (rand(x1*3+y1*5) - 0.5)*delta}
          move(0.5,0.5,0) scale(0.5,0.5,1) T ∪
        {cnt = cnt-1; y1 = y1 + 0.5; z1 = z1 + rand(x1+y1*13)*delta; delta = delta*0.5}
          move(0,0.5,0) (scale(0.5,0.5,1) T ∪ move(0.1,0.1,0) uscale(0.05) sphere)
)";

TEST(Traversal, OperandBoxesGiveTheSameHitsWithFewerVisits) {
    auto c = compile(kChainedTerrain);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    InstanceBoxOptions always;
    always.trial = UINT32_MAX;  // (exact boxes at every depth)
    always.minWeight = 1;
    TraceScene boxed(g, computeBounds(g), true, always), plain(g, computeBounds(g), true, always);
    plain.operandBoxes = false;
    boxed.expansionBytes = plain.expansionBytes = 0;  // (visits of the graph walk alone)
    Tracer a(boxed), b(plain);
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int hits = 0;
    for (int k = 0; k < kRays; ++k) {
        // (low over the terrain, as a landscape's camera sees it)
        const Vec3 o{0.5 + u(rng) * 2, -1.5 + u(rng) * 0.5, 0.6 + u(rng) * 0.3};
        const Vec3 d = normalize(Vec3{u(rng) * 0.4, 1, -0.35 + u(rng) * 0.2});
        SurfaceHit ha;
        hits += expectSameHits(a, b, o, d, ha);
    }
    EXPECT_GT(hits, kRays / 8);
    // The operands a ray's box misses are no longer stepped into.
    EXPECT_LT(a.nodeVisits(), b.nodeVisits() * 9 / 10);
}

}  // namespace
}  // namespace pcsg::tracer
