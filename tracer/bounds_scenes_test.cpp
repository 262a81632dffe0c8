// Soundness of the hyper-bounding boxes on every scene in scenes/: expand each
// scene completely and check that every primitive instance lies inside the box of every
// node on its path, in that node's frame, and inside the per-depth box of every S-node on
// its path. Nothing may ever be culled that is there.
//
// The scenes are big (terrain.pcsg has 2,097,152 triangles), so the check streams: a
// depth-first walk by the one semantics (eval.h) checks each instance as it is produced
// and stores none. To keep it fast, each node on the walk's stack carries the
// intersection of its box with the boxes of the ancestors that share its frame (a point
// is in every one of those boxes if and only if it is in their intersection), so an
// instance is checked once per frame on its path, with the exact axis-aligned box of the
// image of its own box in that frame (Arvo's method is exact for one affine map).
//
// What must lie in a node's box is what the node stands for: below a clipping node (an
// intersection, or a difference entered through an operand it subtracts) only what the
// clipping node keeps. So, going up an instance's path, the region checked is the
// primitive's box until the first clipping node, then that clipping node's box until the
// next one, and so on; a clipping node itself is not checked against what lies below it.
//
// The raw analysis is checked (no safety padding) with a relative tolerance of 1e-9 for
// rounding. Sides that are infinite (planes) must be infinite in the box too.
//
// Under AddressSanitizer the walk stops after the first kSanitizerLimit instances of each
// scene (in depth-first order, so the sample is deterministic); the Release build checks
// them all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bounds.h"
#include "compiler.h"
#include "eval.h"
#include "primitives.h"
#include "sanitizer.h"

namespace pcsg::tracer {
namespace {

constexpr uint64_t kSanitizerLimit = 150'000;

const char* kindName(NodeKind k) {
    switch (k) {
        case NodeKind::Select:
            return "S";
        case NodeKind::Transform:
            return "T";
        case NodeKind::Calc:
            return "C";
        case NodeKind::Paint:
            return "paint";
        case NodeKind::Operator:
            return "operator";
        case NodeKind::Primitive:
            return "primitive";
    }
    return "?";
}

std::string boxText(const Box& b) {
    std::ostringstream s;
    s.precision(17);
    s << "[" << b.lo.x << ", " << b.hi.x << "] x [" << b.lo.y << ", " << b.hi.y << "] x [" << b.lo.z
      << ", " << b.hi.z << "]";
    return s.str();
}

// `inner` lies in `outer` up to a relative tolerance; infinite sides must match.
bool boxInside(const Box& inner, const Box& outer) {
    if (inner.isEmpty()) return true;
    for (int i = 0; i < 3; ++i) {
        const double tlo = 1e-9 * std::max(1.0, std::fabs(inner.lo[i]));
        const double thi = 1e-9 * std::max(1.0, std::fabs(inner.hi[i]));
        if (!(inner.lo[i] >= outer.lo[i] - tlo)) return false;
        if (!(inner.hi[i] <= outer.hi[i] + thi)) return false;
    }
    return true;
}

struct SoundnessReport {
    uint64_t instances = 0;
    uint64_t checks = 0;  // (instance, frame) containment checks
    uint64_t failures = 0;
    std::string firstFailures;  // the first few, described
    bool truncated = false;     // stopped at the instance limit
};

// The streaming check: a depth-first expansion of the graph (docs/language.md semantics,
// through eval.h) that checks each primitive instance against the boxes on its path.
class StreamingSoundness {
  public:
    StreamingSoundness(const Graph& g, const Bounds& b, uint64_t limit)
        : g_(g), b_(b), limit_(limit) {}

    SoundnessReport run() {
        frames_.clear();
        framePool_.clear();
        std::vector<double>& f = paramFrame(0);
        initFrame(g_, f.data());
        frames_.push_back(FrameMaps{Affine::identity(), Affine::identity()});
        walk(g_.axiom, f.data(), 0, kRootPath, 0, 0);
        return report_;
    }

  private:
    struct FrameMaps {
        Affine toWorld, fromWorld;
    };
    struct Entry {
        NodeId node;
        uint32_t depth;
        uint32_t frame;           // index into frames_
        uint32_t childTaken = 0;  // operators: the operand the walk is in
        uint32_t runTop;          // the highest entry of this entry's run (same frame, no clip)
        Box runBox;               // intersection of the boxes of the entries [runTop, this]
    };

    const Graph& g_;
    const Bounds& b_;
    uint64_t limit_;
    SoundnessReport report_;
    std::vector<Entry> path_;
    std::vector<FrameMaps> frames_;
    std::vector<std::vector<double>> framePool_;  // parameter frames by C-node nesting

    std::vector<double>& paramFrame(size_t level) {
        while (framePool_.size() <= level)
            framePool_.emplace_back(std::max<size_t>(g_.slotCount(), 1));
        return framePool_[level];
    }

