// Verifying one scene both ways: see verify_scene.h.
#include "verify_scene.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <fstream>

#include "image_helper.h"
#include "renders.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

std::vector<std::string> SceneVerifyOptions::clockArgs() const {
    std::vector<std::string> args;
    if (clock != 0) args = {"--clock", fmt::format("{}", clock)};
    if (frame != 1) {
        args.push_back("--frame");
        args.push_back(std::to_string(frame));
    }
    return args;
}

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

namespace {

// Step 1, the native render of the cyclic graph; false (with the message) when it failed.
bool renderNativeSide(SceneResult& r, const SceneVerifyOptions& o, const fs::path& work) {
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
fs::path exportSide(SceneResult& r, const SceneVerifyOptions& o, const fs::path& work) {
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
bool renderPovraySide(SceneResult& r, const SceneVerifyOptions& o, const fs::path& pov,
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
void compareSides(SceneResult& r, const SceneVerifyOptions& o, const fs::path& work) {
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

}  // namespace

SceneResult verifyScene(const std::string& scene, const std::string& dir,
                        const SceneVerifyOptions& o, const fs::path& root) {
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

void addImageOptions(CLI::App* cmd, SceneVerifyOptions& o) {
    cmd->add_option("--width", o.width, "Image width after reduction")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--height", o.height, "Image height after reduction")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--ss", o.ss, "Supersampling factor K: both render K*W x K*H")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--threads", o.threads, "Threads for both renderers (default: all cores)")
        ->check(CLI::NonNegativeNumber);
}

void addThresholdOptions(CLI::App* cmd, SceneVerifyOptions& o) {
    cmd->add_option("--pixel-threshold", o.thresholds.pixelOff,
                    "A pixel is off when a channel differs by more than this (0..1)")
        ->capture_default_str();
    cmd->add_option("--max-off", o.thresholds.maxShareOff,
                    "Agree only if at most this share of pixels is off")
        ->capture_default_str();
    cmd->add_option("--max-mean-error", o.thresholds.maxMeanError,
                    "Agree only if the mean absolute error is at most this")
        ->capture_default_str();
}

}  // namespace pcsg::tools
