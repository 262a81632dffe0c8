// Helpers shared by the tracer's tests (header-only, so that it stays out of the library):
// compiling scene text, and a small recursive walker that expands a graph by the one
// semantics, recording every primitive instance with the nodes on its path.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "compiler.h"
#include "eval.h"
#include "instance_boxes.h"

namespace pcsg::tracer::testing {

struct Compiled {
    std::string text;
    Diagnostics diags;
    std::optional<Graph> graph;
};

inline std::unique_ptr<Compiled> compile(std::string text) {
    auto c = std::make_unique<Compiled>();
    c->text = std::move(text);
    c->graph = compileSource("test.pcsg", c->text, c->diags);
    if (!c->graph) ADD_FAILURE() << "scene does not compile:\n" << c->diags.format();
    return c;
}

// One node on an instance's path: the node, its S-node depth, and the map from the node's
// frame to the world.
struct PathNode {
    NodeId node;
    uint32_t depth;
    Affine toWorld;
    uint32_t childTaken = 0;  // operators: the operand the path continues into
};

struct Instance {
    NodeId node;  // the primitive
    PrimitiveKind kind;
    std::vector<double> args;
    Affine toWorld;
    uint32_t material;
    std::vector<PathNode> path;
};

// Expands the graph (recursively: for small test scenes only). Stops after `limit`
// instances.
class Expander {
  public:
    explicit Expander(const Graph& g, size_t limit = 200000) : g_(g), limit_(limit) {}

    std::vector<Instance> run() {
        std::vector<double> frame(g_.slotCount());
        initFrame(g_, frame.data());
        walk(g_.axiom, frame, kRootPath, 0, Affine::identity(), 0);
        return std::move(out_);
    }

  private:
    const Graph& g_;
    size_t limit_;
    std::vector<Instance> out_;
    std::vector<PathNode> path_;

    void walk(NodeId n, const std::vector<double>& frame, uint64_t path, uint32_t depth,
              const Affine& world, uint32_t material) {
        if (out_.size() >= limit_) return;
        const Node& node = g_.nodes[n];
        const EvalState st{frame.data(), path};
        if (node.kind == NodeKind::Select) ++depth;
        path_.push_back(PathNode{n, depth, world});
        switch (node.kind) {
            case NodeKind::Select: {
                checkDepth(g_, n, depth, st);
                const uint32_t r = selectRule(g_, n, st);
                walk(g_.child(n, r), frame, pathRule(path, r), depth, world, material);
                break;
            }
            case NodeKind::Calc: {
                std::vector<double> next(g_.slotCount());
                applyCalc(g_, n, st, next.data());
                walk(g_.child(n), next, path, depth, world, material);
                break;
            }
            case NodeKind::Transform:
                walk(g_.child(n), frame, path, depth, world * transformMatrix(g_, n, st), material);
                break;
            case NodeKind::Paint:
                walk(g_.child(n), frame, path, depth, world, node.payload);
                break;
            case NodeKind::Operator:
                for (uint32_t i = 0; i < node.childCount; ++i) {
                    path_.back().childTaken = i;
                    walk(g_.child(n, i), frame, pathChild(path, i), depth, world, material);
                }
                break;
            case NodeKind::Primitive: {
                const Primitive& p = g_.primitives[node.payload];
                Instance inst{n, p.kind, {}, world, material, path_};
                inst.args.resize(p.constant ? p.values.size() : p.argCount);
                if (!inst.args.empty()) primitiveArgs(g_, n, st, inst.args.data());
                if (p.kind != PrimitiveKind::Empty) out_.push_back(std::move(inst));
                break;
            }
        }
        path_.pop_back();
    }
};

// The instance a scene's axiom C-node hands to the S-node below it ({n = 4} S): that
// S-node and the frame, for tests that expand or box it with other parameter values.
struct AxiomInstance {
    NodeId select = kNone;
    std::vector<double> frame;
};
inline AxiomInstance axiomInstance(const Graph& g) {
    AxiomInstance a{g.child(g.axiom), std::vector<double>(g.slotCount())};
    std::vector<double> root(g.slotCount());
    initFrame(g, root.data());
    applyCalc(g, g.axiom, EvalState{root.data(), kRootPath}, a.frame.data());
    return a;
}

// Expand wherever an instance is met a second time, from the first instance on.
inline InstanceBoxOptions eagerExpansion() {
    InstanceBoxOptions o;
    o.trial = 1;
    o.minExpandWeight = 1;
    o.maxUnrollWeight = 1u << 20;
    return o;
}

// A branching plant n levels deep: paints, choose(), rand(), CSG leaves, a shear.
inline std::string branchingPlant(int n) {
    return R"(
material bark { color <0.4, 0.3, 0.2> }
material leaf { color <0.2, 0.6, 0.1>  phong 0.3 }
settings { seed 3 }
{n = )" + std::to_string(n) +
           R"(; a = 35} P
P if(n > 0, choose(0.7, 0.3) + 1, 1)
1: P -> paint(leaf) (move(0,0,0.3) scale(0.3,0.1,0.3) sphere ∩ cylinder)
2: P -> paint(bark) scale(0.1,0.1,1) cylinder ∪
        {n = n-1} move(0,0,1) rotz(rand()*360) (rotx(a) uscale(0.7) P ∪ roty(-a) uscale(0.6) P)
3: P -> torus(0.5, 0.1) ∪ {n = n-1} move(0,0,0.2) zshear(0.2, 0.1) flipxz uscale(0.8) P
)";
}

