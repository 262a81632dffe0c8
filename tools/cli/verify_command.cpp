// pcsg verify: render a scene natively (the cyclic graph) and with POV-Ray (the expanded
// tree written by export-pov), diff the two images and report whether they agree, with
// the memory and time each way took.
//
// Both renders run as child processes of this one, so that each one's peak RSS is its
// own (wait4's rusage), and both run without anti-aliasing at K times the size; the two
// images are then reduced by the same K×K box filter, so edge sampling is identical.
// Reading, reducing and comparing the images is `pcsg-image compare`'s job (a process of
// its own, which loads OpenImageIO: tools/image/image_helper.h), so that this process
// stays small: a child started from a large process would count its memory as its own.
// The HTML report is tools/report/verify_report.h's.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "child_process.h"
#include "commands.h"
#include "frames.h"
#include "image_helper.h"
#include "renders.h"
#include "scene_input.h"
#include "stats.h"
#include "verify_report.h"
#include "verify_result.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

struct VerifyOptions : VerifySettings {
    std::vector<std::string> scenes;
    std::string allDir;
    std::string reportDir;
    std::string povFile;  // use this POV-Ray file instead of exporting (tests of verify)
    bool json = false;
    bool keep = false;
    std::string imageHelper;  // pcsg-image
    double clock = 0;         // --clock: both sides render the still at this time
    // --frames N [--clock-range A,B] [--cyclic] [--all-frames]: compare frames of an
    // animation, by default the first, the middle and the last of N.
    int frames = 0;
    std::string clockRange;
    bool cyclic = false;
    bool allFrames = false;
    int frame = 1;  // a frame of --frames: its number, passed on with its clock
    // The arguments that pass --clock (and --frame) on to render, export-pov and stats
    // (none for a still at clock 0).
    std::vector<std::string> clockArgs() const {
        std::vector<std::string> args;
        if (clock != 0) args = {"--clock", fmt::format("{}", clock)};
        if (frame != 1) {
            args.push_back("--frame");
            args.push_back(std::to_string(frame));
        }
        return args;
    }
};

// The scene's text for the report (up to 256 KB); empty when it cannot be read.
std::string readSource(const std::string& scene) {
    std::ifstream in(scene, std::ios::binary);
    if (!in) return {};
    std::string text(256 * 1024, '\0');
    in.read(text.data(), std::streamsize(text.size()));
    const bool more = in.gcount() == std::streamsize(text.size()) && in.peek() != EOF;
    text.resize(size_t(in.gcount()));
    if (more) text += "\n... (the rest is left out)\n";
    return text;
}

// Step 1, the native render of the cyclic graph; false (with the message) when it failed.
bool renderNativeSide(SceneResult& r, const VerifyOptions& o, const fs::path& work) {
    std::vector<std::string> extra =
        o.threads > 0 ? std::vector<std::string>{"--threads", std::to_string(o.threads)}
                      : std::vector<std::string>{};
    for (const std::string& a : o.clockArgs()) extra.push_back(a);
    const RenderRun native = renderNative(r.scene, (work / "native_full.png").string(),
                                          o.width * o.ss, o.height * o.ss, extra);
    if (!native.ok) {
        r.message = native.error;
        return false;
    }
    r.native.seconds = native.child.seconds;
    // The whole render command's peak, as wait4 counts it.
    r.native.peakRssBytes = native.child.peakRssBytes;
    r.raysPerSecond = jsonField<double>(native.json, "rays_per_second");
    r.graphBytes = jsonField<uint64_t>(native.json, "graph_bytes");
    r.graphNodes = jsonField<uint64_t>(native.json, "graph_nodes");
    r.native.parseSeconds = jsonField<double>(native.json, "parse_seconds");
    r.native.traceSeconds = jsonField<double>(native.json, "seconds");
    r.native.imageWriteSeconds = jsonField<double>(native.json, "image_write_seconds");
    return true;
}

