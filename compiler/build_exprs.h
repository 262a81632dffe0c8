// The builder's expression phase: arithmetic expressions (docs/language.md section 3) to
// the flat stack code over parameter slots of graph.h, with the checks that need no more
// than the expression: functions and their argument counts, parameters that nothing
// assigns, and, for the scene directives (section 7), values that must be constants.
#pragma once

#include <algorithm>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include "build_state.h"

namespace pcsg {

class ExprCompiler {
  public:
    ExprCompiler(BuildContext& ctx, const Names& names) : ctx_(ctx), g_(ctx.g), names_(names) {}

    // Compiles the expression ExNode `e` into Graph::exprs; a constant expression is
    // folded into one instruction.
    ExprId compile(uint32_t e);

    // The value of a directive's expression, which must be a constant: compiled,
    // evaluated and dropped from the graph's code. Nothing when an error was reported.
    std::optional<double> constant(uint32_t e);

    // The same, but the expression may also read `clock` and `frame` (section 11): then
    // it stays in the graph's code as `timed`, and `value` is its value at the graph's
    // time (not checked: setTime() checks it at each frame's time).
    struct DirectiveValue {
        double value = 0;
        ExprId timed = kNone;
    };
    std::optional<DirectiveValue> directiveValue(uint32_t e);

    // The slot of a parameter (Graph::slot searches linearly: fine for a handful of
    // names, not for a generated file with thousands).
    Slot slotOf(std::string_view name);

  private:
    struct CodeGen {
        uint32_t depth = 0, maxDepth = 0;
        bool readsSlot = false, usesPath = false, usesTime = false;
        void push(uint32_t k = 1) {
            depth += k;
            maxDepth = std::max(maxDepth, depth);
        }
        void pop(uint32_t k = 1) { depth -= k; }
    };

    uint32_t emit(Op op, uint32_t a = 0, double imm = 0, uint8_t argc = 0);
    std::optional<DirectiveValue> directiveExpr(uint32_t e, bool allowTime);
    uint32_t here() const { return static_cast<uint32_t>(g_.code.size()); }
    std::string sourceText(uint32_t from, uint32_t to) const;

    void gen(uint32_t e, CodeGen& cg);
    void name(const ExNode& n, CodeGen& cg);
    void logical(const ExNode& n, CodeGen& cg);
    void arithmetic(const ExNode& n, CodeGen& cg);
    void call(const ExNode& n, CodeGen& cg);
    void ifCall(const ExNode& n, CodeGen& cg);
    void randCall(const ExNode& n, CodeGen& cg);
    void chooseCall(const ExNode& n, CodeGen& cg);
    void functionCall(const ExNode& n, CodeGen& cg);
    // Reports a call that cannot be compiled; a 0 stands in for its value.
    void badCall(const ExNode& n, CodeGen& cg, const std::string& message);
    void wrongCount(const ExNode& n, CodeGen& cg, const std::string& want);

    BuildContext& ctx_;
    Graph& g_;
    const Names& names_;
    std::unordered_map<std::string_view, Slot> slots_;
    std::unordered_set<std::string_view> reportedUnknown_;
    bool constantOnly_ = false;  // compiling a directive's value
};

}  // namespace pcsg
