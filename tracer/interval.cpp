#include "interval.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "eval.h"

namespace pcsg::tracer {

namespace {

constexpr double kInf = Interval::kInf;
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

Interval reals(double lo, double hi, bool nan = false) {
    return Interval{lo, hi, nan};
}
Interval nanOnly() {
    return Interval{kInf, -kInf, true};
}
Interval boolean(bool canTrue, bool canFalse) {
    if (canTrue && canFalse) return Interval::of(0, 1);
    if (canTrue) return Interval::point(1);
    if (canFalse) return Interval::point(0);
    return Interval::bottom();
}

bool hasInfEnd(const Interval& a) {
    return a.hasReals() && (std::isinf(a.lo) || std::isinf(a.hi));
}
bool hasNonZero(const Interval& a) {
    return a.hasReals() && !(a.lo == 0 && a.hi == 0);
}

// x * y with 0 * inf = 0 (the ends of a set of finite values).
double mulEnd(double x, double y) {
    return (x == 0 || y == 0) ? 0.0 : x * y;
}

Interval add(const Interval& a, const Interval& b) {
    bool nan = a.nan || b.nan;
    if (!a.hasReals() || !b.hasReals()) return nan ? nanOnly() : Interval::bottom();
    if ((a.hi == kInf && b.lo == -kInf) || (a.lo == -kInf && b.hi == kInf)) nan = true;
    double lo = a.lo + b.lo, hi = a.hi + b.hi;
    if (std::isnan(lo)) lo = -kInf;
    if (std::isnan(hi)) hi = kInf;
    return reals(lo, hi, nan);
}

Interval neg(const Interval& a) {
    return Interval{-a.hi, -a.lo, a.nan};
}

Interval sub(const Interval& a, const Interval& b) {
    return add(a, neg(b));
}

Interval mul(const Interval& a, const Interval& b) {
    bool nan = a.nan || b.nan;
    if (!a.hasReals() || !b.hasReals()) return nan ? nanOnly() : Interval::bottom();
    if ((a.contains(0) && hasInfEnd(b)) || (b.contains(0) && hasInfEnd(a))) nan = true;
    const double p[4] = {mulEnd(a.lo, b.lo), mulEnd(a.lo, b.hi), mulEnd(a.hi, b.lo),
                         mulEnd(a.hi, b.hi)};
    return reals(*std::min_element(p, p + 4), *std::max_element(p, p + 4), nan);
}

Interval div(const Interval& a, const Interval& b) {
    bool nan = a.nan || b.nan;
    if (!a.hasReals() || !b.hasReals()) return nan ? nanOnly() : Interval::bottom();
    if ((a.contains(0) && b.contains(0)) || (hasInfEnd(a) && hasInfEnd(b))) nan = true;
    if (b.contains(0)) return reals(-kInf, kInf, nan);
    double lo = kInf, hi = -kInf;
    for (double x : {a.lo, a.hi})
        for (double y : {b.lo, b.hi}) {
            const double q = x / y;
            if (std::isnan(q)) continue;
            lo = std::min(lo, q);
            hi = std::max(hi, q);
        }
    if (lo > hi) return nan ? nanOnly() : Interval::bottom();
    return reals(lo, hi, nan);
}

Interval fmodInterval(const Interval& a, const Interval& b) {
    if (a.isPoint() && b.isPoint()) return Interval::point(std::fmod(a.lo, b.lo));
    bool nan = a.nan || b.nan || b.contains(0) || hasInfEnd(a);
    if (!a.hasReals() || !b.hasReals()) return nan ? nanOnly() : Interval::bottom();
    const double m = std::max(std::fabs(b.lo), std::fabs(b.hi));
    double lo = std::max(a.lo, -m), hi = std::min(a.hi, m);
    if (a.lo >= 0) lo = 0;
    if (a.hi <= 0) hi = 0;
    if (a.lo >= 0 && a.hi > m) hi = m;
    if (a.hi <= 0 && a.lo < -m) lo = -m;
    if (lo > hi) return nan ? nanOnly() : Interval::bottom();
    return reals(lo, hi, nan);
}

// A function increasing on its domain [dlo, dhi] (values outside are NaN).
template <class F>
Interval increasing(const Interval& a, F f, double dlo = -kInf, double dhi = kInf) {
    bool nan = a.nan || (a.hasReals() && (a.lo < dlo || a.hi > dhi));
    const double lo = std::max(a.lo, dlo), hi = std::min(a.hi, dhi);
    if (!a.hasReals() || lo > hi) return nan ? nanOnly() : Interval::bottom();
    return reals(f(lo), f(hi), nan);
}

template <class F>
Interval decreasing(const Interval& a, F f, double dlo = -kInf, double dhi = kInf) {
    bool nan = a.nan || (a.hasReals() && (a.lo < dlo || a.hi > dhi));
    const double lo = std::max(a.lo, dlo), hi = std::min(a.hi, dhi);
    if (!a.hasReals() || lo > hi) return nan ? nanOnly() : Interval::bottom();
    return reals(f(hi), f(lo), nan);
}

// Some x = base + period * k, k an integer, in [lo, hi]?
bool containsPeriodic(double lo, double hi, double base, double period) {
    return std::ceil((lo - base) / period) <= std::floor((hi - base) / period);
}

Interval sinInterval(const Interval& a) {
    if (!a.hasReals()) return a.nan ? nanOnly() : Interval::bottom();
    if (a.isPoint()) return Interval::point(sinDegrees(a.lo));
    if (std::isinf(a.lo) || std::isinf(a.hi)) return reals(-1, 1, true);
    if (a.hi - a.lo >= 360) return reals(-1, 1, a.nan);
    const double s1 = sinDegrees(a.lo), s2 = sinDegrees(a.hi);
    double lo = std::min(s1, s2), hi = std::max(s1, s2);
    if (containsPeriodic(a.lo, a.hi, 90, 360)) hi = 1;
    if (containsPeriodic(a.lo, a.hi, -90, 360)) lo = -1;
    return reals(lo, hi, a.nan);
}

Interval cosInterval(const Interval& a) {
    if (a.isPoint()) return Interval::point(cosDegrees(a.lo));
    return sinInterval(add(a, Interval::point(90)));
}

Interval tanInterval(const Interval& a) {
    if (!a.hasReals()) return a.nan ? nanOnly() : Interval::bottom();
    if (a.isPoint()) return Interval::point(sinDegrees(a.lo) / cosDegrees(a.lo));
    if (std::isinf(a.lo) || std::isinf(a.hi) || containsPeriodic(a.lo, a.hi, 90, 180))
        return Interval::all();
    return reals(sinDegrees(a.lo) / cosDegrees(a.lo), sinDegrees(a.hi) / cosDegrees(a.hi), a.nan);
}

Interval absInterval(const Interval& a) {
    if (!a.hasReals()) return a;
    if (a.lo >= 0) return a;
    if (a.hi <= 0) return neg(a);
    return reals(0, std::max(-a.lo, a.hi), a.nan);
}

Interval powInterval(const Interval& a, const Interval& b) {
    if (a.isPoint() && b.isPoint()) return Interval::point(std::pow(a.lo, b.lo));
    if (!a.hasReals() || !b.hasReals()) return (a.nan || b.nan) ? nanOnly() : Interval::bottom();
    const bool nan = a.nan || b.nan;
    if (b.isPoint() && b.lo == std::floor(b.lo) && std::fabs(b.lo) < 1e15) {
        const double k = b.lo;
        if (k >= 0) {
            const bool even = std::fmod(k, 2.0) == 0;
            if (!even) return reals(std::pow(a.lo, k), std::pow(a.hi, k), nan);
            const Interval m = absInterval(a);
            return reals(std::pow(m.lo, k), std::pow(m.hi, k), nan);
        }
    }
    if (a.lo > 0) {
        double lo = kInf, hi = -kInf;
        for (double x : {a.lo, a.hi})
            for (double y : {b.lo, b.hi}) {
                const double p = std::pow(x, y);
                if (std::isnan(p)) return Interval::all();
                lo = std::min(lo, p);
                hi = std::max(hi, p);
            }
        return reals(lo, hi, nan);
    }
    return Interval::all();
}

// fmin/fmax semantics: a NaN argument is ignored unless all are NaN. The minimum is at
// least the smallest lower end and at most the upper end of every argument that is never
// NaN (if there is none, any argument's value can come out alone).
Interval minMax(const Interval* v, uint32_t n, bool isMin) {
    double lo = kInf, hi = -kInf;
    double bound = isMin ? kInf : -kInf;
    bool anyNeverNan = false, nan = true;
    for (uint32_t i = 0; i < n; ++i) {
        if (v[i].isBottom()) return Interval::bottom();
        nan = nan && v[i].nan;
        if (!v[i].hasReals()) continue;
        lo = std::min(lo, v[i].lo);
        hi = std::max(hi, v[i].hi);
        if (!v[i].nan) {
            anyNeverNan = true;
            bound = isMin ? std::min(bound, v[i].hi) : std::max(bound, v[i].lo);
        }
    }
    if (lo > hi) return nan ? nanOnly() : Interval::bottom();
    if (anyNeverNan) {
        if (isMin)
            hi = bound;
        else
            lo = bound;
    }
    return reals(lo, hi, nan);
}

Interval compare(Op op, const Interval& a, const Interval& b) {
    const bool nan = a.nan || b.nan;
    const bool r = a.hasReals() && b.hasReals();
    const bool samePoint = r && a.lo == a.hi && b.lo == b.hi && a.lo == b.lo;
    const bool overlap = r && std::max(a.lo, b.lo) <= std::min(a.hi, b.hi);
    switch (op) {
        case Op::Lt:
            return boolean(r && a.lo < b.hi, nan || (r && a.hi >= b.lo));
        case Op::Le:
            return boolean(r && a.lo <= b.hi, nan || (r && a.hi > b.lo));
        case Op::Gt:
            return boolean(r && a.hi > b.lo, nan || (r && a.lo <= b.hi));
        case Op::Ge:
            return boolean(r && a.hi >= b.lo, nan || (r && a.lo < b.hi));
        case Op::Eq:
            return boolean(overlap, nan || (r && !samePoint));
        case Op::Ne:
            return boolean(nan || (r && !samePoint), overlap);
        default:
            return Interval::all();
    }
}

Interval callFunc(Func f, const Interval* a, uint32_t n, uint64_t seed) {
    switch (f) {
        case Func::Sin:
            return sinInterval(a[0]);
        case Func::Cos:
            return cosInterval(a[0]);
        case Func::Tan:
            return tanInterval(a[0]);
        case Func::Asin:
            return increasing(
                a[0], [](double x) { return std::asin(x) / kDegToRad; }, -1, 1);
        case Func::Acos:
            return decreasing(
                a[0], [](double x) { return std::acos(x) / kDegToRad; }, -1, 1);
        case Func::Atan:
            return increasing(a[0], [](double x) { return std::atan(x) / kDegToRad; });
        case Func::Atan2:
            if (a[0].isPoint() && a[1].isPoint())
                return Interval::point(std::atan2(a[0].lo, a[1].lo) / kDegToRad);
            return reals(-180, 180, a[0].nan || a[1].nan);
        case Func::Sqrt:
            return increasing(
                a[0], [](double x) { return std::sqrt(x); }, 0, kInf);
        case Func::Exp:
            return increasing(a[0], [](double x) { return std::exp(x); });
        case Func::Ln:
            return increasing(
                a[0], [](double x) { return std::log(x); }, 0, kInf);
        case Func::Log10:
            return increasing(
                a[0], [](double x) { return std::log10(x); }, 0, kInf);
        case Func::Pow:
            return powInterval(a[0], a[1]);
        case Func::Abs:
            return absInterval(a[0]);
        case Func::Floor:
            return increasing(a[0], [](double x) { return std::floor(x); });
        case Func::Ceil:
            return increasing(a[0], [](double x) { return std::ceil(x); });
        case Func::Min:
            return minMax(a, n, true);
        case Func::Max:
            return minMax(a, n, false);
        case Func::Mod:
            return fmodInterval(a[0], a[1]);
        case Func::Clamp: {
            const Interval m[2] = {a[0], a[1]};
            const Interval lower = minMax(m, 2, false);
            const Interval k[2] = {lower, a[2]};
            return minMax(k, 2, true);
        }
        case Func::Rand1:
            if (a[0].isPoint()) return Interval::point(randOf(seed, a[0].lo));
            return reals(0, 1);
    }
    return Interval::all();
}

// An arithmetic or comparison operator of the expression code.
Interval binaryOp(Op op, const Interval& a, const Interval& b) {
    switch (op) {
        case Op::Add:
            return add(a, b);
        case Op::Sub:
            return sub(a, b);
        case Op::Mul:
            return mul(a, b);
        case Op::Div:
            return div(a, b);
        case Op::Mod:
            return fmodInterval(a, b);
        case Op::Pow:
            return powInterval(a, b);
        default:
            return compare(op, a, b);
    }
}

// The interpreter: `if` and the short-circuit operators compile to jumps; when a
// condition may be both zero and non-zero both continuations run and their results are
// joined. `forks` bounds the work (beyond it, the result is everything). With `leaves`
// set, the result of every path through the code is also kept there, unjoined: a
// selection `if(c, 2, if(d, 3, 1))` may give {1, 3} where the join says [1, 3].
struct IntervalVm {
    const Graph& g;
    const AbstractFrame& frame;
    uint64_t seed;
    TimeRange time;
    int forks = 0;
    static constexpr int kMaxForks = 64;
    std::vector<Interval>* leaves = nullptr;

