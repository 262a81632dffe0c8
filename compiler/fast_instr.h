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
// reading the slot just stored).
#pragma once

#include <cstdint>

namespace pcsg {

enum class FastOp : uint8_t {
    // leaves: spill acc, then acc = the value
    PushK,      // imm
    PushL,      // frame[a]; an unassigned slot stops the fast run (the plain code throws)
    PushClock,  // the graph's time
    PushFrame,
    PushRand0,  // rand() at call site a
    // acc = f(acc)
    Neg,
    Not,
    ToBool,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sqrt,
    Exp,
    Ln,
    Log10,
    Abs,
    Floor,
    Ceil,
    Rand1,
    // acc = (popped) op acc
    Add,
    Sub,
    Mul,
    Div,
    Mod,
    Pow,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    // acc = acc op imm
    AddK,
    SubK,
    MulK,
    DivK,
    ModK,
    PowK,
    LtK,
    LeK,
    GtK,
    GeK,
    EqK,
    NeK,
    // acc = acc op frame[a] (checked as PushL)
    AddL,
    SubL,
    MulL,
    DivL,
    ModL,
    PowL,
    LtL,
    LeL,
    GtL,
    GeL,
    EqL,
    NeL,
    // spill acc, then acc = imm op frame[a] (checked as PushL)
    AddKL,
    SubKL,
    MulKL,
    DivKL,
    ModKL,
    PowKL,
    LtKL,
    LeKL,
    GtKL,
    GeKL,
    EqKL,
    NeKL,
    // spill acc, then acc = frame[a] op imm (checked as PushL)
    AddLK,
    SubLK,
    MulLK,
    DivLK,
    ModLK,
    PowLK,
    LtLK,
    LeLK,
    GtLK,
    GeLK,
    EqLK,
    NeLK,
    // argc values (acc the last): acc = Func a of them / choose() at call site a
    Call,
    Choose,
    Jump,        // pc = a (absolute index into Graph::fastCode)
    JumpIfZero,  // v = acc, pop; if v == 0, pc = a
    Store,       // out[a] = acc, pop (a C-node's assignment)
    StoreKeep,   // out[a] = acc, kept: Store a then PushL a where the frame is `out`
    End,         // the value is acc
};

struct FastInstr {
    FastOp op = FastOp::End;
    uint8_t argc = 0;
    uint32_t a = 0;
    double imm = 0;
};

// The stack the fast machine needs for an expression or C-node is at most this many
// doubles (larger ones are left to the plain code).
inline constexpr uint32_t kFastStack = 64;

// Expr::fast and Calc::fast when there is no fast form.
inline constexpr uint32_t kNoFast = UINT32_MAX;

}  // namespace pcsg
