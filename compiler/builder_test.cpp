// Tests of the builder: the graph it makes for each construct, checked by its structure
// and by walking it with the shared evaluation code exactly as the renderers do.
#include "builder.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "compile_test_util.h"
#include "compiler.h"
#include "eval.h"

namespace pcsg {
namespace {

// The graph as the builder makes it: fold_constants_test.cpp tests the folding.
std::unique_ptr<testing::Compiled> compile(std::string text) {
    return testing::compileUnfolded(std::move(text));
}

// --- a walk of the graph by the one semantics (see the project's preamble) ---

struct Leaf {
    PrimitiveKind kind;
    Affine world;
    uint32_t material;
    std::vector<double> frame;
    std::vector<double> args;
};

void walk(const Graph& g, NodeId n, const std::vector<double>& frame, uint64_t path, uint32_t depth,
          const Affine& world, uint32_t material, std::vector<Leaf>& out) {
    const Node& node = g.nodes[n];
    const EvalState s{frame.data(), path};
    switch (node.kind) {
        case NodeKind::Select: {
            checkDepth(g, n, depth + 1, s);
            const uint32_t r = selectRule(g, n, s);
            walk(g, g.child(n, r), frame, pathRule(path, r), depth + 1, world, material, out);
            return;
        }
        case NodeKind::Calc: {
            std::vector<double> next(g.slotCount());
            applyCalc(g, n, s, next.data());
            walk(g, g.child(n), next, path, depth, world, material, out);
            return;
        }
        case NodeKind::Transform:
            walk(g, g.child(n), frame, path, depth, world * transformMatrix(g, n, s), material,
                 out);
            return;
        case NodeKind::Paint:
            walk(g, g.child(n), frame, path, depth, world, node.payload, out);
            return;
        case NodeKind::Operator:
            for (uint32_t i = 0; i < node.childCount; ++i)
                walk(g, g.child(n, i), frame, pathChild(path, i), depth, world, material, out);
            return;
        case NodeKind::Primitive: {
            const Primitive& p = g.primitives[node.payload];
            Leaf leaf{p.kind, world, material, frame, {}};
            leaf.args.resize(p.kind == PrimitiveKind::Torus      ? 2
                             : p.kind == PrimitiveKind::Triangle ? 9
                                                                 : 0);
            primitiveArgs(g, n, s, leaf.args.data());
            out.push_back(std::move(leaf));
            return;
        }
    }
}

std::vector<Leaf> leaves(const Graph& g) {
    std::vector<double> frame(g.slotCount());
    initFrame(g, frame.data());
    std::vector<Leaf> out;
    walk(g, g.axiom, frame, kRootPath, 0, Affine::identity(), 0, out);
    return out;
}

double param(const Graph& g, const Leaf& l, const std::string& name) {
    for (Slot s = 0; s < g.slotCount(); ++s)
        if (g.slotNames[s] == name) return l.frame[s];
    ADD_FAILURE() << "no parameter " << name;
    return std::nan("");
}

// Each leaf as a sortable tuple of its world position (the image of the origin and of
// the unit axes), rounded.
std::vector<std::vector<long>> positions(const std::vector<Leaf>& ls) {
    std::vector<std::vector<long>> out;
    for (const Leaf& l : ls) {
        std::vector<long> v{static_cast<long>(l.kind)};
        for (const Vec3& p : {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}}) {
            const Vec3 q = l.world.point(p);
            for (int i = 0; i < 3; ++i) v.push_back(std::lround(q[i] * 1e6));
        }
        out.push_back(v);
    }
    std::sort(out.begin(), out.end());
    return out;
}

// --- the paper's systems (docs/language.md: figures 2, 3a, 5a, 6, 8) ---

const char* kFigure2 =
    "w:S(4)\t// the axiom\n"
    "p1:S(c) : c=0 → tetrahedron\t// terminating rule\n"
    "p2:S(c) : c>0 → move(0.5,0.5,0.5) uscale(0.5) S(c-1) ∪ move(-0.5,-0.5,0.5) uscale(0.5) S(c-1) "
    "∪ "
    "move(0.5,-0.5,-0.5) uscale(0.5) S(c-1) ∪ move(-0.5,0.5,-0.5) uscale(0.5) S(c-1)\t// "
    "generating rule\n";

// Figure 3a with docs/language.md's parentheses.
const char* kFigure3a =
    "{c=4} S // definition of the start node and initialization of c\n"
    "S if(c > 0,2,1) // declaration of the module S and its selection function\n"
    "1: S → tetrahedron // terminating rule\n"
    "2: S → {c=c-1} ( move(0.5,0.5,0.5) uscale(0.5) S ∪ // generating rule\n"
    "           move(-0.5,-0.5,0.5) uscale(0.5) S ∪\n"
    "           move(0.5,-0.5,-0.5) uscale(0.5) S ∪\n"
    "           move(-0.5,0.5,-0.5) uscale(0.5) S )\n";

TEST(Figures, SierpinskiInBothNotationsMakesTheSameObject) {
    auto a = compile(kFigure3a);
    auto b = compile(kFigure2);
    ASSERT_TRUE(a->graph) << a->errors();
    ASSERT_TRUE(b->graph) << b->errors();
    const Graph& ga = *a->graph;
    const Graph& gb = *b->graph;
    // The same shape: one S-node with two rules, eight T-nodes, one primitive.
    for (const Graph* g : {&ga, &gb}) {
        ASSERT_EQ(g->modules.size(), 1u);
        EXPECT_EQ(g->nodes[g->modules[0].node].childCount, 2u);
        EXPECT_EQ(g->transforms.size(), 8u);
        EXPECT_EQ(g->primitives.size(), 1u);
        for (const Transform& t : g->transforms) EXPECT_TRUE(t.constant);
    }
    EXPECT_FALSE(ga.modules[0].notationB);
    EXPECT_TRUE(gb.modules[0].notationB);
    EXPECT_EQ(gb.modules[0].conditions.size(), 2u);
    EXPECT_EQ(gb.modules[0].formals.size(), 1u);
    // And the same 4^4 tetrahedra at the same places.
    const auto la = leaves(ga), lb = leaves(gb);
    EXPECT_EQ(la.size(), 256u);
    EXPECT_EQ(positions(la), positions(lb));
}

TEST(Figures, Figure5aWithTheLeafOfFigure6) {
    const std::string text =
        "{   cnt = 4;           // order of the branching structure\n"
        "    trunk = 2,         // number of trunk segments (cycles of rule with index 2)\n"
        "    fTR = 0.96;        // scaling factor for trunk segments\n"
        "    gamma = -72.0;     // divergence angle\n"
        "    alpha1 = -60.0;    // branching angles\n"
        "    alpha2 = 20.0;\n"
        "    fBR1 = 0.73;       // scaling factors for left and right branches\n"
        "    fBR2 = 0.67;\n"
        "    noleaves = 3;      // if cnt is less than noleaves the limbs bear leaves\n"
        "    segments = 2;     // number of segments for a limb with leaves\n"
        "    fxSG = 1/7;       // scaling factors for segment cylinders\n"
        "    fySG = 1/7;\n"
        "    dSG = 1/segments; // height of a segment cylinder\n"
        "    fLV = 0.6;        // scaling factor for leaves\n"
        "    D = 0.5; thickness = 0.1; dy = 0; dz = 0.2; fx = 0.1; fy = 0.3; fz = 0.8\n"
        "} TR // the start node\n"
        "\n"
        "TR   if(trunk > 0, 2, if(cnt > 0, 3, 1))           // module for the tree\n"
        "1: TR → SG                                         // terminating rule\n"
        "2: TR → SG ∪ {trunk=trunk-1} move(0,0,1) uscale(fTR) TR // rule for the generation of the "
        "trunk\n"
        "                                           // rule for the generation of the branching "
        "structure\n"
        "3: TR → SG ∪ move(0,0,1) rotz(gamma)({cnt=cnt-1} rotx(alpha1) uscale(fBR1) TR ∪\n"
        "                                           {cnt=cnt-1} rotx(alpha2) uscale(fBR2) TR )\n"
        "SG   if(cnt < noleaves, if(segments > 0, 3, 2), 1) // module for segments\n"
        "1: SG → scale(fxSG,fySG,1) cylinder                // this rule is selected for limbs "
        "without leaves\n"
        "2: SG → segment                                    // terminating rule for limbs with "
        "leaves\n"
        "3: SG → segment ∪ {segments=segments-1} move(0,0,dSG) rotz(-90) SG // generating rule for "
        "limbs with leaves\n"
        "                                           // CSG expression for segments with leaves\n"
        "segment = scale(fxSG,fySG,dSG) cylinder ∪ move(0,0,dSG) (uscale( fLV) leaf ∪ flipxz "
        "uscale(fLV) leaf)\n"
        "\n"
        "connected_balls = (move(-D,0,0) sphere  ∪  move(D,0,0) sphere) \\\n"
        "                  (move(-D,0,0) uscale(1-thickness) sphere  ∪  move(D,0,0) "
        "uscale(1-thickness) sphere)\n"
        "leaf = move(0, dy, dz) scale(fx, fy, fz) cylinder  ∩  connected_balls\n";
    auto c = compile(text);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    ASSERT_EQ(g.modules.size(), 2u);
    EXPECT_EQ(g.modules[0].name, "TR");
    EXPECT_EQ(g.modules[1].name, "SG");
    EXPECT_EQ(g.nodes[g.modules[0].node].childCount, 3u);
    EXPECT_EQ(g.nodes[g.modules[1].node].childCount, 3u);
    // `leaf` is built once and shared by both of its uses in `segment`.
    const NodeId seg = g.child(g.modules[1].node, 1);  // rule 2: segment
    ASSERT_TRUE(g.nodes[seg].is(CsgOp::Union));
    const NodeId moved = g.child(seg, 1);
    const NodeId pair = g.child(moved);
    ASSERT_TRUE(g.nodes[pair].is(CsgOp::Union));
    const NodeId leaf1 = g.child(g.child(pair, 0));
    const NodeId leaf2 = g.child(g.child(g.child(pair, 1)));
    EXPECT_EQ(leaf1, leaf2);
    EXPECT_TRUE(g.nodes[leaf1].is(CsgOp::Intersection));
    // It unrolls: trunk of 3 segments, then a binary tree of order 4; every leaf reached.
    const auto ls = leaves(g);
    EXPECT_GT(ls.size(), 100u);
    for (const Leaf& l : ls) EXPECT_TRUE(l.world.isFinite());
    // dSG was computed from segments in order: 1/2.
    EXPECT_EQ(param(g, ls[0], "dSG"), 0.5);
}

TEST(Figures, Figure8WithItsMacrosWrittenOut) {
    std::string text =
        "#define calcT1_1\n"
        "{\n"
        "    cnt = cnt-1;\n"
        "    delta = delta*frc; // variance\n"
        "    kl = kl/2.0; // new length of the cathetii\n"
        "    sd = a*x2 + b*x1 + c*y2 + d*y1; // seed value\n"
        "    rnd = ((-ln(rand(sd)*ex+1.0))+add)*delta; // displacement value\n"
        "    z2 = (z1+z2)/2.0 + rnd; // new height for p2\n"
        "    sd = a*x3 + b*x1 + c*y3 + d*y1; // next seed value\n"
        "    rnd = ((-ln(rand(sd)*ex+1.0))+add)*delta; // next displacement value\n"
        "    z3 = (z1+z3)/2.0 + rnd; // new height for p3\n"
        "    x2 = x1-kl; // new x-coordinate for p2\n"
        "    y3 = y1-kl; // new y-coordinate for p3\n"
        "}\n"
        "#define calcT1_2 { cnt = cnt-1; delta = delta*frc; kl = kl/2.0; x1 = x1+kl }\n"
        "#define calcT1_3 { cnt = cnt-1; delta = delta*frc; kl = kl/2.0; y1 = y1+kl }\n"
        "#define calcT1_4 { cnt = cnt-1; delta = delta*frc; kl = kl/2.0; x1 = x1+kl; y1 = y1+kl }\n"
        "#define calcT2_1 { cnt = cnt-1; delta = delta*frc; kl = kl/2.0 }\n"
        "#define calcT2_2 { cnt = cnt-1; delta = delta*frc; kl = kl/2.0; x1 = x1-kl }\n"
        "#define calcT2_3 { cnt = cnt-1; delta = delta*frc; kl = kl/2.0; y1 = y1-kl }\n"
        "#define calcT2_4 { cnt = cnt-1; delta = delta*frc; kl = kl/2.0; x1 = x1-kl; y1 = y1-kl }\n"
        "#define calc_TRI1 {}\n"
        "#define calc_TRI2 {}\n"
        "\n"
        "{\n"
        "    cnt = 3; // order of the terrain\n"
        "    frc = 0.47; // scaling factor for the variance\n"
        "    delta = 1.0; // initial variance\n"
        "    add = 0.6; // addition value for the random numbers\n"
        "    ex = exp(1.0)-1.0; // for the mapping of the random numbers into [1,e]\n"
        "    kl = 1.0; // length of a cathetus\n"
        "    a = 255; // coefficients for the linear combination\n"
        "    b = pow(255,2);\n"
        "    c = pow(255,3);\n"
        "    d = pow(255,4);\n"
        "} MNT\n"
        "\n"
        "MNT 1 // a constant selection function\n"
        "1:MNT → { // initialization of the points for triangle T1\n"
        "           x1 = 0.0;   y1 = 0.0;   z1 = 0.0;\n"
        "           x2 = 1.0;   y2 = 0.0;   z2 = 0.0;\n"
        "           x3 = 0.0;   y3 = 1.0;   z3 = 0.0;\n"
        "       } T1 ∪\n"
        "       { // initialization of the points for triangle T2\n"
        "           x1 = 0.0;   y1 = 0.0;   z1 = 0.0;\n"
        "           x2 = 1.0;   y2 = 0.0;   z2 = 0.0;\n"
        "           x3 = 0.0;   y3 = 1.0;   z3 = 0.0;\n"
        "       } move(1,1,0) T2\n"
        "\n"
        "T1  if(cnt > 0, 2, 1) // triangle on the upper right part of the xy-plane\n"
        "1:T1 → calc_TRI1 move(0,0,z1) zshear(z2-z1,z3-z1) tri1 // terminating rule for triangle "
        "T1\n"
        "2:T1 → calcT1_1 scale(0.5,0.5,1) T1 ∪ // subdivision of triangle T2\n"
        "       calcT1_2 move(0.5,0,0) scale(0.5,0.5,1) T1 ∪\n"
        "       calcT1_3 move(0,0.5,0) scale(0.5,0.5,1) T1 ∪\n"
        "       calcT1_4 move(0.5,0.5,0) scale(0.5,0.5,1) T2\n"
        "\n"
        "T2  if(cnt > 0, 2, 1) // triangle on the lower left part of the xy-plane\n"
        "1:T2 → calc_TRI2 move(0,0,z1) zshear(z1-z2,z1-z3) tri2 // terminating rule for triangle "
        "T2\n"
        "2:T2 → calcT2_1 scale(0.5,0.5,1) T2 ∪ // subdivision of triangle T2\n"
        "       calcT2_2 move(-0.5,0,0) scale(0.5,0.5,1) T2 ∪\n"
        "       calcT2_3 move(0,-0.5,0) scale(0.5,0.5,1) T2 ∪\n"
        "       calcT2_4 move(-0.5,-0.5,0) scale(0.5,0.5,1) T1\n";
    auto c = compile(text);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    ASSERT_EQ(g.modules.size(), 3u);
    // The first C-node of rule 2 of T1 is calcT1_1 with its eleven ordered assignments.
    const NodeId rule2 = g.child(g.modules[1].node, 1);
    const NodeId calc = g.child(rule2, 0);
    ASSERT_EQ(g.nodes[calc].kind, NodeKind::Calc);
    const Calc& cn = g.calcs[g.nodes[calc].payload];
    EXPECT_EQ(cn.count, 11u);
    EXPECT_FALSE(cn.simultaneous);
    EXPECT_EQ(g.slotNames[g.assignments[cn.first + 3].slot], "sd");
    EXPECT_EQ(g.slotNames[g.assignments[cn.first + 4].slot], "rnd");
    // 2 * 4^3 triangles, all finite.
    const auto ls = leaves(g);
    EXPECT_EQ(ls.size(), 128u);
    for (const Leaf& l : ls) EXPECT_TRUE(l.world.isFinite());
}

// --- C-nodes ---

TEST(CNodes, AssignmentsHoldOnlyForTheirOperand) {
    auto c = compile("{c = 1} ({c = c + 1} sphere ∪ cube ∪ {c = c * 10} cone)");
    ASSERT_TRUE(c->graph) << c->errors();
    const auto ls = leaves(*c->graph);
    ASSERT_EQ(ls.size(), 3u);
    EXPECT_EQ(param(*c->graph, ls[0], "c"), 2);   // sphere
    EXPECT_EQ(param(*c->graph, ls[1], "c"), 1);   // cube: never sees its sibling's c
    EXPECT_EQ(param(*c->graph, ls[2], "c"), 10);  // cone
}

TEST(CNodes, AssignmentsRunInOrderAndSeeEachOther) {
    auto c = compile("{a = 1; b = a + 1, a = 10\n d = a + b} sphere");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    ASSERT_EQ(g.calcs.size(), 1u);
    EXPECT_EQ(g.calcs[0].count, 4u);
    EXPECT_FALSE(g.calcs[0].simultaneous);
    const auto ls = leaves(g);
    EXPECT_EQ(param(g, ls[0], "a"), 10);
    EXPECT_EQ(param(g, ls[0], "b"), 2);
    EXPECT_EQ(param(g, ls[0], "d"), 12);
}

TEST(CNodes, ANotationBCallAssignsItsArgumentsTogether) {
    auto c = compile("w: {x = 1; y = 2} S(y, x)\np: S(x, y) -> sphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const NodeId call = g.child(g.axiom);
    ASSERT_EQ(g.nodes[call].kind, NodeKind::Calc);
    EXPECT_TRUE(g.calcs[g.nodes[call].payload].simultaneous);
    EXPECT_EQ(g.child(call), g.modules[0].node);
    const auto ls = leaves(g);
    EXPECT_EQ(param(g, ls[0], "x"), 2);  // swapped, not x = 2 then y = x = 2
    EXPECT_EQ(param(g, ls[0], "y"), 1);
}

TEST(CNodes, AnEmptyCNodeAddsNoNode) {
    auto c = compile("{} sphere");
    ASSERT_TRUE(c->graph) << c->errors();
    EXPECT_EQ(c->graph->nodes[c->graph->axiom].kind, NodeKind::Primitive);
}

// --- definitions, transforms, primitives, paint ---

TEST(Definitions, AreBuiltOnceAndShared) {
    auto c = compile("d = sphere ∪ cube\nmove(1,0,0) d ∪ d ∩ f\nf = move(0,0,1) d");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    EXPECT_EQ(g.primitives.size(), 2u);
    const NodeId top = g.axiom;
    const NodeId d1 = g.child(g.child(top, 0));
    const NodeId inter = g.child(top, 1);
    EXPECT_EQ(g.child(inter, 0), d1);
    EXPECT_EQ(g.child(g.child(inter, 1)), d1);
}

TEST(Definitions, MayNotReferToThemselvesButModulesMay) {
    auto bad = compile("a = sphere ∪ b\nb = move(1,0,0) a\na");
    EXPECT_FALSE(bad->graph);
    EXPECT_NE(bad->errors().find("definition 'a' refers to itself (a -> b -> a)"),
              std::string::npos)
        << bad->errors();
    auto ok = compile(
        "a = sphere ∪ {n = n - 1} S\nS if(n > 0, 2, 1)\n1: S -> cube\n2: S -> a\n{n = 2} S");
    ASSERT_TRUE(ok->graph) << ok->errors();
    EXPECT_EQ(leaves(*ok->graph).size(), 3u);
}

TEST(Definitions, ALongChainDoesNotRecurse) {
    std::string text;
    const int n = 50000;
    for (int i = 0; i < n; ++i) text += fmt::format("d{} = d{}\n", i, i + 1);
    text += fmt::format("d{} = sphere\nd0\n", n);
    auto c = compile(text);
    ASSERT_TRUE(c->graph) << c->errors().substr(0, 300);
    EXPECT_EQ(c->graph->nodes[c->graph->axiom].kind, NodeKind::Primitive);
}

TEST(Transforms, ConstantOnesAreFoldedAndOthersKeepTheirArguments) {
    auto c = compile(
        "{s = 2} (rot(0,0,1,90) sphere ∪ uscale(s) cube ∪ uscale(0) cone ∪ matrix(1,0,0, 0,1,0, "
        "0,0,1, 1,2,3) plane)");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    ASSERT_EQ(g.transforms.size(), 4u);
    EXPECT_TRUE(g.transforms[0].constant);
    const double ninety = 90;
    EXPECT_EQ(g.transforms[0].matrix,
              makeTransform(TransformOp::Rot, std::vector<double>{0, 0, 1, ninety}.data()));
    EXPECT_FALSE(g.transforms[1].constant);
    EXPECT_EQ(g.transforms[1].argCount, 1u);
    EXPECT_FALSE(g.exprs[g.args[g.transforms[1].firstArg]].constant);
    // A singular constant transformation is left to the run-time check.
    EXPECT_FALSE(g.transforms[2].constant);
    EXPECT_THROW(leaves(g), RuntimeError);
    EXPECT_TRUE(g.transforms[3].constant);
    EXPECT_EQ(g.transforms[3].matrix.t, (Vec3{1, 2, 3}));
}

TEST(Primitives, ArgumentsAreFoldedWhenConstant) {
    auto c = compile("{r = 0.25} (torus(1, 1/4) ∪ torus(1, r) ∪ triangle(0,0,0, 1,0,0, 0,1,0))");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    ASSERT_EQ(g.primitives.size(), 3u);
    EXPECT_TRUE(g.primitives[0].constant);
    EXPECT_EQ(g.primitives[0].values, (std::vector<double>{1, 0.25}));
    EXPECT_FALSE(g.primitives[1].constant);
    EXPECT_EQ(g.primitives[1].argCount, 2u);
    EXPECT_TRUE(g.primitives[2].constant);
    EXPECT_EQ(g.primitives[2].values.size(), 9u);
    const auto ls = leaves(g);
    EXPECT_EQ(ls[1].args, (std::vector<double>{1, 0.25}));
}

TEST(Paint, MaterialsAreIndexedAndTheInnermostWins) {
    auto c = compile(
        "material red { color <1,0,0> }\nmaterial blue { color <0,0,1> phong 0.5 }\n"
        "paint(red) (sphere ∪ paint(blue) cube ∪ paint(default) cone)");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    ASSERT_EQ(g.materials.size(), 3u);
    EXPECT_EQ(g.materials[0].name, "default");
    EXPECT_EQ(g.materials[1].name, "red");
    EXPECT_EQ(g.materials[2].phong, 0.5);
    const auto ls = leaves(g);
    EXPECT_EQ(ls[0].material, 1u);
    EXPECT_EQ(ls[1].material, 2u);
    EXPECT_EQ(ls[2].material, 0u);
}

// --- scene directives ---

TEST(Directives, FillTheSceneAndTheMaterials) {
    auto c = compile(
        "camera { location <4,-6,3>  look_at <0,0,0.5>  sky <0,0,1>  angle 2*20 }\n"
        "light  { position <10,-20,30>  color <1,1,1> }\n"
        "light  { position <-1,0,5>; color <0.5, 0.5, 0.5> }\n"
        "background <0.55, 0.7, 0.9>\n"
        "material bark { color <0.35,0.22,0.1>  ambient 0.1  diffuse 0.7  phong 0.2  phong_size 30 "
        " reflection 0 }\n"
        "material default { color <0.5,0.5,0.5> }\n"
        "settings { seed 7  max_depth 100 }\n"
        "paint(bark) sphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Scene& s = c->graph->scene;
    EXPECT_EQ(s.camera.location, (Vec3{4, -6, 3}));
    EXPECT_EQ(s.camera.lookAt, (Vec3{0, 0, 0.5}));
    EXPECT_EQ(s.camera.angle, 40);
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[1].color, (Vec3{0.5, 0.5, 0.5}));
    EXPECT_EQ(s.background, (Vec3{0.55, 0.7, 0.9}));
    EXPECT_EQ(s.settings.seed, 7u);
    EXPECT_EQ(s.settings.maxDepth, 100u);
    const auto& m = c->graph->materials;
    ASSERT_EQ(m.size(), 2u);
    EXPECT_EQ(m[0].color, (Vec3{0.5, 0.5, 0.5}));
    EXPECT_EQ(m[1].diffuse, 0.7);
    EXPECT_EQ(m[1].phongSize, 30);
    EXPECT_EQ(m[1].ambient, 0.1);
}

// Section 10's blocks inside a material, in POV-Ray's syntax, next to the flat items.
TEST(Directives, MaterialBlocks) {
    auto c = compile(
        "material water {\n"
        "  pigment { color rgbft <0.3, 0.5, 0.6, 0, 0> }\n"
        "  normal { }\n"
        "  finish { ambient 0 diffuse 0.2 brilliance 1.5 phong 0.3 phong_size 60 specular 0.4\n"
        "           roughness 0.01 metallic reflection { 0.05, 0.9 fresnel on metallic 0.5 }\n"
        "           conserve_energy }\n"
        "  interior { ior 1.33 }\n"
        "}\n"
        "material flat { colour <1, 0, 0>  reflection 0.25  finish { metallic 0.3 } }\n"
        "material grey { pigment { rgb 0.5 } finish { reflection { 0.4 } fresnel_off 0 } }\n"
        "paint(water) sphere ∪ paint(flat) cube ∪ paint(grey) cone\n");
    ASSERT_FALSE(c->graph);  // fresnel_off is not an item
    EXPECT_NE(c->errors().find("unknown finish setting 'fresnel_off'"), std::string::npos)
        << c->errors();

    c = compile(
        "material water {\n"
        "  pigment { color rgbft <0.3, 0.5, 0.6, 0, 0> }\n"
        "  normal { }\n"
        "  finish { ambient 0 diffuse 0.2 brilliance 1.5 phong 0.3 phong_size 60 specular 0.4\n"
        "           roughness 0.01 metallic reflection { 0.05, 0.9 fresnel on metallic 0.5 }\n"
        "           conserve_energy }\n"
        "  interior { ior 1.33 }\n"
        "}\n"
        "material flat { colour <1, 0, 0>  reflection 0.25  finish { metallic 0.3 } }\n"
        "material grey { pigment { rgb 0.5 } finish { reflection { 0.4 } } }\n"
        "paint(water) sphere ∪ paint(flat) cube ∪ paint(grey) cone\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const auto& m = c->graph->materials;
    ASSERT_EQ(m.size(), 4u);
    const Material& w = m[1];
    EXPECT_EQ(w.color, (Vec3{0.3, 0.5, 0.6}));
    EXPECT_EQ(w.ambient, 0);
    EXPECT_EQ(w.diffuse, 0.2);
    EXPECT_EQ(w.brilliance, 1.5);
    EXPECT_EQ(w.phong, 0.3);
    EXPECT_EQ(w.phongSize, 60);
    EXPECT_EQ(w.specular, 0.4);
    EXPECT_EQ(w.roughness, 0.01);
    EXPECT_EQ(w.metallic, 1);
    EXPECT_TRUE(w.reflectionRange);
    EXPECT_EQ(w.minReflection(), 0.05);
    EXPECT_EQ(w.reflection, 0.9);
    EXPECT_TRUE(w.fresnel);
    EXPECT_EQ(w.reflectMetallic, 0.5);
    EXPECT_TRUE(w.conserveEnergy);
    EXPECT_TRUE(w.interior);
    EXPECT_EQ(w.ior, 1.33);
    EXPECT_EQ(m[2].color, (Vec3{1, 0, 0}));
    EXPECT_EQ(m[2].reflection, 0.25);
    EXPECT_EQ(m[2].minReflection(), 0.25);
    EXPECT_EQ(m[2].metallic, 0.3);
    EXPECT_FALSE(m[2].interior);
    EXPECT_EQ(m[3].color, (Vec3{0.5, 0.5, 0.5}));
    EXPECT_FALSE(m[3].reflectionRange);  // one value: the minimum and the maximum
    EXPECT_EQ(m[3].minReflection(), 0.4);
}

// Transparency (section 10): filter and transmit of the colour, the interior's fade items,
// and the trace settings.
TEST(Directives, TransparencyItems) {
    auto c = compile(
        "settings { max_trace_level 12  adc_bailout 0.02 }\n"
        "material a { pigment { color rgbft <1, 0.5, 0.25, 0.6, 0.3> }\n"
        "  interior { ior 1.33 fade_distance 4 fade_power 1001 fade_color rgb <0.5, 0.25, 0> } }\n"
        "material b { color rgbt <0.2, 0.4, 0.6, 0.7>  interior { fade_color <1, 0, 0> } }\n"
        "paint(a) sphere ∪ paint(b) cube\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Settings& st = c->graph->scene.settings;
    EXPECT_EQ(st.maxTraceLevel, 12u);
    EXPECT_EQ(st.adcBailout, 0.02);
    const auto& m = c->graph->materials;
    ASSERT_EQ(m.size(), 3u);
    EXPECT_EQ(m[1].filter, 0.6);
    EXPECT_EQ(m[1].transmit, 0.3);
    EXPECT_EQ(m[1].ior, 1.33);
    EXPECT_EQ(m[1].fadeDistance, 4);
    EXPECT_EQ(m[1].fadePower, 1001);
    EXPECT_EQ(m[1].fadeColour, (Vec3{0.5, 0.25, 0}));
    EXPECT_TRUE(m[1].interior);
    EXPECT_EQ(m[2].filter, 0);
    EXPECT_EQ(m[2].transmit, 0.7);
    EXPECT_EQ(m[2].fadeColour, (Vec3{1, 0, 0}));
    EXPECT_EQ(c->graph->scene.settings.maxTraceLevel, 12u);
    auto d = compile("sphere");
    ASSERT_TRUE(d->graph);
    EXPECT_EQ(d->graph->scene.settings.maxTraceLevel, 5u);
    EXPECT_EQ(d->graph->scene.settings.adcBailout, 1.0 / 255.0);
}

TEST(Directives, DefaultsWithoutAny) {
    auto c = compile("sphere");
    ASSERT_TRUE(c->graph) << c->errors();
    const Scene& s = c->graph->scene;
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].position, (Vec3{10, -20, 30}));
    EXPECT_EQ(s.background, (Vec3{0, 0, 0}));
    EXPECT_EQ(s.camera.location, (Vec3{0, -5, 2}));
    EXPECT_EQ(s.settings.maxDepth, 256u);
    ASSERT_EQ(c->graph->materials.size(), 1u);
    EXPECT_EQ(c->graph->materials[0].color, (Vec3{1, 1, 1}));
    EXPECT_EQ(c->graph->materials[0].diffuse, 0.6);
}

TEST(Directives, RandOfAConstantUsesTheSeed) {
    auto a = compile("settings { seed 1 }\n{x = rand(3)} sphere");
    auto b = compile("settings { seed 2 }\n{x = rand(3)} sphere");
    ASSERT_TRUE(a->graph && b->graph);
    const auto la = leaves(*a->graph), lb = leaves(*b->graph);
    EXPECT_EQ(param(*a->graph, la[0], "x"), randOf(1, 3));
    EXPECT_EQ(param(*b->graph, lb[0], "x"), randOf(2, 3));
}

// --- whole-file checks ---

TEST(Checks, TrianglesUnderIntersectionsAndDifferencesAreFound) {
    EXPECT_TRUE(compile("tri1 ∪ move(1,0,0) tri2 ∪ triangle(0,0,0,1,0,0,0,1,1)")->graph);
    for (const char* text : {"sphere ∩ tri1", "tri2 \\ cube", "sphere ∩ (cube ∪ move(1,0,0) tri1)",
                             "d = {a=1} paint(default) tri1\nsphere \\ d",
                             "S 1\n1: S -> T\nT 1\n1: T -> tri2\nS ∩ cube"}) {
        auto c = compile(text);
        EXPECT_FALSE(c->graph) << text;
        EXPECT_NE(c->errors().find("is reachable as an operand of this"), std::string::npos)
            << text << c->errors();
    }
}

TEST(Checks, ExactlyOneAxiom) {
    EXPECT_NE(compile("d = sphere")->errors().find("1:1: error: the file has no axiom"),
              std::string::npos);
    EXPECT_NE(compile("sphere\ncube")
                  ->errors()
                  .find("2:1: error: a second axiom (the first is at line 1)"),
              std::string::npos);
}

TEST(Checks, ParametersMustBeAssignedSomewhere) {
    auto c = compile("S if(depth > 0, 1, 1)\n1: S -> sphere\nS");
    EXPECT_NE(c->errors().find("1:6: error: unknown parameter 'depth'"), std::string::npos)
        << c->errors();
    // Assigned anywhere in the file is enough at compile time.
    EXPECT_TRUE(compile("S if(depth > 0, 1, 1)\n1: S -> sphere\n{depth = 1} S")->graph);
    EXPECT_TRUE(compile("p: S(depth) : depth > 0 -> sphere\nw: S(1)")->graph);
}

}  // namespace
}  // namespace pcsg
