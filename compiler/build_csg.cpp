// The builder's lowering phase: S-, T-, C-, paint, operator and primitive nodes
// (docs/language.md sections 4 and 5). See build_csg.h.
#include "build_csg.h"

#include <fmt/format.h>

#include <cmath>

#include "build_names.h"
#include "eval.h"

namespace pcsg {

namespace {

struct TransformInfo {
    uint32_t args;
    const char* names;
};

TransformInfo transformInfo(TransformOp op) {
    switch (op) {
        case TransformOp::Move:
            return {3, "dx, dy, dz"};
        case TransformOp::Scale:
            return {3, "fx, fy, fz"};
        case TransformOp::UScale:
            return {1, "f"};
        case TransformOp::RotX:
        case TransformOp::RotY:
        case TransformOp::RotZ:
            return {1, "an angle in degrees"};
        case TransformOp::Rot:
            return {4, "ax, ay, az, angle"};
        case TransformOp::ZShear:
            return {2, "a, b"};
        case TransformOp::FlipYZ:
        case TransformOp::FlipXZ:
        case TransformOp::FlipXY:
            return {0, ""};
        case TransformOp::Matrix:
            return {12, "m11 ... m33, tx, ty, tz"};
    }
    return {0, ""};
}

class CsgLowering {
  public:
    CsgLowering(BuildContext& ctx, Names& names, ExprCompiler& exprs)
        : ctx_(ctx), g_(ctx.g), ast_(ctx.ast), names_(names), exprs_(exprs) {}

    void run();

  private:
    void selectNodes();
    void selections();
    void rules();
    NodeId placeholder();
    NodeId csg(uint32_t c);
    NodeId operatorNode(const CsgNode& n);
    NodeId calc(const CsgNode& n);
    NodeId paint(const CsgNode& n);
    NodeId name(const CsgNode& n);
    NodeId call(const CsgNode& n);
    NodeId transform(const CsgNode& n);
    NodeId primitive(const CsgNode& n);
    bool arguments(const CsgNode& n, uint32_t& firstArg, std::vector<double>& values);

