// The DOT writer of `pcsg graph` on hand-built graphs: which edges are back edges, that
// every node is drawn once, the labels, and that Graphviz accepts what it writes.
#include "graph_dot.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>

#include "child_process.h"

namespace pcsg::tools {
namespace {

// An expression that only carries source text (the writer reads nothing else).
ExprId textExpr(Graph& g, const std::string& text) {
    const ExprId e = g.addConstant(0);
    g.exprs[e].text = text;
    return e;
}

NodeId transform(Graph& g, TransformOp op, const std::vector<std::string>& args, NodeId child) {
    Transform t;
    t.op = op;
    t.firstArg = static_cast<uint32_t>(g.args.size());
    t.argCount = static_cast<uint32_t>(args.size());
    for (const auto& a : args) g.args.push_back(textExpr(g, a));
    g.transforms.push_back(t);
    return g.addNode(NodeKind::Transform, static_cast<uint32_t>(g.transforms.size() - 1), {child});
}

NodeId calc(Graph& g, const std::vector<std::pair<std::string, std::string>>& assigns, NodeId child,
            bool simultaneous = false) {
    Calc c;
    c.first = static_cast<uint32_t>(g.assignments.size());
    c.count = static_cast<uint32_t>(assigns.size());
    c.simultaneous = simultaneous;
    for (const auto& [name, value] : assigns)
        g.assignments.push_back({g.slot(name), textExpr(g, value)});
    g.calcs.push_back(c);
    return g.addNode(NodeKind::Calc, static_cast<uint32_t>(g.calcs.size() - 1), {child});
}

NodeId primitive(Graph& g, PrimitiveKind kind, const std::vector<std::string>& args = {}) {
    Primitive p;
    p.kind = kind;
    p.firstArg = static_cast<uint32_t>(g.args.size());
    p.argCount = static_cast<uint32_t>(args.size());
    for (const auto& a : args) g.args.push_back(textExpr(g, a));
    g.primitives.push_back(p);
    return g.addNode(NodeKind::Primitive, static_cast<uint32_t>(g.primitives.size() - 1), {});
}

// A module's S-node with `rules` placeholder children, filled in by setRule.
NodeId module(Graph& g, const std::string& name, const std::string& select, uint32_t rules) {
    Module m;
    m.name = name;
    m.select = textExpr(g, select);
    g.modules.push_back(m);
    const NodeId s = g.addNode(NodeKind::Select, static_cast<uint32_t>(g.modules.size() - 1),
                               std::vector<NodeId>(rules, 0));
    g.modules.back().node = s;
    return s;
}

void setRule(Graph& g, NodeId s, uint32_t rule, NodeId body) {
    g.edges[g.nodes[s].firstChild + rule - 1] = body;
}

// Figure 3a of the paper, as the builder would make it:
//   {c=6} S;  S if(c > 0,2,1);  1: S -> tetrahedron
//   2: S -> {c=c-1} ( move(..) uscale(0.5) S ∪ ... four times )
Graph sierpinski() {
    Graph g;
    g.materials.push_back(Material{});
    const NodeId s = module(g, "S", "if(c > 0,2,1)", 2);
    setRule(g, s, 1, primitive(g, PrimitiveKind::Tetrahedron));
    const char* moves[4][3] = {{"0.5", "0.5", "0.5"},
                               {"-0.5", "-0.5", "0.5"},
                               {"0.5", "-0.5", "-0.5"},
                               {"-0.5", "0.5", "-0.5"}};
    std::vector<NodeId> parts;
    for (auto& m : moves)
        parts.push_back(transform(g, TransformOp::Move, {m[0], m[1], m[2]},
                                  transform(g, TransformOp::UScale, {"0.5"}, s)));
    const NodeId u = g.addOperator(CsgOp::Union, parts);
    setRule(g, s, 2, calc(g, {{"c", "c-1"}}, u));
    g.axiom = calc(g, {{"c", "6"}}, s);
    return g;
}

size_t countBack(const DotLayout& l, NodeId to) {
    size_t n = 0;
    for (const auto& e : l.edges) n += e.back && e.to == to;
    return n;
}

// Whether the graph without its back edges has no cycle (Kahn's algorithm).
bool acyclicWithoutBackEdges(const Graph& g, const DotLayout& l) {
    std::vector<uint32_t> indegree(g.nodes.size(), 0);
    std::multimap<NodeId, NodeId> out;
    for (const auto& e : l.edges)
        if (!e.back) {
            ++indegree[e.to];
            out.emplace(e.from, e.to);
        }
    std::vector<NodeId> ready;
    for (NodeId n = 0; n < g.nodes.size(); ++n)
        if (indegree[n] == 0) ready.push_back(n);
    size_t seen = 0;
    while (!ready.empty()) {
        const NodeId n = ready.back();
        ready.pop_back();
        ++seen;
        auto [b, e] = out.equal_range(n);
        for (auto it = b; it != e; ++it)
            if (--indegree[it->second] == 0) ready.push_back(it->second);
    }
    return seen == g.nodes.size();
}

TEST(GraphDot, SierpinskiHasOneSNodeWithTwoRulesAndFourBackEdges) {
    const Graph g = sierpinski();
    const DotLayout l = layoutGraph(g);
    const NodeId s = g.modules[0].node;

    size_t ruleEdges = 0, edgesIntoS = 0;
    for (const auto& e : l.edges) {
        ruleEdges += e.from == s;
        edgesIntoS += e.to == s;
    }
    EXPECT_EQ(ruleEdges, 2u);
    EXPECT_EQ(countBack(l, s), 4u);
    EXPECT_EQ(edgesIntoS, 5u);  // the four back edges and the axiom's C-node
    for (const auto& e : l.edges) {
        if (e.back) {
            EXPECT_EQ(g.nodes[e.from].kind, NodeKind::Transform);
            EXPECT_EQ(e.to, s);
        }
    }
    // The axiom's {c=6} -> S is a forward edge: it is what puts S at the top.
    for (const auto& e : l.edges) {
        if (e.from == g.axiom) {
            EXPECT_FALSE(e.back);
        }
    }
    EXPECT_EQ(l.order.size(), g.nodes.size());
    EXPECT_EQ(l.order.front(), g.axiom);
    EXPECT_EQ(l.edges.size(), g.edges.size());
    EXPECT_TRUE(acyclicWithoutBackEdges(g, l));
}

TEST(GraphDot, SierpinskiDotText) {
    const Graph g = sierpinski();
    const std::string dot = toDot(g, {"sierpinski.pcsg"});
    const NodeId s = g.modules[0].node;

    EXPECT_NE(dot.find("digraph pcsg {"), std::string::npos);
    EXPECT_NE(dot.find("label=\"sierpinski.pcsg\""), std::string::npos);
    EXPECT_NE(dot.find(fmt::format("n{} [label=\"S\\nif(c > 0,2,1)\", shape=box", s)),
              std::string::npos);
    EXPECT_NE(dot.find("label=\"move(0.5, 0.5, 0.5)\""), std::string::npos);
    EXPECT_NE(dot.find("label=\"uscale(0.5)\""), std::string::npos);
    EXPECT_NE(dot.find("label=\"{c = c-1}\""), std::string::npos);
    EXPECT_NE(dot.find("label=\"{c = 6}\""), std::string::npos);
    EXPECT_NE(dot.find("label=\"tetrahedron\""), std::string::npos);
    EXPECT_NE(dot.find("label=\"∪\""), std::string::npos);
    EXPECT_NE(dot.find(fmt::format("axiom -> n{};", g.axiom)), std::string::npos);

    // Exactly four dashed, non-constraining edges, all into S; two labelled rule edges.
    const std::regex back("n(\\d+) -> n(\\d+) \\[style=dashed, constraint=false");
    size_t backs = 0;
    for (auto it = std::sregex_iterator(dot.begin(), dot.end(), back); it != std::sregex_iterator();
         ++it) {
        ++backs;
        EXPECT_EQ(std::stoul((*it)[2]), s);
    }
    EXPECT_EQ(backs, 4u);
    EXPECT_NE(
        dot.find(fmt::format("n{} -> n", s) + std::to_string(g.child(s, 0)) + " [label=\"1\"]"),
        std::string::npos);
    EXPECT_NE(
        dot.find(fmt::format("n{} -> n", s) + std::to_string(g.child(s, 1)) + " [label=\"2\"]"),
        std::string::npos);
}

TEST(GraphDot, ASharedDefinitionIsDrawnOnce) {
    Graph g;
    // Leaf = sphere \ cube, used by both operands of a union.
    const NodeId leaf = g.addOperator(CsgOp::Difference, {primitive(g, PrimitiveKind::Sphere),
                                                          primitive(g, PrimitiveKind::Cube)});
    const NodeId a = transform(g, TransformOp::RotZ, {"45"}, leaf);
    const NodeId b = transform(g, TransformOp::FlipXZ, {}, leaf);
    g.axiom = g.addOperator(CsgOp::Union, {a, b});
    const std::string dot = toDot(g);

    const std::string decl = fmt::format("n{} [label=", leaf);
    EXPECT_EQ(dot.find(decl), dot.rfind(decl));
    EXPECT_NE(dot.find(fmt::format("n{} -> n{};", a, leaf)), std::string::npos);
    EXPECT_NE(dot.find(fmt::format("n{} -> n{};", b, leaf)), std::string::npos);
    // The difference operator's backslash is escaped for DOT; flips have no arguments.
    EXPECT_NE(dot.find(fmt::format("n{} [label=\"\\\\\"", leaf)), std::string::npos);
    EXPECT_NE(dot.find("label=\"flipxz\""), std::string::npos);
    EXPECT_NE(dot.find("label=\"rotz(45)\""), std::string::npos);
    EXPECT_EQ(dot.find("dashed"), std::string::npos);  // no cycle, no back edge
}

TEST(GraphDot, MutualRecursionBreaksEveryCycleAtAnSNode) {
    // Terrain-like: T1 refers to itself and to T2, T2 to itself and to T1.
    Graph g;
    const NodeId t1 = module(g, "T1", "if(n > 0, 2, 1)", 2);
    const NodeId t2 = module(g, "T2", "if(n > 0, 2, 1)", 2);
    setRule(g, t1, 1, primitive(g, PrimitiveKind::Tri1));
    setRule(g, t2, 1, primitive(g, PrimitiveKind::Tri2));
    setRule(g, t1, 2,
            calc(g, {{"n", "n-1"}},
                 g.addOperator(CsgOp::Union, {transform(g, TransformOp::UScale, {"0.5"}, t1),
                                              transform(g, TransformOp::UScale, {"0.5"}, t2)})));
    setRule(g, t2, 2,
            calc(g, {{"n", "n-1"}},
                 g.addOperator(CsgOp::Union, {transform(g, TransformOp::UScale, {"0.5"}, t2),
                                              transform(g, TransformOp::UScale, {"0.5"}, t1)})));
    g.axiom = calc(g, {{"n", "5"}}, g.addOperator(CsgOp::Union, {t1, t2}));

    const DotLayout l = layoutGraph(g);
    EXPECT_TRUE(acyclicWithoutBackEdges(g, l));
    for (const auto& e : l.edges) {
        if (e.back) {
            EXPECT_EQ(g.nodes[e.to].kind, NodeKind::Select);
        }
    }
    // T1's self reference, T2's self reference and T2's reference to T1 close cycles;
    // T1 -> T2 is the edge that first reaches T2.
    EXPECT_EQ(countBack(l, t1), 2u);
    EXPECT_EQ(countBack(l, t2), 1u);
}

TEST(GraphDot, NotationBShowsFormalsAndConditions) {
    Graph g;
    Module m;
    m.name = "S";
    m.notationB = true;
    m.formals = {g.slot("c")};
    m.conditions = {textExpr(g, "c == 0"), kNone};
    g.modules.push_back(m);
    const NodeId s = g.addNode(NodeKind::Select, 0, {0, 0});
    g.modules[0].node = s;
    setRule(g, s, 1, primitive(g, PrimitiveKind::Tetrahedron));
    setRule(g, s, 2, calc(g, {{"c", "c-1"}}, transform(g, TransformOp::UScale, {"0.5"}, s), true));
    g.axiom = calc(g, {{"c", "6"}}, s, true);
    const std::string dot = toDot(g);
    EXPECT_NE(dot.find("label=\"S(c)\""), std::string::npos);
    EXPECT_NE(dot.find("[label=\"1: c == 0\"]"), std::string::npos);
    EXPECT_NE(dot.find("[label=\"2\"]"), std::string::npos);
}

TEST(GraphDot, LabelsOfEveryKind) {
    Graph g;
    Material bark;
    bark.name = "bark";
    bark.color = {0.35, 0.22, 0.1};
    g.materials = {Material{}, bark};
    const NodeId torus = primitive(g, PrimitiveKind::Torus, {"R", "r*0.5"});
    const NodeId p = g.addNode(NodeKind::Paint, 1, {torus});
    const NodeId c = calc(g, {{"sd", "rand(x)"}, {"rnd", "sd*2"}}, p);
    const NodeId i = g.addOperator(CsgOp::Intersection, {c, primitive(g, PrimitiveKind::Plane)});
    g.axiom = transform(g, TransformOp::Matrix,
                        {"1", "0", "0", "0", "1", "0", "0", "0", "1", "0", "0", "2"}, i);

    EXPECT_EQ(nodeLabel(g, torus), "torus(R, r*0.5)");
    EXPECT_EQ(nodeLabel(g, p), "paint(bark)");
    EXPECT_EQ(nodeLabel(g, c), "{sd = rand(x)\nrnd = sd*2}");
    EXPECT_EQ(nodeLabel(g, i), "∩");
    EXPECT_EQ(nodeLabel(g, g.axiom), "matrix(1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 2)");
    const std::string dot = toDot(g);
    // The paint node shows its (sRGB-encoded) colour, with readable text on it.
    EXPECT_NE(dot.find("fillcolor=\"#a08159\", fontcolor=\"black\""), std::string::npos) << dot;
}

TEST(GraphDot, LongAndOddTextIsShortenedAndEscaped) {
    Graph g;
    const std::string longText(200, 'x');
    g.axiom = calc(g, {{"a", longText}, {"b", "1 +\n   2"}}, primitive(g, PrimitiveKind::Sphere));
    const std::string label = nodeLabel(g, g.axiom);
    EXPECT_NE(label.find(std::string(60, 'x') + "..."), std::string::npos);
    EXPECT_EQ(label.find(std::string(61, 'x')), std::string::npos);
    EXPECT_NE(label.find("b = 1 + 2"), std::string::npos);

    EXPECT_EQ(dotEscape("a\"b\\c\nd"), "a\\\"b\\\\c\\nd");
    EXPECT_EQ(dotEscape("∪ ok"), "∪ ok");
    EXPECT_EQ(dotEscape(std::string("x\xff\xc3y\x01")), "x??y ");
}

TEST(GraphDot, AVeryDeepChainDoesNotExhaustTheStack) {
    Graph g;
    NodeId n = primitive(g, PrimitiveKind::Sphere);
    for (int i = 0; i < 200000; ++i) n = g.addOperator(CsgOp::Union, {n});
    g.axiom = n;
    const DotLayout l = layoutGraph(g);
    EXPECT_EQ(l.order.size(), g.nodes.size());
    EXPECT_EQ(l.edges.size(), g.nodes.size() - 1);
}

TEST(GraphDot, GraphvizAcceptsTheOutput) {
    if (!inPath("dot")) GTEST_SKIP() << "Graphviz's dot is not installed";
    const Graph g = sierpinski();
    const auto dir = std::filesystem::temp_directory_path() /
                     ("pcsg-graph-dot-test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const auto dotFile = dir / "s.dot", svgFile = dir / "s.svg";
    std::ofstream(dotFile) << toDot(g, {"sierpinski \"fig. 3b\""});
    const ChildResult r = runChild({"dot", "-Tsvg", dotFile.string(), "-o", svgFile.string()});
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
    std::ifstream in(svgFile);
    const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.find("if(c &gt; 0,2,1)"), std::string::npos);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pcsg::tools
