// The shared evaluation code: see eval.h. Both renderers give a graph its meaning only
// through these functions.
#include "eval.h"

#include <fmt/format.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <tuple>

#include "eval_core.h"
#include "eval_recall.h"

namespace pcsg {

// ---------------------------------------------------------------------------------------
// Errors.

RuntimeError::RuntimeError(FileLoc l, std::string msg)
    : std::runtime_error(msg), loc(l), message(std::move(msg)) {}

std::string RuntimeError::format(const Graph& g) const {
    std::string out = fmt::format("{}: error: {}", g.where(loc), message);
    if (!modulePath.empty()) {
        // Long paths through one recursive module read better as runs: "S (x12) -> T".
        out += "\n  module path: ";
        for (size_t i = 0; i < modulePath.size();) {
            size_t j = i;
            while (j < modulePath.size() && modulePath[j] == modulePath[i]) ++j;
            if (i > 0) out += " -> ";
            out += modulePath[i];
            if (j - i > 1) out += fmt::format(" (x{})", j - i);
            i = j;
        }
    }
    return out;
}

double unassigned() {
    return std::bit_cast<double>(kUnassignedBits);
}
bool isUnassigned(double v) {
    return std::bit_cast<uint64_t>(v) == kUnassignedBits;
}

void initFrame(const Graph& g, double* frame) {
    const double u = unassigned();
    for (size_t i = 0; i < g.slotCount(); ++i) frame[i] = u;
}

std::string describeFrame(const Graph& g, const double* frame) {
    std::string out;
    size_t shown = 0;
    for (size_t i = 0; i < g.slotCount(); ++i) {
        if (isUnassigned(frame[i])) continue;
        if (shown == 12) {
            out += ", ...";
            break;
        }
        if (shown++) out += ", ";
        out += fmt::format("{} = {}", g.slotNames[i], frame[i]);
    }
    return out.empty() ? std::string("no parameters assigned") : out;
}

// ---------------------------------------------------------------------------------------
// Instance paths and randomness.

uint64_t pathChild(uint64_t path, uint32_t childIndex) {
    return pathChildInline(path, childIndex);
}
uint64_t pathRule(uint64_t path, uint32_t ruleIndex) {
    return pathRuleInline(path, ruleIndex);
}

double randOf(uint64_t seed, double x) {
    return randOfInline(seed, x);
}

double randAt(uint64_t seed, uint64_t path, uint32_t callSite) {
    return randAtInline(seed, path, callSite);
}

// ---------------------------------------------------------------------------------------
// Expressions.

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

[[noreturn]] void unassignedRead(const Graph& g, const Expr& e, Slot s) {
    throw RuntimeError(e.loc, fmt::format("parameter '{}' is read before it is assigned on "
                                          "this path (in '{}')",
                                          g.slotNames[s], e.text));
}

}  // namespace

double callFunc(Func f, const double* a, uint32_t n, uint64_t seed) {
    switch (f) {
        case Func::Sin:
            return sinDegrees(a[0]);
        case Func::Cos:
            return cosDegrees(a[0]);
        case Func::Tan:
            return sinDegrees(a[0]) / cosDegrees(a[0]);
        case Func::Asin:
            return std::asin(a[0]) / kDegToRad;
        case Func::Acos:
            return std::acos(a[0]) / kDegToRad;
        case Func::Atan:
            return std::atan(a[0]) / kDegToRad;
        case Func::Atan2:
            return std::atan2(a[0], a[1]) / kDegToRad;
        case Func::Sqrt:
            return std::sqrt(a[0]);
        case Func::Exp:
            return std::exp(a[0]);
        case Func::Ln:
            return lnRecalled(a[0]);
        case Func::Log10:
            return std::log10(a[0]);
        case Func::Pow:
            return powRecalled(a[0], a[1]);
        case Func::Abs:
            return std::fabs(a[0]);
        case Func::Floor:
            return std::floor(a[0]);
        case Func::Ceil:
            return std::ceil(a[0]);
        case Func::Min: {
            double m = a[0];
            for (uint32_t i = 1; i < n; ++i) m = std::fmin(m, a[i]);
            return m;
        }
        case Func::Max: {
            double m = a[0];
            for (uint32_t i = 1; i < n; ++i) m = std::fmax(m, a[i]);
            return m;
        }
        case Func::Mod:
            return std::fmod(a[0], a[1]);
        case Func::Clamp:
            return std::fmin(std::fmax(a[0], a[1]), a[2]);
        case Func::Rand1:
            return randOfInline(seed, a[0]);
    }
    return std::nan("");
}

