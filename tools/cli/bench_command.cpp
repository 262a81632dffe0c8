// pcsg bench: render a set of scenes natively and with POV-Ray on the exported text, in
// one run on one machine, at the same size and sampling, and compare time and memory.
// Ratios measured side by side are what the targets of docs/benchmarks.md are about;
// absolute times on a shared machine are not.
//
// When pcsg-embree (tools/bench/embree_bench.cpp, built when Embree 3 is found) is beside
// pcsg, each triangle-only scene is also traced by Embree on its expanded mesh, the
// yardstick of the native renderer: its build and trace times, rays per second and peak
// RSS fill four more columns, and three more targets compare the two. The trace rates are
// compared on the same rays, each after its own build: Embree's against pcsg-trace's
// (tools/bench/trace_bench.cpp), which renders the same pixel centres once to build and
// then times further renders, in a fifth column.
#include <fmt/format.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "bench_animation.h"
#include "bench_median.h"
#include "bench_plot.h"
#include "commands.h"
#include "embree_run.h"
#include "renders.h"
#include "stats.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

struct BenchOptions {
    std::vector<std::string> scenes;
    int width = 640, height = 480;
    double adaptive = 0.3;  // POV-Ray's +A0.3 and the tracer's --adaptive 0.3
    int threads = 0;
    bool json = false;
    bool nativeOnly = false;
    int repeat = 1;        // each row measured this many times, its figures the medians
    std::string markdown;  // append the table to this file
    uint64_t maxNodes = 10'000'000;
    // The animation row: frames of animationScene (0: none). By default 48 with the
    // default scene set, none when scenes are named.
    std::optional<int> animationFrames;
    std::string plot;  // --plot FILE: the scaling sweep instead of the table
    std::vector<int> plotOrders = {4, 16};
    std::string animationScene = std::string(PCSG_SOURCE_DIR) + "/scenes/growing_tree.pcsg";
};

// The scenes of the targets: the Sierpinski tetrahedron at growing order and the
// paper's plant and terrain.
std::vector<std::string> defaultScenes() {
    const std::string root = PCSG_SOURCE_DIR;
    return {root + "/scenes/sierpinski.pcsg",
            root + "/tools/bench/sierpinski_8.pcsg",
            root + "/tools/bench/sierpinski_9.pcsg",
            root + "/tools/bench/sierpinski_10.pcsg",
            root + "/tools/bench/sierpinski_12.pcsg",
            root + "/scenes/sympodial_tree.pcsg",
            root + "/scenes/terrain.pcsg",
            root + "/scenes/terrain_sea.pcsg"};
}

std::string machine() {
    std::string cpu = "unknown CPU";
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0) {
            cpu = line.substr(line.find(':') + 2);
            break;
        }
    utsname u{};
    uname(&u);
    return fmt::format("{}, {} cores, {} {}", cpu, std::thread::hardware_concurrency(), u.sysname,
                       u.release);
}

std::string today() {
    const std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%d", std::gmtime(&t));
    return buf;
}

// The yardstick programs beside pcsg (none: not built).
struct Yardsticks {
    std::optional<std::string> embree = findEmbree(), nativeTrace = findNativeTrace();
};