// Every S-node instance's box from `a` and from `b`, following the derivation from the
// axiom (recursively: small systems only); returns how many were compared.
inline size_t expectSameBoxes(const Graph& g, const InstanceBoxes& a, const InstanceBoxes& b) {
    auto wa = a.makeWorker(), wb = b.makeWorker();
    size_t checks = 0;
    auto walk = [&](auto&& self, NodeId n, const std::vector<double>& frame, uint64_t path,
                    uint32_t depth) -> void {
        const Node& node = g.nodes[n];
        const EvalState st{frame.data(), path};
        if (node.kind == NodeKind::Select) {
            ++depth;
            ++checks;
            EXPECT_EQ(a.box(*wa, n, depth, frame.data(), path),
                      b.box(*wb, n, depth, frame.data(), path))
                << "module " << g.modules[node.payload].name << " at depth " << depth;
            const uint32_t r = selectRule(g, n, st);
            return self(self, g.child(n, r), frame, pathRule(path, r), depth);
        }
        if (node.kind == NodeKind::Calc) {
            std::vector<double> next(g.slotCount());
            applyCalc(g, n, st, next.data());
            return self(self, g.child(n), next, path, depth);
        }
        if (node.kind == NodeKind::Operator)
            for (uint32_t i = 0; i < node.childCount; ++i)
                self(self, g.child(n, i), frame, pathChild(path, i), depth);
        if (node.kind == NodeKind::Transform || node.kind == NodeKind::Paint)
            self(self, g.child(n), frame, path, depth);
    };
    std::vector<double> frame(g.slotCount());
    initFrame(g, frame.data());
    walk(walk, g.axiom, frame, kRootPath, 0);
    return checks;
}

// A few systems from the paper and beyond, shared by the tests.

// The Sierpinski tetrahedron of the given order: one instance per depth, each four times
// the size of the one below.
inline std::string sierpinski(int order) {
    return "\n{c = " + std::to_string(order) + R"(} S
S if(c > 0, 2, 1)
1: S -> tetrahedron
2: S -> {c = c-1} ( move(0.5,0.5,0.5) uscale(0.5) S ∪ move(-0.5,-0.5,0.5) uscale(0.5) S ∪
                    move(0.5,-0.5,-0.5) uscale(0.5) S ∪ move(-0.5,0.5,-0.5) uscale(0.5) S )
)";
}
inline const std::string kSierpinskiText = sierpinski(4);
inline const char* const kSierpinski = kSierpinskiText.c_str();  // (order 4)

// The scene file scenes/terrain.pcsg at order `order` (its cnt) instead of 10 ("" when the
// file or its cnt is not found).
inline std::string terrain(int order) {
    std::ifstream in(std::string(PCSG_SCENES_DIR) + "/terrain.pcsg");
    std::stringstream text;
    text << in.rdbuf();
    std::string s = text.str();
    const size_t at = s.find("cnt = 10;");
    if (at == std::string::npos) return "";
    return s.replace(at, 9, "cnt = " + std::to_string(order) + ";");
}

// A flower head of p petals: 21 petals as a chain of unions 21 deep, each a rotation
// further on; each value of p is an instance of its own.
inline const char* const kFlower = R"(
material petal { color <1, 1, 0.9> }
{p = 21} F
F if(p > 0, 2, 1)
1: F -> scale(0.2, 0.2, 0.1) sphere
2: F -> paint(petal) roty(-12 - 10*mod(p, 2)) move(0.45, 0, 0) scale(0.36, 0.08, 0.02) sphere ∪
        {p = p-1} rotz(360/21) F
)";

}  // namespace pcsg::tracer::testing