bool chooseWeightsValid(const double* w, uint32_t n) {
    double total = 0;
    for (uint32_t i = 0; i < n; ++i) {
        if (!(w[i] >= 0) || !std::isfinite(w[i])) return false;
        total += w[i];
    }
    return total > 0;
}

double choosePick(const double* w, uint32_t n, double u) {
    double total = 0;
    for (uint32_t i = 0; i < n; ++i) total += w[i];
    const double x = u * total;
    double acc = 0;
    for (uint32_t i = 0; i < n; ++i) {
        acc += w[i];
        if (x < acc && w[i] > 0) return i + 1;
    }
    for (uint32_t i = n; i-- > 0;)  // rounding: the last rule with a positive weight
        if (w[i] > 0) return i + 1;
    return n;
}

namespace {

// choose(w1..wn): a rule number 1..n with probability proportional to the weights.
double chooseRule(const Graph& g, const Expr& e, const double* w, uint32_t n, double u) {
    double total = 0;
    for (uint32_t i = 0; i < n; ++i) {
        if (!(w[i] >= 0) || !std::isfinite(w[i]))
            throw RuntimeError(e.loc, fmt::format("choose() weight {} is {} in '{}': weights "
                                                  "must be finite and not negative",
                                                  i + 1, w[i], e.text));
        total += w[i];
    }
    if (!(total > 0))
        throw RuntimeError(e.loc, fmt::format("choose() weights are all zero in '{}'", e.text));
    return choosePick(w, n, u);
}

double run(const Graph& g, const Expr& e, EvalState s, double* stack) {
    const Instr* code = g.code.data();
    const uint64_t seed = g.scene.settings.seed;
    uint32_t sp = 0;
    for (uint32_t pc = e.begin; pc < e.end;) {
        const Instr& in = code[pc++];
        switch (in.op) {
            case Op::Const:
                stack[sp++] = in.imm;
                break;
            case Op::Load: {
                const double v = s.frame[in.a];
                if (std::isnan(v) && isUnassigned(v)) unassignedRead(g, e, in.a);
                stack[sp++] = v;
                break;
            }
            case Op::Neg:
                stack[sp - 1] = -stack[sp - 1];
                break;
            case Op::Not:
                stack[sp - 1] = stack[sp - 1] == 0 ? 1.0 : 0.0;
                break;
            case Op::ToBool:
                stack[sp - 1] = stack[sp - 1] != 0 ? 1.0 : 0.0;
                break;
#define PCSG_BINARY(OP, EXPR)           \
    case Op::OP: {                      \
        const double b = stack[--sp];   \
        const double a = stack[sp - 1]; \
        stack[sp - 1] = (EXPR);         \
        break;                          \
    }
                PCSG_BINARY(Add, a + b)
                PCSG_BINARY(Sub, a - b)
                PCSG_BINARY(Mul, a * b)
                PCSG_BINARY(Div, a / b)
                PCSG_BINARY(Mod, std::fmod(a, b))
                PCSG_BINARY(Pow, powRecalled(a, b))
                PCSG_BINARY(Lt, a < b ? 1.0 : 0.0)
                PCSG_BINARY(Le, a <= b ? 1.0 : 0.0)
                PCSG_BINARY(Gt, a > b ? 1.0 : 0.0)
                PCSG_BINARY(Ge, a >= b ? 1.0 : 0.0)
                PCSG_BINARY(Eq, a == b ? 1.0 : 0.0)
                PCSG_BINARY(Ne, a != b ? 1.0 : 0.0)
#undef PCSG_BINARY
            case Op::Jump:
                pc = in.a;
                break;
            case Op::JumpIfZero:
                if (stack[--sp] == 0) pc = in.a;
                break;
            case Op::Call: {
                sp -= in.argc;
                stack[sp] = callFunc(static_cast<Func>(in.a), stack + sp, in.argc, seed);
                ++sp;
                break;
            }
            case Op::Rand0:
                stack[sp++] = randAt(seed, s.path, in.a);
                break;
            case Op::Choose: {
                sp -= in.argc;
                stack[sp] = chooseRule(g, e, stack + sp, in.argc, randAt(seed, s.path, in.a));
                ++sp;
                break;
            }
            case Op::Clock:
                stack[sp++] = g.time.clock;
                break;
            case Op::Frame:
                stack[sp++] = g.time.frame;
                break;
        }
    }
    return sp > 0 ? stack[sp - 1] : std::nan("");
}

}  // namespace

