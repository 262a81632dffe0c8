// Hand-built graphs for the povexport tests (header-only, test code only): the shapes
// the builder makes, without the compiler.
#pragma once

#include <string>
#include <vector>

#include "eval.h"
#include "graph.h"

namespace pcsg::testgraphs {

// Appends an expression of raw instructions; jump targets are relative to its start.
inline ExprId addCode(Graph& g, std::vector<Instr> code, uint32_t maxStack,
                      std::string text = "expr", bool usesPath = false) {
    Expr e;
    e.begin = static_cast<uint32_t>(g.code.size());
    for (auto& in : code) {
        if (in.op == Op::Jump || in.op == Op::JumpIfZero) in.a += e.begin;
        if (in.op == Op::Rand0 || in.op == Op::Choose) usesPath = true;
        g.code.push_back(in);
    }
    e.end = static_cast<uint32_t>(g.code.size());
    e.maxStack = maxStack;
    e.usesPath = usesPath;
    e.text = std::move(text);
    e.loc = {0, 1, 1};
    g.exprs.push_back(e);
    return static_cast<ExprId>(g.exprs.size() - 1);
}

inline Instr cst(double v) {
    return Instr{Op::Const, 0, 0, v};
}
inline Instr load(Slot s) {
    return Instr{Op::Load, 0, s, 0};
}
inline Instr op(Op o, uint32_t a = 0, uint8_t argc = 0) {
    return Instr{o, argc, a, 0};
}

// if(slot > 0, a, b)
inline ExprId ifPositive(Graph& g, Slot s, double a, double b) {
    return addCode(
        g, {load(s), cst(0), op(Op::Gt), op(Op::JumpIfZero, 6), cst(a), op(Op::Jump, 7), cst(b)}, 2,
        "if(c > 0, a, b)");
}

// slot + delta
inline ExprId plusConst(Graph& g, Slot s, double delta) {
    return addCode(g, {load(s), cst(delta), op(Op::Add)}, 2, "c + delta");
}

inline NodeId primitive(Graph& g, PrimitiveKind kind, std::vector<double> values = {}) {
    Primitive p;
    p.kind = kind;
    p.constant = true;
    p.values = std::move(values);
    g.primitives.push_back(p);
    return g.addNode(NodeKind::Primitive, static_cast<uint32_t>(g.primitives.size() - 1), {});
}

// A primitive whose arguments are expressions.
inline NodeId primitiveOf(Graph& g, PrimitiveKind kind, const std::vector<ExprId>& args) {
    Primitive p;
    p.kind = kind;
    p.constant = false;
    p.firstArg = static_cast<uint32_t>(g.args.size());
    p.argCount = static_cast<uint32_t>(args.size());
    g.args.insert(g.args.end(), args.begin(), args.end());
    g.primitives.push_back(p);
    return g.addNode(NodeKind::Primitive, static_cast<uint32_t>(g.primitives.size() - 1), {});
}

inline NodeId transform(Graph& g, TransformOp op, std::vector<double> args, NodeId child) {
    Transform t;
    t.op = op;
    t.constant = true;
    t.matrix = makeTransform(op, args.data());
    t.firstArg = static_cast<uint32_t>(g.args.size());
    t.argCount = static_cast<uint32_t>(args.size());
    for (double a : args) g.args.push_back(g.addConstant(a));
    g.transforms.push_back(t);
    return g.addNode(NodeKind::Transform, static_cast<uint32_t>(g.transforms.size() - 1), {child});
}

// A transformation whose arguments are expressions.
inline NodeId transformOf(Graph& g, TransformOp op, const std::vector<ExprId>& args, NodeId child) {
    Transform t;
    t.op = op;
    t.constant = false;
    t.firstArg = static_cast<uint32_t>(g.args.size());
    t.argCount = static_cast<uint32_t>(args.size());
    g.args.insert(g.args.end(), args.begin(), args.end());
    g.transforms.push_back(t);
    return g.addNode(NodeKind::Transform, static_cast<uint32_t>(g.transforms.size() - 1), {child});
}

inline NodeId calc(Graph& g, std::vector<Assignment> as, NodeId child) {
    Calc c;
    c.first = static_cast<uint32_t>(g.assignments.size());
    c.count = static_cast<uint32_t>(as.size());
    g.assignments.insert(g.assignments.end(), as.begin(), as.end());
    g.calcs.push_back(c);
    return g.addNode(NodeKind::Calc, static_cast<uint32_t>(g.calcs.size() - 1), {child});
}

inline NodeId paint(Graph& g, uint32_t material, NodeId child) {
    return g.addNode(NodeKind::Paint, material, {child});
}

// An S-node for a new module with `rules` placeholder children; set them with setRule.
inline NodeId module(Graph& g, const std::string& name, ExprId select, uint32_t rules) {
    Module m;
    m.name = name;
    m.select = select;
    g.modules.push_back(m);
    const NodeId n = g.addNode(NodeKind::Select, static_cast<uint32_t>(g.modules.size() - 1),
                               std::vector<NodeId>(rules, 0));
    g.modules.back().node = n;
    return n;
}
inline void setRule(Graph& g, NodeId selectNode, uint32_t rule, NodeId body) {
    g.edges[g.nodes[selectNode].firstChild + rule] = body;
}

inline void defaultScene(Graph& g) {
    if (g.materials.empty()) g.materials.push_back(Material{.name = "default"});
    if (g.scene.lights.empty()) g.scene.lights.push_back(Light{});
}

// Figure 3a: {c = order} S; S if(c > 0, 2, 1); 1: S -> tetrahedron;
// 2: S -> {c = c-1} (move(.5,.5,.5) uscale(.5) S ∪ ... four corners).
inline Graph sierpinski(int order, PrimitiveKind leaf = PrimitiveKind::Tetrahedron) {
    Graph g;
    defaultScene(g);
    const Slot c = g.slot("c");
    const NodeId s = module(g, "S", ifPositive(g, c, 2, 1), 2);
    setRule(g, s, 0, primitive(g, leaf));
    const double corners[4][3] = {
        {0.5, 0.5, 0.5}, {-0.5, -0.5, 0.5}, {0.5, -0.5, -0.5}, {-0.5, 0.5, -0.5}};
    std::vector<NodeId> parts;
    for (const auto& k : corners)
        parts.push_back(transform(g, TransformOp::Move, {k[0], k[1], k[2]},
                                  transform(g, TransformOp::UScale, {0.5}, s)));
    const NodeId u = g.addOperator(CsgOp::Union, parts);
    setRule(g, s, 1, calc(g, {{c, plusConst(g, c, -1)}}, u));
    g.axiom = calc(g, {{c, g.addConstant(order)}}, s);
    return g;
}

// A stochastic branching system: {d = depth} B; B if(d > 0, choose(0.5, 0.5), 1);
// 1: B -> move(rand(), 0, 0) sphere; 2: B -> {d = d-1} (move(0,0,1) uscale(.6) B ∪ rotz(90) B ∪
// cube).
inline Graph stochastic(int depth) {
    Graph g;
    defaultScene(g);
    const Slot d = g.slot("d");
    const ExprId sel = addCode(g,
                               {load(d), cst(0), op(Op::Gt), op(Op::JumpIfZero, 8), cst(0.5),
                                cst(0.5), op(Op::Choose, 0, 2), op(Op::Jump, 9), cst(1)},
                               3, "if(d > 0, choose(0.5, 0.5), 1)");
    g.randCallSites = 2;
    const NodeId b = module(g, "B", sel, 2);
    const ExprId rnd = addCode(g, {op(Op::Rand0, 1)}, 1, "rand()");
    const NodeId leaf = transformOf(g, TransformOp::Move, {rnd, g.addConstant(0), g.addConstant(0)},
                                    primitive(g, PrimitiveKind::Sphere));
    setRule(g, b, 0, leaf);
    const NodeId up =
        transform(g, TransformOp::Move, {0, 0, 1}, transform(g, TransformOp::UScale, {0.6}, b));
    const NodeId turned = transform(g, TransformOp::RotZ, {90}, b);
    const NodeId u = g.addOperator(CsgOp::Union, {up, turned, primitive(g, PrimitiveKind::Cube)});
    setRule(g, b, 1, calc(g, {{d, plusConst(g, d, -1)}}, u));
    g.axiom = calc(g, {{d, g.addConstant(depth)}}, b);
    return g;
}

}  // namespace pcsg::testgraphs