// Step 2, the expanded tree: its size, and the POV-Ray text (exported, or --pov's).
// Returns the POV-Ray file, empty when the export failed.
fs::path exportSide(SceneResult& r, const VerifyOptions& o, const fs::path& work) {
    const RenderRun stats = expandedStats(r.scene, o.clockArgs());
    r.expandedBytes = jsonField<uint64_t>(stats.json, "expanded_bytes");
    r.expandedNodes = jsonField<uint64_t>(stats.json, "expanded_nodes");
    r.primitives = jsonField<uint64_t>(stats.json, "primitive_equivalence");
    if (!r.graphBytes) r.graphBytes = jsonField<uint64_t>(stats.json, "graph_bytes");
    if (!r.graphNodes) r.graphNodes = jsonField<uint64_t>(stats.json, "graph_nodes");
    if (!o.povFile.empty()) {
        r.povFile = o.povFile;
        return o.povFile;
    }
    const fs::path pov = work / (r.dir + ".pov");
    const RenderRun exported =
        exportPov(r.scene, pov.string(), o.width * o.ss, o.height * o.ss, o.clockArgs());
    if (!exported.ok) {
        r.message = exported.error;
        return {};
    }
    r.povFile = pov.filename().string();
    r.povInReport = true;
    return pov;
}

// Step 3, POV-Ray on the exported text, without anti-aliasing, at the same size.
bool renderPovraySide(SceneResult& r, const VerifyOptions& o, const fs::path& pov,
                      const fs::path& work) {
    std::vector<std::string> povArgs = {"-A"};
    if (o.threads > 0) povArgs.push_back("+WT" + std::to_string(o.threads));
    // A hand-written file (--pov) may read POV-Ray's own clock: it gets the frame's.
    if (!o.povFile.empty()) povArgs.push_back(fmt::format("+K{}", o.clock));
    const RenderRun povray = renderPovray(pov.string(), (work / "povray_full.png").string(),
                                          o.width * o.ss, o.height * o.ss, povArgs);
    if (!povray.ok) {
        // POV-Ray rejecting our exported text is a failure of the exporter.
        if (povray.child.started) r.status = 1;
        r.message = povray.error;
        return false;
    }
    r.povray.seconds = povray.child.seconds;
    r.povray.peakRssBytes = povray.child.peakRssBytes;
    r.povray.parseSeconds = povray.parseSeconds;
    r.povray.traceSeconds = povray.traceSeconds;
    return true;
}

// Step 4, the same box filter on both, then the comparison (pcsg-image compare), which
// also writes the reduced images and the heat map for the report.
void compareSides(SceneResult& r, const VerifyOptions& o, const fs::path& work) {
    const int W = o.width * o.ss, H = o.height * o.ss;
    ImageCompareOptions co;
    co.ss = o.ss;
    co.thresholds = o.thresholds;
    co.reducedA = (work / "native.png").string();
    co.reducedB = (work / "povray.png").string();
    co.heatMap = (work / "diff.png").string();
    const fs::path nativeFull = work / "native_full.png", povFull = work / "povray_full.png";
    const ImageCompareRun cmp =
        compareImagesWithHelper(o.imageHelper, nativeFull.string(), povFull.string(), co);
    if (cmp.widthA > 0 && cmp.widthB > 0 &&
        (cmp.widthA != W || cmp.heightA != H || cmp.widthB != W || cmp.heightB != H)) {
        r.message = fmt::format("image sizes differ: native {}x{}, POV-Ray {}x{}, expected {}x{}",
                                cmp.widthA, cmp.heightA, cmp.widthB, cmp.heightB, W, H);
        return;
    }
    if (cmp.status == 2) {
        r.message = "comparing the images failed:\n" + firstLines(cmp.error);
        return;
    }
    r.metrics = *cmp.metrics;
    std::error_code ec;
    fs::remove(nativeFull, ec);
    fs::remove(povFull, ec);
    r.status = r.metrics.agree ? 0 : 1;
    r.message = r.metrics.agree ? "the images agree" : "the images differ";
}

// Verifies one scene (at o.clock), writing its images into root/dir.
SceneResult verifyScene(const std::string& scene, const std::string& dir, const VerifyOptions& o,
                        const fs::path& root) {
    SceneResult r;
    r.scene = scene;
    r.name = fs::path(scene).stem().string();
    r.dir = dir;
    r.source = readSource(scene);
    const fs::path work = root / dir;
    std::error_code ec;
    fs::create_directories(work, ec);
    if (!renderNativeSide(r, o, work)) return r;
    const fs::path pov = exportSide(r, o, work);
    if (pov.empty() || !renderPovraySide(r, o, pov, work)) return r;
    compareSides(r, o, work);
    return r;
}

