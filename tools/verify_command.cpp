// pcsg verify: render a scene natively (the cyclic graph) and with POV-Ray (the expanded
// tree written by export-pov), diff the two images and report whether they agree, with
// the memory and time each way took.
//
// Both renders run as child processes of this one, so that each one's peak RSS is its
// own (wait4's rusage), and both run without anti-aliasing at K times the size; the two
// images are then reduced by the same K×K box filter, so edge sampling is identical.
// Reading, reducing and comparing the images is `pcsg-image compare`'s job (a process of
// its own, the only one that loads OpenImageIO: tools/image_helper.h).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "child_process.h"
#include "commands.h"
#include "image_helper.h"
#include "renders.h"
#include "stats.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

struct VerifyOptions {
    std::vector<std::string> scenes;
    std::string allDir;
    int width = 320, height = 240, ss = 2;
    int threads = 0;
    std::string reportDir;
    std::string povFile;  // use this POV-Ray file instead of exporting (tests of verify)
    bool json = false;
    bool keep = false;
    Thresholds thresholds;
    std::string imageHelper;  // pcsg-image
};

struct Side {
    double seconds = 0;          // wall time of the render process
    uint64_t peakRssBytes = 0;   // of the render process
    std::optional<double> parseSeconds;
    std::optional<uint64_t> imageWriterPeakRssBytes;  // native: pcsg-image write's
};

struct SceneResult {
    std::string scene, name;
    int status = 2;  // 0 agree, 1 disagree, 2 could not run
    std::string message;
    ImageMetrics metrics;
    Side native, povray;
    std::optional<uint64_t> graphBytes, expandedBytes, expandedNodes, primitives;
    std::optional<double> raysPerSecond;
    std::string dir;  // where the images are, relative to the report root
};

SceneResult verifyScene(const std::string& scene, const VerifyOptions& o, const fs::path& root) {
    SceneResult r;
    r.scene = scene;
    r.name = fs::path(scene).stem().string();
    const fs::path work = root / r.name;
    r.dir = r.name;
    std::error_code ec;
    fs::create_directories(work, ec);
    const int W = o.width * o.ss, H = o.height * o.ss;
    const std::vector<std::string> threads =
        o.threads > 0 ? std::vector<std::string>{"--threads", std::to_string(o.threads)}
                      : std::vector<std::string>{};

    // 1. The native render of the cyclic graph.
    const fs::path nativeFull = work / "native_full.png";
    const RenderRun native = renderNative(scene, nativeFull.string(), W, H, threads);
    if (!native.ok) {
        r.message = native.error;
        return r;
    }
    r.native.seconds = native.child.seconds;
    // The render process's own peak (wait4 would report the larger of it and that of the
    // pcsg-image it ran to write the image); the writer's is kept beside it.
    r.native.peakRssBytes =
        jsonField<uint64_t>(native.json, "peak_rss_bytes").value_or(native.child.peakRssBytes);
    r.native.imageWriterPeakRssBytes =
        jsonField<uint64_t>(native.json, "image_writer_peak_rss_bytes");
    r.raysPerSecond = jsonField<double>(native.json, "rays_per_second");
    r.graphBytes = jsonField<uint64_t>(native.json, "graph_bytes");

    // 2. The expanded tree: its size, and the POV-Ray text.
    const RenderRun stats = expandedStats(scene);
    r.expandedBytes = jsonField<uint64_t>(stats.json, "expanded_bytes");
    r.expandedNodes = jsonField<uint64_t>(stats.json, "expanded_nodes");
    r.primitives = jsonField<uint64_t>(stats.json, "primitive_equivalence");
    if (!r.graphBytes) r.graphBytes = jsonField<uint64_t>(stats.json, "graph_bytes");
    fs::path pov = work / (r.name + ".pov");
    if (!o.povFile.empty()) {
        pov = o.povFile;
    } else {
        const RenderRun exported = exportPov(scene, pov.string(), W, H);
        if (!exported.ok) {
            r.message = exported.error;
            return r;
        }
    }

    // 3. POV-Ray on the exported text, without anti-aliasing, at the same size.
    const fs::path povFull = work / "povray_full.png";
    std::vector<std::string> povArgs = {"-A"};
    if (o.threads > 0) povArgs.push_back("+WT" + std::to_string(o.threads));
    const RenderRun povray = renderPovray(pov.string(), povFull.string(), W, H, povArgs);
    if (!povray.child.started) {
        r.message = povray.error;
        return r;
    }
    if (!povray.ok) {
        r.status = 1;  // POV-Ray rejecting our exported text is a failure of the exporter
        r.message = povray.error;
        return r;
    }
    r.povray.seconds = povray.child.seconds;
    r.povray.peakRssBytes = povray.child.peakRssBytes;
    r.povray.parseSeconds = povray.parseSeconds;

    // 4. The same box filter on both, then the comparison (pcsg-image compare), which also
    // writes the reduced images and the heat map for the report.
    ImageCompareOptions co;
    co.ss = o.ss;
    co.thresholds = o.thresholds;
    co.reducedA = (work / "native.png").string();
    co.reducedB = (work / "povray.png").string();
    co.heatMap = (work / "diff.png").string();
    const ImageCompareRun cmp =
        compareImagesWithHelper(o.imageHelper, nativeFull.string(), povFull.string(), co);
    if (cmp.widthA > 0 && cmp.widthB > 0 &&
        (cmp.widthA != W || cmp.heightA != H || cmp.widthB != W || cmp.heightB != H)) {
        r.message = fmt::format("image sizes differ: native {}x{}, POV-Ray {}x{}, expected {}x{}",
                                cmp.widthA, cmp.heightA, cmp.widthB, cmp.heightB, W, H);
        return r;
    }
    if (cmp.status == 2) {
        r.message = "comparing the images failed:\n" + firstLines(cmp.error);
        return r;
    }
    r.metrics = *cmp.metrics;
    fs::remove(nativeFull, ec);
    fs::remove(povFull, ec);
    r.status = r.metrics.agree ? 0 : 1;
    r.message = r.metrics.agree ? "the images agree" : "the images differ";
    return r;
}

