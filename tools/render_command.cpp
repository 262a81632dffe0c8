// pcsg render SCENE -o OUT [--width W] [--height H] [--aa N] [--adaptive T] [--threads N]
//                          [--json]
// Ray traces the scene's cyclic graph directly (tracer/): the graph is never expanded.
// Prints the figures of the paper's Table 1 and more (tools/stats.h).
//
// The image file is written by the pcsg-image helper (tools/image_helper.h), so that this
// process never loads OpenImageIO: `pcsg-image write` is started as soon as the scene
// compiles, loads its libraries (about half a second) while this process renders, and then
// gets the linear float pixels through a pipe. When the scene fails at run time, the
// helper is killed and reaped before it has written or said anything. The render's peak
// RSS is its own (getrusage RUSAGE_SELF: the helper is another process); the helper's is
// printed beside it.
//
// Exit status: 0 the image was written; 1 the scene is at fault (a compile error or a
// run-time error of docs/language.md, reported once with its module path; no image is
// written); 2 something could not run (bad options, an unwritable output file, no
// pcsg-image).
#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>

#include "commands.h"
#include "eval.h"
#include "expander.h"
#include "image_format.h"
#include "image_helper.h"
#include "render.h"
#include "scene_input.h"
#include "stats.h"
#include "traversal.h"

namespace pcsg::tools {

namespace {

struct RenderCommandOptions {
    std::string scene;
    std::string output;
    int width = 640, height = 480;
    int aa = 1;
    double adaptive = 0;
    int threads = 0;
    bool json = false;
    bool noBounds = false;
    bool noInstanceBoxes = false;
    size_t boxCacheMb = 64;
    size_t expansionCacheMb = 16;
    uint64_t countVisits = 20'000'000;
};

// A progress bar on standard error, redrawn at most every 1%.
class ProgressBar {
  public:
    void update(double fraction) {
        const int percent = static_cast<int>(fraction * 100);
        if (percent <= shown_.load(std::memory_order_relaxed)) return;
        std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
        if (!lock.owns_lock() || percent <= shown_) return;
        shown_ = percent;
        const int width = 40, filled = percent * width / 100;
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        std::fprintf(stderr, "\r  [%s%s] %3d%%  %.1f s", std::string(filled, '#').c_str(),
                     std::string(width - filled, '.').c_str(), percent, elapsed);
        std::fflush(stderr);
    }
    void finish() {
        if (shown_ >= 0) std::fprintf(stderr, "\r%70s\r", "");
    }

