// The fast form of the expression code: the same expressions as Graph::code (graph.h),
// translated by fast_code.h's peephole pass into an accumulator machine with
// superinstructions, and run by evalExpr() and applyCalc() (eval.h) whenever an
// expression or a C-node has it. Graph::code stays the reference: every analysis (constant
// folding, the step memo's reads, the tracer's interval bounds) reads that, and the fast
// form gives the same doubles bit for bit.
//
// The machine keeps the top of the stack in a register, `acc`; a push spills acc to the
// stack, a binary operator takes its left operand from the stack. A leaf operand (a
// constant or a parameter) followed by a binary operator is one instruction (`AddK 1.0`,
// `MulL x`), and so are two leaves and their operator (`MulKL 255 x`: 255 * x); a
// one-argument function is one instruction (`Ln`), and a C-node's assignments are one
// program ending each value with `Store slot` (`StoreKeep` when the next value starts by
// reading the slot just stored). Two parameters and their operator are one instruction too
// (`AddLL z1 z2`: z1 + z2), and a product of a constant and a parameter added to acc
// (`AddMulKL b x1`), as the terrain's seeds `a*x2 + b*x1 + c*y2 + d*y1` are sums of them.
#pragma once

#include <cstdint>

namespace pcsg {

// The operations, in the order of FastOp's values: X(name) each. The one list makes the
// enum, the names fast_code.cpp prints and the dispatch table of the machine (fast_eval.cpp),
// so that the three cannot fall out of step.
// clang-format off
#define PCSG_FAST_COMPARISONS(X, FORM) \
    X(Lt##FORM) X(Le##FORM) X(Gt##FORM) X(Ge##FORM) X(Eq##FORM) X(Ne##FORM)
#define PCSG_FAST_OPS(X)                                                                    \
    /* leaves: spill acc, then acc = the value */                                         \
    X(PushK)     /* imm */                                                                \
    X(PushL)     /* frame[a]; an unassigned slot stops the fast run (the plain code throws) */ \
    X(PushClock) /* the graph's time */                                                   \
    X(PushFrame)                                                                          \
    X(PushRand0) /* rand() at call site a */                                              \
    /* acc = f(acc) */                                                                    \
    X(Neg) X(Not) X(ToBool) X(Sin) X(Cos) X(Tan) X(Asin) X(Acos) X(Atan) X(Sqrt) X(Exp)   \
    X(Ln) X(Log10) X(Abs) X(Floor) X(Ceil) X(Rand1)                                       \
    /* acc = (popped) op acc */                                                           \
    X(Add) X(Sub) X(Mul) X(Div) X(Mod) X(Pow) PCSG_FAST_COMPARISONS(X, )                  \
    /* acc = acc op imm */                                                                \
    X(AddK) X(SubK) X(MulK) X(DivK) X(ModK) X(PowK) PCSG_FAST_COMPARISONS(X, K)           \
    /* acc = acc op frame[a] (checked as PushL) */                                        \
    X(AddL) X(SubL) X(MulL) X(DivL) X(ModL) X(PowL) PCSG_FAST_COMPARISONS(X, L)           \
    /* spill acc, then acc = imm op frame[a] (checked as PushL) */                        \
    X(AddKL) X(SubKL) X(MulKL) X(DivKL) X(ModKL) X(PowKL) PCSG_FAST_COMPARISONS(X, KL)    \
    /* spill acc, then acc = frame[a] op imm (checked as PushL) */                        \
    X(AddLK) X(SubLK) X(MulLK) X(DivLK) X(ModLK) X(PowLK) PCSG_FAST_COMPARISONS(X, LK)    \
    /* spill acc, then acc = frame[a] op frame[b] (checked as PushL) */                   \
    X(AddLL) X(SubLL) X(MulLL) X(DivLL) X(ModLL) X(PowLL) PCSG_FAST_COMPARISONS(X, LL)    \
    /* acc = acc + imm * frame[a] (checked as PushL): MulKL and the Add after it */       \
    X(AddMulKL)                                                                           \
    /* Fused runs of the instructions above, written over the first of the run: the rest  \
       of the run stays in place and gives its operands; the machine skips it. The same   \
       operations in the same order, each with its own NaN fix and check. */              \
    X(SumMulKL4)   /* MulKL, AddMulKL, AddMulKL, AddMulKL: a terrain's seed */            \
    X(RandLnChain) /* Rand1, MulK, AddK, Ln, Neg, AddK, MulL: a terrain's rnd */          \
    X(MeanAddL)    /* AddLL, DivK, AddL: a terrain's (z1+z2)/2.0 + rnd */                 \
    /* argc values (acc the last): acc = Func a of them / choose() at call site a */      \
    X(Call)                                                                               \
    X(Choose)                                                                             \
    X(Jump)       /* pc = a (absolute index into Graph::fastCode) */                      \
    X(JumpIfZero) /* v = acc, pop; if v == 0, pc = a */                                   \
    X(Store)      /* out[a] = acc, pop (a C-node's assignment) */                         \
    X(StoreKeep)  /* out[a] = acc, kept: Store a then PushL a where the frame is `out` */ \
    X(End)        /* the value is acc */
// clang-format on

#define PCSG_FAST_ENUMERATOR(name) name,
enum class FastOp : uint8_t { PCSG_FAST_OPS(PCSG_FAST_ENUMERATOR) };
#undef PCSG_FAST_ENUMERATOR

struct FastInstr {
    FastOp op = FastOp::End;
    uint8_t argc = 0;
    uint16_t b = 0;  // the second parameter of an OpLL form (slots below 2^16 only)
    uint32_t a = 0;
    double imm = 0;
};

// The stack the fast machine needs for an expression or C-node is at most this many
// doubles (larger ones are left to the plain code).
inline constexpr uint32_t kFastStack = 64;

// Expr::fast and Calc::fast when there is no fast form.
inline constexpr uint32_t kNoFast = UINT32_MAX;

}  // namespace pcsg