    Interval leaf(const Interval& r) {
        if (leaves) leaves->push_back(r);
        return r;
    }

    Interval run(uint32_t pc, uint32_t end, std::vector<Interval> stack) {
        const Instr* code = g.code.data();
        while (pc < end) {
            const Instr& in = code[pc++];
            switch (in.op) {
                case Op::Jump:
                    pc = in.a;
                    break;
                case Op::JumpIfZero: {
                    const Interval v = stack.back();
                    stack.pop_back();
                    const bool canJump = v.contains(0);
                    const bool canFall = v.nan || hasNonZero(v);
                    if (canJump && canFall) {
                        if (++forks > kMaxForks) return leaf(Interval::all());
                        const Interval x = run(in.a, end, stack);
                        const Interval y = run(pc, end, stack);
                        return join(x, y);
                    }
                    if (canJump)
                        pc = in.a;
                    else if (!canFall)
                        return Interval::bottom();
                    break;
                }
                default:
                    if (!execute(in, stack)) return Interval::bottom();
                    break;
            }
            if (!stack.empty() && stack.back().isBottom()) return Interval::bottom();
        }
        return leaf(stack.empty() ? Interval::all() : stack.back());
    }

    // Runs one instruction that does not jump, on the stack; false when it reads a slot
    // that is never assigned (every evaluation fails).
    bool execute(const Instr& in, std::vector<Interval>& stack) const {
        switch (in.op) {
            case Op::Const:
                stack.push_back(Interval::point(in.imm));
                break;
            case Op::Load: {
                const AbstractSlot& s = frame[in.a];
                if (s.value.isBottom()) return false;  // always unassigned
                stack.push_back(s.value);
                break;
            }
            case Op::Neg:
                stack.back() = neg(stack.back());
                break;
            case Op::Not: {
                const Interval v = stack.back();
                stack.back() = boolean(v.contains(0), v.nan || hasNonZero(v));
                break;
            }
            case Op::ToBool: {
                const Interval v = stack.back();
                stack.back() = boolean(v.nan || hasNonZero(v), v.contains(0));
                break;
            }
            case Op::Add:
            case Op::Sub:
            case Op::Mul:
            case Op::Div:
            case Op::Mod:
            case Op::Pow:
            case Op::Lt:
            case Op::Le:
            case Op::Gt:
            case Op::Ge:
            case Op::Eq:
            case Op::Ne: {
                const Interval b = stack.back();
                stack.pop_back();
                const Interval a = stack.back();
                stack.back() = binaryOp(in.op, a, b);
                break;
            }
            case Op::Call: {
                const size_t base = stack.size() - in.argc;
                const Interval r =
                    callFunc(static_cast<Func>(in.a), stack.data() + base, in.argc, seed);
                stack.resize(base);
                stack.push_back(r);
                break;
            }
            case Op::Rand0:
                stack.push_back(reals(0, 1));
                break;
            case Op::Choose: {
                const size_t base = stack.size() - in.argc;
                stack.resize(base);
                stack.push_back(reals(1, in.argc));
                break;
            }
            case Op::Clock:
                stack.push_back(Interval::of(time.clockLo, time.clockHi));
                break;
            case Op::Frame:
                stack.push_back(Interval::of(time.frameLo, time.frameHi));
                break;
            case Op::Jump:
            case Op::JumpIfZero:
                break;  // run's
        }
        return true;
    }
};

// The finite reals of an argument interval (NaN and infinite values are run-time errors
// in transformations and primitive arguments).
Interval finiteArg(const Interval& a) {
    return Interval{a.lo, a.hi, false};
}

// RotX, RotY or RotZ by an angle in the interval: sets the rotation's plane in `out`.
void planeRotationInterval(TransformOp op, const Interval& angle, IntervalAffine& out) {
    auto& l = out.l;
    const Interval c = cosInterval(angle), s = sinInterval(angle);
    const Interval ns = neg(s);
    const int p = op == TransformOp::RotX ? 1 : (op == TransformOp::RotY ? 2 : 0);
    const int q = (p + 1) % 3;
    // rotation in the (p, q) plane: RotX (y,z), RotY (z,x), RotZ (x,y)
    l[p][p] = c, l[p][q] = ns, l[q][p] = s, l[q][q] = c;
}

// Rot: by the angle a[3] about the axis (a[0], a[1], a[2]), into `out`'s linear part;
// false when the axis is the zero vector (every evaluation fails).
bool axisRotationInterval(const Interval* a, IntervalAffine& out) {
    auto& l = out.l;
    const Interval one = Interval::of(-1, 1);
    if (!(a[0].isPoint() && a[1].isPoint() && a[2].isPoint())) {
        for (auto& row : l)
            for (auto& e : row) e = one;
        return true;
    }
    const double len = std::sqrt(a[0].lo * a[0].lo + a[1].lo * a[1].lo + a[2].lo * a[2].lo);
    if (!(len > 0)) return false;
    const double k[3] = {a[0].lo / len, a[1].lo / len, a[2].lo / len};
    const Interval c = cosInterval(a[3]), s = sinInterval(a[3]);
    const Interval tt = sub(Interval::point(1), c);
    auto kk = [&](int i, int j) { return mul(tt, Interval::point(k[i] * k[j])); };
    auto sk = [&](int i) { return mul(s, Interval::point(k[i])); };
    l[0][0] = add(c, kk(0, 0));
    l[0][1] = sub(kk(0, 1), sk(2));
    l[0][2] = add(kk(0, 2), sk(1));
    l[1][0] = add(kk(1, 0), sk(2));
    l[1][1] = add(c, kk(1, 1));
    l[1][2] = sub(kk(1, 2), sk(0));
    l[2][0] = sub(kk(2, 0), sk(1));
    l[2][1] = add(kk(2, 1), sk(0));
    l[2][2] = add(c, kk(2, 2));
    for (auto& row : l)
        for (auto& e : row) e = Interval{std::max(e.lo, -1.0), std::min(e.hi, 1.0), false};
    return true;
}

// The matrices of a transformation whose arguments (finite, not all points) are in `a`;
// false when every evaluation fails.
bool transformOfIntervals(TransformOp op, const Interval* a, IntervalAffine& out) {
    out = IntervalAffine::of(Affine::identity());
    auto& l = out.l;
    switch (op) {
        case TransformOp::Move:
            out.t[0] = a[0], out.t[1] = a[1], out.t[2] = a[2];
            break;
        case TransformOp::Scale:
            l[0][0] = a[0], l[1][1] = a[1], l[2][2] = a[2];
            break;
        case TransformOp::UScale:
            l[0][0] = l[1][1] = l[2][2] = a[0];
            break;
        case TransformOp::RotX:
        case TransformOp::RotY:
        case TransformOp::RotZ:
            planeRotationInterval(op, a[0], out);
            break;
        case TransformOp::Rot:
            return axisRotationInterval(a, out);
        case TransformOp::ZShear:
            l[2][0] = a[0], l[2][1] = a[1];
            break;
        case TransformOp::FlipYZ:
            l[0][0] = Interval::point(-1);
            break;
        case TransformOp::FlipXZ:
            l[1][1] = Interval::point(-1);
            break;
        case TransformOp::FlipXY:
            l[2][2] = Interval::point(-1);
            break;
        case TransformOp::Matrix:
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) l[i][j] = a[3 * j + i];
            out.t[0] = a[9], out.t[1] = a[10], out.t[2] = a[11];
            break;
    }
    return true;
}

}  // namespace

