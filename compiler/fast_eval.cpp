// The fast machine: runs the accumulator code of fast_instr.h. Every value is computed by
// the same operation, in the same order, as the plain stack machine of eval.cpp would
// compute it; what would throw there stops the run here instead (see eval_core.h).
#include <bit>
#include <cmath>

#include "eval.h"
#include "eval_core.h"

namespace pcsg {

namespace {
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

inline bool unassignedBits(double v) {
    return std::bit_cast<uint64_t>(v) == kUnassignedBits;
}
}  // namespace

// One binary operator in its five forms: the left operand popped, then a constant, a
// parameter, both leaves (constant and parameter, parameter and constant). `FIX` runs after
// the operation: for Add and Mul of two NaNs, x86 gives the first operand's NaN
// (quietened), and the plain machine's `a + b` takes a as the first; here the compiler may
// swap the operands of a commutative operator, so the first's NaN is restored explicitly
// (the sign and payload of a NaN reach rand(x) and the error messages).
#define PCSG_FAST_BINARY(OP, EXPR, FIX)           \
    case FastOp::OP: {                            \
        const double a = st[--sp], b = acc;       \
        acc = (EXPR);                             \
        FIX;                                      \
        break;                                    \
    }                                             \
    case FastOp::OP##K: {                         \
        const double a = acc, b = in.imm;         \
        acc = (EXPR);                             \
        FIX;                                      \
        break;                                    \
    }                                             \
    case FastOp::OP##L: {                         \
        const double a = acc, b = frame[in.a];    \
        if (unassignedBits(b)) return false;      \
        acc = (EXPR);                             \
        FIX;                                      \
        break;                                    \
    }                                             \
    case FastOp::OP##KL: {                        \
        const double a = in.imm, b = frame[in.a]; \
        if (unassignedBits(b)) return false;      \
        st[sp++] = acc;                           \
        acc = (EXPR);                             \
        FIX;                                      \
        break;                                    \
    }                                             \
    case FastOp::OP##LK: {                        \
        const double a = frame[in.a], b = in.imm; \
        if (unassignedBits(a)) return false;      \
        st[sp++] = acc;                           \
        acc = (EXPR);                             \
        FIX;                                      \
        break;                                    \
    }
#define PCSG_FAST_FIRST_NAN(SYMBOL) \
    if (acc != acc && a != a) acc = a SYMBOL a
#define PCSG_FAST_NO_FIX (void)0
#define PCSG_FAST_PUSH(OP, EXPR) \
    case FastOp::OP:             \
        st[sp++] = acc;          \
        acc = (EXPR);            \
        break;
#define PCSG_FAST_UNARY(OP, EXPR) \
    case FastOp::OP:              \
        acc = (EXPR);             \
        break;

bool runFast(const Graph& g, uint32_t start, const double* frame, double* out, uint64_t path,
             double& result) {
    const FastInstr* const code = g.fastCode.data();
    const uint64_t seed = g.scene.settings.seed;
    double st[kFastStack];
    double acc = 0;
    uint32_t sp = 0;
    for (const FastInstr* pc = code + start;;) {
        const FastInstr& in = *pc++;
        switch (in.op) {
            PCSG_FAST_PUSH(PushK, in.imm)
            case FastOp::PushL: {
                const double v = frame[in.a];
                if (unassignedBits(v)) return false;
                st[sp++] = acc, acc = v;
                break;
            }
                PCSG_FAST_PUSH(PushClock, g.time.clock)
                PCSG_FAST_PUSH(PushFrame, g.time.frame)
                PCSG_FAST_PUSH(PushRand0, randAtInline(seed, path, in.a))
                PCSG_FAST_UNARY(Neg, -acc)
                PCSG_FAST_UNARY(Not, acc == 0 ? 1.0 : 0.0)
                PCSG_FAST_UNARY(ToBool, acc != 0 ? 1.0 : 0.0)
                PCSG_FAST_UNARY(Sin, sinDegrees(acc))
                PCSG_FAST_UNARY(Cos, cosDegrees(acc))
                PCSG_FAST_UNARY(Tan, sinDegrees(acc) / cosDegrees(acc))
                PCSG_FAST_UNARY(Asin, std::asin(acc) / kDegToRad)
                PCSG_FAST_UNARY(Acos, std::acos(acc) / kDegToRad)
                PCSG_FAST_UNARY(Atan, std::atan(acc) / kDegToRad)
                PCSG_FAST_UNARY(Sqrt, std::sqrt(acc))
                PCSG_FAST_UNARY(Exp, std::exp(acc))
                PCSG_FAST_UNARY(Ln, lnRecalled(acc))
                PCSG_FAST_UNARY(Log10, std::log10(acc))
                PCSG_FAST_UNARY(Abs, std::fabs(acc))
                PCSG_FAST_UNARY(Floor, std::floor(acc))
                PCSG_FAST_UNARY(Ceil, std::ceil(acc))
                PCSG_FAST_UNARY(Rand1, randOfInline(seed, acc))
                PCSG_FAST_BINARY(Add, a + b, PCSG_FAST_FIRST_NAN(+))
                PCSG_FAST_BINARY(Sub, a - b, PCSG_FAST_NO_FIX)
                PCSG_FAST_BINARY(Mul, a * b, PCSG_FAST_FIRST_NAN(*))
                PCSG_FAST_BINARY(Div, a / b, PCSG_FAST_NO_FIX)
                PCSG_FAST_BINARY(Mod, std::fmod(a, b), PCSG_FAST_NO_FIX)
                PCSG_FAST_BINARY(Pow, powRecalled(a, b), PCSG_FAST_NO_FIX)
                PCSG_FAST_BINARY(Lt, a < b ? 1.0 : 0.0, PCSG_FAST_NO_FIX)
                PCSG_FAST_BINARY(Le, a <= b ? 1.0 : 0.0, PCSG_FAST_NO_FIX)
                PCSG_FAST_BINARY(Gt, a > b ? 1.0 : 0.0, PCSG_FAST_NO_FIX)
                PCSG_FAST_BINARY(Ge, a >= b ? 1.0 : 0.0, PCSG_FAST_NO_FIX)
                PCSG_FAST_BINARY(Eq, a == b ? 1.0 : 0.0, PCSG_FAST_NO_FIX)
                PCSG_FAST_BINARY(Ne, a != b ? 1.0 : 0.0, PCSG_FAST_NO_FIX)
            case FastOp::Call:
                st[sp] = acc, sp -= in.argc - 1u;
                acc = callFunc(static_cast<Func>(in.a), st + sp, in.argc, seed);
                break;
            case FastOp::Choose:
                st[sp] = acc, sp -= in.argc - 1u;
                if (!chooseWeightsValid(st + sp, in.argc)) return false;
                acc = choosePick(st + sp, in.argc, randAtInline(seed, path, in.a));
                break;
            case FastOp::Jump:
                pc = code + in.a;
                break;
            case FastOp::JumpIfZero: {
                const double v = acc;
                acc = st[--sp];
                if (v == 0) pc = code + in.a;
                break;
            }
            case FastOp::Store:
                out[in.a] = acc, acc = st[--sp];
                break;
            case FastOp::StoreKeep:
                if (unassignedBits(acc)) return false;
                out[in.a] = acc;
                break;
            case FastOp::End:
                result = acc;
                return true;
        }
    }
}

#undef PCSG_FAST_BINARY
#undef PCSG_FAST_UNARY
#undef PCSG_FAST_PUSH
#undef PCSG_FAST_FIRST_NAN
#undef PCSG_FAST_NO_FIX

}  // namespace pcsg