BenchRow benchScene(const std::string& scene, const BenchOptions& o, const fs::path& work,
                    const Yardsticks& y) {
    BenchRow row;
    row.scene = fs::path(scene).stem().string();
    std::vector<std::string> threads;
    if (o.threads > 0) threads = {"--threads", std::to_string(o.threads)};
    std::vector<std::string> nativeArgs = threads;
    if (o.adaptive > 0)
        nativeArgs.insert(nativeArgs.end(), {"--adaptive", fmt::format("{}", o.adaptive)});

    const RenderRun native = renderNative(scene, (work / (row.scene + "_native.png")).string(),
                                          o.width, o.height, nativeArgs);
    row.nativeOk = native.ok;
    if (!native.ok) {
        row.note = native.error;
        return row;
    }
    row.nativeSeconds = jsonField<double>(native.json, "seconds").value_or(native.child.seconds);
    // The whole render command's peak, as wait4 reports it.
    row.nativeRss = native.child.peakRssBytes;
    row.nativeCommandSeconds = native.child.seconds;
    row.raysPerSecond = jsonField<double>(native.json, "rays_per_second");
    row.primitives = jsonField<uint64_t>(native.json, "primitive_equivalence");
    if (o.nativeOnly) return row;
    if (y.embree)
        row.embree = runEmbree(*y.embree, scene, o.width, o.height, o.threads, o.maxNodes);
    if (row.embree && y.nativeTrace)
        row.nativeTrace = runNativeTrace(*y.nativeTrace, scene, o.width, o.height, o.threads);

    const fs::path pov = work / (row.scene + ".pov");
    const RenderRun exported = exportPov(scene, pov.string(), o.width, o.height,
                                         {"--max-nodes", std::to_string(o.maxNodes)});
    if (!exported.ok) {
        row.note = exported.error.find("node budget") != std::string::npos
                       ? fmt::format("not exported: more than --max-nodes {} nodes", o.maxNodes)
                       : "not exported: " + exported.error.substr(exported.error.find('\n') + 1);
        return row;
    }
    std::vector<std::string> povArgs = {o.adaptive > 0 ? fmt::format("+A{}", o.adaptive) : "-A"};
    if (o.threads > 0) povArgs.push_back("+WT" + std::to_string(o.threads));
    const RenderRun povray = renderPovray(
        pov.string(), (work / (row.scene + "_povray.png")).string(), o.width, o.height, povArgs);
    std::error_code ec;
    fs::remove(pov, ec);
    row.povOk = povray.ok;
    if (!povray.ok) {
        row.note = povray.error;
        return row;
    }
    // POV-Ray's time includes parsing the exported text: that is what the expanded tree costs.
    row.povSeconds = povray.child.seconds;
    row.povRss = povray.child.peakRssBytes;
    row.povParseSeconds = povray.parseSeconds;
    return row;
}

// A performance target of docs/benchmarks.md and whether this run met it.
struct Target {
    std::string what;
    bool met = false;
};

// The whole `pcsg render` command's peak RSS at order 8, 640x480, +A0.3.
constexpr uint64_t kOrder8RssLimit = 22'000'000;

// The Sierpinski order in a bench scene's name (sierpinski_9: 9), or 0 for another scene.
int sierpinskiOrder(const std::string& scene) {
    const std::string prefix = "sierpinski_";
    if (scene.rfind(prefix, 0) != 0) return 0;
    try {
        return std::stoi(scene.substr(prefix.size()));
    } catch (const std::exception&) {
        return 0;
    }
}

// The trace-rate target of a row that Embree traced: on the same rays as Embree's, each
// after its own build (pcsg-trace), or where pcsg-trace did not run, on pcsg render's rays.
Target traceRateTarget(const BenchRow& r) {
    const EmbreeRun& e = *r.embree;
    const double rate = r.nativeTrace ? r.nativeTrace->raysPerSecond : r.raysPerSecond.value_or(0);
    std::string how = "pcsg render's rays";
    if (r.nativeTrace)
        how = fmt::format(
            "the same rays, each after its build; {} instances expanded again in "
            "each timed render; pcsg render's rate {:.0f}",
            r.nativeTrace->traceExpansions, r.raysPerSecond.value_or(0));
    return {
        fmt::format("{} native trace rate within 3x of Embree's ({:.0f} against {:.0f} rays/s: "
                    "1/{:.2f}; {})",
                    r.scene, rate, e.raysPerSecond, e.raysPerSecond / std::max(rate, 1e-9), how),
        rate * 3 >= e.raysPerSecond};
}

