// The fast machine: runs the accumulator code of fast_instr.h. Every value is computed by
// the same operation, in the same order, as the plain stack machine of eval.cpp would
// compute it; what would throw there stops the run here instead (see eval_core.h).
#include <bit>
#include <cmath>
#include <iterator>

#include "eval.h"
#include "eval_core.h"
#include "eval_recall.h"

namespace pcsg {

namespace {
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

inline bool unassignedBits(double v) {
    return std::bit_cast<uint64_t>(v) == kUnassignedBits;
}

// a + b and a * b with the first operand's NaN (see PCSG_FAST_BINARY): the one rule of the
// machine's Add and Mul, AddMulKL and the fused runs.
inline double addFirstNan(double a, double b) {
    const double r = a + b;
    return r != r && a != a ? a + a : r;
}
inline double mulFirstNan(double a, double b) {
    const double r = a * b;
    return r != r && a != a ? a * a : r;
}

// The rnd chain's first four operations, ln(rand(sd)*k1 + k2), as Rand1, MulK, AddK and Ln
// compute them (Ln's lnRecalled gives std::log's bits; its table is not consulted here,
// where the chain's own table below missed).
double randLnComputed(double sd, double seedBits, double k1, double k2) {
    const double u = randOfInline(std::bit_cast<uint64_t>(seedBits), sd);
    return std::log(addFirstNan(mulFirstNan(u, k1), k2));
}

// The same, recalled by the bits of sd, the seed, k1 and k2 (slots chosen by sd's alone):
// the two triangles at an edge, and every expansion of them, seed the same rnd. A hit skips
// rand()'s three mixes and the logarithm's own recall.
inline double randLnRecalled(uint64_t seed, double sd, double k1, double k2) {
    thread_local Recall<4, double (*)(double, double, double, double), 1> memo(randLnComputed);
    return memo({sd, std::bit_cast<double>(seed), k1, k2});
}

// The fused runs' values (fast_instr.h), computed plainly first: +, * and / of a NaN give a
// NaN, so a value that is not one read no unassigned slot (kUnassignedBits is a NaN) and
// needed none of the runs' NaN fixes (each gives one NaN for another). Only a NaN is
// computed again with each instruction's check and fix, in their order: the bits the
// instructions one by one give, or false where the first of them would stop.
// MulKL, AddMulKL, AddMulKL, AddMulKL: sum of imm * frame[a] over in[0..4).
[[gnu::always_inline]] inline bool sumMulKL4(const FastInstr* in, const double* frame, double& v) {
    const double x0 = frame[in[0].a], x1 = frame[in[1].a];
    const double x2 = frame[in[2].a], x3 = frame[in[3].a];
    v = in[0].imm * x0;
    v = v + in[1].imm * x1;
    v = v + in[2].imm * x2;
    v = v + in[3].imm * x3;
    if (v == v) [[likely]]
        return true;
    if (unassignedBits(x0) || unassignedBits(x1)) return false;
    if (unassignedBits(x2) || unassignedBits(x3)) return false;
    v = mulFirstNan(in[0].imm, x0);
    v = addFirstNan(v, mulFirstNan(in[1].imm, x1));
    v = addFirstNan(v, mulFirstNan(in[2].imm, x2));
    v = addFirstNan(v, mulFirstNan(in[3].imm, x3));
    return true;
}
// Neg, AddK, MulL after the logarithm l: (-l + k) * x.
[[gnu::always_inline]] inline bool lnTimes(double l, double k, double x, double& v) {
    v = (-l + k) * x;
    if (v == v) [[likely]]
        return true;
    if (unassignedBits(x)) return false;
    v = mulFirstNan(addFirstNan(-l, k), x);
    return true;
}
// AddLL, DivK, AddL: (a + b) / k + c.
[[gnu::always_inline]] inline bool meanAdd(double a, double b, double k, double c, double& v) {
    v = (a + b) / k + c;
    if (v == v) [[likely]]
        return true;
    if (unassignedBits(a) || unassignedBits(b) || unassignedBits(c)) return false;
    v = addFirstNan(addFirstNan(a, b) / k, c);
    return true;
}
}  // namespace

// The machine is threaded: each operation ends by jumping straight to the next one's code
// through a table of label addresses (a GNU extension that GCC and Clang have), where a
// switch in a loop took a bounds check and a jump back to the loop's head per operation,
// about half the instructions of a typical one. The table is made from PCSG_FAST_OPS, the
// list FastOp itself is made from.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#endif
#define PCSG_FAST_NEXT                                \
    do {                                              \
        in = pc++;                                    \
        goto* kTargets[static_cast<uint8_t>(in->op)]; \
    } while (0)
#define PCSG_FAST_OP(OP) op_##OP:

// The end of a form that spills acc (two leaves and their operator): when a Store follows
// (a C-node's `x2 = x1-kl`, a T-node's argument `z2-z1`), it is done here without its
// dispatch, and acc is not spilled, since the Store would pop it straight back. The same
// value in the same slot, the same stack after; a jump to the Store still runs it alone.
#define PCSG_FAST_SPILL_OR_STORE(KEPT)            \
    do {                                          \
        if (pc->op == FastOp::Store) {            \
            out[pc->a] = acc, acc = (KEPT), ++pc; \
        } else {                                  \
            st[sp++] = (KEPT);                    \
        }                                         \
    } while (0)
// Whether a form stops for its parameter v (checked as PushL), asked after acc has the
// form's value: where a NaN operand gives a NaN (NAN_OUT: + - * /), only a NaN value can
// have read kUnassignedBits (itself a NaN), so a number skips the test.
#define PCSG_FAST_STOPS(NAN_OUT, V) ((!(NAN_OUT) || acc != acc) && unassignedBits(V))
// One binary operator in its six forms: the left operand popped, then a constant, a
// parameter, both leaves (constant and parameter, parameter and constant, two parameters).
// For Add and Mul of two NaNs, x86 gives the first operand's NaN (quietened), and the plain
// machine's `a + b` takes a as the first; here the compiler may swap the operands of a
// commutative operator, so addFirstNan and mulFirstNan restore the first's NaN explicitly
// (the sign and payload of a NaN reach rand(x) and the error messages).
#define PCSG_FAST_BINARY(OP, EXPR, NAN_OUT)                                           \
    PCSG_FAST_OP(OP) {                                                                \
        const double a = st[--sp], b = acc;                                           \
        acc = (EXPR);                                                                 \
    }                                                                                 \
    PCSG_FAST_NEXT;                                                                   \
    PCSG_FAST_OP(OP##K) {                                                             \
        const double a = acc, b = in->imm;                                            \
        acc = (EXPR);                                                                 \
    }                                                                                 \
    PCSG_FAST_NEXT;                                                                   \
    PCSG_FAST_OP(OP##L) {                                                             \
        const double a = acc, b = frame[in->a];                                       \
        acc = (EXPR);                                                                 \
        if (PCSG_FAST_STOPS(NAN_OUT, b)) return false;                                \
    }                                                                                 \
    PCSG_FAST_NEXT;                                                                   \
    PCSG_FAST_OP(OP##KL) {                                                            \
        const double a = in->imm, b = frame[in->a];                                   \
        const double kept = acc;                                                      \
        acc = (EXPR);                                                                 \
        if (PCSG_FAST_STOPS(NAN_OUT, b)) return false;                                \
        PCSG_FAST_SPILL_OR_STORE(kept);                                               \
    }                                                                                 \
    PCSG_FAST_NEXT;                                                                   \
    PCSG_FAST_OP(OP##LK) {                                                            \
        const double a = frame[in->a], b = in->imm;                                   \
        const double kept = acc;                                                      \
        acc = (EXPR);                                                                 \
        if (PCSG_FAST_STOPS(NAN_OUT, a)) return false;                                \
        PCSG_FAST_SPILL_OR_STORE(kept);                                               \
    }                                                                                 \
    PCSG_FAST_NEXT;                                                                   \
    PCSG_FAST_OP(OP##LL) {                                                            \
        const double a = frame[in->a];                                                \
        const double b = frame[in->b];                                                \
        const double kept = acc;                                                      \
        acc = (EXPR);                                                                 \
        if (PCSG_FAST_STOPS(NAN_OUT, a) || PCSG_FAST_STOPS(NAN_OUT, b)) return false; \
        PCSG_FAST_SPILL_OR_STORE(kept);                                               \
    }                                                                                 \
    PCSG_FAST_NEXT;
// MulKL and the Add that takes its product: MulKL's value and NaN fix, then Add's.
#define PCSG_FAST_ADD_MUL_KL                        \
    PCSG_FAST_OP(AddMulKL) {                        \
        const double k = in->imm, x = frame[in->a]; \
        if (unassignedBits(x)) return false;        \
        acc = addFirstNan(acc, mulFirstNan(k, x));  \
    }                                               \
    PCSG_FAST_NEXT;
// The Store or StoreKeep after a fused run, done without its dispatch (the terrain's runs
// end values: the seed is kept for rand(sd), rnd and the height are stored).
#define PCSG_FAST_THEN_STORE                    \
    if (pc->op == FastOp::Store) {              \
        out[pc->a] = acc, acc = st[--sp], ++pc; \
    } else if (pc->op == FastOp::StoreKeep) {   \
        if (unassignedBits(acc)) return false;  \
        out[pc->a] = acc, ++pc;                 \
    }
// AddMulKL, then the fused runs (fast_instr.h): this instruction and the next ones'
// operands, each operation as its own instruction computes it (an unassigned read stops
// the run; nothing is stored before it, so stopping earlier or later gives the same), then
// pc skips the run (and does the store after it).
#define PCSG_FAST_FUSED_RUNS                                                                      \
    PCSG_FAST_ADD_MUL_KL                                                                          \
    PCSG_FAST_OP(SumMulKL4) {                                                                     \
        double v;                                                                                 \
        if (!sumMulKL4(in, frame, v)) return false;                                               \
        st[sp++] = acc, acc = v;                                                                  \
        pc += 3;                                                                                  \
        PCSG_FAST_THEN_STORE                                                                      \
    }                                                                                             \
    PCSG_FAST_NEXT;                                                                               \
    PCSG_FAST_OP(RandLnChain) {                                                                   \
        const double l = randLnRecalled(seed, acc, in[1].imm, in[2].imm);                         \
        if (!lnTimes(l, in[5].imm, frame[in[6].a], acc)) return false;                            \
        pc += 6;                                                                                  \
        PCSG_FAST_THEN_STORE                                                                      \
    }                                                                                             \
    PCSG_FAST_NEXT;                                                                               \
    PCSG_FAST_OP(MeanAddL) {                                                                      \
        double v;                                                                                 \
        if (!meanAdd(frame[in[0].a], frame[in[0].b], in[1].imm, frame[in[2].a], v)) return false; \
        st[sp++] = acc, acc = v;                                                                  \
        pc += 2;                                                                                  \
        PCSG_FAST_THEN_STORE                                                                      \
    }                                                                                             \
    PCSG_FAST_NEXT;
#define PCSG_FAST_PUSH(OP, EXPR) \
    PCSG_FAST_OP(OP)             \
    st[sp++] = acc;              \
    acc = (EXPR);                \
    PCSG_FAST_NEXT;
#define PCSG_FAST_UNARY(OP, EXPR) \
    PCSG_FAST_OP(OP)              \
    acc = (EXPR);                 \
    PCSG_FAST_NEXT;
#define PCSG_FAST_TARGET(OP) &&op_##OP,

bool runFast(const Graph& g, uint32_t start, const double* frame, double* out, uint64_t path,
             double& result) {
    static const void* const kTargets[] = {PCSG_FAST_OPS(PCSG_FAST_TARGET)};
    static_assert(std::size(kTargets) == static_cast<size_t>(FastOp::End) + 1);
    const FastInstr* const code = g.fastCode.data();
    const uint64_t seed = g.scene.settings.seed;
    double st[kFastStack];
    double acc = 0;
    uint32_t sp = 0;
    const FastInstr* pc = code + start;
    const FastInstr* in = nullptr;
    PCSG_FAST_NEXT;
    PCSG_FAST_PUSH(PushK, in->imm)
    PCSG_FAST_OP(PushL) {
        const double v = frame[in->a];
        if (unassignedBits(v)) return false;
        st[sp++] = acc, acc = v;
    }
    PCSG_FAST_NEXT;
    PCSG_FAST_PUSH(PushClock, g.time.clock)
    PCSG_FAST_PUSH(PushFrame, g.time.frame)
    PCSG_FAST_PUSH(PushRand0, randAtInline(seed, path, in->a))
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
    PCSG_FAST_BINARY(Add, addFirstNan(a, b), true)
    PCSG_FAST_BINARY(Sub, a - b, true)
    PCSG_FAST_BINARY(Mul, mulFirstNan(a, b), true)
    PCSG_FAST_BINARY(Div, a / b, true)
    PCSG_FAST_BINARY(Mod, std::fmod(a, b), false)
    PCSG_FAST_BINARY(Pow, powRecalled(a, b), false)
    PCSG_FAST_BINARY(Lt, a < b ? 1.0 : 0.0, false)
    PCSG_FAST_BINARY(Le, a <= b ? 1.0 : 0.0, false)
    PCSG_FAST_BINARY(Gt, a > b ? 1.0 : 0.0, false)
    PCSG_FAST_BINARY(Ge, a >= b ? 1.0 : 0.0, false)
    PCSG_FAST_BINARY(Eq, a == b ? 1.0 : 0.0, false)
    PCSG_FAST_BINARY(Ne, a != b ? 1.0 : 0.0, false)
    PCSG_FAST_FUSED_RUNS
    PCSG_FAST_OP(Call) {
        st[sp] = acc, sp -= in->argc - 1u;
        acc = callFunc(static_cast<Func>(in->a), st + sp, in->argc, seed);
    }
    PCSG_FAST_NEXT;
    PCSG_FAST_OP(Choose) {
        st[sp] = acc, sp -= in->argc - 1u;
        if (!chooseWeightsValid(st + sp, in->argc)) return false;
        acc = choosePick(st + sp, in->argc, randAtInline(seed, path, in->a));
    }
    PCSG_FAST_NEXT;
    PCSG_FAST_OP(Jump) pc = code + in->a;
    PCSG_FAST_NEXT;
    PCSG_FAST_OP(JumpIfZero) {
        const double v = acc;
        acc = st[--sp];
        if (v == 0) pc = code + in->a;
    }
    PCSG_FAST_NEXT;
    PCSG_FAST_OP(Store) out[in->a] = acc, acc = st[--sp];
    PCSG_FAST_NEXT;
    PCSG_FAST_OP(StoreKeep) {
        if (unassignedBits(acc)) return false;
        out[in->a] = acc;
    }
    PCSG_FAST_NEXT;
    PCSG_FAST_OP(End) result = acc;
    return true;
}

#undef PCSG_FAST_BINARY
#undef PCSG_FAST_SPILL_OR_STORE
#undef PCSG_FAST_ADD_MUL_KL
#undef PCSG_FAST_FUSED_RUNS
#undef PCSG_FAST_THEN_STORE
#undef PCSG_FAST_UNARY
#undef PCSG_FAST_PUSH
#undef PCSG_FAST_STOPS
#undef PCSG_FAST_TARGET
#undef PCSG_FAST_OP
#undef PCSG_FAST_NEXT
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

}  // namespace pcsg