namespace {
// A lone leaf (a T-node's argument `0` or `z1`), read without the machine's set-up, into v:
// false where e is more than a constant or an assigned parameter.
[[gnu::always_inline]] inline bool leafOf(const Graph& g, const Expr& e, EvalState s, double& v) {
    if (e.fast == kNoFast) return false;
    const FastInstr* f = g.fastCode.data() + e.fast;
    if (f[1].op != FastOp::End) return false;
    if (f->op == FastOp::PushK) {
        v = f->imm;
        return true;
    }
    if (f->op != FastOp::PushL || isUnassigned(s.frame[f->a])) return false;
    v = s.frame[f->a];
    return true;
}

// evalExpr()'s body.
[[gnu::always_inline]] inline double evalInline(const Graph& g, ExprId id, EvalState s) {
    const Expr& e = g.exprs[id];
    double v;
    if (e.fast != kNoFast) {
        if (leafOf(g, e, s, v)) return v;
        if (runFast(g, e.fast, s.frame, nullptr, s.path, v)) return v;
    }
    constexpr uint32_t kSmall = 64;
    if (e.maxStack <= kSmall) {
        double stack[kSmall];
        return run(g, e, s, stack);
    }
    std::vector<double> stack(e.maxStack);
    return run(g, e, s, stack.data());
}
}  // namespace

double evalExpr(const Graph& g, ExprId id, EvalState s) {
    return evalInline(g, id, s);
}

// ---------------------------------------------------------------------------------------
// S-nodes, C-nodes, T-nodes, primitives.

namespace {
const Module& moduleOf(const Graph& g, NodeId n) {
    return g.modules[g.nodes[n].payload];
}

[[noreturn]] void nonFinite(const Graph& g, const Expr& e, double v, const char* what,
                            const double* frame) {
    throw RuntimeError(e.loc, fmt::format("{} '{}' is {} (not a finite number) with {}", what,
                                          e.text, v, describeFrame(g, frame)));
}
}  // namespace

uint32_t selectRule(const Graph& g, NodeId n, EvalState s) {
    const Module& m = moduleOf(g, n);
    const uint32_t rules = g.nodes[n].childCount;
    if (m.notationB) {
        for (uint32_t i = 0; i < m.conditions.size() && i < rules; ++i) {
            const ExprId c = m.conditions[i];
            if (c == kNone) return i;
            const double v = evalExpr(g, c, s);
            if (!std::isfinite(v)) nonFinite(g, g.exprs[c], v, "the condition", s.frame);
            if (v != 0) return i;
        }
        throw RuntimeError(m.loc, fmt::format("no rule of module {} applies with {}", m.name,
                                              describeFrame(g, s.frame)));
    }
    const Expr& e = g.exprs[m.select];
    const double v = evalExpr(g, m.select, s);
    if (!std::isfinite(v))
        nonFinite(g, e, v, fmt::format("the selection function of module {}", m.name).c_str(),
                  s.frame);
    const double r = std::round(v);
    if (r < 1 || r > rules)
        throw RuntimeError(e.loc, fmt::format("the selection function of module {} gave rule {}, "
                                              "but {} has rules 1..{} (with {})",
                                              m.name, r, m.name, rules, describeFrame(g, s.frame)));
    return static_cast<uint32_t>(r) - 1;
}

