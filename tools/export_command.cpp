// pcsg export-pov SCENE -o OUT.pov [--max-nodes N] [--width W --height H] [--json]:
// unroll the cyclic graph into a finite CSG tree (povexport/expander.h) and write it as
// POV-Ray 3.7 scene text (povexport/pov_writer.h).
//
// pcsg stats SCENE [--json] [--max-visits N]: the expanded tree's size (primitives,
// nodes, bytes) beside the cyclic graph's bytes, found by the counting pass without
// building the tree, so it works for systems far beyond any node budget.
//
// Exit status: 0 success, 1 the scene is at fault (compile error, run-time error, too
// large for the node budget), 2 something could not run (the output is not writable).
#include <fmt/format.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "commands.h"
#include "eval.h"
#include "expander.h"
#include "pov_writer.h"
#include "scene_input.h"
#include "stats.h"

namespace pcsg::tools {

namespace {

double since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct ExportOptions {
    std::string scene;
    std::string output;
    uint64_t maxNodes = 10'000'000;
    int width = 640, height = 480;
    uint32_t maxUnion = 32;
    bool json = false;
};

int runExport(const ExportOptions& o) {
    if (o.width <= 0 || o.height <= 0) {
        std::cerr << "pcsg export-pov: --width and --height must be positive\n";
        return 2;
    }
    if (o.maxNodes == 0) {
        std::cerr << "pcsg export-pov: --max-nodes must be positive\n";
        return 2;
    }
    const CompiledScene compiled = compileScene(o.scene, std::cerr);
    if (!compiled.graph) return 1;
    const Graph& g = *compiled.graph;

    const auto start = std::chrono::steady_clock::now();
    ExpandedTree tree;
    try {
        ExpandOptions eo;
        eo.maxNodes = o.maxNodes;
        tree = expand(g, eo);
    } catch (const RuntimeError& e) {
        std::cerr << e.format(g) << "\n";
        return 1;
    } catch (const BudgetError& e) {
        std::cerr << fmt::format("pcsg export-pov: error: {}: {}\n", o.scene, e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::cerr << fmt::format(
            "pcsg export-pov: error: {}: out of memory while expanding; "
            "lower --max-nodes\n",
            o.scene);
        return 1;
    }
    const double expandSeconds = since(start);

    PovOptions po;
    po.width = o.width;
    po.height = o.height;
    po.maxUnionChildren = o.maxUnion;
    po.title = o.scene;
    PovWriteStats written;
    const auto writeStart = std::chrono::steady_clock::now();
    if (o.output == "-") {
        try {
            written = writePov(g, tree, std::cout, po);
        } catch (const std::exception& e) {
            std::cerr << "pcsg export-pov: " << e.what() << " (standard output)\n";
            return 2;
        }
    } else {
        // Written beside the target and renamed at the end: a failed export leaves no
        // partial file in place of the requested one.
        namespace fs = std::filesystem;
        const fs::path target(o.output);
        const fs::path temp = target.string() + ".partial";
        {
            std::vector<char> buffer(1 << 20);  // declared first: it outlives the stream
            std::ofstream out;
            out.rdbuf()->pubsetbuf(buffer.data(), static_cast<std::streamsize>(buffer.size()));
            out.open(temp, std::ios::binary | std::ios::trunc);
            if (!out) {
                std::cerr << "pcsg export-pov: cannot write " << o.output << ": "
                          << std::strerror(errno) << "\n";
                return 2;
            }
            try {
                written = writePov(g, tree, out, po);
                out.close();
                if (!out) throw std::runtime_error("could not write the POV-Ray file");
            } catch (const std::exception& e) {
                std::error_code ec;
                fs::remove(temp, ec);
                std::cerr << "pcsg export-pov: " << e.what() << " " << o.output << "\n";
                return 2;
            }
        }
        std::error_code ec;
        fs::rename(temp, target, ec);
        if (ec) {
            fs::remove(temp, ec);
            std::cerr << "pcsg export-pov: cannot write " << o.output << ": " << ec.message()
                      << "\n";
            return 2;
        }
    }
    const double writeSeconds = since(writeStart);

    Stats s;
    s.scene = o.scene;
    s.width = static_cast<uint32_t>(o.width);
    s.height = static_cast<uint32_t>(o.height);
    s.primitiveEquivalence = tree.primitives.size();
    s.expandedNodes = tree.nodes.size();
    s.graphBytes = g.graphBytes();
    s.expandedBytes = tree.bytes();
    s.parseSeconds = compiled.seconds;
    s.seconds = expandSeconds + writeSeconds;
    s.peakRssBytes = peakRssBytes();
    // With -o -, standard output is the scene: the report goes to standard error.
    std::ostream& report = o.output == "-" ? std::cerr : std::cout;
    if (o.json) {
        nlohmann::json j = s.toJson();
        j["output"] = o.output;
        j["pov_bytes"] = written.bytes;
        j["pov_objects"] = written.objects;
        j["skipped_degenerate_triangles"] = written.skipped;
        j["expand_seconds"] = expandSeconds;
        j["write_seconds"] = writeSeconds;
        report << j.dump(2) << "\n";
    } else {
        report << fmt::format("{}: wrote {} ({} objects, {}) in {:.3f} s\n", o.scene,
                              o.output == "-" ? std::string("standard output") : o.output,
                              written.objects, humanBytes(written.bytes), *s.seconds);
        if (written.skipped)
            report << fmt::format(
                "  left out {} degenerate triangle{} (no area; POV-Ray rejects them)\n",
                written.skipped, written.skipped == 1 ? "" : "s");
    }
    return 0;
}

struct StatsOptions {
    std::string scene;
    bool json = false;
    uint64_t maxVisits = 4'000'000'000ULL;
};

int runStats(const StatsOptions& o) {
    const CompiledScene compiled = compileScene(o.scene, std::cerr);
    if (!compiled.graph) return 1;
    const Graph& g = *compiled.graph;
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
    s.seconds = since(start);
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

void addExportCommands(CLI::App& app, int& status) {
    auto e = std::make_shared<ExportOptions>();
    auto* ex = app.add_subcommand(
        "export-pov",
        "Unroll the scene's cyclic graph into a finite CSG tree and write it as POV-Ray 3.7 "
        "scene text (render it with `povray +IOUT.pov +W640 +H480`)");
    ex->add_option("scene", e->scene, "The .pcsg file (- reads standard input)")->required();
    ex->add_option("-o,--output", e->output, "The POV-Ray file to write (- for standard output)")
        ->required();
    ex->add_option("--max-nodes", e->maxNodes,
                   "Node budget of the expanded tree: a larger expansion stops with an error "
                   "that says how many nodes it would need")
        ->capture_default_str();
    ex->add_option("--width", e->width, "Image width the camera's aspect ratio is set for")
        ->capture_default_str();
    ex->add_option("--height", e->height, "Image height the camera's aspect ratio is set for")
        ->capture_default_str();
    ex->add_option("--max-union", e->maxUnion,
                   "Unions with more operands are regrouped into a balanced nest of at most "
                   "this many per level")
        ->capture_default_str()
        ->check(CLI::Range(2u, 100000u));
    ex->add_flag("--json", e->json, "Print the export's figures as JSON");
    ex->callback([e, &status] { status = runExport(*e); });

    auto s = std::make_shared<StatsOptions>();
    auto* st = app.add_subcommand(
        "stats",
        "The expanded tree's size (primitives, nodes, bytes) beside the cyclic graph's bytes: "
        "the memory the graph saves, counted without building the tree");
    st->add_option("scene", s->scene, "The .pcsg file (- reads standard input)")->required();
    st->add_flag("--json", s->json, "Print the figures as JSON");
    st->add_option("--max-visits", s->maxVisits,
                   "Work limit of the counting pass in graph-node visits (stochastic systems "
                   "cannot be memoised)")
        ->capture_default_str();
    st->callback([s, &status] { status = runStats(*s); });
}

}  // namespace pcsg::tools
