// The builder's expression phase: arithmetic expressions to the stack code of graph.h
// (docs/language.md section 3; section 7 for the constants of directives). See
// build_exprs.h.
#include "build_exprs.h"

#include <fmt/format.h>

#include <cmath>

#include "eval.h"

namespace pcsg {

namespace {

struct FuncInfo {
    Kw kw;
    Func func;
    uint8_t minArgs, maxArgs;  // maxArgs 255: any number
};

constexpr FuncInfo kFunctions[] = {
    {Kw::Sin, Func::Sin, 1, 1},     {Kw::Cos, Func::Cos, 1, 1},     {Kw::Tan, Func::Tan, 1, 1},
    {Kw::Asin, Func::Asin, 1, 1},   {Kw::Acos, Func::Acos, 1, 1},   {Kw::Atan, Func::Atan, 1, 1},
    {Kw::Atan2, Func::Atan2, 2, 2}, {Kw::Sqrt, Func::Sqrt, 1, 1},   {Kw::Exp, Func::Exp, 1, 1},
    {Kw::Ln, Func::Ln, 1, 1},       {Kw::Log10, Func::Log10, 1, 1}, {Kw::Pow, Func::Pow, 2, 2},
    {Kw::Abs, Func::Abs, 1, 1},     {Kw::Floor, Func::Floor, 1, 1}, {Kw::Ceil, Func::Ceil, 1, 1},
    {Kw::Min, Func::Min, 2, 255},   {Kw::Max, Func::Max, 2, 255},   {Kw::Mod, Func::Mod, 2, 2},
    {Kw::Clamp, Func::Clamp, 3, 3},
};

const FuncInfo* functionInfo(Kw k) {
    for (const auto& f : kFunctions)
        if (f.kw == k) return &f;
    return nullptr;
}

struct BinaryOp {
    Tok tok;
    Op op;
};

// The left-associative binary operators of a Chain (&& and || are not: they jump).
constexpr BinaryOp kBinaryOps[] = {
    {Tok::Plus, Op::Add},    {Tok::Minus, Op::Sub}, {Tok::Star, Op::Mul}, {Tok::Slash, Op::Div},
    {Tok::Percent, Op::Mod}, {Tok::Lt, Op::Lt},     {Tok::Le, Op::Le},    {Tok::Gt, Op::Gt},
    {Tok::Ge, Op::Ge},       {Tok::Eq, Op::Eq},     {Tok::Ne, Op::Ne},
};

Op binaryOp(Tok t) {
    for (const BinaryOp& b : kBinaryOps)
        if (b.tok == t) return b.op;
    return Op::Add;
}

}  // namespace

std::string argumentCount(uint32_t n) {
    return fmt::format("{} argument{}", n, n == 1 ? "" : "s");
}

Slot ExprCompiler::slotOf(std::string_view name) {
    auto it = slots_.find(name);
    if (it != slots_.end()) return it->second;
    const Slot s = g_.slot(std::string(name));
    slots_.emplace(name, s);
    return s;
}

std::optional<double> ExprCompiler::constant(uint32_t e) {
    const auto v = directiveExpr(e, false);
    if (!v) return std::nullopt;
    return v->value;
}

std::optional<ExprCompiler::DirectiveValue> ExprCompiler::directiveValue(uint32_t e) {
    return directiveExpr(e, true);
}

std::optional<ExprCompiler::DirectiveValue> ExprCompiler::directiveExpr(uint32_t e,
                                                                        bool allowTime) {
    const size_t codeSize = g_.code.size(), exprCount = g_.exprs.size();
    const uint32_t sites = g_.randCallSites;
    constantOnly_ = true;
    const size_t errors = ctx_.diags.count();
    const ExprId id = compile(e);
    constantOnly_ = false;
    std::optional<DirectiveValue> value;
    const Expr& x = g_.exprs[id];
    if (ctx_.diags.count() == errors && x.usesTime && !x.usesPath && allowTime) {
        // kept: evaluated again at each frame's time
        return DirectiveValue{evalExpr(g_, id, EvalState{nullptr, kRootPath}), id};
    }
    if (ctx_.diags.count() != errors) {
        // reported already (a parameter, rand(), a syntax error): nothing to evaluate
    } else if (x.usesTime) {
        ctx_.error(
            ctx_.ast.exprs[e].from,
            fmt::format("'{}' reads the time (clock, frame): settings are constants", x.text));
    } else if (!g_.exprs[id].constant) {
        // compile() reports every way to be non-constant; should it miss one, this
        // error stands in for it, as evaluating needs a frame there is none of
        ctx_.error(ctx_.ast.exprs[e].from,
                   fmt::format("'{}' is not a constant", g_.exprs[id].text));
    } else {
        const double v = evalExpr(g_, id, EvalState{nullptr, kRootPath});
        if (std::isfinite(v))
            value = DirectiveValue{v, kNone};
        else
            ctx_.error(ctx_.ast.exprs[e].from,
                       fmt::format("'{}' is {}, not a finite number", g_.exprs[id].text, v));
    }
    g_.code.resize(codeSize);
    g_.exprs.resize(exprCount);
    g_.randCallSites = sites;
    return value;
}

// The source text of tokens [from, to], one space where the source had any gap.
std::string ExprCompiler::sourceText(uint32_t from, uint32_t to) const {
    const std::vector<Token>& t = ctx_.tokens;
    std::string s;
    for (uint32_t i = from; i <= to && i < t.size(); ++i) {
        if (t[i].kind == Tok::Newline || t[i].kind == Tok::End) continue;
        if (i > from) {
            const Token& p = t[i - 1];
            if (p.offset + p.length != t[i].offset) s += ' ';
        }
        s += spelling(ctx_.src, t[i]);
        if (s.size() > 200) {
            s.resize(200);
            s += "...";
            break;
        }
    }
    return s;
}

uint32_t ExprCompiler::emit(Op op, uint32_t a, double imm, uint8_t argc) {
    g_.code.push_back(Instr{op, argc, a, imm});
    return static_cast<uint32_t>(g_.code.size() - 1);
}

ExprId ExprCompiler::compile(uint32_t e) {
    CodeGen cg;
    Expr x;
    x.begin = here();
    gen(e, cg);
    x.end = here();
    x.maxStack = cg.maxDepth;
    x.usesPath = cg.usesPath;
    x.usesTime = cg.usesTime;
    x.constant = !cg.readsSlot && !cg.usesPath && !cg.usesTime;
    const ExNode& n = ctx_.ast.exprs[e];
    x.loc = ctx_.loc(n.from);
    x.text = sourceText(n.from, n.to);
    g_.exprs.push_back(std::move(x));
    const ExprId id = static_cast<ExprId>(g_.exprs.size() - 1);
    Expr& added = g_.exprs[id];
    if (added.constant && added.end - added.begin > 1) {
        // Fold a constant expression into one instruction.
        const double v = evalExpr(g_, id, EvalState{nullptr, kRootPath});
        g_.code.resize(added.begin);
        emit(Op::Const, 0, v);
        added.end = here();
        added.maxStack = 1;
    }
    return id;
}

void ExprCompiler::gen(uint32_t e, CodeGen& cg) {
    const ExNode& n = ctx_.ast.exprs[e];
    switch (n.kind) {
        case ExKind::Number:
            emit(Op::Const, 0, n.value);
            cg.push();
            return;
        case ExKind::Name:
            return name(n, cg);
        case ExKind::Unary:
            gen(n.a, cg);
            if (n.op == Tok::Minus)
                emit(Op::Neg);
            else if (n.op == Tok::Bang)
                emit(Op::Not);
            return;
        case ExKind::Power:
            gen(n.a, cg);
            gen(n.b, cg);
            emit(Op::Pow);
            cg.pop();
            return;
        case ExKind::Chain: {
            const Tok level = ctx_.ast.chainItems[n.first].op;
            if (level == Tok::AndAnd || level == Tok::OrOr) return logical(n, cg);
            return arithmetic(n, cg);
        }
        case ExKind::Call:
            return call(n, cg);
        case ExKind::Time:
            emit(ctx_.tokens[n.tok].kw == Kw::Clock ? Op::Clock : Op::Frame);
            cg.usesTime = true;
            cg.push();
            return;
    }
}

// A parameter: a slot to load, which some C-node or formal must assign.
void ExprCompiler::name(const ExNode& n, CodeGen& cg) {
    const std::string_view name = ctx_.text(n.tok);
    if (constantOnly_) {
        ctx_.error(n.tok,
                   fmt::format("'{}': the values of a directive are constants, not parameters",
                               clip(name)));
    } else if (!names_.assigned.count(name) && ctx_.ast.dropped == 0 &&
               reportedUnknown_.insert(name).second) {
        ctx_.error(n.tok,
                   fmt::format("unknown parameter '{}': no C-node or formal parameter assigns it",
                               clip(name)));
    }
    emit(Op::Load, slotOf(name));
    cg.readsSlot = true;
    cg.push();
}

// a && b && ..., a || b || ...: short-circuit, only the operands needed are evaluated.
void ExprCompiler::logical(const ExNode& n, CodeGen& cg) {
    const ChainItem* items = ctx_.ast.chainItems.data() + n.first;
    const bool isAnd = items[0].op == Tok::AndAnd;
    const uint32_t base = cg.depth;
    std::vector<uint32_t> patches;  // jumps to the end (||) or to "false" (&&)
    for (uint32_t i = 0; i <= n.count; ++i) {
        const uint32_t operand = i == 0 ? n.a : items[i - 1].operand;
        gen(operand, cg);
        if (i == n.count) {
            emit(Op::ToBool);
            break;
        }
        const uint32_t skip = emit(Op::JumpIfZero);
        cg.pop();
        if (isAnd) {
            patches.push_back(skip);
        } else {
            emit(Op::Const, 0, 1.0);
            cg.push();
            patches.push_back(emit(Op::Jump));
            cg.pop();
            g_.code[skip].a = here();
        }
    }
    if (isAnd) {
        const uint32_t toEnd = emit(Op::Jump);
        for (uint32_t p : patches) g_.code[p].a = here();
        emit(Op::Const, 0, 0.0);
        g_.code[toEnd].a = here();
    } else {
        for (uint32_t p : patches) g_.code[p].a = here();
    }
    cg.depth = base + 1;
}

// a op b op ...: left-associative, each operator on the two values on top of the stack.
void ExprCompiler::arithmetic(const ExNode& n, CodeGen& cg) {
    const ChainItem* items = ctx_.ast.chainItems.data() + n.first;
    gen(n.a, cg);
    for (uint32_t i = 0; i < n.count; ++i) {
        gen(items[i].operand, cg);
        emit(binaryOp(items[i].op));
        cg.pop();
    }
}

void ExprCompiler::badCall(const ExNode& n, CodeGen& cg, const std::string& message) {
    ctx_.error(n.tok, message);
    emit(Op::Const, 0, 0.0);
    cg.push();
}

void ExprCompiler::wrongCount(const ExNode& n, CodeGen& cg, const std::string& want) {
    badCall(n, cg, fmt::format("{}() takes {}, found {}", clip(ctx_.text(n.tok)), want, n.count));
}

void ExprCompiler::call(const ExNode& n, CodeGen& cg) {
    const Token& f = ctx_.tokens[n.tok];
    if (f.kind != Tok::Keyword)
        return badCall(n, cg, fmt::format("unknown function '{}'", clip(ctx_.text(n.tok))));
    switch (f.kw) {
        case Kw::If:
            return ifCall(n, cg);
        case Kw::Rand:
            return randCall(n, cg);
        case Kw::Choose:
            return chooseCall(n, cg);
        default:
            return functionCall(n, cg);
    }
}

// if(c, a, b): only the branch taken is evaluated.
void ExprCompiler::ifCall(const ExNode& n, CodeGen& cg) {
    if (n.count != 3) return wrongCount(n, cg, "3 arguments (condition, then, else)");
    const uint32_t* args = ctx_.ast.lists.data() + n.first;
    gen(args[0], cg);
    const uint32_t toElse = emit(Op::JumpIfZero);
    cg.pop();
    const uint32_t base = cg.depth;
    gen(args[1], cg);
    const uint32_t toEnd = emit(Op::Jump);
    g_.code[toElse].a = here();
    cg.depth = base;
    gen(args[2], cg);
    g_.code[toEnd].a = here();
}

// rand() depends on the instance (section 6); rand(x) is a function of x and the seed.
void ExprCompiler::randCall(const ExNode& n, CodeGen& cg) {
    if (n.count == 0) {
        if (constantOnly_)
            ctx_.error(n.tok, "rand() depends on the instance: it is not a constant");
        emit(Op::Rand0, g_.randCallSites++);
        cg.usesPath = true;
        cg.push();
        return;
    }
    if (n.count != 1) return wrongCount(n, cg, "no argument or 1");
    gen(ctx_.ast.lists[n.first], cg);
    emit(Op::Call, static_cast<uint32_t>(Func::Rand1), 0, 1);
}

void ExprCompiler::chooseCall(const ExNode& n, CodeGen& cg) {
    if (n.count < 1 || n.count > 255) return wrongCount(n, cg, "1 to 255 weights");
    if (constantOnly_) ctx_.error(n.tok, "choose() depends on the instance: it is not a constant");
    for (uint32_t i = 0; i < n.count; ++i) gen(ctx_.ast.lists[n.first + i], cg);
    emit(Op::Choose, g_.randCallSites++, 0, static_cast<uint8_t>(n.count));
    cg.usesPath = true;
    cg.pop(n.count - 1);
}

// The functions of kFunctions: every argument evaluated, then one Call.
void ExprCompiler::functionCall(const ExNode& n, CodeGen& cg) {
    const FuncInfo* info = functionInfo(ctx_.tokens[n.tok].kw);
    if (!info) return badCall(n, cg, fmt::format("'{}' is not a function", clip(ctx_.text(n.tok))));
    if (n.count < info->minArgs || n.count > info->maxArgs) {
        if (info->maxArgs == 255) return wrongCount(n, cg, "2 to 255 arguments");
        return wrongCount(n, cg, argumentCount(info->minArgs));
    }
    for (uint32_t i = 0; i < n.count; ++i) gen(ctx_.ast.lists[n.first + i], cg);
    emit(Op::Call, static_cast<uint32_t>(info->func), 0, static_cast<uint8_t>(n.count));
    cg.pop(n.count - 1);
}

}  // namespace pcsg
