// Which language features a scene uses, read from its syntax tree: `pcsg fuzz --json`'s
// coverage counts (docs/fuzz.md).
#pragma once

#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace pcsg::fuzz {

// The feature names, in the order the coverage lists them.
const std::vector<std::string>& featureNames();

// The features of featureNames() that the scene's text uses (nothing when it does not
// parse): select (a notation-A selection function), transform, calc (a C-node), paint,
// union, intersection, difference, each primitive (tri1, tri2 and triangle() count as
// triangle), notation_b (a notation-B rule or axiom), rand (rand() or rand(x)), choose.
std::set<std::string> featuresOf(std::string_view text);

}  // namespace pcsg::fuzz
