// pcsg check FILE [--stats] [--json]: compile a scene, print its diagnostics, exit 0
// when it compiles and 1 when it does not; with --stats the cyclic graph's figures:
// nodes by kind, edges, modules, parameters, expressions and its size in bytes.
#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "scene_input.h"
#include "stats.h"

namespace pcsg::tools {

namespace {

struct CheckOptions {
    std::string scene;
    bool stats = false;
    bool json = false;
};

// The node kinds in the order they are printed: JSON key, label for people.
struct KindName {
    NodeKind kind;
    CsgOp op;  // for NodeKind::Operator
    const char* key;
    const char* label;
};
constexpr KindName kKinds[] = {
    {NodeKind::Select, {}, "select", "S-nodes (select)"},
    {NodeKind::Transform, {}, "transform", "T-nodes (transform)"},
    {NodeKind::Calc, {}, "calc", "C-nodes (calculate)"},
    {NodeKind::Paint, {}, "paint", "paint nodes"},
    {NodeKind::Operator, CsgOp::Union, "union", "∪ nodes (union)"},
    {NodeKind::Operator, CsgOp::Intersection, "intersection", "∩ nodes (intersection)"},
    {NodeKind::Operator, CsgOp::Difference, "difference", "\\ nodes (difference)"},
    {NodeKind::Primitive, {}, "primitive", "primitives"},
};

size_t countKind(const Graph& g, const KindName& kind) {
    size_t n = 0;
    for (const Node& node : g.nodes)
        n += node.kind == kind.kind && (kind.kind != NodeKind::Operator || node.op() == kind.op);
    return n;
}

int runCheck(const CheckOptions& o) {
    const CompiledScene compiled = compileScene(o.scene, std::cerr);
    if (!compiled.graph) {
        if (o.json) std::cout << nlohmann::json{{"scene", o.scene}, {"ok", false}}.dump(2) << "\n";
        return 1;
    }
    const Graph& g = *compiled.graph;
    Stats stats;
    stats.scene = o.scene;
    stats.graphBytes = g.graphBytes();
    stats.parseSeconds = compiled.seconds;

    if (o.json) {
        nlohmann::json j = stats.toJson();
        j["ok"] = true;
        nlohmann::json nodes;
        for (const KindName& k : kKinds) nodes[k.key] = countKind(g, k);
        nodes["total"] = g.nodes.size();
        j["nodes"] = nodes;
        j["edges"] = g.edges.size();
        j["modules"] = g.modules.size();
        j["parameters"] = g.slotCount();
        j["expressions"] = g.exprs.size();
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    if (!o.stats) {
        std::cout << fmt::format("{}: ok ({} module{}, {} nodes, {} graph)\n", o.scene,
                                 g.modules.size(), g.modules.size() == 1 ? "" : "s", g.nodes.size(),
                                 humanBytes(*stats.graphBytes));
        return 0;
    }
    // Column widths count bytes, and ∪ ∩ are three bytes each: pad by display width.
    auto line = [](const std::string& label, const std::string& value) {
        size_t width = 0;
        for (unsigned char c : label) width += (c & 0xC0) != 0x80;
        std::cout << label << std::string(width < 24 ? 24 - width : 1, ' ') << value << "\n";
    };
    line("scene", o.scene);
    for (const KindName& k : kKinds) line(k.label, fmt::format("{}", countKind(g, k)));
    line("nodes", fmt::format("{}", g.nodes.size()));
    line("edges", fmt::format("{}", g.edges.size()));
    line("modules", fmt::format("{}", g.modules.size()));
    line("parameters", fmt::format("{}", g.slotCount()));
    line("expressions", fmt::format("{}", g.exprs.size()));
    line("graph bytes", fmt::format("{} ({} B)", humanBytes(*stats.graphBytes), *stats.graphBytes));
    line("compile time", fmt::format("{:.3f} s", compiled.seconds));
    return 0;
}

}  // namespace

void addCheckCommand(CLI::App& app, int& status) {
    auto o = std::make_shared<CheckOptions>();
    auto* cmd = app.add_subcommand(
        "check",
        "Compile a scene and print its errors: exit status 0 when it compiles, 1 when not");
    cmd->add_option("scene", o->scene, "The .pcsg file (- reads standard input)")->required();
    cmd->add_flag("--stats", o->stats,
                  "Print the cyclic graph's figures: nodes by kind, edges, modules, parameters, "
                  "expressions, size in bytes");
    cmd->add_flag("--json", o->json, "Print the same figures as JSON (implies --stats)");
    cmd->callback([o, &status] { status = runCheck(*o); });
}

}  // namespace pcsg::tools