    bool clips(const Entry& e) const {
        const Node& n = g_.nodes[e.node];
        return n.is(CsgOp::Intersection) || (n.is(CsgOp::Difference) && e.childTaken > 0);
    }

    Box ownBox(NodeId n, uint32_t depth) const {
        Box box = b_.node[n];
        if (g_.nodes[n].kind == NodeKind::Select) box = intersect(box, b_.select(g_, n, depth));
        return box;
    }

    void push(NodeId n, uint32_t depth, uint32_t frame) {
        Entry e{n, depth, frame, 0, static_cast<uint32_t>(path_.size()), ownBox(n, depth)};
        if (!path_.empty()) {
            const Entry& parent = path_.back();
            if (parent.frame == frame && !clips(parent)) {
                e.runTop = parent.runTop;
                e.runBox = intersect(e.runBox, parent.runBox);
            }
        }
        path_.push_back(e);
    }

    void walk(NodeId n, const double* frame, size_t level, uint64_t path, uint32_t depth,
              uint32_t frameIndex) {
        if (report_.instances >= limit_) {
            report_.truncated = true;
            return;
        }
        const Node& node = g_.nodes[n];
        const EvalState st{frame, path};
        if (node.kind == NodeKind::Select) ++depth;
        push(n, depth, frameIndex);
        switch (node.kind) {
            case NodeKind::Select: {
                checkDepth(g_, n, depth, st);
                const uint32_t r = selectRule(g_, n, st);
                walk(g_.child(n, r), frame, level, pathRule(path, r), depth, frameIndex);
                break;
            }
            case NodeKind::Calc: {
                std::vector<double>& next = paramFrame(level + 1);
                applyCalc(g_, n, st, next.data());
                walk(g_.child(n), next.data(), level + 1, path, depth, frameIndex);
                break;
            }
            case NodeKind::Transform: {
                const Affine toWorld = frames_[frameIndex].toWorld * transformMatrix(g_, n, st);
                frames_.push_back(FrameMaps{toWorld, toWorld.inverse()});
                walk(g_.child(n), frame, level, path, depth,
                     static_cast<uint32_t>(frames_.size() - 1));
                frames_.pop_back();
                break;
            }
            case NodeKind::Paint:
                walk(g_.child(n), frame, level, path, depth, frameIndex);
                break;
            case NodeKind::Operator:
                for (uint32_t i = 0; i < node.childCount; ++i) {
                    path_.back().childTaken = i;
                    walk(g_.child(n, i), frame, level, pathChild(path, i), depth, frameIndex);
                }
                break;
            case NodeKind::Primitive: {
                const Primitive& p = g_.primitives[node.payload];
                if (p.kind == PrimitiveKind::Empty) break;
                double args[9] = {};
                primitiveArgs(g_, n, st, args);
                ++report_.instances;
                checkInstance(primitiveBox(p.kind, args), frameIndex);
                break;
            }
        }
        path_.pop_back();
    }

    // Checks the primitive at the top of path_ (its box `pb`, in frame `pf`).
    void checkInstance(const Box& pb, uint32_t pf) {
        Box region = pb;
        const Affine* regionToWorld = &frames_[pf].toWorld;
        int64_t j = static_cast<int64_t>(path_.size()) - 1;
        while (j >= 0 && !region.isEmpty()) {
            const Entry& e = path_[static_cast<size_t>(j)];
            const Affine m = frames_[e.frame].fromWorld * *regionToWorld;
            const Box image = transformBox(m, region);
            ++report_.checks;
            if (!boxInside(image, e.runBox)) fail(image, static_cast<size_t>(j));
            const int64_t next = static_cast<int64_t>(e.runTop) - 1;
            if (next < 0) break;
            const Entry& up = path_[static_cast<size_t>(next)];
            if (clips(up)) {
                // What the clipping node keeps of this instance: its image there, cut by
                // the boxes of the other operands of an intersection, or by the first
                // operand of a difference. That is what must lie in the clipping node's
                // box and in the boxes above it.
                region = image;  // the run below a clipping node is in its frame
                const Node& c = g_.nodes[up.node];
                for (uint32_t i = 0; i < c.childCount; ++i) {
                    if (i == up.childTaken) continue;
                    if (c.is(CsgOp::Difference) && i > 0) break;
                    region = intersect(region, b_.node[g_.child(up.node, i)]);
                }
                regionToWorld = &frames_[up.frame].toWorld;
            }
            j = next;
        }
    }