std::string ratio(const std::optional<uint64_t>& big, const std::optional<uint64_t>& small) {
    if (!big || !small || *small == 0) return "-";
    return fmt::format("{:.1f}x", double(*big) / double(*small));
}

// "frame 3 of 5 (clock 0.5)" for a frame of --frames, nothing for a still.
std::string frameLabel(const SceneResult& r) {
    if (r.frames == 0) return {};
    return fmt::format(" frame {} of {} (clock {})", r.frame, r.frames, r.clock);
}

void printResult(const SceneResult& r, std::ostream& out) {
    const char* verdict = r.status == 0 ? "AGREE" : (r.status == 1 ? "DIFFER" : "ERROR");
    out << fmt::format("{}{}: {} ({})\n", r.scene, frameLabel(r), verdict, r.message);
    if (r.metrics.width > 0) {
        const auto& m = r.metrics;
        out << fmt::format(
            "  image {}x{}: mean abs error {:.4f}, RMSE {:.4f}, PSNR {:.1f} dB, "
            "pixels off {:.2f}%, largest difference {:.3f} at ({}, {})\n",
            m.width, m.height, m.meanAbsError, m.rmse, m.psnr, 100 * m.shareOff, m.maxError, m.maxX,
            m.maxY);
        out << fmt::format(
            "  memory: graph {} vs expanded tree {} ({}), native peak RSS {} vs "
            "POV-Ray {} ({})\n",
            opt(r.graphBytes), opt(r.expandedBytes), ratio(r.expandedBytes, r.graphBytes),
            humanBytes(r.native.peakRssBytes), humanBytes(r.povray.peakRssBytes),
            ratio(r.povray.peakRssBytes, r.native.peakRssBytes));
        out << fmt::format(
            "  time: native {:.2f} s, POV-Ray {:.2f} s{}; primitives {}\n", r.native.seconds,
            r.povray.seconds,
            r.povray.parseSeconds ? fmt::format(" ({:.2f} s parsing)", *r.povray.parseSeconds) : "",
            opt(r.primitives, false));
    }
}

nlohmann::json toJson(const SceneResult& r) {
    nlohmann::json j;
    j["scene"] = r.scene;
    j["status"] = r.status == 0 ? "agree" : (r.status == 1 ? "differ" : "error");
    j["message"] = r.message;
    if (r.frames > 0) {
        j["frame"] = r.frame;
        j["frames"] = r.frames;
        j["clock"] = r.clock;
    }
    if (r.metrics.width > 0) {
        const auto& m = r.metrics;
        j["width"] = m.width;
        j["height"] = m.height;
        j["mean_abs_error"] = m.meanAbsError;
        j["rmse"] = m.rmse;
        j["psnr"] = std::isfinite(m.psnr) ? nlohmann::json(m.psnr) : nlohmann::json("inf");
        j["max_error"] = m.maxError;
        j["share_off"] = m.shareOff;
        j["native_seconds"] = r.native.seconds;
        j["native_peak_rss_bytes"] = r.native.peakRssBytes;
        j["povray_seconds"] = r.povray.seconds;
        j["povray_peak_rss_bytes"] = r.povray.peakRssBytes;
        if (r.povray.parseSeconds) j["povray_parse_seconds"] = *r.povray.parseSeconds;
    }
    if (r.graphBytes) j["graph_bytes"] = *r.graphBytes;
    if (r.expandedBytes) j["expanded_bytes"] = *r.expandedBytes;
    if (r.expandedNodes) j["expanded_nodes"] = *r.expandedNodes;
    if (r.primitives) j["primitive_equivalence"] = *r.primitives;
    return j;
}

// Adds the .pcsg files of --all DIR to the scenes; false (with the error printed) when
// the directory cannot be read.
bool addSceneDirectory(VerifyOptions& o) {
    if (o.allDir.empty()) return true;
    std::error_code ec;
    std::vector<std::string> found;
    for (const auto& e : fs::directory_iterator(o.allDir, ec))
        if (e.path().extension() == ".pcsg") found.push_back(e.path().string());
    if (ec) {
        std::cerr << "pcsg verify: cannot read directory " << o.allDir << ": " << ec.message()
                  << "\n";
        return false;
    }
    std::sort(found.begin(), found.end());
    o.scenes.insert(o.scenes.end(), found.begin(), found.end());
    return true;
}