// The yardstick targets against Embree on the expanded mesh, judged on the rows that
// Embree traced: the native trace rate within 3x of Embree's and the native peak RSS at
// most 1/20 of Embree's (Sierpinski order 8 and the terrain), and the whole native command
// faster than Embree's whole command, its build included, from order 9 on.
void addEmbreeTargets(const std::vector<BenchRow>& rows, std::vector<Target>& t) {
    std::string ahead;
    bool allAhead = true;
    for (const BenchRow& r : rows) {
        if (!r.nativeOk || !r.embree) continue;
        const EmbreeRun& e = *r.embree;
        if (r.scene == "sierpinski_8" || r.scene == "terrain") {
            t.push_back(traceRateTarget(r));
            const double rss = double(e.peakRss) / double(std::max<uint64_t>(r.nativeRss, 1));
            t.push_back({fmt::format("{} native peak RSS at most 1/20 of Embree's ({} against {}: "
                                     "1/{:.1f})",
                                     r.scene, humanBytes(r.nativeRss), humanBytes(e.peakRss), rss),
                         rss >= 20});
        }
        if (const int order = sierpinskiOrder(r.scene); order >= 9) {
            ahead += fmt::format("{}order {}: {:.2f} s against {:.2f} s", ahead.empty() ? "" : "; ",
                                 order, r.nativeCommandSeconds, e.seconds);
            allAhead = allAhead && r.nativeCommandSeconds < e.seconds;
        }
    }
    if (!ahead.empty())
        t.push_back(
            {"whole time (Embree's build included) ahead of Embree from order 9 on (" + ahead + ")",
             allAhead});
}

// The performance targets (docs/benchmarks.md), judged from the rows that are there.
std::vector<Target> targetsOf(const std::vector<BenchRow>& rows) {
    auto find = [&](const char* name) -> const BenchRow* {
        for (const auto& r : rows)
            if (r.scene == name && r.nativeOk) return &r;
        return nullptr;
    };
    auto rssRatio = [](const BenchRow& r) {
        return double(r.povRss) / double(std::max<uint64_t>(r.nativeRss, 1));
    };
    std::vector<Target> t;
    if (const BenchRow* r = find("sierpinski_8")) {
        t.push_back({fmt::format("order 8 whole render command at most {} peak RSS ({})",
                                 humanBytes(kOrder8RssLimit), humanBytes(r->nativeRss)),
                     r->nativeRss <= kOrder8RssLimit});
        if (r->povOk) {
            const double time = r->povSeconds / std::max(r->nativeSeconds, 1e-9);
            t.push_back({fmt::format("order 8 at least 5x faster than POV-Ray ({:.2f}x{})", time,
                                     runsText(timeRatios(r->runs))),
                         time >= 5});
            t.push_back({fmt::format("order 8 peak RSS at most 1/20 of POV-Ray's (1/{:.1f}{})",
                                     rssRatio(*r), runsText(rssRatios(r->runs), 1)),
                         rssRatio(*r) >= 20});
        }
    }
    if (const BenchRow* r = find("sierpinski_9"); r && r->povOk)
        t.push_back({fmt::format("order 9 peak RSS at most 1/20 of POV-Ray's (1/{:.1f}{})",
                                 rssRatio(*r), runsText(rssRatios(r->runs), 1)),
                     rssRatio(*r) >= 20});
    const BenchRow *o10 = find("sierpinski_10"), *o12 = find("sierpinski_12");
    if (o12) {
        if (o10 && o10->povOk)
            t.push_back({fmt::format("order 12 natively ({:.2f} s) in less time than POV-Ray "
                                     "needs for order 10 ({:.2f} s)",
                                     o12->nativeSeconds, o10->povSeconds),
                         o12->nativeSeconds < o10->povSeconds});
        t.push_back({fmt::format("order 12 peak RSS under 64 MB ({})", humanBytes(o12->nativeRss)),
                     o12->nativeRss < (64ull << 20)});
    }
    // Issue 13: the tree at least 5x, the terrain at least 10x and in at most 64 MB.
    for (const auto& [name, factor] : {std::pair{"sympodial_tree", 5.0}, {"terrain", 10.0}})
        if (const BenchRow* r = find(name); r && r->povOk) {
            const double time = r->povSeconds / std::max(r->nativeSeconds, 1e-9);
            t.push_back({fmt::format("{} at least {:g}x faster than POV-Ray ({:.2f}x{})", name,
                                     factor, time, runsText(timeRatios(r->runs))),
                         time >= factor});
        }
    if (const BenchRow* r = find("terrain"))
        t.push_back({fmt::format("terrain whole render command at most 64.0 MB peak RSS ({})",
                                 humanBytes(r->nativeRss)),
                     r->nativeRss <= (64ull << 20)});
    // The textured scene of issue 11: picture 9's island in a bump-mapped, Fresnel sea.
    if (const BenchRow* r = find("terrain_sea"); r && r->povOk) {
        t.push_back({fmt::format("terrain_sea (textured) faster than POV-Ray ({:.2f}x{})",
                                 r->povSeconds / std::max(r->nativeSeconds, 1e-9),
                                 runsText(timeRatios(r->runs))),
                     r->nativeSeconds < r->povSeconds});
        t.push_back(
            {fmt::format("terrain_sea (textured) in less peak RSS than POV-Ray (1/{:.1f}{})",
                         rssRatio(*r), runsText(rssRatios(r->runs), 1)),
             r->nativeRss < r->povRss});
    }
    addEmbreeTargets(rows, t);
    return t;
}

