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
// One scene is verified by verify_scene.h (which `pcsg fuzz` shares); the HTML report is
// tools/report/verify_report.h's.
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
#include "verify_scene.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

struct VerifyOptions : SceneVerifyOptions {
    std::vector<std::string> scenes;
    std::string allDir;
    std::string reportDir;
    bool json = false;
    bool keep = false;
    // --frames N [--clock-range A,B] [--cyclic] [--all-frames]: compare frames of an
    // animation, by default the first, the middle and the last of N.
    int frames = 0;
    std::string clockRange;
    bool cyclic = false;
    bool allFrames = false;
};

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

// A jittered area light samples other points in each renderer (POV-Ray draws random
// numbers, the tracer a fixed hash): its penumbrae cannot agree pixel for pixel.
void warnJitter(const std::string& scene) {
    std::ostringstream ignored;  // compile errors are reported by the native render
    const CompiledScene c = compileScene(scene, ignored);
    if (!c.graph) return;
    for (const Light& l : c.graph->scene.lights)
        if (l.jitter && l.areaLight()) {
            std::cerr << "pcsg verify: warning: " << scene
                      << " has an area light with 'jitter', which POV-Ray samples at random: "
                         "its soft shadows may differ\n";
            return;
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
        warnJitter(scene);
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
    addImageOptions(cmd, *o);
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
    addThresholdOptions(cmd, *o);
    cmd->add_flag("--json", o->json, "Print the results as JSON");
    cmd->add_flag("--keep", o->keep, "Keep the images (in a temporary directory) without --report");
    cmd->callback([o, &status] { status = runVerify(*o); });
}

}  // namespace pcsg::tools
