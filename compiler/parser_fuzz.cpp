// libFuzzer target: any bytes through compileSource. Built with -DPCSG_FUZZ=ON and clang
// (see compiler/CMakeLists.txt), under AddressSanitizer and UndefinedBehaviorSanitizer.
//
//   CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DPCSG_FUZZ=ON -DPCSG_TESTS=OFF \
//       -DPCSG_BENCH=OFF -DCMAKE_CXX_FLAGS=-fsanitize=fuzzer-no-link,address,undefined
//   cmake --build build-fuzz --target parser_fuzz
//   mkdir -p build-fuzz/corpus
//   build-fuzz/compiler/parser_fuzz -max_total_time=120 -dict=compiler/parser_fuzz.dict \
//       build-fuzz/corpus tests/diagnostics scenes
//
// (The CMAKE_CXX_FLAGS instrument the compiler library too: without them libFuzzer
// gets no coverage from it and AddressSanitizer does not see inside it.)
//
// Besides "never crash, hang or exhaust the stack", every graph that compiles must be
// well formed: indices inside their arrays, and expression code whose stack never goes
// deeper than the maxStack it declares (the evaluator sizes its stack from it). And pcsg
// fmt of a scene that compiles gives a text that compiles and that it leaves unchanged.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "compiler.h"
#include "eval.h"
#include "fast_code.h"
#include "formatter.h"

namespace {

using namespace pcsg;

[[noreturn]] void broken(const char* what) {
    std::fprintf(stderr, "malformed graph: %s\n", what);
    std::abort();
}
void check(bool ok, const char* what) {
    if (!ok) broken(what);
}

// The stack depth along every path through an expression's code (jumps only go forward).
void checkStack(const Graph& g, const Expr& e) {
    const uint32_t n = e.end - e.begin;
    std::vector<int> depthAt(n + 1, -1);  // the depth on entry to each instruction
    depthAt[0] = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const int d = depthAt[i];
        if (d < 0) continue;  // unreachable
        const Instr& in = g.code[e.begin + i];
        int need = 0, change = 0;
        check(stackEffect(in, need, change) && d >= need, "an instruction without its operands");
        const int next = d + change;
        const uint32_t target = in.op == Op::Jump || in.op == Op::JumpIfZero ? in.a : kNone;
        check(next <= static_cast<int>(e.maxStack), "stack deeper than maxStack");
        if (target != kNone) {
            check(target > e.begin + i && target <= e.end,
                  "jump outside the expression or backwards");
            int& t = depthAt[target - e.begin];
            check(t < 0 || t == next, "paths meet with different depths");
            t = next;
        }
        if (in.op != Op::Jump) {
            int& f = depthAt[i + 1];
            check(f < 0 || f == next, "paths meet with different depths");
            f = next;
        }
    }
    check(depthAt[n] == 1, "an expression leaves other than one value");
}

void checkGraph(const Graph& g) {
    check(g.axiom < g.nodes.size(), "axiom");
    for (const Node& nd : g.nodes)
        check(nd.firstChild + nd.childCount <= g.edges.size(), "children");
    for (NodeId e : g.edges) check(e < g.nodes.size(), "edge");
    for (const Expr& e : g.exprs) {
        check(e.begin < e.end && e.end <= g.code.size(), "expression range");
        checkStack(g, e);
    }
    for (const Assignment& a : g.assignments)
        check(a.slot < g.slotCount() && a.value < g.exprs.size(), "assignment");
    for (ExprId a : g.args) check(a < g.exprs.size(), "argument");
    // Evaluate every expression with all parameters set: exercises the code the
    // builder emitted through the shared evaluator.
    std::vector<double> frame(g.slotCount(), 1.0);
    for (ExprId id = 0; id < g.exprs.size(); ++id) {
        try {
            (void)evalExpr(g, id, EvalState{frame.data(), kRootPath});
        } catch (const RuntimeError&) {
            // choose() with bad weights: a run-time error, as the language says.
        }
    }
}

// pcsg fmt of a scene that compiles: either a clear error (a macro it cannot keep), or a
// text that compiles too and that it prints again unchanged.
void checkFormatted(std::string_view text) {
    Diagnostics diags;
    const std::optional<std::string> once = formatScene("fuzz.pcsg", text, diags);
    if (!once) {
        check(diags.hasErrors(), "pcsg fmt refused without an error");
        return;
    }
    Diagnostics again;
    check(compileSource("fmt.pcsg", *once, again).has_value(), "pcsg fmt's text does not compile");
    const std::optional<std::string> twice = formatScene("fmt.pcsg", *once, again);
    check(twice && *twice == *once, "pcsg fmt is not idempotent");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    Diagnostics diags;
    const auto graph = compileSource("fuzz.pcsg", text, diags);
    const std::string printed = diags.format();
    if (graph) {
        check(!diags.hasErrors(), "a graph despite errors");
        checkGraph(*graph);
        checkFormatted(text);
    } else {
        check(diags.hasErrors() && !printed.empty(), "no graph and no error");
        check(diags.errors().size() <= Diagnostics::kMaxErrors, "too many errors");
    }
    return 0;
}