std::string targetsText(const std::vector<Target>& targets) {
    std::string t;
    for (const Target& target : targets)
        t += fmt::format("- {} {}\n", target.met ? "met:" : "NOT MET:", target.what);
    return t.empty() ? t : "\nTargets:\n" + t;
}

// Each repetition's times and peaks (--repeat), POV-Ray's where it rendered.
nlohmann::json runsJson(const std::vector<SideBySideRun>& runs) {
    nlohmann::json j = nlohmann::json::array();
    for (const SideBySideRun& r : runs) {
        nlohmann::json e = {{"native_seconds", r.nativeSeconds},
                            {"native_peak_rss_bytes", r.nativeRss}};
        if (r.povOk) e["povray_seconds"] = r.povSeconds, e["povray_peak_rss_bytes"] = r.povRss;
        j.push_back(e);
    }
    return j;
}

// The animation targets: at least 3x less total time than POV-Ray on the exported frames,
// and at most 1/10 of its peak RSS.
std::vector<Target> animationTargets(const std::optional<AnimationRow>& a) {
    if (!a || !a->nativeOk || !a->povOk) return {};
    const double time = a->povSeconds() / std::max(a->nativeSeconds, 1e-9);
    const double rss = double(a->povRss) / double(std::max<uint64_t>(a->nativeRss, 1));
    return {{fmt::format("{} frames of {} in at least 3x less time than POV-Ray ({:.2f}x{})",
                         a->frames, a->scene, time, runsText(timeRatios(a->runs))),
             time >= 3},
            {fmt::format("{} frames of {} at most 1/10 of POV-Ray's peak RSS (1/{:.1f}{})",
                         a->frames, a->scene, rss, runsText(rssRatios(a->runs), 1)),
             rss >= 10}};
}

// The animation's table: both whole commands.
std::string animationTable(const AnimationRow& a) {
    std::string t =
        "\n| animation | frames | native (one command) | export + POV-Ray (one command) | "
        "POV-Ray / native | native peak RSS | POV-Ray peak RSS | RSS ratio |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|\n";
    const std::string native = a.nativeOk ? fmt::format("{:.2f} s", a.nativeSeconds) : "failed";
    std::string pov = "-", ratio = "-", povRss = "-", rssRatio = "-";
    if (a.povOk) {
        pov = fmt::format("{:.2f} s + {:.2f} s", a.exportSeconds, a.povraySeconds);
        ratio = fmt::format("{:.2f}", a.povSeconds() / std::max(a.nativeSeconds, 1e-9));
        povRss = humanBytes(a.povRss);
        rssRatio =
            fmt::format("{:.1f}", double(a.povRss) / double(std::max<uint64_t>(a.nativeRss, 1)));
    } else if (!a.note.empty()) {
        pov = a.note.substr(0, a.note.find('\n'));
    }
    t += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", a.scene, a.frames, native, pov,
                     ratio, a.nativeOk ? humanBytes(a.nativeRss) : "-", povRss, rssRatio);
    return t + targetsText(animationTargets(a));
}