Interval Interval::point(double v) {
    if (std::isnan(v)) return nanOnly();
    return Interval{v, v, false};
}

bool Interval::contains(double v) const {
    return std::isnan(v) ? nan : (lo <= v && v <= hi);
}

Interval join(const Interval& a, const Interval& b) {
    return Interval{std::min(a.lo, b.lo), std::max(a.hi, b.hi), a.nan || b.nan};
}

bool joinInto(AbstractFrame& a, const AbstractFrame& b) {
    bool changed = false;
    for (size_t i = 0; i < a.size(); ++i) {
        AbstractSlot s{join(a[i].value, b[i].value), a[i].unassigned || b[i].unassigned};
        if (!(s == a[i])) {
            a[i] = s;
            changed = true;
        }
    }
    return changed;
}

AbstractFrame widen(const AbstractFrame& prev, const AbstractFrame& next) {
    AbstractFrame out = next;
    for (size_t i = 0; i < out.size(); ++i) {
        if (!prev[i].value.hasReals()) continue;
        if (out[i].value.lo < prev[i].value.lo) out[i].value.lo = -kInf;
        if (out[i].value.hi > prev[i].value.hi) out[i].value.hi = kInf;
    }
    return out;
}

Interval evalInterval(const Graph& g, ExprId e, const AbstractFrame& frame, const TimeRange* time) {
    const Expr& x = g.exprs[e];
    IntervalVm vm{g, frame, g.scene.settings.seed, time ? *time : TimeRange::at(g.time)};
    std::vector<Interval> stack;
    stack.reserve(x.maxStack + 1);
    return vm.run(x.begin, x.end, std::move(stack));
}