    BuildContext& ctx_;
    Graph& g_;
    const Ast& ast_;
    Names& names_;
    ExprCompiler& exprs_;
    std::unordered_map<uint32_t, NodeId> definitionNode_;  // statement -> node
    NodeId placeholder_ = kNone;
};

void CsgLowering::run() {
    selectNodes();
    selections();
    for (uint32_t d : names_.definitionOrder) {
        if (names_.cyclic.count(d)) continue;
        definitionNode_[d] = csg(ast_.stmts[d].body);
    }
    rules();
    if (names_.axiom) g_.axiom = csg(names_.axiom->body);
    // Modules whose rules were rejected keep no dangling edges.
    for (ModuleInfo& m : names_.modules)
        for (size_t k = 0; k < m.rules.size(); ++k)
            if (g_.edges[g_.nodes[m.node].firstChild + k] == kNone)
                g_.edges[g_.nodes[m.node].firstChild + k] = placeholder();
}

// One S-node per module, its children filled in once the rules are built.
void CsgLowering::selectNodes() {
    for (ModuleInfo& m : names_.modules) {
        Module mod;
        mod.name = std::string(m.name);
        mod.notationB = m.notationB;
        mod.loc = ctx_.loc(m.decl != kNoNode ? ast_.stmts[m.decl].nameTok : m.firstTok);
        const uint32_t index = static_cast<uint32_t>(g_.modules.size());
        m.node = g_.addNode(NodeKind::Select, index, std::vector<NodeId>(m.rules.size(), kNone),
                            mod.loc);
        mod.node = m.node;
        for (uint32_t f : m.formals) m.formalSlots.push_back(exprs_.slotOf(ctx_.text(f)));
        mod.formals = m.formalSlots;
        g_.modules.push_back(std::move(mod));
    }
}

// Notation A: the selection function; notation B: each rule's condition.
void CsgLowering::selections() {
    for (uint32_t mi = 0; mi < names_.modules.size(); ++mi) {
        const ModuleInfo& m = names_.modules[mi];
        if (m.notationB) {
            for (uint32_t r : m.rules) {
                const uint32_t c = ast_.stmts[r].expr;
                const ExprId e = c == kNoNode ? kNone : exprs_.compile(c);
                g_.modules[mi].conditions.push_back(e);
            }
        } else if (m.decl != kNoNode) {
            g_.modules[mi].select = exprs_.compile(ast_.stmts[m.decl].expr);
        }
    }
}

// The bodies of the rules, the S-nodes' children.
void CsgLowering::rules() {
    for (ModuleInfo& m : names_.modules) {
        for (size_t k = 0; k < m.rules.size(); ++k) {
            const NodeId body = csg(ast_.stmts[m.rules[k]].body);
            g_.edges[g_.nodes[m.node].firstChild + k] = body;
        }
    }
}

NodeId CsgLowering::placeholder() {
    if (placeholder_ == kNone) {
        Primitive p;
        p.kind = PrimitiveKind::Empty;
        g_.primitives.push_back(p);
        placeholder_ =
            g_.addNode(NodeKind::Primitive, static_cast<uint32_t>(g_.primitives.size() - 1), {});
    }
    return placeholder_;
}

NodeId CsgLowering::csg(uint32_t c) {
    const CsgNode& n = ast_.csg[c];
    switch (n.kind) {
        case CsgKind::Operator:
            return operatorNode(n);
        case CsgKind::Transform:
            return transform(n);
        case CsgKind::Calc:
            return calc(n);
        case CsgKind::Paint:
            return paint(n);
        case CsgKind::Primitive:
            return primitive(n);
        case CsgKind::Name:
            return name(n);
        case CsgKind::Call:
            return call(n);
    }
    return placeholder();
}

NodeId CsgLowering::operatorNode(const CsgNode& n) {
    std::vector<NodeId> children;
    children.reserve(n.count);
    for (uint32_t i = 0; i < n.count; ++i) children.push_back(csg(ast_.lists[n.first + i]));
    return g_.addOperator(n.csgOp, children, ctx_.loc(n.tok));
}

// A C-node `{a = ...; b = ...}`: assignments in order, each seeing those before.
NodeId CsgLowering::calc(const CsgNode& n) {
    const NodeId child = csg(n.child);
    if (n.count == 0) return child;  // `{}` assigns nothing
    Calc calc;
    calc.count = n.count;
    // Compile all values first: compile() may not interleave with the list.
    std::vector<Assignment> list;
    for (uint32_t i = 0; i < n.count; ++i) {
        const Assign& a = ast_.assigns[n.first + i];
        const ExprId value = exprs_.compile(a.value);
        list.push_back(Assignment{exprs_.slotOf(ctx_.text(a.nameTok)), value});
    }
    calc.first = static_cast<uint32_t>(g_.assignments.size());
    g_.assignments.insert(g_.assignments.end(), list.begin(), list.end());
    g_.calcs.push_back(calc);
    return g_.addNode(NodeKind::Calc, static_cast<uint32_t>(g_.calcs.size() - 1), {child},
                      ctx_.loc(n.tok));
}

NodeId CsgLowering::paint(const CsgNode& n) {
    const NodeId child = csg(n.child);
    const std::string_view name = ctx_.text(n.nameTok);
    uint32_t material = 0;
    if (name != "default") {
        auto it = names_.materialByName.find(name);
        if (it == names_.materialByName.end()) {
            if (!names_.dropped(name))
                ctx_.error(
                    n.nameTok,
                    fmt::format("unknown material '{}'{}", clip(name),
                                names_.materialByName.empty() ? " (no material is defined)" : ""));
            return child;
        }
        material = it->second;
    }
    return g_.addNode(NodeKind::Paint, material, {child}, ctx_.loc(n.tok));
}

// A module name is an edge to its S-node; a definition's name, its one shared node.
NodeId CsgLowering::name(const CsgNode& n) {
    const std::string_view name = ctx_.text(n.nameTok);
    auto m = names_.moduleByName.find(name);
    if (m != names_.moduleByName.end()) return names_.modules[m->second].node;
    auto d = names_.definitionByName.find(name);
    if (d != names_.definitionByName.end()) {
        auto built = definitionNode_.find(d->second);
        return built != definitionNode_.end() ? built->second : placeholder();
    }
    if (names_.dropped(name)) return placeholder();
    if (names_.assigned.count(name))
        ctx_.error(n.nameTok,
                   fmt::format("'{}' is a parameter, not a module or definition", clip(name)));
    else
        ctx_.error(n.nameTok, fmt::format("unknown module or definition '{}'", clip(name)));
    return placeholder();
}

// A notation-B call S(e1, ...): a simultaneous C-node on S's formals over its S-node.
NodeId CsgLowering::call(const CsgNode& n) {
    const std::string_view name = ctx_.text(n.nameTok);
    auto it = names_.moduleByName.find(name);
    if (it == names_.moduleByName.end()) {
        if (names_.dropped(name)) return placeholder();
        if (names_.definitionByName.count(name))
            ctx_.error(n.nameTok, fmt::format("definition '{}' takes no arguments", clip(name)));
        else
            ctx_.error(n.nameTok, fmt::format("unknown module '{}'", clip(name)));
        return placeholder();
    }
    const ModuleInfo& m = names_.modules[it->second];
    if (!m.notationB) {
        ctx_.error(n.nameTok,
                   fmt::format("module {} uses notation A and has no parameter list; set its "
                               "parameters with a C-node, as in '{{c = ...}} {}'",
                               clip(name), clip(name)));
        return placeholder();
    }
    if (n.count != m.formals.size()) {
        ctx_.error(n.nameTok, fmt::format("module {} takes {} ({}), found {}", clip(name),
                                          argumentCount(static_cast<uint32_t>(m.formals.size())),
                                          formalList(ctx_, m.formals), n.count));
        return placeholder();
    }
    if (n.count == 0) return m.node;
    std::vector<Assignment> list;
    for (uint32_t i = 0; i < n.count; ++i)
        list.push_back(Assignment{m.formalSlots[i], exprs_.compile(ast_.lists[n.first + i])});
    Calc calc;
    calc.first = static_cast<uint32_t>(g_.assignments.size());
    calc.count = n.count;
    calc.simultaneous = true;
    g_.assignments.insert(g_.assignments.end(), list.begin(), list.end());
    g_.calcs.push_back(calc);
    return g_.addNode(NodeKind::Calc, static_cast<uint32_t>(g_.calcs.size() - 1), {m.node},
                      ctx_.loc(n.nameTok));
}

// Compiles a list of arguments; returns whether all are constant and finite, with
// their values.
bool CsgLowering::arguments(const CsgNode& n, uint32_t& firstArg, std::vector<double>& values) {
    std::vector<ExprId> ids;
    for (uint32_t i = 0; i < n.count; ++i) ids.push_back(exprs_.compile(ast_.lists[n.first + i]));
    firstArg = static_cast<uint32_t>(g_.args.size());
    g_.args.insert(g_.args.end(), ids.begin(), ids.end());
    bool constant = true;
    for (ExprId id : ids) {
        if (!g_.exprs[id].constant) {
            constant = false;
            continue;
        }
        const double v = evalExpr(g_, id, EvalState{nullptr, kRootPath});
        if (!std::isfinite(v)) constant = false;  // left to the run-time check
        values.push_back(v);
    }
    return constant;
}

// A T-node; its matrix is computed now when all arguments are constant and it is regular.
NodeId CsgLowering::transform(const CsgNode& n) {
    const TransformInfo info = transformInfo(n.op);
    const NodeId child = csg(n.child);
    if (n.count != info.args) {
        ctx_.error(n.tok, fmt::format("{} takes {} ({}), found {}", clip(ctx_.text(n.tok)),
                                      argumentCount(info.args), info.names, n.count));
        return child;
    }
    Transform tr;
    tr.op = n.op;
    tr.argCount = n.count;
    std::vector<double> values;
    const bool constant = arguments(n, tr.firstArg, values);
    if (constant) {
        if (const std::optional<Affine> m = constantTransform(n.op, values.data())) {
            tr.constant = true;
            tr.matrix = *m;
        }
    }
    g_.transforms.push_back(tr);
    return g_.addNode(NodeKind::Transform, static_cast<uint32_t>(g_.transforms.size() - 1), {child},
                      ctx_.loc(n.tok));
}

NodeId CsgLowering::primitive(const CsgNode& n) {
    const uint32_t want = primitiveArgCount(n.prim);
    if (n.count != want) {
        if (want == 0)
            ctx_.error(n.tok, fmt::format("{} takes no arguments", clip(ctx_.text(n.tok))));
        else
            ctx_.error(n.tok, fmt::format("{} takes {} ({}), found {}", clip(ctx_.text(n.tok)),
                                          argumentCount(want), primitiveArgNames(n.prim), n.count));
        return placeholder();
    }
    Primitive p;
    p.kind = n.prim;
    p.argCount = n.count;
    std::vector<double> values;
    p.constant = arguments(n, p.firstArg, values);
    if (p.constant) p.values = std::move(values);
    g_.primitives.push_back(std::move(p));
    return g_.addNode(NodeKind::Primitive, static_cast<uint32_t>(g_.primitives.size() - 1), {},
                      ctx_.loc(n.tok));
}

}  // namespace

void lowerCsg(BuildContext& ctx, Names& names, ExprCompiler& exprs) {
    CsgLowering(ctx, names, exprs).run();
}

}  // namespace pcsg