nlohmann::json animationJson(const AnimationRow& a) {
    nlohmann::json j = {{"scene", a.scene},
                        {"frames", a.frames},
                        {"native_ok", a.nativeOk},
                        {"povray_ok", a.povOk}};
    if (a.nativeOk) j["native_seconds"] = a.nativeSeconds, j["native_peak_rss_bytes"] = a.nativeRss;
    if (a.povOk) {
        j["export_seconds"] = a.exportSeconds;
        j["povray_seconds"] = a.povraySeconds;
        j["povray_peak_rss_bytes"] = a.povRss;
    }
    if (!a.note.empty()) j["note"] = a.note;
    if (!a.runs.empty()) j["runs"] = runsJson(a.runs);
    nlohmann::json targets = nlohmann::json::array();
    for (const Target& t : animationTargets(a))
        targets.push_back({{"target", t.what}, {"met", t.met}});
    j["targets"] = targets;
    return j;
}

// One row of the table, without the Embree columns.
std::string tableRow(const BenchRow& r) {
    const std::string prims = r.primitives ? fmt::format("{}", *r.primitives) : "-";
    const std::string native = r.nativeOk ? fmt::format("{:.2f} s", r.nativeSeconds) : "failed";
    std::string pov = "-", timeRatio = "-", povRss = "-", rssRatio = "-";
    if (r.povOk) {
        pov = fmt::format("{:.2f} s", r.povSeconds);
        if (r.povParseSeconds) pov += fmt::format(" ({:.2f} s)", *r.povParseSeconds);
        timeRatio = fmt::format("{:.2f}", r.povSeconds / std::max(r.nativeSeconds, 1e-9));
        povRss = humanBytes(r.povRss);
        rssRatio =
            fmt::format("{:.1f}", double(r.povRss) / double(std::max<uint64_t>(r.nativeRss, 1)));
    } else if (!r.note.empty()) {
        pov = r.note.substr(0, r.note.find('\n'));
    }
    return fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} |", r.scene, prims, native,
                       pov, timeRatio,
                       r.raysPerSecond ? fmt::format("{:.0f}", *r.raysPerSecond) : "-",
                       r.nativeOk ? humanBytes(r.nativeRss) : "-", povRss, rssRatio);
}

// The Embree columns of a row ("-" where Embree did not trace the scene).
std::string embreeCells(const BenchRow& r) {
    if (!r.embree) return " - | - | - | - | - |";
    const EmbreeRun& e = *r.embree;
    const std::string native =
        r.nativeTrace ? fmt::format("{:.0f}", r.nativeTrace->raysPerSecond) : std::string("-");
    return fmt::format(" {:.2f} s | {:.2f} s | {:.0f} | {} | {} |", e.buildSeconds, e.traceSeconds,
                       e.raysPerSecond, humanBytes(e.peakRss), native);
}

std::string tableOf(const std::vector<BenchRow>& rows, const BenchOptions& o) {
    const bool embree = std::any_of(rows.begin(), rows.end(),
                                    [](const BenchRow& r) { return r.embree.has_value(); });
    std::string t =
        fmt::format("Benchmark of {}, {}: {}x{}, {} (both renderers), measured side by side{}.\n\n",
                    today(), machine(), o.width, o.height,
                    o.adaptive > 0 ? fmt::format("adaptive anti-aliasing {}", o.adaptive)
                                   : std::string("no anti-aliasing"),
                    o.repeat > 1 ? fmt::format("; each figure is the median of {} runs, one "
                                               "after the other, and each verdict gives the "
                                               "range of the runs' ratios",
                                               o.repeat)
                                 : "");
    t += "| scene | primitives | native time | POV-Ray time (parse) | POV-Ray / native | rays/s | "
         "native peak RSS | POV-Ray peak RSS | RSS ratio |";
    if (embree)
        t += " Embree build | Embree trace | Embree rays/s | Embree peak RSS | native trace "
             "rays/s |";
    t += "\n|---|---:|---:|---:|---:|---:|---:|---:|---:|";
    if (embree) t += "---:|---:|---:|---:|---:|";
    t += "\n";
    for (const auto& r : rows) t += tableRow(r) + (embree ? embreeCells(r) : "") + "\n";
    t += targetsText(targetsOf(rows));
    t += "\nPeak RSS is each whole render command's, as /usr/bin/time -v counts it; both "
         "write their PNG in-process.\n";
    if (embree)
        t += "Embree (pcsg-embree) traces the expanded mesh of each triangle-only scene: one "
             "camera ray per pixel centre and one shadow ray per hit and light, in packets of "
             "8; its peak RSS is its whole command's. The native trace rate (pcsg-trace) is "
             "pcsg's on the same rays, each after its own build: the pixel centres rendered "
             "once to build what pcsg builds as rays ask for it, then again, timed. Each "
             "traces its rays 5 times and takes the median pass.\n";
    return t;
}

