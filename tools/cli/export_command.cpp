// pcsg export-pov SCENE -o OUT.pov [--max-nodes N] [--width W --height H] [--json]:
// unroll the cyclic graph into a finite CSG tree (povexport/expander.h) and write it as
// POV-Ray 3.7 scene text (povexport/pov_writer.h).
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
#include <optional>
#include <stdexcept>
#include <tuple>

#include "commands.h"
#include "eval.h"
#include "expander.h"
#include "frames.h"
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
    double clock = 0;  // --clock: the frame's time
    int frame = 1;     // --frame: the still's frame number
    int frames = 0;    // --frames N: one file per frame, a driver and an .ini (0: a still)
    std::string clockRange;
    bool cyclic = false;
};

// Unrolls the graph; nullopt (with the error printed) when the scene is at fault.
std::optional<ExpandedTree> expandScene(const Graph& g, const ExportOptions& o) {
    try {
        ExpandOptions eo;
        eo.maxNodes = o.maxNodes;
        return expand(g, eo);
    } catch (const RuntimeError& e) {
        std::cerr << e.format(g) << "\n";
    } catch (const BudgetError& e) {
        std::cerr << fmt::format("pcsg export-pov: error: {}: {}\n", o.scene, e.what());
    } catch (const std::bad_alloc&) {
        std::cerr << fmt::format(
            "pcsg export-pov: error: {}: out of memory while expanding; lower --max-nodes\n",
            o.scene);
    }
    return std::nullopt;
}

// Streams the POV-Ray text to the file, written beside the target and renamed at the
// end: a failed export leaves no partial file in place of the requested one. Throws
// std::runtime_error with the message to print.
PovWriteStats writePovFile(const Graph& g, const ExpandedTree& tree, const PovOptions& po,
                           const std::string& output) {
    namespace fs = std::filesystem;
    const fs::path target(output);
    const fs::path temp = target.string() + ".partial";
    PovWriteStats written;
    {
        std::vector<char> buffer(1 << 20);  // declared first: it outlives the stream
        std::ofstream out;
        out.rdbuf()->pubsetbuf(buffer.data(), static_cast<std::streamsize>(buffer.size()));
        out.open(temp, std::ios::binary | std::ios::trunc);
        if (!out)
            throw std::runtime_error(
                fmt::format("cannot write {}: {}", output, std::strerror(errno)));
        try {
            written = writePov(g, tree, out, po);
            out.close();
            if (!out) throw std::runtime_error("could not write the POV-Ray file");
        } catch (const std::exception& e) {
            std::error_code ec;
            fs::remove(temp, ec);
            throw std::runtime_error(fmt::format("{} {}", e.what(), output));
        }
    }
    std::error_code ec;
    fs::rename(temp, target, ec);
    if (ec) {
        const std::string why = ec.message();
        fs::remove(temp, ec);
        throw std::runtime_error(fmt::format("cannot write {}: {}", output, why));
    }
    return written;
}

void printExport(const ExportOptions& o, const Stats& s, const PovWriteStats& written,
                 double expandSeconds, double writeSeconds) {
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
        return;
    }
    report << fmt::format("{}: wrote {} ({} objects, {}) in {:.3f} s\n", o.scene,
                          o.output == "-" ? std::string("standard output") : o.output,
                          written.objects, humanBytes(written.bytes), *s.seconds);
    if (written.skipped)
        report << fmt::format(
            "  left out {} degenerate triangle{} (no area; POV-Ray rejects them)\n",
            written.skipped, written.skipped == 1 ? "" : "s");
}

int exportOne(const ExportOptions& o, Graph& g, const CompiledScene& compiled);