bool applyCalcInterval(const Graph& g, NodeId n, const AbstractFrame& in, AbstractFrame& out,
                       const TimeRange* time) {
    const Calc& c = g.calcs[g.nodes[n].payload];
    out = in;
    const Assignment* as = g.assignments.data() + c.first;
    if (!c.simultaneous) {
        for (uint32_t i = 0; i < c.count; ++i) {
            const Interval v = evalInterval(g, as[i].value, out, time);
            if (v.isBottom()) return false;
            out[as[i].slot] = AbstractSlot{v, false};
        }
        return true;
    }
    std::vector<Interval> values(c.count);
    for (uint32_t i = 0; i < c.count; ++i) {
        values[i] = evalInterval(g, as[i].value, in, time);
        if (values[i].isBottom()) return false;
    }
    for (uint32_t i = 0; i < c.count; ++i) out[as[i].slot] = AbstractSlot{values[i], false};
    return true;
}

std::vector<Interval> evalIntervalPaths(const Graph& g, ExprId e, const AbstractFrame& frame,
                                        const TimeRange* time) {
    const Expr& x = g.exprs[e];
    std::vector<Interval> leaves;
    IntervalVm vm{g, frame, g.scene.settings.seed, time ? *time : TimeRange::at(g.time)};
    vm.leaves = &leaves;
    std::vector<Interval> stack;
    stack.reserve(x.maxStack + 1);
    vm.run(x.begin, x.end, std::move(stack));
    return leaves;
}