void applyCalc(const Graph& g, NodeId n, EvalState in, double* out) {
    const Calc& c = g.calcs[g.nodes[n].payload];
    std::memcpy(out, in.frame, g.slotCount() * sizeof(double));
    if (c.fast != kNoFast) {
        double unused;
        if (runFast(g, c.fast, c.simultaneous ? in.frame : out, out, in.path, unused)) return;
        // the plain code below reports the error
        std::memcpy(out, in.frame, g.slotCount() * sizeof(double));
    }
    const Assignment* as = g.assignments.data() + c.first;
    if (!c.simultaneous) {
        const EvalState cur{out, in.path};
        for (uint32_t i = 0; i < c.count; ++i) out[as[i].slot] = evalExpr(g, as[i].value, cur);
        return;
    }
    constexpr uint32_t kSmall = 16;
    double small[kSmall];
    std::vector<double> big;
    double* values = small;
    if (c.count > kSmall) {
        big.resize(c.count);
        values = big.data();
    }
    for (uint32_t i = 0; i < c.count; ++i) values[i] = evalExpr(g, as[i].value, in);
    for (uint32_t i = 0; i < c.count; ++i) out[as[i].slot] = values[i];
}

namespace {
// move() and zshear(), the terrain's two T-steps a triangle: their matrices are the arguments
// written into the identity, and their determinant is 1 exactly (see checkedTransform).
bool isUnitShear(TransformOp op) {
    return op == TransformOp::Move || op == TransformOp::ZShear;
}
// makeTransform() of move() or zshear(), written into `m` (which holds the identity).
[[gnu::always_inline]] inline void writeUnitShear(TransformOp op, const double* a, Affine& m) {
    if (op == TransformOp::Move)
        m.t = {a[0], a[1], a[2]};
    else
        m.l[2][0] = a[0], m.l[2][1] = a[1];
}
}  // namespace

Affine makeTransform(TransformOp op, const double* a) {
    Affine m;
    switch (op) {
        case TransformOp::Move:
        case TransformOp::ZShear:
            writeUnitShear(op, a, m);
            return m;
        case TransformOp::Scale:
            return Affine::scale({a[0], a[1], a[2]});
        case TransformOp::UScale:
            return Affine::scale({a[0], a[0], a[0]});
        case TransformOp::RotX: {
            const double c = cosDegrees(a[0]), s = sinDegrees(a[0]);
            m.l[1][1] = c, m.l[1][2] = -s, m.l[2][1] = s, m.l[2][2] = c;
            return m;
        }
        case TransformOp::RotY: {
            const double c = cosDegrees(a[0]), s = sinDegrees(a[0]);
            m.l[0][0] = c, m.l[0][2] = s, m.l[2][0] = -s, m.l[2][2] = c;
            return m;
        }
        case TransformOp::RotZ: {
            const double c = cosDegrees(a[0]), s = sinDegrees(a[0]);
            m.l[0][0] = c, m.l[0][1] = -s, m.l[1][0] = s, m.l[1][1] = c;
            return m;
        }
        case TransformOp::Rot: {
            // Rodrigues' formula about the unit axis k: R = cI + s[k]x + (1-c) k k^T.
            const double len = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
            const Vec3 k{a[0] / len, a[1] / len, a[2] / len};
            const double c = cosDegrees(a[3]), s = sinDegrees(a[3]), t = 1 - c;
            m.l[0][0] = c + t * k.x * k.x;
            m.l[0][1] = t * k.x * k.y - s * k.z;
            m.l[0][2] = t * k.x * k.z + s * k.y;
            m.l[1][0] = t * k.y * k.x + s * k.z;
            m.l[1][1] = c + t * k.y * k.y;
            m.l[1][2] = t * k.y * k.z - s * k.x;
            m.l[2][0] = t * k.z * k.x - s * k.y;
            m.l[2][1] = t * k.z * k.y + s * k.x;
            m.l[2][2] = c + t * k.z * k.z;
            return m;
        }
        case TransformOp::FlipYZ:
            m.l[0][0] = -1;
            return m;
        case TransformOp::FlipXZ:
            m.l[1][1] = -1;
            return m;
        case TransformOp::FlipXY:
            m.l[2][2] = -1;
            return m;
        case TransformOp::Matrix:
            // POV-Ray's row-vector form p' = p·M + t: coordinate i of the result takes
            // p_j times M[j][i], so L[i][j] = M[j][i] = a[3*j + i].
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) m.l[i][j] = a[3 * j + i];
            m.t = {a[9], a[10], a[11]};
            return m;
    }
    return m;
}