nlohmann::json jsonOf(const std::vector<BenchRow>& rows, const BenchOptions& o) {
    nlohmann::json scenes = nlohmann::json::array();
    for (const auto& r : rows) {
        nlohmann::json e = {{"scene", r.scene}, {"native_ok", r.nativeOk}, {"povray_ok", r.povOk}};
        if (r.nativeOk)
            e["native_seconds"] = r.nativeSeconds, e["native_peak_rss_bytes"] = r.nativeRss;
        if (r.povOk) e["povray_seconds"] = r.povSeconds, e["povray_peak_rss_bytes"] = r.povRss;
        if (r.povParseSeconds) e["povray_parse_seconds"] = *r.povParseSeconds;
        if (r.raysPerSecond) e["rays_per_second"] = *r.raysPerSecond;
        if (r.primitives) e["primitive_equivalence"] = *r.primitives;
        if (!r.note.empty()) e["note"] = r.note;
        if (r.nativeOk) e["native_command_seconds"] = r.nativeCommandSeconds;
        if (!r.runs.empty()) e["runs"] = runsJson(r.runs);
        if (r.embree) {
            e["embree_triangles"] = r.embree->triangles;
            e["embree_build_seconds"] = r.embree->buildSeconds;
            e["embree_trace_seconds"] = r.embree->traceSeconds;
            e["embree_rays_per_second"] = r.embree->raysPerSecond;
            e["embree_seconds"] = r.embree->seconds;
            e["embree_peak_rss_bytes"] = r.embree->peakRss;
        }
        if (r.nativeTrace) {
            e["native_trace_build_seconds"] = r.nativeTrace->buildSeconds;
            e["native_trace_seconds"] = r.nativeTrace->traceSeconds;
            e["native_trace_rays"] = r.nativeTrace->rays;
            e["native_trace_rays_per_second"] = r.nativeTrace->raysPerSecond;
            e["native_trace_expansions"] = r.nativeTrace->traceExpansions;
        }
        scenes.push_back(e);
    }
    nlohmann::json targets = nlohmann::json::array();
    for (const Target& t : targetsOf(rows)) targets.push_back({{"target", t.what}, {"met", t.met}});
    return {{"date", today()},    {"machine", machine()},   {"width", o.width},
            {"height", o.height}, {"adaptive", o.adaptive}, {"repeat", o.repeat},
            {"scenes", scenes},   {"targets", targets}};
}

// A row measured o.repeat times (stopping at a failed native run), with a progress line
// before each ("bench: WHAT (run 2 of 3) ..."): the one measurement, or the row combine()
// makes of all of them (medianRow, medianAnimation).
template <typename Measure, typename Combine>
auto measureRepeated(const BenchOptions& o, const std::string& what, Measure&& measure,
                     Combine&& combine) {
    std::vector<decltype(measure())> repetitions;
    for (int k = 0; k < o.repeat; ++k) {
        if (!o.json)
            std::cerr << "bench: " << what
                      << (o.repeat > 1 ? fmt::format(" (run {} of {})", k + 1, o.repeat) : "")
                      << " ...\n";
        repetitions.push_back(measure());
        if (!repetitions.back().nativeOk) break;
    }
    return o.repeat > 1 ? combine(repetitions) : repetitions.front();
}

