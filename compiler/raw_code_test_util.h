// Hand-built expressions in the compiler's tests: raw instructions appended to a graph's
// code, as the builder would append a parsed expression's.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "graph.h"

namespace pcsg::testing {

// Appends an expression made of raw instructions; jump targets are relative to its start.
inline ExprId addCode(Graph& g, std::vector<Instr> code, uint32_t maxStack,
                      std::string text = "expr") {
    Expr e;
    e.begin = static_cast<uint32_t>(g.code.size());
    for (auto& in : code) {
        if (in.op == Op::Jump || in.op == Op::JumpIfZero) in.a += e.begin;
        g.code.push_back(in);
    }
    e.end = static_cast<uint32_t>(g.code.size());
    e.maxStack = maxStack;
    e.text = std::move(text);
    e.loc = {0, 7, 3};
    g.exprs.push_back(e);
    return static_cast<ExprId>(g.exprs.size() - 1);
}

}  // namespace pcsg::testing
