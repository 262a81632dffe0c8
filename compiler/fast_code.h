// The peephole pass that gives a graph's expressions, C-nodes and T-nodes' arguments their
// fast form (fast_instr.h), and its text for tests and debugging.
//
// The pass reads Graph::code and writes Graph::fastCode, Expr::fast, Calc::fast and
// Transform::fast. A pass that changes Graph::code afterwards must call dropFastCode() first
// (or build again): until then evaluation would follow the old code. The compiler builds the
// fast form last (compileSource); graphs made by hand have none and run the plain code.
#pragma once

#include <string>

#include "graph.h"

namespace pcsg {

// Translates every expression and C-node of g (replacing any fast form there was). Code the
// fast machine cannot run (a stack deeper than kFastStack, a backward jump, code that
// does not leave exactly one value: only hand-made code) keeps running plain.
// A plain instruction's effect on the stack: the values it needs on it and the change of
// its depth; false for an instruction that cannot be well formed (a call without
// arguments, an unknown operator). Shared by the translation and the parser fuzzer's
// graph checks.
bool stackEffect(const Instr& in, int& need, int& change);

void buildFastCode(Graph& g);

// Forgets the fast form: every expression and C-node runs the plain code again.
void dropFastCode(Graph& g);

// The fast form of an expression or of a C-node's assignments, one instruction a line
// ("PushL x", "AddK 1", "Call min/3", "Store y"), or "" when it has none.
std::string dumpFastExpr(const Graph& g, ExprId e);
std::string dumpFastCalc(const Graph& g, uint32_t calc);

}  // namespace pcsg