    // Finds which box of the run [runTop, j] the image leaves, and describes it.
    void fail(const Box& image, size_t j) {
        ++report_.failures;
        if (report_.failures > 5) return;
        std::ostringstream s;
        for (size_t k = path_[j].runTop; k <= j; ++k) {
            const Entry& e = path_[k];
            const Box own = ownBox(e.node, e.depth);
            if (boxInside(image, own)) continue;
            s << "instance " << report_.instances << ": the box " << boxText(image)
              << " of what lies below is not inside the box " << boxText(own) << " of "
              << kindName(g_.nodes[e.node].kind) << "-node " << e.node << " (depth " << e.depth
              << ", " << g_.where(g_.nodes[e.node].loc) << ")\n";
            break;
        }
        report_.firstFailures += s.str();
    }
};

std::vector<std::string> sceneFiles() {
    std::vector<std::string> out;
    for (const auto& entry : std::filesystem::directory_iterator(PCSG_SCENES_DIR))
        if (entry.path().extension() == ".pcsg") out.push_back(entry.path().stem().string());
    std::sort(out.begin(), out.end());
    return out;
}

struct LoadedScene {
    std::string text;
    Diagnostics diags;
    std::optional<Graph> graph;
};

std::unique_ptr<LoadedScene> loadScene(const std::string& name) {
    auto s = std::make_unique<LoadedScene>();
    const std::string path = std::string(PCSG_SCENES_DIR) + "/" + name + ".pcsg";
    s->graph = compileFile(path, s->text, s->diags);
    return s;
}

BoundsOptions rawAnalysis() {
    BoundsOptions opt;
    opt.pad = false;  // check the analysis itself, not the safety margin
    return opt;
}

class BoundsOnScenes : public ::testing::TestWithParam<std::string> {};

TEST_P(BoundsOnScenes, EveryInstanceLiesInEveryBoxOnItsPath) {
    const auto scene = loadScene(GetParam());
    ASSERT_TRUE(scene->graph) << scene->diags.format();
    const Graph& g = *scene->graph;
    const Bounds b = computeBounds(g, rawAnalysis());
    const uint64_t limit = kAddressSanitizer ? kSanitizerLimit : UINT64_MAX;
    const SoundnessReport r = StreamingSoundness(g, b, limit).run();
    EXPECT_GT(r.instances, 0u);
    EXPECT_GE(r.checks, r.instances);
    // The walk must see every instance: the counts the scenes' header comments state.
    if (!r.truncated) {
        const std::pair<const char*, uint64_t> stated[] = {{"sierpinski", 4096},
                                                           {"sierpinski_pl", 4096},
                                                           {"landsberg", 2 * 65536},
                                                           {"terrain", 2 * 1048576}};
        for (const auto& [name, count] : stated)
            if (GetParam() == name) {
                EXPECT_EQ(r.instances, count);
            }
    }
    EXPECT_EQ(r.failures, 0u) << GetParam() << ": " << r.failures << " of " << r.checks
                              << " checks failed; the first:\n"
                              << r.firstFailures;
    RecordProperty("instances", std::to_string(r.instances));
    if (r.truncated) RecordProperty("sampled", "first instances only (sanitizer build)");
}

INSTANTIATE_TEST_SUITE_P(Scenes, BoundsOnScenes, ::testing::ValuesIn(sceneFiles()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                             return info.param;
                         });

TEST(BoundsOnScenesCheck, AllScenesAreListed) {
    // The parameterised test above must not silently run on nothing.
    const auto files = sceneFiles();
    EXPECT_GE(files.size(), 11u);
    EXPECT_NE(std::find(files.begin(), files.end(), "terrain"), files.end());
}

TEST(BoundsOnScenesCheck, DetectsABoxThatIsTooSmall) {
    // The check must be able to fail: shrink one node's box a little, on a real scene, and
    // the instances that stick out must be reported. Each kind of node is tried.
    const auto scene = loadScene("seed001_tree");
    ASSERT_TRUE(scene->graph) << scene->diags.format();
    const Graph& g = *scene->graph;
    const Bounds good = computeBounds(g, rawAnalysis());
    ASSERT_EQ(StreamingSoundness(g, good, UINT64_MAX).run().failures, 0u);
    bool shrunk[8] = {};
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        const auto k = static_cast<size_t>(g.nodes[n].kind);
        const Box& box = good.node[n];
        if (shrunk[k] || !box.isBounded()) continue;
        Bounds bad = good;
        // Pull the top face down to the middle (the boxes need not be tight: the interval
        // analysis may take rules that no instance takes).
        bad.node[n].hi.z = box.center().z;
        if (g.nodes[n].kind == NodeKind::Select)
            for (uint32_t d = 0; d < bad.levels; ++d) {
                Box& db = bad.depthBox[static_cast<size_t>(g.nodes[n].payload) * bad.levels + d];
                if (db.isBounded()) db.hi.z = db.center().z;
            }
        const SoundnessReport r = StreamingSoundness(g, bad, UINT64_MAX).run();
        EXPECT_GT(r.failures, 0u) << kindName(g.nodes[n].kind) << "-node " << n
                                  << " shrunk without a report";
        shrunk[k] = true;
    }
    for (NodeKind k : {NodeKind::Select, NodeKind::Transform, NodeKind::Calc, NodeKind::Paint,
                       NodeKind::Operator, NodeKind::Primitive})
        EXPECT_TRUE(shrunk[static_cast<size_t>(k)]) << "no " << kindName(k) << "-node tried";
}

}  // namespace
}  // namespace pcsg::tracer