// The directory the images go to: --report's, or a temporary one; empty when it cannot
// be made.
fs::path makeRoot(const VerifyOptions& o) {
    fs::path root = o.reportDir;
    if (root.empty()) {
        char tmpl[] = "/tmp/pcsg-verify-XXXXXX";
        if (!mkdtemp(tmpl)) return {};
        root = tmpl;
    }
    std::error_code ec;
    fs::create_directories(root, ec);
    return root;
}

void printSummary(const std::vector<SceneResult>& results, const VerifyOptions& o,
                  const fs::path& root) {
    if (o.json) {
        nlohmann::json j = nlohmann::json::array();
        for (const auto& r : results) j.push_back(toJson(r));
        std::cout << (results.size() == 1 ? j[0] : j).dump(2) << "\n";
        return;
    }
    size_t agree = 0;
    for (const auto& r : results) agree += r.status == 0;
    std::cout << fmt::format("{} of {} {} agree", agree, results.size(),
                             o.frames > 0 ? "frame(s)" : "scene(s)");
    if (!o.reportDir.empty())
        std::cout << "; report: " << (root / "index.html").string();
    else if (o.keep)
        std::cout << "; images kept in " << root.string();
    std::cout << "\n";
}

// The frames of --frames to compare: the first, the middle and the last of N (each once),
// or all of them with --all-frames; none without --frames (a still). False (with the
// error printed) for a wrong --clock-range.
bool framesToCompare(const VerifyOptions& o, FramePlan& plan, std::vector<int>& frames) {
    if (o.frames == 0) return true;
    plan.frames = o.frames;
    plan.cyclic = o.cyclic;
    plan.first = 1;
    plan.last = o.frames;
    if (!o.clockRange.empty()) {
        std::string error;
        const auto range = parseClockRange(o.clockRange, error);
        if (!range) {
            std::cerr << "pcsg verify: error: " << error << "\n";
            return false;
        }
        std::tie(plan.clockFrom, plan.clockTo) = *range;
    }
    std::set<int> chosen;
    if (o.allFrames) {
        for (int f = 1; f <= o.frames; ++f) chosen.insert(f);
    } else {
        chosen = {1, (o.frames + 1) / 2, o.frames};
    }
    frames.assign(chosen.begin(), chosen.end());
    return true;
}

// Verifies one scene: the still, or each frame of `frames` at its clock (its images in
// a directory of its own, "NAME_frameF").
void verifySceneFrames(const std::string& scene, VerifyOptions o, const FramePlan& plan,
                       const std::vector<int>& frames, std::set<std::string>& dirs,
                       const fs::path& root, std::vector<SceneResult>& results, int& status,
                       const std::string& written) {
    const size_t runs = std::max<size_t>(1, frames.size());
    for (size_t i = 0; i < runs; ++i) {
        std::string dirKey = scene;
        if (!frames.empty()) {
            o.clock = frameClock(plan, frames[i]);
            o.frame = frames[i];
            dirKey = fmt::format("{}_frame{}", fs::path(scene).stem().string(), frames[i]);
        }
        SceneResult r = verifyScene(scene, reportDirName(dirKey, dirs), o, root);
        if (!frames.empty()) {
            r.frame = frames[i];
            r.frames = plan.frames;
            r.clock = o.clock;
            r.name += fmt::format(" frame {} (clock {})", r.frame, r.clock);  // the report's title
        }
        if (!o.json) printResult(r, std::cout);
        status = std::max(status, r.status);
        results.push_back(std::move(r));
        if (!o.reportDir.empty()) {
            writeScenePage(results.back(), o, written, root);
            writeIndex(results, 0, o, written, root);
        }
    }
}

