// The peephole pass to the fast form: see fast_code.h.
#include "fast_code.h"

#include <fmt/format.h>

#include <utility>
#include <vector>

namespace pcsg {

namespace {

bool isLeaf(Op op) {
    return op == Op::Const || op == Op::Load;
}
bool isBinary(Op op) {
    return op >= Op::Add && op <= Op::Ne;
}
// The binary operator an instruction is: an operator, or pow(a, b) and mod(a, b), which
// compute what the operators ^ and % compute (std::pow, std::fmod); Op::Const otherwise.
Op binaryOf(const Instr& in) {
    if (isBinary(in.op)) return in.op;
    if (in.op == Op::Call && in.argc == 2 && static_cast<Func>(in.a) == Func::Pow) return Op::Pow;
    if (in.op == Op::Call && in.argc == 2 && static_cast<Func>(in.a) == Func::Mod) return Op::Mod;
    return Op::Const;
}
// The binary operator `op` in the form with base `form` (FastOp::Add, AddK or AddL).
FastOp binaryForm(Op op, FastOp form) {
    return static_cast<FastOp>(static_cast<int>(form) + static_cast<int>(op) -
                               static_cast<int>(Op::Add));
}

// The one-argument functions that are instructions of their own.
bool unaryFunc(Func f, FastOp& op) {
    constexpr std::pair<Func, FastOp> kUnary[] = {
        {Func::Sin, FastOp::Sin},     {Func::Cos, FastOp::Cos},     {Func::Tan, FastOp::Tan},
        {Func::Asin, FastOp::Asin},   {Func::Acos, FastOp::Acos},   {Func::Atan, FastOp::Atan},
        {Func::Sqrt, FastOp::Sqrt},   {Func::Exp, FastOp::Exp},     {Func::Ln, FastOp::Ln},
        {Func::Log10, FastOp::Log10}, {Func::Abs, FastOp::Abs},     {Func::Floor, FastOp::Floor},
        {Func::Ceil, FastOp::Ceil},   {Func::Rand1, FastOp::Rand1},
    };
    for (const auto& [func, fast] : kUnary)
        if (func == f) {
            op = fast;
            return true;
        }
    return false;
}

// The stack depth before each instruction of [begin, end] (the last: at the end), and
// the jump targets; false when the fast machine cannot run the code (see buildFastCode).
struct CodeShape {
    std::vector<int> depth;
    std::vector<uint8_t> target;
    int maxDepth = 0;
};

bool shapeOf(const Graph& g, uint32_t begin, uint32_t end, CodeShape& s) {
    const uint32_t n = end - begin;
    s.depth.assign(n + 1, -1);
    s.target.assign(n + 1, 0);
    s.depth[0] = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const Instr& in = g.code[begin + i];
        int need, change;
        if (s.depth[i] < 0 || !stackEffect(in, need, change) || s.depth[i] < need) return false;
        const int after = s.depth[i] + change;
        s.maxDepth = std::max(s.maxDepth, std::max(after, s.depth[i]));
        if (in.op == Op::Jump || in.op == Op::JumpIfZero) {
            if (in.a <= begin + i || in.a > end) return false;  // forward jumps only
            int& d = s.depth[in.a - begin];
            if (d >= 0 && d != after) return false;
            d = after;
            s.target[in.a - begin] = 1;
            if (in.op == Op::Jump) continue;  // the next depth comes from a jump to it
        }
        int& next = s.depth[i + 1];
        if (next >= 0 && next != after) return false;
        next = after;
    }
    return s.depth[n] == 1 && s.maxDepth + 1 < static_cast<int>(kFastStack);
}

FastInstr plainToFast(const Instr& in) {
    FastInstr f;
    f.a = in.a, f.argc = in.argc, f.imm = in.imm;
    switch (in.op) {
        case Op::Const:
            f.op = FastOp::PushK;
            break;
        case Op::Load:
            f.op = FastOp::PushL;
            break;
        case Op::Neg:
            f.op = FastOp::Neg;
            break;
        case Op::Not:
            f.op = FastOp::Not;
            break;
        case Op::ToBool:
            f.op = FastOp::ToBool;
            break;
        case Op::Jump:
            f.op = FastOp::Jump;
            break;
        case Op::JumpIfZero:
            f.op = FastOp::JumpIfZero;
            break;
        case Op::Call:
            if (binaryOf(in) != Op::Const) {
                f.op = binaryForm(binaryOf(in), FastOp::Add);
                f.argc = 0;
                break;
            }
            if (in.argc != 1 || !unaryFunc(static_cast<Func>(in.a), f.op)) f.op = FastOp::Call;
            break;
        case Op::Rand0:
            f.op = FastOp::PushRand0;
            break;
        case Op::Choose:
            f.op = FastOp::Choose;
            break;
        case Op::Clock:
            f.op = FastOp::PushClock;
            break;
        case Op::Frame:
            f.op = FastOp::PushFrame;
            break;
        default:
            f.op = binaryForm(in.op, FastOp::Add);
            break;
    }
    return f;
}

// The fast instruction for the plain code at pc: a leaf and the binary operator that takes
// it, two leaves (a constant and a parameter, or two parameters) and theirs, or one
// instruction; returns how
// many plain instructions it stands for. An operator that is a jump target is not fused.
uint32_t fuse(const Graph& g, uint32_t pc, uint32_t end, const std::vector<uint8_t>& target,
              uint32_t begin, FastInstr& f) {
    const Instr& in = g.code[pc];
    const auto fusable = [&](uint32_t i) {
        return i < end && binaryOf(g.code[i]) != Op::Const && !target[i - begin];
    };
    const bool twoLeaves = isLeaf(in.op) && pc + 2 < end + 1 && isLeaf(g.code[pc + 1].op) &&
                           !target[pc + 1 - begin] && fusable(pc + 2);
    if (twoLeaves && in.op == Op::Load && g.code[pc + 1].op == Op::Load &&
        g.code[pc + 1].a <= UINT16_MAX) {
        f = FastInstr{binaryForm(binaryOf(g.code[pc + 2]), FastOp::AddLL), 0,
                      static_cast<uint16_t>(g.code[pc + 1].a), in.a, 0};
        return 3;
    }
    if (twoLeaves && in.op != g.code[pc + 1].op) {
        const bool constFirst = in.op == Op::Const;
        const Instr& k = constFirst ? in : g.code[pc + 1];
        const Instr& l = constFirst ? g.code[pc + 1] : in;
        f = FastInstr{
            binaryForm(binaryOf(g.code[pc + 2]), constFirst ? FastOp::AddKL : FastOp::AddLK), 0, 0,
            l.a, k.imm};
        return 3;
    }
    if (isLeaf(in.op) && fusable(pc + 1)) {
        const FastOp form = in.op == Op::Const ? FastOp::AddK : FastOp::AddL;
        f = FastInstr{binaryForm(binaryOf(g.code[pc + 1]), form), 0, 0, in.a, in.imm};
        return 2;
    }
    f = plainToFast(in);
    return 1;
}

// The runs of instructions that one fused instruction does (fast_instr.h): the run's first
// instruction becomes the fused one; the others stay, for their operands and for a jump
// that lands inside the run (it runs them one by one, as before).
struct FusedRun {
    FastOp fused;
    std::vector<FastOp> ops;
};
const FusedRun kFusedRuns[] = {
    {FastOp::SumMulKL4, {FastOp::MulKL, FastOp::AddMulKL, FastOp::AddMulKL, FastOp::AddMulKL}},
    {FastOp::RandLnChain,
     {FastOp::Rand1, FastOp::MulK, FastOp::AddK, FastOp::Ln, FastOp::Neg, FastOp::AddK,
      FastOp::MulL}},
    {FastOp::MeanAddL, {FastOp::AddLL, FastOp::DivK, FastOp::AddL}},
};

bool runAt(const Graph& g, size_t i, const FusedRun& run) {
    if (i + run.ops.size() > g.fastCode.size()) return false;
    for (size_t k = 0; k < run.ops.size(); ++k)
        if (g.fastCode[i + k].op != run.ops[k]) return false;
    return true;
}

// Writes the fused op over the first instruction of each run in g.fastCode[first, ..).
void fuseRuns(Graph& g, size_t first) {
    for (size_t i = first; i < g.fastCode.size(); ++i)
        for (const FusedRun& run : kFusedRuns)
            if (runAt(g, i, run)) {
                g.fastCode[i].op = run.fused;
                i += run.ops.size() - 1;
                break;
            }
}

// Appends the fast form of the plain code [begin, end) to g.fastCode, without its End;
// false (and nothing appended) when the fast machine cannot run it. `held`: the slot the
// instruction before stored and that acc still holds (a Store that may become StoreKeep).
bool translate(Graph& g, uint32_t begin, uint32_t end, Slot held = kNone) {
    CodeShape s;
    if (begin >= end || end > g.code.size() || !shapeOf(g, begin, end, s)) return false;
    std::vector<uint32_t> newPc(end - begin + 1, 0);
    std::vector<size_t> jumps;
    uint32_t pc = begin;
    if (held != kNone && g.code[pc].op == Op::Load && g.code[pc].a == held) {
        g.fastCode.back().op = FastOp::StoreKeep;  // acc already holds the value
        newPc[0] = static_cast<uint32_t>(g.fastCode.size());
        ++pc;
    }
    const size_t first = g.fastCode.size();
    while (pc < end) {
        FastInstr f;
        const uint32_t n = fuse(g, pc, end, s.target, begin, f);
        for (uint32_t i = 0; i < n; ++i)
            newPc[pc + i - begin] = static_cast<uint32_t>(g.fastCode.size());
        if (f.op == FastOp::Jump || f.op == FastOp::JumpIfZero) jumps.push_back(g.fastCode.size());
        pc += n;
        // an Add that takes a MulKL's product (no jump lands on the Add: fuse() did not
        // fuse it, so it is not a target)
        if (f.op == FastOp::Add && g.fastCode.size() > first &&
            g.fastCode.back().op == FastOp::MulKL && !s.target[pc - 1 - begin]) {
            g.fastCode.back().op = FastOp::AddMulKL;
            continue;
        }
        g.fastCode.push_back(f);
    }
    newPc[end - begin] = static_cast<uint32_t>(g.fastCode.size());
    for (size_t j : jumps) g.fastCode[j].a = newPc[g.fastCode[j].a - begin];
    fuseRuns(g, first);
    return true;
}

uint32_t translateExpr(Graph& g, const Expr& e) {
    const auto start = static_cast<uint32_t>(g.fastCode.size());
    if (!translate(g, e.begin, e.end)) return kNoFast;
    g.fastCode.push_back(FastInstr{FastOp::End});
    return start;
}

// A program that stores values: the expression of assignment i to its slot, for i < count,
// then End; none (nothing left in fastCode) where the machine cannot run one of them.
// `chained`: each expression reads the frame the one before stored into, so one that starts
// by reading that slot keeps it in acc.
template <class AssignmentAt>
uint32_t translateStores(Graph& g, uint32_t count, bool chained, AssignmentAt assignmentAt) {
    const auto start = static_cast<uint32_t>(g.fastCode.size());
    Slot held = kNone;
    for (uint32_t i = 0; i < count; ++i) {
        const auto [value, slot] = assignmentAt(i);
        const Expr& e = g.exprs[value];
        if (!translate(g, e.begin, e.end, held)) {
            g.fastCode.resize(start);
            return kNoFast;
        }
        g.fastCode.push_back(FastInstr{FastOp::Store, 0, 0, slot});
        held = chained ? slot : kNone;
    }
    g.fastCode.push_back(FastInstr{FastOp::End});
    return start;
}

// In order (not simultaneous), the frame the values read is the one they are stored in.
uint32_t translateCalc(Graph& g, const Calc& c) {
    return translateStores(g, c.count, !c.simultaneous, [&](uint32_t i) {
        const Assignment& as = g.assignments[c.first + i];
        return std::pair<ExprId, Slot>{as.value, as.slot};
    });
}

// A lone constant or parameter: evalExpr() reads it without the machine.
bool loneLeaf(const Graph& g, ExprId id) {
    const Expr& e = g.exprs[id];
    return e.end == e.begin + 1 && isLeaf(g.code[e.begin].op);
}

// A T-node's arguments as one program, argument i stored to out[i] (the frame read is not
// `out`, so no StoreKeep); none when every argument is a lone leaf or the machine cannot
// run one of them.
uint32_t translateArgs(Graph& g, const Transform& t) {
    if (t.constant) return kNoFast;
    bool leavesOnly = true;
    for (uint32_t i = 0; i < t.argCount; ++i) leavesOnly &= loneLeaf(g, g.args[t.firstArg + i]);
    if (leavesOnly) return kNoFast;
    return translateStores(g, t.argCount, false, [&](uint32_t i) {
        return std::pair<ExprId, Slot>{g.args[t.firstArg + i], i};
    });
}

#define PCSG_FAST_NAME(name) #name,
constexpr const char* kOpNames[] = {PCSG_FAST_OPS(PCSG_FAST_NAME)};
#undef PCSG_FAST_NAME
static_assert(std::size(kOpNames) == static_cast<size_t>(FastOp::End) + 1);

std::string slotName(const Graph& g, uint32_t s) {
    return s < g.slotNames.size() ? g.slotNames[s] : fmt::format("#{}", s);
}

std::string dumpFrom(const Graph& g, uint32_t start) {
    if (start == kNoFast) return "";
    std::string out;
    for (uint32_t pc = start; pc < g.fastCode.size(); ++pc) {
        const FastInstr& in = g.fastCode[pc];
        const auto op = static_cast<size_t>(in.op);
        out += fmt::format("{:4}  {}", pc - start, kOpNames[op]);
        if (in.op == FastOp::PushK || (in.op >= FastOp::AddK && in.op <= FastOp::NeK))
            out += fmt::format(" {}", in.imm);
        else if ((in.op >= FastOp::AddKL && in.op <= FastOp::NeKL) || in.op == FastOp::AddMulKL ||
                 in.op == FastOp::SumMulKL4)
            out += fmt::format(" {} {}", in.imm, slotName(g, in.a));
        else if (in.op >= FastOp::AddLK && in.op <= FastOp::NeLK)
            out += fmt::format(" {} {}", slotName(g, in.a), in.imm);
        else if ((in.op >= FastOp::AddLL && in.op <= FastOp::NeLL) || in.op == FastOp::MeanAddL)
            out += fmt::format(" {} {}", slotName(g, in.a), slotName(g, in.b));
        else if (in.op == FastOp::PushL || in.op == FastOp::Store || in.op == FastOp::StoreKeep ||
                 (in.op >= FastOp::AddL && in.op <= FastOp::NeL))
            out += fmt::format(" {}", slotName(g, in.a));
        else if (in.op == FastOp::Jump || in.op == FastOp::JumpIfZero)
            out += fmt::format(" {}", in.a - start);
        else if (in.op == FastOp::Call || in.op == FastOp::Choose || in.op == FastOp::PushRand0)
            out += fmt::format(" {}/{}", in.a, in.argc);
        out += '\n';
        if (in.op == FastOp::End) break;
    }
    return out;
}

}  // namespace