  private:
    std::mutex mutex_;
    std::atomic<int> shown_{-1};
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

int runRender(const RenderCommandOptions& o) {
    if (o.width <= 0 || o.height <= 0) {
        std::cerr << "pcsg render: --width and --height must be positive\n";
        return 2;
    }
    if (o.aa < 1 || o.aa > 64) {
        std::cerr << "pcsg render: --aa must be between 1 and 64 (samples per pixel: N x N)\n";
        return 2;
    }
    if (!(o.adaptive >= 0) || o.adaptive > 3) {
        std::cerr << "pcsg render: --adaptive must be between 0 and 3 (POV-Ray's +A threshold, "
                     "e.g. 0.3)\n";
        return 2;
    }
    if (o.adaptive > 0 && o.aa > 1) {
        std::cerr << "pcsg render: --aa and --adaptive exclude each other\n";
        return 2;
    }
    if (o.threads < 0) {
        std::cerr << "pcsg render: --threads must not be negative (0: all cores)\n";
        return 2;
    }
    if (!imageFormatOf(o.output)) {
        std::cerr << fmt::format("pcsg render: cannot write '{}': unknown image type ({})\n",
                                 o.output, kImageTypesHint);
        return 2;
    }
    // Before the render: without the writer, the render would be for nothing.
    const std::optional<std::string> imageHelper = findImageHelper();
    if (!imageHelper) {
        std::cerr << "pcsg render: cannot write '" << o.output
                  << "': " << missingImageHelperMessage() << "\n";
        return 2;
    }
    const CompiledScene compiled = compileScene(o.scene, std::cerr);
    if (!compiled.graph) return 1;
    const Graph& g = *compiled.graph;
    // The writer starts now, so that its start-up overlaps the count and the render; every
    // return below without an image abandons it (the destructor, if not explicitly).
    ImageWriter writer(*imageHelper, o.output, o.width, o.height);

    Stats s;
    s.scene = o.scene;
    s.width = static_cast<uint32_t>(o.width);
    s.height = static_cast<uint32_t>(o.height);
    s.graphBytes = g.graphBytes();
    s.parseSeconds = compiled.seconds;

    // Primitive equivalence: what the expanded tree would hold, counted without building
    // it. The count walks every path of the expansion (memoised), so it also finds the
    // scene's run-time errors on paths no ray visits.
    ExpansionCount count;
    try {
        CountOptions co;
        co.maxVisits = o.countVisits;
        count = countExpansion(g, co);
    } catch (const RuntimeError& e) {
        writer.abandon();
        std::cerr << e.format(g) << "\n";
        return 1;
    }
    if (count.complete) s.primitiveEquivalence = count.primitives;

    tracer::RenderOptions ro;
    ro.width = o.width;
    ro.height = o.height;
    ro.aa = o.aa;
    ro.adaptive = o.adaptive;
    ro.threads = o.threads;
    ro.useBounds = !o.noBounds;
    ro.instanceBoxes = !o.noInstanceBoxes;
    ro.instanceBoxBytes = o.boxCacheMb << 20;
    ro.expansionBytesPerThread = o.expansionCacheMb << 20;
    auto bar = std::make_shared<ProgressBar>();
    const bool showProgress = isatty(STDERR_FILENO) != 0;
    if (showProgress) ro.progress = [bar](double f) { bar->update(f); };

    tracer::RenderResult result;
    try {
        result = tracer::render(g, ro);
    } catch (const RuntimeError& e) {
        if (showProgress) bar->finish();
        writer.abandon();
        std::cerr << e.format(g) << "\n";
        return 1;
    } catch (const std::exception& e) {
        if (showProgress) bar->finish();
        writer.abandon();
        std::cerr << "pcsg render: error: " << o.scene << ": " << e.what() << "\n";
        return 2;
    }
    if (showProgress) bar->finish();

    const ImageWriteResult written = writer.finish(result.rgb);
    if (!written.ok) {
        std::cerr << "pcsg render: " << written.error << "\n";
        return 2;
    }

    s.rays = result.rays;
    s.seconds = result.seconds;
    s.raysPerSecond = result.seconds > 0 ? result.rays / result.seconds : 0.0;
    // RUSAGE_SELF: this process's own peak, without the writer's (printed beside it).
    s.peakRssBytes = peakRssBytes();
    if (o.json) {
        nlohmann::json j = s.toJson();
        j["output"] = o.output;
        j["node_visits"] = result.nodeVisits;
        j["bounds_seconds"] = result.boundsSeconds;
        j["unbounded_nodes"] = result.infiniteBoxes;
        j["instance_boxes"] = {{"entries", result.instanceBoxes.entries},
                               {"bytes", result.instanceBoxes.bytes},
                               {"computed", result.instanceBoxes.computed},
                               {"full", result.instanceBoxes.full}};
        j["expanded_instances"] = result.expansions;
        j["aa"] = o.aa;
        j["adaptive"] = o.adaptive;
        j["graph_nodes"] = g.nodes.size();
        j["image_writer_peak_rss_bytes"] = written.peakRssBytes;
        // After the render: the part of the wall time spent on the image.
        j["image_write_seconds"] = written.seconds;
        j["image_writer_seconds"] = written.helperSeconds;  // its whole life, start-up included
        if (!count.complete) j["primitive_equivalence_note"] = "too large to count (rand/choose)";
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << fmt::format("{}: wrote {} ({}x{}) in {:.3f} s\n", o.scene, o.output, o.width,
                                 o.height, result.seconds);
        s.print(std::cout);
        if (!count.complete)
            std::cout << fmt::format("{:<24}{}\n", "primitive equivalence",
                                     "too large to count (the system uses rand() or choose())");
        std::cout << fmt::format("{:<24}{}\n", "graph nodes", g.nodes.size());
        std::cout << fmt::format("{:<24}{}\n", "node visits", result.nodeVisits);
        if (result.instanceBoxes.entries > 0)
            std::cout << fmt::format(
                "{:<24}{} instances, {}{}\n", "instance-box cache", result.instanceBoxes.entries,
                humanBytes(result.instanceBoxes.bytes), result.instanceBoxes.full ? " (full)" : "");
        std::cout << fmt::format("{:<24}{} ({}, {:.3f} s after the render)\n",
                                 "image writer peak RSS", humanBytes(written.peakRssBytes),
                                 kImageHelperName, written.seconds);
    }
    return 0;
}

}  // namespace

void addRenderCommand(CLI::App& app, int& status) {
    auto o = std::make_shared<RenderCommandOptions>();
    auto* cmd = app.add_subcommand(
        "render",
        "Ray trace a scene's cyclic CSG graph directly, without expanding it, and write the "
        "image (.png 8-bit sRGB, .exr linear float, .tif 16-bit sRGB). Camera, lights and "
        "materials follow POV-Ray 3.7, so the image can be compared with POV-Ray's rendering "
        "of `pcsg export-pov`. Prints rays, rays per second, primitive equivalence (the "
        "primitives the expanded tree would hold), graph bytes, peak memory and time. The "
        "image file is written by the pcsg-image helper (found beside pcsg, or in PATH), which "
        "starts while the scene renders and then gets the pixels through a pipe; its peak "
        "memory is printed separately.\n"
        "Exit status: 0 written, 1 the scene has an error (nothing written), 2 could not run.");
    cmd->add_option("scene", o->scene, "The .pcsg file (- reads standard input)")->required();
    cmd->add_option("-o,--output", o->output, "The image to write: .png, .exr, .tif or .tiff")
        ->required();
    cmd->add_option("--width", o->width, "Image width in pixels")->capture_default_str();
    cmd->add_option("--height", o->height, "Image height in pixels")->capture_default_str();
    cmd->add_option("--aa", o->aa, "Anti-aliasing: N x N stratified samples per pixel (1: none)")
        ->capture_default_str();
    cmd->add_option("--adaptive", o->adaptive,
                    "Adaptive anti-aliasing like POV-Ray's +A T (e.g. 0.3): pixels that differ "
                    "from a neighbour by T or more get 9 more samples (0: off)")
        ->capture_default_str();
    cmd->add_option("--threads", o->threads,
                    "Worker threads (0: all cores); the image is the "
                    "same whatever the count")
        ->capture_default_str();
    cmd->add_flag("--json", o->json, "Print the figures as JSON");
    cmd->add_flag("--no-bounds", o->noBounds,
                  "Do not cull with hyper-bounding boxes (slow; for checking that culling never "
                  "changes the image)");
    cmd->add_flag("--no-instance-boxes", o->noInstanceBoxes,
                  "Cull with the static hyper-bounding boxes alone, without the exact boxes of "
                  "sub-graph instances (for comparison; the image is the same)");
    cmd->add_option("--box-cache-mb", o->boxCacheMb,
                    "Memory limit of the instance-box cache in MB (the exact boxes of sub-graph "
                    "instances, filled lazily while rendering)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1 << 20));
    cmd->add_option("--expansion-cache-mb", o->expansionCacheMb,
                    "Memory limit per thread, in MB, of the cache of expanded sub-graph "
                    "instances (small instances unrolled once and traced as flat arrays; 0: "
                    "none; the image is the same)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1 << 20));
    cmd->add_option("--count-visits", o->countVisits,
                    "Work limit of the primitive-equivalence count in graph-node visits")
        ->capture_default_str();
    cmd->callback([o, &status] { status = runRender(*o); });
}

}  // namespace pcsg::tools
