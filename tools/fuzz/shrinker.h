// Shrinking a failing system (`pcsg fuzz`, docs/fuzz.md): one-step reductions of its
// syntax tree, printed back by the formatter (compiler/formatter.h), kept while a
// predicate still holds ("the renderers still disagree").
//
// The reductions, tried in this order (bigger cuts first):
//  - drop everything the axiom no longer reaches (modules, definitions, materials);
//  - drop a statement: a light, the background, a material, the settings, a definition,
//    a notation-B rule, or a module with all its rules;
//  - replace a CSG node by `empty`, an operator by one of its operands, drop one operand
//    of an operator with three or more, and drop a transformation, C-node or paint
//    (the node becomes its operand);
//  - lower a small whole number by one (recursion depths), round a fraction to one
//    decimal, then to a whole number.
// A reduction that does not compile is skipped without asking the predicate. The search
// is greedy: it keeps the first reduction that still fails and goes on from there, until
// a whole round of reductions fails to shrink or the budget of predicate calls is spent.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace pcsg::fuzz {

// True when the text still shows the failure being shrunk.
using StillFails = std::function<bool(const std::string& text)>;

struct ShrinkOptions {
    int maxTries = 200;     // calls of the predicate at most
    double maxSeconds = 0;  // and for at most this long (0: no limit)
};

struct ShrinkResult {
    std::string text;  // the smallest failing system found (formatted)
    int tries = 0;     // predicate calls
    int accepted = 0;  // reductions kept
};

// Every one-step reduction of a scene that compiles, formatted, in the order tried. The
// scene must compile (else: none).
std::vector<std::string> shrinkCandidates(const std::string& text);

// Shrinks `text` (which should fail) while `stillFails` holds.
ShrinkResult shrinkSystem(const std::string& text, const StillFails& stillFails,
                          const ShrinkOptions& options = {});

}  // namespace pcsg::fuzz
