// The cyclic CSG graph as Graphviz DOT, drawn like the seed paper's figures 3b and 5b:
// the axiom at the top, S-nodes (module name and selection function) as boxes whose
// rules hang below them, T- and C-nodes labelled with their source text, paint nodes
// with their material, ∪ ∩ \ as circles and primitives as leaves.
//
// Every node of the graph is drawn once, so a definition used twice is one node with
// two edges into it. An edge that closes a cycle (found by a depth-first walk from the
// axiom: it points to an S-node still on the walk's stack) is a *back edge*: dashed and
// with constraint=false, so Graphviz lays the graph out top-down and the recursion reads
// as arrows returning to the module's S-node.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "graph.h"

namespace pcsg::tools {

struct DotEdge {
    NodeId from = kNone, to = kNone;
    uint32_t index = 0;  // which child of `from` (for an S-node: rule index-1)
    bool back = false;   // closes a cycle: points to an S-node on the walk's stack
};

// The nodes in drawing order (a depth-first preorder from the axiom, then S-nodes of
// modules the axiom never reaches, then anything else) and every edge, classified.
struct DotLayout {
    std::vector<NodeId> order;
    std::vector<DotEdge> edges;
};
DotLayout layoutGraph(const Graph& g);

// A node's label as plain text (lines separated by '\n'), e.g. "S\nif(c > 0,2,1)",
// "move(0.5, 0.5, 0.5)", "{c = c-1}", "paint(bark)", "∪", "sphere".
std::string nodeLabel(const Graph& g, NodeId n);

// Text made safe inside a DOT double-quoted string: backslash and quote escaped, control
// characters and invalid UTF-8 replaced, '\n' turned into DOT's centred line break.
std::string dotEscape(const std::string& text);

struct DotOptions {
    std::string title;  // shown above the graph (e.g. the scene's file name)
};

void writeDot(const Graph& g, std::ostream& out, const DotOptions& options = {});
std::string toDot(const Graph& g, const DotOptions& options = {});

}  // namespace pcsg::tools