// --frames N: OUT01.pov ... (each frame at its time, as `pcsg render --frames` names its
// images), OUT.pov a driver that includes frame `frame_number`'s file, and OUT.ini that
// makes POV-Ray render frames 1..N of the driver into OUT01.png ... (`povray OUT.ini`).
int runExportFrames(const ExportOptions& o, CompiledScene& compiled) {
    namespace fs = std::filesystem;
    FramePlan plan;
    plan.frames = o.frames;
    plan.cyclic = o.cyclic;
    std::string error;
    if (!o.clockRange.empty()) {
        const auto range = parseClockRange(o.clockRange, error);
        if (!range) {
            std::cerr << "pcsg export-pov: error: " << error << "\n";
            return 2;
        }
        std::tie(plan.clockFrom, plan.clockTo) = *range;
    }
    Graph& g = *compiled.graph;
    for (int f = 1; f <= o.frames; ++f) {
        ExportOptions fo = o;
        fo.output = frameFileName(o.output, f, o.frames);
        const double clock = frameClock(plan, f);
        if (!setSceneTime(g, Time{clock, f}, std::cerr)) {
            std::cerr << fmt::format("  at frame {} of {}, clock {}\n", f, o.frames, clock);
            return 1;
        }
        if (const int status = exportOne(fo, g, compiled)) return status;
    }
    const fs::path out(o.output);
    const std::string stem = out.stem().string();
    const int width = static_cast<int>(std::to_string(o.frames).size());
    std::ofstream driver(out, std::ios::trunc);
    driver << fmt::format(
        "// {} frames of {}, exported by pcsg export-pov --frames: render them all with\n"
        "//   povray {}.ini\n"
        "// (frame f is {}<f>.pov, its number zero-padded to {} digit(s)).\n"
        "#include concat(\"{}\", str(frame_number, -{}, 0), \".pov\")\n",
        o.frames, o.scene, stem, stem, width, stem, width);
    const fs::path ini = out.parent_path() / (stem + ".ini");
    std::ofstream iniOut(ini, std::ios::trunc);
    iniOut << fmt::format(
        "; {} frames of {}, exported by pcsg export-pov --frames. Run `povray {}.ini`\n"
        "; (from this directory): POV-Ray renders frame f of the driver {}.pov, which\n"
        "; includes {}<f>.pov, into {}<f>.png, the names `pcsg render --frames` writes.\n"
        "Input_File_Name={}.pov\nOutput_File_Name={}.png\nOutput_File_Type=N\n"
        "Initial_Frame=1\nFinal_Frame={}\nWidth={}\nHeight={}\n",
        o.frames, o.scene, stem, stem, stem, stem, stem, stem, o.frames, o.width, o.height);
    driver.close();
    iniOut.close();
    if (!driver || !iniOut) {
        std::cerr << "pcsg export-pov: cannot write " << out.string() << " or " << ini.string()
                  << "\n";
        return 2;
    }
    if (!o.json)
        std::cout << fmt::format("{}: wrote {} frames, the driver {} and {} (povray {})\n", o.scene,
                                 o.frames, out.string(), ini.string(), ini.filename().string());
    return 0;
}

int runExport(const ExportOptions& o) {
    CompiledScene compiled = compileScene(o.scene, std::cerr);
    if (!compiled.graph) return 1;
    Graph& g = *compiled.graph;
    if (o.frames > 0) {
        if (o.output == "-") {
            std::cerr << "pcsg export-pov: error: --frames writes files: -o - is not allowed\n";
            return 2;
        }
        return runExportFrames(o, compiled);
    }
    if (!setSceneTime(g, Time{o.clock, o.frame}, std::cerr)) return 1;
    return exportOne(o, g, compiled);
}

// Exports the graph at the time it is set to.
int exportOne(const ExportOptions& o, Graph& g, const CompiledScene& compiled) {
    const auto start = std::chrono::steady_clock::now();
    const std::optional<ExpandedTree> tree = expandScene(g, o);
    if (!tree) return 1;
    const double expandSeconds = since(start);

    PovOptions po;
    po.width = o.width;
    po.height = o.height;
    po.maxUnionChildren = o.maxUnion;
    po.title = o.scene;
    PovWriteStats written;
    const auto writeStart = std::chrono::steady_clock::now();
    try {
        written = o.output == "-" ? writePov(g, *tree, std::cout, po)
                                  : writePovFile(g, *tree, po, o.output);
    } catch (const std::exception& e) {
        std::cerr << "pcsg export-pov: " << e.what()
                  << (o.output == "-" ? " (standard output)\n" : "\n");
        return 2;
    }
    const double writeSeconds = since(writeStart);

    Stats s;
    s.scene = o.scene;
    s.width = static_cast<uint32_t>(o.width);
    s.height = static_cast<uint32_t>(o.height);
    s.primitiveEquivalence = tree->primitives.size();
    s.expandedNodes = tree->nodes.size();
    s.graphBytes = g.graphBytes();
    s.expandedBytes = tree->bytes();
    s.parseSeconds = compiled.seconds;
    s.seconds = expandSeconds + writeSeconds;
    s.peakRssBytes = peakRssBytes();
    printExport(o, s, written, expandSeconds, writeSeconds);
    return 0;
}

}  // namespace

void addExportCommand(CLI::App& app, int& status) {
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
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    ex->add_option("--width", e->width, "Image width the camera's aspect ratio is set for")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    ex->add_option("--height", e->height, "Image height the camera's aspect ratio is set for")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    ex->add_option("--max-union", e->maxUnion,
                   "Unions with more operands are regrouped into a balanced nest of at most "
                   "this many per level")
        ->capture_default_str()
        ->check(CLI::Range(2u, 100000u));
    auto* clock = addClockOption(ex, e->clock);
    auto* frames =
        ex->add_option("--frames", e->frames,
                       "Export N frames of an animation: OUT01.pov ... (named as `pcsg render "
                       "--frames` names images), the driver OUT.pov and OUT.ini: `povray "
                       "OUT.ini` renders them all into OUT01.png ...")
            ->check(CLI::Range(1, 1000000));
    clock->excludes(frames);
    addFrameOption(ex, e->frame)->excludes(frames);
    ex->add_option("--clock-range", e->clockRange,
                   "A,B: the clocks of the first and last frame (default 0,1)")
        ->needs(frames);
    ex->add_flag("--cyclic", e->cyclic,
                 "A cyclic animation (POV-Ray's +KC): the clock steps by (B-A)/N")
        ->needs(frames);
    ex->add_flag("--json", e->json, "Print the export's figures as JSON");
    ex->callback([e, &status] { status = runExport(*e); });
}

}  // namespace pcsg::tools