std::string opt(const std::optional<uint64_t>& v, bool bytes = true) {
    if (!v) return "-";
    return bytes ? humanBytes(*v) : fmt::format("{}", *v);
}

std::string ratio(const std::optional<uint64_t>& big, const std::optional<uint64_t>& small) {
    if (!big || !small || *small == 0) return "-";
    return fmt::format("{:.1f}x", double(*big) / double(*small));
}

void printResult(const SceneResult& r, std::ostream& out) {
    const char* verdict = r.status == 0 ? "AGREE" : (r.status == 1 ? "DIFFER" : "ERROR");
    out << fmt::format("{}: {} ({})\n", r.scene, verdict, r.message);
    if (r.metrics.width > 0) {
        const auto& m = r.metrics;
        out << fmt::format("  image {}x{}: mean abs error {:.4f}, RMSE {:.4f}, PSNR {:.1f} dB, "
                           "pixels off {:.2f}%, largest difference {:.3f} at ({}, {})\n",
                           m.width, m.height, m.meanAbsError, m.rmse, m.psnr, 100 * m.shareOff,
                           m.maxError, m.maxX, m.maxY);
        out << fmt::format("  memory: graph {} vs expanded tree {} ({}), native peak RSS {} vs "
                           "POV-Ray {} ({})\n",
                           opt(r.graphBytes), opt(r.expandedBytes), ratio(r.expandedBytes, r.graphBytes),
                           humanBytes(r.native.peakRssBytes), humanBytes(r.povray.peakRssBytes),
                           ratio(r.povray.peakRssBytes, r.native.peakRssBytes));
        out << fmt::format("  time: native {:.2f} s, POV-Ray {:.2f} s{}; primitives {}\n",
                           r.native.seconds, r.povray.seconds,
                           r.povray.parseSeconds ? fmt::format(" ({:.2f} s parsing)", *r.povray.parseSeconds) : "",
                           opt(r.primitives, false));
    }
}