std::vector<uint32_t> reachableRules(const Graph& g, NodeId n, const AbstractFrame& frame,
                                     bool* mayFail, const TimeRange* time) {
    const Module& m = g.modules[g.nodes[n].payload];
    const uint32_t rules = g.nodes[n].childCount;
    std::vector<uint32_t> out;
    bool fails = false;
    if (m.notationB) {
        bool earlierMayFail = true;
        for (uint32_t i = 0; i < m.conditions.size() && i < rules && earlierMayFail; ++i) {
            const ExprId c = m.conditions[i];
            if (c == kNone) {
                out.push_back(i);
                earlierMayFail = false;
                break;
            }
            const Interval v = evalInterval(g, c, frame, time);
            // A NaN or infinite condition is a run-time error.
            const bool canTrue = v.hasReals() && !(v.lo == 0 && v.hi == 0);
            const bool canFalse = v.contains(0);
            if (canTrue) out.push_back(i);
            if (v.nan || v.lo == -Interval::kInf || v.hi == Interval::kInf) fails = true;
            earlierMayFail = canFalse;
        }
        if (earlierMayFail) fails = true;  // no condition may hold
    } else {
        // Path by path, so that the rules of an if-chain stay a set.
        std::vector<uint8_t> taken(rules, 0);
        for (const Interval& v : evalIntervalPaths(g, m.select, frame, time)) {
            if (v.nan) fails = true;
            if (!v.hasReals()) continue;
            const double lo = std::round(v.lo), hi = std::round(v.hi);
            if (lo < 1 || hi > rules) fails = true;
            for (double r = std::max(1.0, lo); r <= std::min<double>(rules, hi); r += 1)
                taken[static_cast<uint32_t>(r) - 1] = 1;
        }
        for (uint32_t r = 0; r < rules; ++r)
            if (taken[r]) out.push_back(r);
    }
    if (mayFail) *mayFail = fails;
    return out;
}