std::optional<Affine> constantTransform(TransformOp op, const double* a) {
    if (op == TransformOp::Rot && a[0] == 0 && a[1] == 0 && a[2] == 0) return std::nullopt;
    const Affine m = makeTransform(op, a);
    if (!m.isFinite() || !(m.determinant() != 0)) return std::nullopt;
    return m;
}

namespace {

// The values of a T-node's arguments into `a`, each checked finite in order. Its program
// (Transform::fast) computes each argument as evalExpr() would, all in one run of the
// machine; where it stops (an unassigned read), the arguments are evaluated one by one,
// which reports the first error as it always did. A lone leaf is read here, anything else
// through evalExpr() (out of line: the leaves' path keeps a small frame).
[[gnu::noinline]] void argumentsInGeneral(const Graph& g, const Transform& t, EvalState s,
                                          double* a) {
    double unused;
    const bool all = t.fast != kNoFast && runFast(g, t.fast, s.frame, a, s.path, unused);
    for (uint32_t i = 0; i < t.argCount; ++i) {
        const ExprId id = g.args[t.firstArg + i];
        if (!all && !leafOf(g, g.exprs[id], s, a[i])) a[i] = evalExpr(g, id, s);
        if (!std::isfinite(a[i]))
            nonFinite(g, g.exprs[id], a[i], "the transformation argument", s.frame);
    }
}

// The same, first tried for a T-node with no program (all its arguments lone leaves, as
// move(0, 0, z1)) without a call: no registers saved, the loop only reads. Where a leaf is
// unassigned or a value not finite, argumentsInGeneral() starts again and reports it.
void argumentsOf(const Graph& g, const Transform& t, EvalState s, double* a) {
    if (t.fast == kNoFast) {
        const ExprId* ids = g.args.data() + t.firstArg;
        uint32_t i = 0;
        while (i < t.argCount && leafOf(g, g.exprs[ids[i]], s, a[i]) && std::isfinite(a[i])) ++i;
        if (i == t.argCount) return;
    }
    argumentsInGeneral(g, t, s, a);
}

// A T-node's arguments, checked, and its matrix. move() and zshear() of finite arguments
// have the determinant 1 exactly (its products of the zeros and ones of the identity are
// exact), so they need no singularity test: transformMatrix and transformPair write them
// without this function (no call of makeTransform, no matrix returned through two frames).
Affine checkedTransform(const Graph& g, NodeId n, EvalState s, double* a) {
    const Transform& t = g.transforms[g.nodes[n].payload];
    argumentsOf(g, t, s, a);
    const FileLoc loc = t.argCount ? g.exprs[g.args[t.firstArg]].loc : g.nodes[n].loc;
    if (t.op == TransformOp::Rot && a[0] == 0 && a[1] == 0 && a[2] == 0)
        throw RuntimeError(
            loc, fmt::format("rot() about the zero axis with {}", describeFrame(g, s.frame)));
    const Affine m = makeTransform(t.op, a);
    if (!(m.determinant() != 0) || !m.isFinite())
        throw RuntimeError(
            loc, fmt::format("{} is singular (a zero scale factor?) with {}",
                             t.op == TransformOp::Matrix ? "matrix()" : "the transformation",
                             describeFrame(g, s.frame)));
    return m;
}

}  // namespace

Affine transformMatrix(const Graph& g, NodeId n, EvalState s) {
    const Transform& t = g.transforms[g.nodes[n].payload];
    if (t.constant) return t.matrix;
    double a[12];
    if (!isUnitShear(t.op)) return checkedTransform(g, n, s, a);
    argumentsOf(g, t, s, a);
    Affine m;
    writeUnitShear(t.op, a, m);
    return m;
}