nlohmann::json toJson(const SceneResult& r) {
    nlohmann::json j;
    j["scene"] = r.scene;
    j["status"] = r.status == 0 ? "agree" : (r.status == 1 ? "differ" : "error");
    j["message"] = r.message;
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
        if (r.native.imageWriterPeakRssBytes)
            j["native_image_writer_peak_rss_bytes"] = *r.native.imageWriterPeakRssBytes;
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

std::string htmlEscape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '&': out += "&amp;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

const char* kStyle =
    "<style>body{font-family:sans-serif;margin:2em;background:#fafafa;color:#222}"
    "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:4px 10px;"
    "text-align:right}th{background:#eee}td:first-child,th:first-child{text-align:left}"
    ".agree{color:#080;font-weight:bold}.differ{color:#b00;font-weight:bold}"
    ".error{color:#b60;font-weight:bold}figure{display:inline-block;margin:0 1em 1em 0}"
    "img{image-rendering:pixelated;border:1px solid #999}pre{background:#eee;padding:1em}</style>";

std::string statusClass(int status) { return status == 0 ? "agree" : (status == 1 ? "differ" : "error"); }

std::string sceneTables(const SceneResult& r) {
    const auto& m = r.metrics;
    std::string h;
    h += "<table><tr><th>metric</th><th>value</th></tr>";
    h += fmt::format("<tr><td>mean absolute error</td><td>{:.5f}</td></tr>", m.meanAbsError);
    h += fmt::format("<tr><td>RMSE</td><td>{:.5f}</td></tr>", m.rmse);
    h += fmt::format("<tr><td>PSNR</td><td>{:.2f} dB</td></tr>", m.psnr);
    h += fmt::format("<tr><td>pixels off by more than the threshold</td><td>{:.3f}%</td></tr>", 100 * m.shareOff);
    h += fmt::format("<tr><td>largest difference</td><td>{:.4f} at ({}, {})</td></tr></table>", m.maxError, m.maxX, m.maxY);
    h += "<table><tr><th></th><th>native (cyclic graph)</th><th>POV-Ray (expanded tree)</th><th>ratio</th></tr>";
    h += fmt::format("<tr><td>scene in memory</td><td>{}</td><td>{}</td><td>{}</td></tr>", opt(r.graphBytes),
                     opt(r.expandedBytes), ratio(r.expandedBytes, r.graphBytes));
    h += fmt::format("<tr><td>peak RSS</td><td>{}</td><td>{}</td><td>{}</td></tr>", humanBytes(r.native.peakRssBytes),
                     humanBytes(r.povray.peakRssBytes), ratio(r.povray.peakRssBytes, r.native.peakRssBytes));
    h += fmt::format("<tr><td>render time</td><td>{:.2f} s</td><td>{:.2f} s</td><td>{:.2f}x</td></tr>",
                     r.native.seconds, r.povray.seconds, r.native.seconds > 0 ? r.povray.seconds / r.native.seconds : 0.0);
    h += fmt::format("<tr><td>primitives</td><td colspan=2>{}</td><td></td></tr></table>", opt(r.primitives, false));
    return h;
}

void writeScenePage(const SceneResult& r, const fs::path& root) {
    std::ofstream out(root / r.dir / "index.html");
    out << "<!DOCTYPE html><html><head><meta charset=utf-8><title>pcsg verify: " << htmlEscape(r.name)
        << "</title>" << kStyle << "</head><body>";
    out << "<h1>" << htmlEscape(r.name) << ": <span class=" << statusClass(r.status) << ">"
        << htmlEscape(r.message.substr(0, r.message.find('\n'))) << "</span></h1>";
    out << "<p>" << htmlEscape(r.scene) << "</p>";
    if (r.metrics.width > 0) {
        for (const char* img : {"native", "povray", "diff"})
            out << "<figure><img src=\"" << img << ".png\" alt=\"" << img << "\" width=" << r.metrics.width
                << "><figcaption>" << (std::string(img) == "native" ? "native (cyclic graph)"
                                       : std::string(img) == "povray" ? "POV-Ray (expanded tree)"
                                                                      : "difference (heat map)")
                << "</figcaption></figure>";
        out << sceneTables(r);
    } else {
        out << "<pre>" << htmlEscape(r.message) << "</pre>";
    }
    out << "</body></html>\n";
}

void writeIndex(const std::vector<SceneResult>& results, const fs::path& root) {
    std::ofstream out(root / "index.html");
    out << "<!DOCTYPE html><html><head><meta charset=utf-8><title>pcsg verify</title>" << kStyle
        << "</head><body><h1>pcsg verify</h1><table><tr><th>scene</th><th>verdict</th><th>native</th>"
           "<th>POV-Ray</th><th>mean abs error</th><th>pixels off</th><th>graph</th><th>expanded tree</th>"
           "<th>native RSS</th><th>POV-Ray RSS</th><th>native time</th><th>POV-Ray time</th></tr>";
    for (const auto& r : results) {
        out << "<tr><td><a href=\"" << r.dir << "/index.html\">" << htmlEscape(r.name) << "</a></td><td class="
            << statusClass(r.status) << ">" << statusClass(r.status) << "</td>";
        if (r.metrics.width > 0)
            out << "<td><img src=\"" << r.dir << "/native.png\" alt=\"native " << htmlEscape(r.name)
                << "\" width=160></td><td><img src=\"" << r.dir << "/povray.png\" alt=\"povray "
                << htmlEscape(r.name) << "\" width=160></td>"
                << fmt::format("<td>{:.4f}</td><td>{:.2f}%</td>", r.metrics.meanAbsError, 100 * r.metrics.shareOff);
        else
            out << "<td colspan=4>" << htmlEscape(r.message.substr(0, r.message.find('\n'))) << "</td>";
        out << "<td>" << opt(r.graphBytes) << "</td><td>" << opt(r.expandedBytes) << "</td><td>"
            << humanBytes(r.native.peakRssBytes) << "</td><td>" << humanBytes(r.povray.peakRssBytes)
            << fmt::format("</td><td>{:.2f} s</td><td>{:.2f} s</td></tr>", r.native.seconds, r.povray.seconds);
    }
    out << "</table></body></html>\n";
}

int runVerify(VerifyOptions o) {
    if (!o.allDir.empty()) {
        std::error_code ec;
        std::vector<std::string> found;
        for (const auto& e : fs::directory_iterator(o.allDir, ec))
            if (e.path().extension() == ".pcsg") found.push_back(e.path().string());
        if (ec) {
            std::cerr << "pcsg verify: cannot read directory " << o.allDir << ": " << ec.message() << "\n";
            return 2;
        }
        std::sort(found.begin(), found.end());
        o.scenes.insert(o.scenes.end(), found.begin(), found.end());
    }
    if (o.scenes.empty()) {
        std::cerr << "pcsg verify: no scene given (a .pcsg file, or --all DIR)\n";
        return 2;
    }
    if (o.ss < 1 || o.width < 1 || o.height < 1) {
        std::cerr << "pcsg verify: --width, --height and --ss must be positive\n";
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
    fs::path root;
    bool temporary = false;
    if (!o.reportDir.empty()) {
        root = o.reportDir;
    } else {
        char tmpl[] = "/tmp/pcsg-verify-XXXXXX";
        if (!mkdtemp(tmpl)) {
            std::cerr << "pcsg verify: cannot create a temporary directory\n";
            return 2;
        }
        root = tmpl;
        temporary = !o.keep;
    }
    std::error_code ec;
    fs::create_directories(root, ec);

    std::vector<SceneResult> results;
    int status = 0;
    for (const auto& scene : o.scenes) {
        if (!o.json && o.scenes.size() > 1) std::cerr << "verifying " << scene << " ...\n";
        SceneResult r = verifyScene(scene, o, root);
        if (!o.reportDir.empty()) writeScenePage(r, root);
        if (!o.json) printResult(r, std::cout);
        status = std::max(status, r.status);
        results.push_back(std::move(r));
    }
    if (!o.reportDir.empty() && o.scenes.size() > 1) writeIndex(results, root);
    if (o.json) {
        nlohmann::json j = nlohmann::json::array();
        for (const auto& r : results) j.push_back(toJson(r));
        std::cout << (results.size() == 1 ? j[0] : j).dump(2) << "\n";
    } else {
        size_t agree = 0;
        for (const auto& r : results) agree += r.status == 0;
        std::cout << fmt::format("{} of {} scene(s) agree", agree, results.size());
        if (!o.reportDir.empty()) std::cout << "; report: " << (root / (o.scenes.size() > 1 ? "index.html" : results[0].dir + "/index.html")).string();
        else if (o.keep) std::cout << "; images kept in " << root.string();
        std::cout << "\n";
    }
    if (temporary) fs::remove_all(root, ec);
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
    cmd->add_option("--all", o->allDir, "Verify every .pcsg file in this directory");
    cmd->add_option("--width", o->width, "Image width after reduction")->capture_default_str();
    cmd->add_option("--height", o->height, "Image height after reduction")->capture_default_str();
    cmd->add_option("--ss", o->ss, "Supersampling factor K: both render K*W x K*H")->capture_default_str();
    cmd->add_option("--threads", o->threads, "Threads for both renderers (default: all cores)");
    cmd->add_option("--report", o->reportDir, "Write an HTML report (images, heat map, tables) here");
    cmd->add_option("--pov", o->povFile, "Render this POV-Ray file instead of exporting the scene");
    cmd->add_option("--pixel-threshold", o->thresholds.pixelOff,
                    "A pixel is off when a channel differs by more than this (0..1)")->capture_default_str();
    cmd->add_option("--max-off", o->thresholds.maxShareOff,
                    "Agree only if at most this share of pixels is off")->capture_default_str();
    cmd->add_option("--max-mean-error", o->thresholds.maxMeanError,
                    "Agree only if the mean absolute error is at most this")->capture_default_str();
    cmd->add_flag("--json", o->json, "Print the results as JSON");
    cmd->add_flag("--keep", o->keep, "Keep the images (in a temporary directory) without --report");
    cmd->callback([o, &status] { status = runVerify(*o); });
}

}  // namespace pcsg::tools