// The animation row, when the options ask for one.
std::optional<AnimationRow> animationRow(const BenchOptions& o, const fs::path& work) {
    const int frames = o.animationFrames.value_or(o.scenes.empty() ? 48 : 0);
    if (frames <= 0) return std::nullopt;
    AnimationBenchOptions a;
    a.scene = o.animationScene;
    a.frames = frames;
    a.width = o.width;
    a.height = o.height;
    a.adaptive = o.adaptive;
    a.threads = o.threads;
    a.nativeOnly = o.nativeOnly;
    return measureRepeated(
        o, fmt::format("{} frames of {}", frames, o.animationScene),
        [&] { return benchAnimation(a, work); }, medianAnimation);
}

int printBench(const std::vector<BenchRow>& rows, const std::optional<AnimationRow>& animation,
               const BenchOptions& o) {
    std::string table = tableOf(rows, o);
    if (animation) table += animationTable(*animation);
    if (o.json) {
        nlohmann::json j = jsonOf(rows, o);
        if (animation) j["animation"] = animationJson(*animation);
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << table;
    }
    if (!o.markdown.empty()) {
        std::ofstream out(o.markdown, std::ios::app);
        out << "\n" << table;
        if (!out) {
            std::cerr << "pcsg bench: cannot write " << o.markdown << "\n";
            return 2;
        }
    }
    return 0;
}

// --plot FILE: the Sierpinski sweep, its table (or JSON) and the SVG.
int runPlot(const BenchOptions& o, const fs::path& work) {
    if (o.plotOrders[0] > o.plotOrders[1]) {
        std::cerr << "pcsg bench: --plot-orders A,B needs A <= B\n";
        return 2;
    }
    ScalingOptions so;
    so.fromOrder = o.plotOrders[0];
    so.toOrder = o.plotOrders[1];
    so.width = o.width;
    so.height = o.height;
    so.adaptive = o.adaptive;
    so.threads = o.threads;
    so.maxNodes = std::max<uint64_t>(o.maxNodes, 20'000'000);
    const std::vector<ScalingPoint> points = measureScaling(so, work, std::cerr);
    const std::string caption =
        fmt::format("pcsg bench --plot, {}, {}: {}x{}, +A{}, each renderer's whole command",
                    today(), machine(), o.width, o.height, o.adaptive);
    std::ofstream out(o.plot, std::ios::trunc);
    out << scalingSvg(points, caption);
    if (!out) {
        std::cerr << "pcsg bench: cannot write " << o.plot << "\n";
        return 2;
    }
    nlohmann::json j = nlohmann::json::array();
    std::string t = "| order | pcsg | POV-Ray | Embree |\n|---:|---:|---:|---:|\n";
    for (const ScalingPoint& p : points) {
        auto cell = [&](int r) {
            return p.seconds[r] ? fmt::format("{:.2f} s, {}", *p.seconds[r], humanBytes(*p.rss[r]))
                                : std::string("-");
        };
        t += fmt::format("| {} | {} | {} | {} |\n", p.order, cell(0), cell(1), cell(2));
        nlohmann::json e = {{"order", p.order}};
        const char* keys[3] = {"native", "povray", "embree"};
        for (int r = 0; r < 3; ++r)
            if (p.seconds[r])
                e[keys[r]] = {{"seconds", *p.seconds[r]}, {"peak_rss_bytes", *p.rss[r]}};
        j.push_back(e);
    }
    std::cout << (o.json ? j.dump(2) + "\n" : t + "wrote " + o.plot + "\n");
    return 0;
}