int runVerify(VerifyOptions o) {
    if (!addSceneDirectory(o)) return 2;
    FramePlan plan;
    std::vector<int> frames;
    if (!framesToCompare(o, plan, frames)) return 2;
    if (o.scenes.empty()) {
        std::cerr << "pcsg verify: no scene given (a .pcsg file, or --all DIR)\n";
        return 2;
    }
    if (!inPath("povray")) {
        std::cerr << "pcsg verify: POV-Ray is not installed (it renders the exported tree): "
                     "install it with `apt-get install povray`\n";
        return 2;
    }
    if (const auto helper = findImageHelper()) {
        o.imageHelper = *helper;
    } else {
        std::cerr << "pcsg verify: " << missingImageHelperMessage() << "\n";
        return 2;
    }
    const fs::path root = makeRoot(o);
    if (root.empty()) {
        std::cerr << "pcsg verify: cannot create a temporary directory\n";
        return 2;
    }
    std::vector<SceneResult> results;
    int status = 0;
    const std::string written = localTime();
    std::set<std::string> dirs = {"index.html"};  // the report's own page is taken
    for (const auto& scene : o.scenes) {
        if (!o.json && o.scenes.size() > 1) std::cerr << "verifying " << scene << " ...\n";
        verifySceneFrames(scene, o, plan, frames, dirs, root, results, status, written);
    }
    printSummary(results, o, root);
    std::error_code ec;
    if (o.reportDir.empty() && !o.keep) fs::remove_all(root, ec);
    return status;
}

}  // namespace

void addVerifyCommand(CLI::App& app, int& status) {
    auto o = std::make_shared<VerifyOptions>();
    auto* cmd = app.add_subcommand(
        "verify",
        "Render a scene natively (the cyclic graph) and with POV-Ray (the expanded tree written "
        "by\n"
        "export-pov), both without anti-aliasing at --ss times the size, reduce both with the "
        "same\n"
        "box filter, and compare them. Exit status: 0 the images agree, 1 they differ, 2 "
        "something\n"
        "could not run. Also reports memory (graph vs expanded tree, both peak RSS) and time.\n"
        "The images are compared by the pcsg-image helper (beside pcsg, or in PATH).");
    cmd->add_option("scenes", o->scenes, "Scene files (.pcsg)");
    cmd->add_option("--all", o->allDir, "Verify every .pcsg file in this directory")
        ->check(CLI::ExistingDirectory);
    cmd->add_option("--width", o->width, "Image width after reduction")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--height", o->height, "Image height after reduction")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--ss", o->ss, "Supersampling factor K: both render K*W x K*H")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--threads", o->threads, "Threads for both renderers (default: all cores)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--report", o->reportDir,
                    "Write an HTML report into this directory; open DIR/index.html");
    auto* clock = addClockOption(cmd, o->clock);
    auto* frames = cmd->add_option("--frames", o->frames,
                                   "Compare frames of an animation of N frames (numbered as "
                                   "`pcsg render --frames`): the first, the middle and the last")
                       ->check(CLI::Range(1, 1000000));
    clock->excludes(frames);
    cmd->add_option("--clock-range", o->clockRange,
                    "A,B: the clocks of the first and last frame (default 0,1)")
        ->needs(frames);
    cmd->add_flag("--cyclic", o->cyclic,
                  "A cyclic animation (POV-Ray's +KC): the clock steps by (B-A)/N")
        ->needs(frames);
    cmd->add_flag("--all-frames", o->allFrames, "Compare every frame of the N")->needs(frames);
    cmd->add_option("--pov", o->povFile,
                    "Render this POV-Ray file instead of exporting the scene (a hand-written "
                    "scene to compare with); POV-Ray gets each frame's clock as +K");
    cmd->add_option("--pixel-threshold", o->thresholds.pixelOff,
                    "A pixel is off when a channel differs by more than this (0..1)")
        ->capture_default_str();
    cmd->add_option("--max-off", o->thresholds.maxShareOff,
                    "Agree only if at most this share of pixels is off")
        ->capture_default_str();
    cmd->add_option("--max-mean-error", o->thresholds.maxMeanError,
                    "Agree only if the mean absolute error is at most this")
        ->capture_default_str();
    cmd->add_flag("--json", o->json, "Print the results as JSON");
    cmd->add_flag("--keep", o->keep, "Keep the images (in a temporary directory) without --report");
    cmd->callback([o, &status] { status = runVerify(*o); });
}

}  // namespace pcsg::tools
