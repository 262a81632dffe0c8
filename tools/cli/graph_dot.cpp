#include "graph_dot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "primitive_table.h"

namespace pcsg::tools {

namespace {

// Longest expression text shown in a label, in bytes; longer ones end in "...".
constexpr size_t kMaxExprText = 60;

// The length of the valid UTF-8 sequence starting at s[i], or 0 when it is invalid.
size_t utf8Length(const std::string& s, size_t i) {
    const auto b = static_cast<unsigned char>(s[i]);
    size_t n = 0;
    if (b < 0x80) return 1;
    if ((b & 0xE0) == 0xC0 && b >= 0xC2)
        n = 2;
    else if ((b & 0xF0) == 0xE0)
        n = 3;
    else if ((b & 0xF8) == 0xF0 && b <= 0xF4)
        n = 4;
    else
        return 0;
    if (i + n > s.size()) return 0;
    for (size_t k = 1; k < n; ++k)
        if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
    return n;
}

// An expression's source text on one line, shortened to kMaxExprText bytes.
std::string exprText(const Graph& g, ExprId e) {
    if (e >= g.exprs.size()) return "?";
    std::string out;
    bool space = false;
    for (char c : g.exprs[e].text) {
        const bool ws = c == ' ' || c == '\t' || c == '\n' || c == '\r';
        if (ws) {
            space = !out.empty();
            continue;
        }
        if (space) out += ' ';
        space = false;
        out += c;
    }
    if (out.size() > kMaxExprText) {
        size_t cut = kMaxExprText;
        // Do not split a UTF-8 sequence.
        while (cut > 0 && (static_cast<unsigned char>(out[cut]) & 0xC0) == 0x80) --cut;
        out = out.substr(0, cut) + "...";
    }
    return out.empty() ? "?" : out;
}

std::string argList(const Graph& g, uint32_t first, uint32_t count) {
    std::string s;
    for (uint32_t i = 0; i < count; ++i) {
        if (i) s += ", ";
        s += first + i < g.args.size() ? exprText(g, g.args[first + i]) : "?";
    }
    return s;
}

const char* transformName(TransformOp op) {
    switch (op) {
        case TransformOp::Move:
            return "move";
        case TransformOp::Scale:
            return "scale";
        case TransformOp::UScale:
            return "uscale";
        case TransformOp::RotX:
            return "rotx";
        case TransformOp::RotY:
            return "roty";
        case TransformOp::RotZ:
            return "rotz";
        case TransformOp::Rot:
            return "rot";
        case TransformOp::ZShear:
            return "zshear";
        case TransformOp::FlipYZ:
            return "flipyz";
        case TransformOp::FlipXZ:
            return "flipxz";
        case TransformOp::FlipXY:
            return "flipxy";
        case TransformOp::Matrix:
            return "matrix";
    }
    return "transform";
}

std::string materialName(const Graph& g, uint32_t m) {
    if (m < g.materials.size() && !g.materials[m].name.empty()) return g.materials[m].name;
    return m == 0 ? std::string("default") : fmt::format("material {}", m);
}

// The rule edge's label: its number, and for notation B its condition.
std::string ruleLabel(const Graph& g, NodeId s, uint32_t rule) {
    std::string label = fmt::format("{}", rule + 1);
    const Node& n = g.nodes[s];
    if (n.payload < g.modules.size()) {
        const Module& m = g.modules[n.payload];
        if (m.notationB && rule < m.conditions.size() && m.conditions[rule] != kNone)
            label += ": " + exprText(g, m.conditions[rule]);
    }
    return label;
}

// "#rrggbb" of a linear colour, sRGB-encoded as the picture would show it.
std::string hexColor(const Vec3& c, double* luminance) {
    auto enc = [](double v) {
        v = std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0);
        v = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
        return static_cast<int>(std::lround(v * 255));
    };
    const int r = enc(c.x), gr = enc(c.y), b = enc(c.z);
    *luminance = (0.2126 * r + 0.7152 * gr + 0.0722 * b) / 255.0;
    return fmt::format("#{:02x}{:02x}{:02x}", r, gr, b);
}

// The node's DOT attributes besides its label.
std::string nodeStyle(const Graph& g, NodeId id) {
    const Node& n = g.nodes[id];
    switch (n.kind) {
        case NodeKind::Select:
            return R"(shape=box, style="filled,bold", fillcolor="#fde9b0", peripheries=2)";
        case NodeKind::Transform:
            return R"(shape=box, style=filled, fillcolor="#dfeaf7")";
        case NodeKind::Calc:
            return R"(shape=box, style="rounded,filled", fillcolor="#e4f3dc")";
        case NodeKind::Paint: {
            if (n.payload >= g.materials.size()) return R"(shape=box, style="rounded")";
            double lum = 0;
            const std::string fill = hexColor(g.materials[n.payload].color, &lum);
            return fmt::format(
                R"(shape=box, style="rounded,filled", fillcolor="{}", fontcolor="{}")", fill,
                lum < 0.45 ? "white" : "black");
        }
        case NodeKind::Operator:
            return R"(shape=circle, width=0.35, fixedsize=true, fontsize=14)";
        case NodeKind::Primitive:
            return R"(shape=ellipse, style=filled, fillcolor="#eeeeee")";
    }
    return "shape=box";
}

}  // namespace

