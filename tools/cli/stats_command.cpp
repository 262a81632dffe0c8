// pcsg stats SCENE [--json] [--max-visits N]: the expanded tree's size (primitives,
// nodes, bytes) beside the cyclic graph's bytes, found by the counting pass without
// building the tree, so it works for systems far beyond any node budget.
//
// Exit status: 0 success, 1 the scene is at fault (compile error, run-time error, too
// large to count).
#include <fmt/format.h>

#include <chrono>
#include <iostream>
#include <memory>

#include "commands.h"
#include "eval.h"
#include "expander.h"
#include "scene_input.h"
#include "stats.h"

namespace pcsg::tools {

namespace {

struct StatsOptions {
    std::string scene;
    bool json = false;
    uint64_t maxVisits = 4'000'000'000ULL;
    double clock = 0;  // --clock: the frame counted
    int frame = 1;     // --frame: its frame number
};

int runStats(const StatsOptions& o) {
    CompiledScene compiled = compileScene(o.scene, std::cerr);
    if (!compiled.graph) return 1;
    Graph& g = *compiled.graph;
    if (!setSceneTime(g, Time{o.clock, o.frame}, std::cerr)) return 1;
    const auto start = std::chrono::steady_clock::now();
    ExpansionCount count;
    try {
        CountOptions co;
        co.maxVisits = o.maxVisits;
        count = countExpansion(g, co);
    } catch (const RuntimeError& e) {
        std::cerr << e.format(g) << "\n";
        return 1;
    }
    if (!count.complete) {
        std::cerr << fmt::format(
            "pcsg stats: error: {}: the expanded tree is too large to count within {} graph "
            "visits (--max-visits); its sub-graphs use rand() or choose(), which defeats "
            "the counting pass's memoisation\n",
            o.scene, o.maxVisits);
        return 1;
    }
    Stats s;
    s.scene = o.scene;
    s.primitiveEquivalence = count.primitives;
    s.expandedNodes = count.nodes;
    s.graphBytes = g.graphBytes();
    s.expandedBytes = count.treeBytes();
    s.parseSeconds = compiled.seconds;
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (o.json) {
        nlohmann::json j = s.toJson();
        j["graph_nodes"] = g.nodes.size();
        j["count_visits"] = count.visits;
        j["saturated"] = count.nodes == UINT64_MAX;
        std::cout << j.dump(2) << "\n";
    } else {
        s.print(std::cout);
        std::cout << fmt::format("{:<24}{}\n", "graph nodes", g.nodes.size());
        if (count.nodes == UINT64_MAX)
            std::cout << "(the counts saturated at 2^64 - 1: the tree is larger still)\n";
    }
    return 0;
}

}  // namespace

void addStatsCommand(CLI::App& app, int& status) {
    auto s = std::make_shared<StatsOptions>();
    auto* st = app.add_subcommand(
        "stats",
        "The expanded tree's size (primitives, nodes, bytes) beside the cyclic graph's bytes: "
        "the memory the graph saves, counted without building the tree");
    st->add_option("scene", s->scene, "The .pcsg file (- reads standard input)")->required();
    addClockOption(st, s->clock);
    addFrameOption(st, s->frame);
    st->add_flag("--json", s->json, "Print the figures as JSON");
    st->add_option("--max-visits", s->maxVisits,
                   "Work limit of the counting pass in graph-node visits (stochastic systems "
                   "cannot be memoised)")
        ->capture_default_str();
    st->callback([s, &status] { status = runStats(*s); });
}

}  // namespace pcsg::tools