int runBench(BenchOptions o) {
    if (!o.nativeOnly && !inPath("povray")) {
        std::cerr << "pcsg bench: " << kPovrayInstallHint << " (or use --native-only)\n";
        return 2;
    }
    char tmpl[] = "/tmp/pcsg-bench-XXXXXX";
    if (!mkdtemp(tmpl)) {
        std::cerr << "pcsg bench: cannot create a temporary directory\n";
        return 2;
    }
    const fs::path work = tmpl;
    if (!o.plot.empty()) {
        const int status = runPlot(o, work);
        std::error_code ec;
        fs::remove_all(work, ec);
        return status;
    }
    const Yardsticks yardsticks;
    std::vector<BenchRow> rows;
    int status = 0;
    for (const auto& scene : o.scenes.empty() ? defaultScenes() : o.scenes) {
        rows.push_back(measureRepeated(
            o, scene, [&] { return benchScene(scene, o, work, yardsticks); }, medianRow));
        if (!rows.back().nativeOk) status = 1;
    }
    const std::optional<AnimationRow> animation = animationRow(o, work);
    if (animation && !animation->nativeOk) status = 1;
    std::error_code ec;
    fs::remove_all(work, ec);
    if (const int printed = printBench(rows, animation, o)) return printed;
    return status;
}

}  // namespace

void addBenchCommand(CLI::App& app, int& status) {
    auto o = std::make_shared<BenchOptions>();
    auto* cmd = app.add_subcommand(
        "bench",
        "Render scenes natively and with POV-Ray on the exported text, side by side in one run,\n"
        "and print both times, their ratio, rays per second, both peak RSS values and the\n"
        "primitive equivalence (peak RSS of each whole render command), then which targets are\n"
        "met. Without scenes: the Sierpinski tetrahedron at orders 6, 8, 9, 10 and 12, the\n"
        "sympodial tree, the terrain and the textured terrain_sea, then 48 frames of the growing "
        "tree (one `pcsg render\n"
        "--frames` command against one `povray` command on the exported frames' .ini). When\n"
        "pcsg-embree is beside pcsg (built when Embree 3 is found), triangle-only scenes are\n"
        "also traced by Embree on the expanded mesh, the yardstick, and by pcsg-trace (the same\n"
        "rays through pcsg's tracer, after its own build) for the trace rates. Microbenchmarks\n"
        "of the hot paths are the separate pcsg_microbench program (Google Benchmark).");
    cmd->add_option("scenes", o->scenes, "Scene files (.pcsg)");
    cmd->add_option("--width", o->width, "Image width")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--height", o->height, "Image height")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--adaptive", o->adaptive,
                    "Adaptive anti-aliasing threshold for both (POV-Ray's +A); 0 for none")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 3.0));
    cmd->add_option("--threads", o->threads, "Threads for both renderers (default: all cores)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--max-nodes", o->maxNodes, "Expansion budget for the exported tree")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_flag("--native-only", o->nativeOnly, "Render natively only (no POV-Ray, no Embree)");
    auto* repeat =
        cmd->add_option("--repeat", o->repeat,
                        "Measure each row N times, one side-by-side run after the other, and "
                        "report the median of each figure, with the range of the runs' ratios "
                        "beside each verdict (a shared machine's timings vary by 20% from run to "
                        "run)")
            ->capture_default_str()
            ->check(CLI::Range(1, 100));
    cmd->add_option("--markdown", o->markdown,
                    "Append the table, with date and machine, to this file");
    cmd->add_option("--animation-frames", o->animationFrames,
                    "Frames of the animation row (default: 48 with the default scenes, none "
                    "when scenes are named; 0: none)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--animation-scene", o->animationScene, "The animated scene of that row")
        ->capture_default_str()
        ->check(CLI::ExistingFile);
    cmd->add_option("--plot", o->plot,
                    "Instead of the table: render the Sierpinski tetrahedron at each order of "
                    "--plot-orders with pcsg, POV-Ray (on the export) and Embree (on the mesh, "
                    "when pcsg-embree is built), each until its memory would pass half the "
                    "machine's, and draw time and peak RSS against the order into this SVG");
    cmd->add_option("--plot-orders", o->plotOrders, "A,B: the orders of --plot")
        ->delimiter(',')
        ->expected(2)
        ->capture_default_str()
        ->check(CLI::Range(1, 20));
    repeat->excludes("--plot");
    cmd->add_flag("--json", o->json, "Print the results as JSON");
    cmd->callback([o, &status] { status = runBench(*o); });
}

}  // namespace pcsg::tools