IntervalAffine IntervalAffine::of(const Affine& m) {
    IntervalAffine r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) r.l[i][j] = Interval::point(m.l[i][j]);
        r.t[i] = Interval::point(m.t[i]);
    }
    return r;
}

bool transformInterval(const Graph& g, NodeId n, const AbstractFrame& frame, IntervalAffine& out,
                       const TimeRange* time) {
    const Transform& t = g.transforms[g.nodes[n].payload];
    if (t.constant) {
        out = IntervalAffine::of(t.matrix);
        return true;
    }
    Interval a[12];
    bool points = true;
    for (uint32_t i = 0; i < t.argCount; ++i) {
        a[i] = finiteArg(evalInterval(g, g.args[t.firstArg + i], frame, time));
        if (!a[i].hasReals()) return false;
        points = points && a[i].isPoint();
    }
    if (points) {
        double v[12];
        for (uint32_t i = 0; i < t.argCount; ++i) v[i] = a[i].lo;
        out = IntervalAffine::of(makeTransform(t.op, v));
        return true;
    }
    return transformOfIntervals(t.op, a, out);
}

bool primitiveArgsInterval(const Graph& g, NodeId n, const AbstractFrame& frame, Interval* out,
                           const TimeRange* time) {
    const Primitive& p = g.primitives[g.nodes[n].payload];
    if (p.constant) {
        for (size_t i = 0; i < p.values.size(); ++i) out[i] = Interval::point(p.values[i]);
        return true;
    }
    for (uint32_t i = 0; i < p.argCount; ++i) {
        out[i] = finiteArg(evalInterval(g, g.args[p.firstArg + i], frame, time));
        if (!out[i].hasReals()) return false;
    }
    return true;
}

Box transformBox(const IntervalAffine& m, const Box& b) {
    if (b.isEmpty()) return b;
    Box r;
    for (int i = 0; i < 3; ++i) {
        double lo = m.t[i].lo, hi = m.t[i].hi;
        for (int j = 0; j < 3; ++j) {
            const Interval& e = m.l[i][j];
            const double p[4] = {mulEnd(e.lo, b.lo[j]), mulEnd(e.lo, b.hi[j]),
                                 mulEnd(e.hi, b.lo[j]), mulEnd(e.hi, b.hi[j])};
            const double plo = *std::min_element(p, p + 4), phi = *std::max_element(p, p + 4);
            lo = (lo == -kInf || plo == -kInf) ? -kInf : lo + plo;
            hi = (hi == kInf || phi == kInf) ? kInf : hi + phi;
        }
        r.lo[i] = lo;
        r.hi[i] = hi;
    }
    return r;
}

}  // namespace pcsg::tracer