void transformPair(const Graph& g, NodeId n, EvalState s, Affine& forward, Affine& inverse) {
    const Transform& t = g.transforms[g.nodes[n].payload];
    if (t.constant) {
        forward = t.matrix;
        inverse = forward.inverse();
        return;
    }
    double a[12];
    if (isUnitShear(t.op)) {
        argumentsOf(g, t, s, a);
        forward = Affine::identity();
        writeUnitShear(t.op, a, forward);
    } else {
        forward = checkedTransform(g, n, s, a);
    }
    inverse = inverseOf(t.op, a, forward);
}

// Affine::inverse() of a translation by (x, y, z): the determinant and every entry of the
// linear part are products and differences of the identity's zeros and ones, so exactly 1
// and the identity (every zero +0); the translation is -(L t) with L the identity, whose
// sums keep their terms 0 * x in Affine::vector's order (the signs of zeros).
// Of zshear(a, b) (L's row 2 is (a, b, 1)): the entries that are not constant are
// 0*b - 0, 0*a - 0 (x - +0 is x), 0*b - a and 0*a - b; L t with t = +0 adds up to +0 in
// each row (its last term is +0, and -0 + +0 is +0), so the translation is -0.
Affine inverseOf(TransformOp op, const double* a, const Affine& forward) {
    if (op == TransformOp::Move) {
        const double x = a[0], y = a[1], z = a[2];
        return Affine::translate(
            {-((x + 0.0 * y) + 0.0 * z), -((0.0 * x + y) + 0.0 * z), -((0.0 * x + 0.0 * y) + z)});
    }
    if (op == TransformOp::ZShear) {
        Affine r;
        r.l[0][1] = 0.0 * a[1], r.l[1][0] = 0.0 * a[0];
        r.l[2][0] = 0.0 * a[1] - a[0], r.l[2][1] = 0.0 * a[0] - a[1];
        r.t = {-0.0, -0.0, -0.0};
        return r;
    }
    return forward.inverse();
}

void primitiveArgs(const Graph& g, NodeId n, EvalState s, double* out) {
    const Primitive& p = g.primitives[g.nodes[n].payload];
    if (p.constant) {
        for (size_t i = 0; i < p.values.size(); ++i) out[i] = p.values[i];
        return;
    }
    for (uint32_t i = 0; i < p.argCount; ++i) {
        const ExprId id = g.args[p.firstArg + i];
        out[i] = evalExpr(g, id, s);
        if (!std::isfinite(out[i]))
            nonFinite(g, g.exprs[id], out[i], "the primitive argument", s.frame);
    }
}

namespace {

double sinDegreesComputed(double a) {
    const double r = std::fmod(a, 360.0);
    if (r == 0 || r == 180 || r == -180) return 0;
    if (r == 90 || r == -270) return 1;
    if (r == -90 || r == 270) return -1;
    return std::sin(a * kDegToRad);
}

}  // namespace

double sinDegrees(double a) {
    thread_local Recall<1, double (*)(double)> memo(sinDegreesComputed);
    return memo({a});
}

double powRecalled(double a, double b) {
    thread_local Recall<2, double (*)(double, double)> memo(
        [](double x, double y) { return std::pow(x, y); });
    return memo({a, b});
}

double lnRecalled(double a) {
    thread_local Recall<1, double (*)(double)> memo([](double x) { return std::log(x); });
    return memo({a});
}

double cosDegrees(double a) {
    return sinDegrees(a + 90.0);
}

void checkDepth(const Graph& g, NodeId n, uint32_t depth, EvalState s) {
    if (depth <= g.scene.settings.maxDepth) return;
    const Module& m = moduleOf(g, n);
    throw RuntimeError(
        m.loc, fmt::format("module {} reached depth {}, beyond settings max_depth "
                           "{}, with {}: does every path reach a terminating rule?",
                           m.name, depth, g.scene.settings.maxDepth, describeFrame(g, s.frame)));
}

}  // namespace pcsg