DotLayout layoutGraph(const Graph& g) {
    DotLayout layout;
    const size_t count = g.nodes.size();
    // 0: not reached yet, 1: on the walk's stack, 2: finished.
    std::vector<uint8_t> state(count, 0);
    struct Frame {
        NodeId node;
        uint32_t next;
    };
    std::vector<Frame> stack;  // explicit: a graph may be a very deep chain
    auto walk = [&](NodeId root) {
        if (root >= count || state[root] != 0) return;
        state[root] = 1;
        layout.order.push_back(root);
        stack.push_back({root, 0});
        while (!stack.empty()) {
            const NodeId node = stack.back().node;
            const Node& n = g.nodes[node];
            if (stack.back().next >= n.childCount) {
                state[node] = 2;
                stack.pop_back();
                continue;
            }
            const uint32_t i = stack.back().next++;
            if (n.firstChild + i >= g.edges.size()) continue;
            const NodeId c = g.child(node, i);
            if (c >= count) continue;
            DotEdge e{node, c, i, false};
            e.back = state[c] == 1 && g.nodes[c].kind == NodeKind::Select;
            layout.edges.push_back(e);
            if (state[c] == 0) {
                state[c] = 1;
                layout.order.push_back(c);
                stack.push_back({c, 0});
            }
        }
    };
    walk(g.axiom);
    for (const Module& m : g.modules) walk(m.node);
    for (NodeId n = 0; n < count; ++n) walk(n);
    return layout;
}

std::string nodeLabel(const Graph& g, NodeId id) {
    const Node& n = g.nodes[id];
    switch (n.kind) {
        case NodeKind::Select: {
            if (n.payload >= g.modules.size()) return "S";
            const Module& m = g.modules[n.payload];
            if (m.notationB) {
                std::string formals;
                for (size_t i = 0; i < m.formals.size(); ++i) {
                    if (i) formals += ", ";
                    formals += m.formals[i] < g.slotNames.size() ? g.slotNames[m.formals[i]] : "?";
                }
                return m.formals.empty() ? m.name : m.name + "(" + formals + ")";
            }
            return m.select == kNone ? m.name : m.name + "\n" + exprText(g, m.select);
        }
        case NodeKind::Transform: {
            if (n.payload >= g.transforms.size()) return "T";
            const Transform& t = g.transforms[n.payload];
            const std::string name = transformName(t.op);
            if (t.argCount == 0) return name;
            return name + "(" + argList(g, t.firstArg, t.argCount) + ")";
        }
        case NodeKind::Calc: {
            if (n.payload >= g.calcs.size()) return "C";
            const Calc& c = g.calcs[n.payload];
            std::string s = "{";
            for (uint32_t i = 0; i < c.count; ++i) {
                if (c.first + i >= g.assignments.size()) break;
                const Assignment& a = g.assignments[c.first + i];
                if (i) s += "\n";
                s += a.slot < g.slotNames.size() ? g.slotNames[a.slot] : "?";
                s += " = " + exprText(g, a.value);
            }
            s += "}";
            // A notation-B call assigns all values at once, computed from the caller's.
            return c.simultaneous && c.count > 1 ? s + "\n(simultaneous)" : s;
        }
        case NodeKind::Paint:
            return "paint(" + materialName(g, n.payload) + ")";
        case NodeKind::Operator:
            return n.is(CsgOp::Union) ? "∪" : n.is(CsgOp::Intersection) ? "∩" : "\\";
        case NodeKind::Primitive: {
            if (n.payload >= g.primitives.size()) return "primitive";
            const Primitive& p = g.primitives[n.payload];
            const std::string name = primitiveName(p.kind);
            if (p.argCount == 0) return name;
            return name + "(" + argList(g, p.firstArg, p.argCount) + ")";
        }
    }
    return "?";
}

std::string dotEscape(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (size_t i = 0; i < text.size();) {
        const char c = text[i];
        const size_t len = utf8Length(text, i);
        if (len == 0) {
            out += '?';
            ++i;
            continue;
        }
        if (len > 1) {
            out.append(text, i, len);
            i += len;
            continue;
        }
        ++i;
        if (c == '\n')
            out += "\\n";
        else if (c == '\\')
            out += "\\\\";
        else if (c == '"')
            out += "\\\"";
        else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
            out += ' ';
        else
            out += c;
    }
    return out;
}

void writeDot(const Graph& g, std::ostream& out, const DotOptions& options) {
    const DotLayout layout = layoutGraph(g);
    out << "digraph pcsg {\n";
    out << "    graph [fontname=\"Helvetica\", ordering=out, nodesep=0.3, ranksep=0.45";
    if (!options.title.empty())
        out << ", labelloc=t, fontsize=14, label=\"" << dotEscape(options.title) << "\"";
    out << "];\n";
    out << "    node [fontname=\"Helvetica\", fontsize=11, height=0.3];\n";
    out << "    edge [arrowsize=0.6, fontname=\"Helvetica\", fontsize=9];\n";
    if (g.axiom < g.nodes.size()) {
        out << "    axiom [shape=plaintext, fontsize=10, label=\"axiom\"];\n";
        out << "    axiom -> n" << g.axiom << ";\n";
    }
    for (NodeId n : layout.order)
        out << "    n" << n << " [label=\"" << dotEscape(nodeLabel(g, n)) << "\", "
            << nodeStyle(g, n) << "];\n";
    for (const DotEdge& e : layout.edges) {
        out << "    n" << e.from << " -> n" << e.to;
        std::vector<std::string> attrs;
        if (g.nodes[e.from].kind == NodeKind::Select)
            attrs.push_back("label=\"" + dotEscape(ruleLabel(g, e.from, e.index)) + "\"");
        if (e.back)
            attrs.push_back("style=dashed, constraint=false, headport=e, color=\"#2b62b0\"");
        if (!attrs.empty()) {
            out << " [";
            for (size_t i = 0; i < attrs.size(); ++i) out << (i ? ", " : "") << attrs[i];
            out << "]";
        }
        out << ";\n";
    }
    out << "}\n";
}

std::string toDot(const Graph& g, const DotOptions& options) {
    std::ostringstream s;
    writeDot(g, s, options);
    return s.str();
}

}  // namespace pcsg::tools