bool stackEffect(const Instr& in, int& need, int& change) {
    need = 0, change = 0;
    switch (in.op) {
        case Op::Const:
        case Op::Load:
        case Op::Rand0:
        case Op::Clock:
        case Op::Frame:
            change = 1;
            return true;
        case Op::Neg:
        case Op::Not:
        case Op::ToBool:
            need = 1;
            return true;
        case Op::Jump:
            return true;
        case Op::JumpIfZero:
            need = 1, change = -1;
            return true;
        case Op::Call:
        case Op::Choose:
            need = in.argc, change = 1 - in.argc;
            return in.argc >= 1;
        default:
            need = 2, change = -1;
            return isBinary(in.op);
    }
}

void dropFastCode(Graph& g) {
    g.fastCode.clear();
    for (Expr& e : g.exprs) e.fast = kNoFast;
    for (Calc& c : g.calcs) c.fast = kNoFast;
    for (Transform& t : g.transforms) t.fast = kNoFast;
}

void buildFastCode(Graph& g) {
    dropFastCode(g);
    for (Expr& e : g.exprs) e.fast = translateExpr(g, e);
    for (Calc& c : g.calcs) c.fast = translateCalc(g, c);
    for (Transform& t : g.transforms) t.fast = translateArgs(g, t);
}

std::string dumpFastExpr(const Graph& g, ExprId e) {
    return dumpFrom(g, g.exprs[e].fast);
}

std::string dumpFastCalc(const Graph& g, uint32_t calc) {
    return dumpFrom(g, g.calcs[calc].fast);
}

}  // namespace pcsg
