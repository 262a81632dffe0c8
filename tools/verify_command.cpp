// pcsg verify: render a scene natively (the cyclic graph) and with POV-Ray (the expanded
// tree written by export-pov), diff the two images and report whether they agree, with
// the memory and time each way took.
//
// Both renders run as child processes of this one, so that each one's peak RSS is its
// own (wait4's rusage), and both run without anti-aliasing at K times the size; the two
// images are then reduced by the same K×K box filter, so edge sampling is identical.
// Reading, reducing and comparing the images is `pcsg-image compare`'s job (a process of
// its own, the only one that loads OpenImageIO: tools/image_helper.h).
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
#include "heat_ramp.h"
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
    double seconds = 0;         // wall time of the render process
    uint64_t peakRssBytes = 0;  // of the render process
    std::optional<double> parseSeconds, traceSeconds;
    std::optional<double> imageWriteSeconds;          // native: pcsg-image write's
    std::optional<uint64_t> imageWriterPeakRssBytes;  // native: pcsg-image write's
};

struct SceneResult {
    std::string scene, name;
    int status = 2;  // 0 agree, 1 disagree, 2 could not run
    std::string message;
    ImageMetrics metrics;
    Side native, povray;
    std::optional<uint64_t> graphBytes, graphNodes, expandedBytes, expandedNodes, primitives;
    std::optional<double> raysPerSecond;
    std::string dir;      // where the images are, relative to the report root
    std::string povFile;  // the POV-Ray scene: a file name in dir, or --pov's path
    bool povInReport = false;
    std::string source;  // the scene's text, for the report
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

// Verifies one scene, writing its images into root/dir.
SceneResult verifyScene(const std::string& scene, const std::string& dir, const VerifyOptions& o,
                        const fs::path& root) {
    SceneResult r;
    r.scene = scene;
    r.name = fs::path(scene).stem().string();
    const fs::path work = root / dir;
    r.dir = dir;
    r.source = readSource(scene);
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
    r.graphNodes = jsonField<uint64_t>(native.json, "graph_nodes");
    r.native.parseSeconds = jsonField<double>(native.json, "parse_seconds");
    r.native.traceSeconds = jsonField<double>(native.json, "seconds");
    r.native.imageWriteSeconds = jsonField<double>(native.json, "image_write_seconds");

    // 2. The expanded tree: its size, and the POV-Ray text.
    const RenderRun stats = expandedStats(scene);
    r.expandedBytes = jsonField<uint64_t>(stats.json, "expanded_bytes");
    r.expandedNodes = jsonField<uint64_t>(stats.json, "expanded_nodes");
    r.primitives = jsonField<uint64_t>(stats.json, "primitive_equivalence");
    if (!r.graphBytes) r.graphBytes = jsonField<uint64_t>(stats.json, "graph_bytes");
    if (!r.graphNodes) r.graphNodes = jsonField<uint64_t>(stats.json, "graph_nodes");
    fs::path pov = work / (dir + ".pov");
    if (!o.povFile.empty()) {
        pov = o.povFile;
        r.povFile = o.povFile;
    } else {
        const RenderRun exported = exportPov(scene, pov.string(), W, H);
        if (!exported.ok) {
            r.message = exported.error;
            return r;
        }
        r.povFile = pov.filename().string();
        r.povInReport = true;
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
    r.povray.traceSeconds = povray.traceSeconds;

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

// ---- The HTML report --------------------------------------------------------------------
//
// Static pages, with no scripts but the images' inline load handlers and nothing from
// elsewhere, linked by relative paths only, so the report directory can be moved or
// copied as a whole:
//
//   DIR/index.html                  every scene: its verdict, thumbnails and main figures
//   DIR/NAME/index.html             one scene: the three images, the metrics, memory, time
//   DIR/NAME/native.png, povray.png, diff.png, NAME.pov
//
// Every <img> marks itself from inline onload/onerror handlers: data-state="loaded" and
// data-natural="WxH", or data-state="broken", which also draws a red frame around it.
// tests/report_in_chromium.sh reads these marks from headless Chromium's DOM.

std::string htmlEscape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '&':
                out += "&amp;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&#39;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

// The gist of a message in one line: its first line, and when that ends in ':' (as in
// "the native render failed:" above the renderer's own errors) the first line below it.
std::string summary(const std::string& message) {
    std::istringstream in(message);
    std::string first, line;
    std::getline(in, first);
    if (first.empty() || first.back() != ':') return first;
    while (std::getline(in, line)) {
        const size_t start = line.find_first_not_of(" \t");
        if (start != std::string::npos) return first + " " + line.substr(start);
    }
    return first.substr(0, first.size() - 1);
}

// A directory name for a scene inside the report: its file's stem, with anything but
// letters, digits, '.', '-' and '_' replaced, so that links need no escaping; a name
// already taken (two scenes/x.pcsg from different directories) gets "_2", "_3", ...
std::string reportDirName(const std::string& scene, std::set<std::string>& taken) {
    std::string base;
    for (char c : fs::path(scene).stem().string())
        base += std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_'
                    ? c
                    : '_';
    if (base.empty() || base[0] == '.') base = "scene" + base;
    std::string name = base;
    for (int i = 2; taken.count(name); ++i) name = fmt::format("{}_{}", base, i);
    taken.insert(name);
    return name;
}

const char* kStyle = R"(<style>
body{font-family:sans-serif;margin:1.5em 2em;background:#fafafa;color:#222;line-height:1.4}
h1{margin:.2em 0 .4em}h2{margin:1.4em 0 .3em;font-size:1.2em}
nav{margin-bottom:.5em}a{color:#0645ad}
.verdict{display:inline-block;padding:0 .4em;border-radius:4px;color:#fff;font-size:.8em;
 vertical-align:middle}
.verdict.agree{background:#1a7f37}.verdict.differ{background:#c62828}.verdict.error{background:#b45f06}
.note,.settings,footer{color:#555;max-width:60em}footer{margin-top:2em;font-size:.85em}
table{border-collapse:collapse;margin:.5em 0 1em}
td,th{border:1px solid #ccc;padding:4px 8px;text-align:right;white-space:nowrap;vertical-align:middle}
th{background:#eee;text-align:center}td:first-child,th:first-child,td.text{text-align:left}
td.merged{text-align:center}td.sub{padding-left:2em}td.msg{text-align:left;white-space:normal}
td.no{background:#fde8e8}.wide{overflow-x:auto}.wide table{font-size:.92em}
td.scene{white-space:normal;max-width:13em}.path{font-size:.8em;color:#666;word-break:break-all}
.yes{color:#1a7f37;font-weight:bold}.no{color:#c62828;font-weight:bold}
.figures{display:flex;flex-wrap:wrap;gap:1.5em;align-items:flex-start}
figure{margin:0;max-width:100%}figcaption{font-size:.9em;max-width:26em;margin-top:.3em}
.frame{position:relative;display:inline-block;max-width:100%}
.frame img{display:block;max-width:100%;height:auto}
img{border:1px solid #999;background:#fff}img.pixels{image-rendering:pixelated}
img[data-state=broken]{outline:3px solid #d00;min-width:6em;min-height:3em}
.marker{position:absolute;width:18px;height:18px;margin:-11px 0 0 -11px;border:2px solid #0cf;
 border-radius:50%;pointer-events:none}
.ramp{height:12px;border:1px solid #999}
.ticks{position:relative;height:1.3em}
.ticks span{position:absolute;transform:translateX(-50%)}
.ticks span.first{transform:none}.ticks span.last{transform:translateX(-100%)}
.legend{position:relative;margin:.4em 0 .2em;padding-top:1.1em;width:20em;max-width:100%;
 font-size:.8em}
.threshold{position:absolute;top:0;height:calc(1.1em + 14px);border-left:2px solid #06c;
 padding-left:3px;line-height:1;white-space:nowrap;color:#06c}
pre{background:#eee;padding:1em;overflow:auto;max-height:30em}
</style>)";

std::string statusClass(int status) {
    return status == 0 ? "agree" : (status == 1 ? "differ" : "error");
}

std::string verdictBadge(int status) {
    return fmt::format("<span class=\"verdict {0}\">{0}</span>", statusClass(status));
}

// An image that marks itself loaded or broken (see above).
std::string imgTag(const std::string& src, const std::string& alt, int width, int height,
                   const char* cls) {
    return fmt::format(
        "<img src=\"{}\" alt=\"{}\" width={} height={} class=\"{}\" "
        "onload=\"this.dataset.state='loaded';"
        "this.dataset.natural=this.naturalWidth+'x'+this.naturalHeight\" "
        "onerror=\"this.dataset.state='broken'\">",
        htmlEscape(src), htmlEscape(alt), width, height, cls);
}

std::string seconds(double s) {
    if (s <= 0) return "-";
    if (s < 0.01) return fmt::format("{:.2f} ms", 1000 * s);
    return s < 1 ? fmt::format("{:.3f} s", s) : fmt::format("{:.2f} s", s);
}
std::string seconds(const std::optional<double>& s) {
    return s ? seconds(*s) : "-";
}
std::string bytes(uint64_t b) {
    return b == 0 ? "-" : humanBytes(b);
}
std::string times(double big, double small) {
    return big > 0 && small > 0 ? fmt::format("{:.1f}&times;", big / small) : "";
}
// A share of 0..1 as a percentage.
std::string percent(double share) {
    return fmt::format("{:g}%", 100 * share);
}
// A channel difference (sRGB, 0..1), and the same in 8-bit steps.
std::string channel(double v, int digits = 4) {
    return fmt::format("{:.{}f} ({:.1f}/255)", v, digits, 255 * v);
}
// A count in thousands or millions.
std::string humanCount(double v) {
    if (v >= 1e6) return fmt::format("{:.2f} million", v / 1e6);
    if (v >= 1e3) return fmt::format("{:.1f} thousand", v / 1e3);
    return fmt::format("{:.0f}", v);
}

std::string localTime() {
    const std::time_t now = std::time(nullptr);
    char buf[64];
    std::tm tm{};
    localtime_r(&now, &tm);
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M %Z", &tm);
    return buf;
}

// What every page says about how the images were made and judged.
std::string settingsHtml(const VerifyOptions& o) {
    const auto& t = o.thresholds;
    std::string h = "<p class=settings>";
    h += fmt::format("Both renderers drew {}&times;{} pixels without anti-aliasing{}",
                     o.width * o.ss, o.height * o.ss,
                     o.threads > 0 ? fmt::format(" on {} thread(s) each", o.threads) : "");
    if (o.ss > 1)
        h += fmt::format(
            "; each image was then reduced by the same {0}&times;{0} box filter to "
            "{1}&times;{2}",
            o.ss, o.width, o.height);
    h += fmt::format(
        ". The images agree when at most {} of the pixels are <em>off</em>, that is a channel "
        "differs by more than {:g} ({:.1f}/255), and the mean absolute error is at most {:g} "
        "({:.1f}/255). Channel values are sRGB-encoded, from 0 to 1 (255 in an 8-bit "
        "image).</p>",
        percent(t.maxShareOff), t.pixelOff, 255 * t.pixelOff, t.maxMeanError, 255 * t.maxMeanError);
    return h;
}

// The colour ramp of diff.png (heat_ramp.h, which diffHeatMap draws with): the gradient
// and a tick at every stop, with the threshold of an "off" pixel marked on it.
std::string heatLegend(double pixelOff) {
    const double at = std::clamp(pixelOff / kHeatFullScale, 0.0, 1.0) * 100;
    std::string ticks;
    for (size_t i = 0; i < kHeatStops.size(); ++i) {
        const bool first = i == 0, last = i + 1 == kHeatStops.size();
        const double d = double(kHeatStops[i].at) * kHeatFullScale;
        ticks += fmt::format("<span{} style=\"left:{:.2f}%\">{}{:.3g}</span>",
                             first  ? " class=first"
                             : last ? " class=last"
                                    : "",
                             100.0 * kHeatStops[i].at, last ? "&ge;&nbsp;" : "", d);
    }
    return fmt::format(
        "<div class=legend><span class=threshold style=\"left:{:.1f}%\">off above {:g}</span>"
        "<div class=ramp style=\"background:{}\"></div><div class=ticks>{}</div></div>",
        at, pixelOff, heatCssGradient(), ticks);
}

std::string metricsTable(const SceneResult& r, const Thresholds& t) {
    const auto& m = r.metrics;
    const auto yesNo = [](bool ok) {
        return ok ? "<td class=yes>yes</td>" : "<td class=no>no</td>";
    };
    const long pixels = long(m.width) * m.height;
    std::string h = "<table><tr><th></th><th>value</th><th>to agree</th><th>met</th></tr>";
    h += fmt::format(
        "<tr><td>pixels off (a channel differs by more than {:g})</td><td>{:.3f}% ({} of {} "
        "pixels)</td><td>at most {}</td>{}</tr>",
        t.pixelOff, 100 * m.shareOff, std::lround(m.shareOff * double(pixels)), pixels,
        percent(t.maxShareOff), yesNo(m.shareOff <= t.maxShareOff));
    h += fmt::format(
        "<tr><td>mean absolute error (all channels)</td><td>{}</td><td>at most {:g}</td>{}</tr>",
        channel(m.meanAbsError, 5), t.maxMeanError, yesNo(m.meanAbsError <= t.maxMeanError));
    h += fmt::format("<tr><td>root mean square error</td><td>{}</td><td></td><td></td></tr>",
                     channel(m.rmse, 5));
    h += fmt::format("<tr><td>peak signal-to-noise ratio</td><td>{}</td><td></td><td></td></tr>",
                     std::isfinite(m.psnr) ? fmt::format("{:.2f} dB", m.psnr)
                                           : std::string("&infin; (identical images)"));
    h += fmt::format("<tr><td>largest channel difference</td><td>{}</td><td></td><td></td></tr>",
                     m.maxError > 0
                         ? fmt::format("{} at pixel ({}, {})", channel(m.maxError), m.maxX, m.maxY)
                         : std::string("none: every pixel is equal"));
    return h + "</table>";
}

std::string costTable(const SceneResult& r) {
    const auto count = [](const std::optional<uint64_t>& v, const char* what) {
        return v ? fmt::format(" ({} {})", *v, what) : std::string();
    };
    std::string h =
        "<table><tr><th></th><th>native (cyclic graph)</th><th>POV-Ray (expanded tree)</th>"
        "<th>POV-Ray &divide; native</th></tr>";
    h += fmt::format(
        "<tr><td>scene in memory</td><td>{}{}</td><td>{}{}</td><td>{}</td></tr>", opt(r.graphBytes),
        count(r.graphNodes, "nodes"), opt(r.expandedBytes), count(r.expandedNodes, "nodes"),
        r.graphBytes && r.expandedBytes ? times(double(*r.expandedBytes), double(*r.graphBytes))
                                        : "");
    if (r.primitives)
        h += fmt::format(
            "<tr><td>primitives in the picture</td><td colspan=2 class=merged>{} (the same "
            "for both)</td><td></td></tr>",
            *r.primitives);
    h += fmt::format(
        "<tr><td>peak RSS of the render process</td><td>{}</td><td>{}</td><td>{}</td></tr>",
        bytes(r.native.peakRssBytes), bytes(r.povray.peakRssBytes),
        times(double(r.povray.peakRssBytes), double(r.native.peakRssBytes)));
    if (r.native.imageWriterPeakRssBytes)
        h += fmt::format(
            "<tr><td class=sub>peak RSS of <code>pcsg-image write</code>, a process of its "
            "own</td><td>{}</td><td>-</td><td></td></tr>",
            bytes(*r.native.imageWriterPeakRssBytes));
    h += fmt::format(
        "<tr><td>wall time of the render process</td><td>{}</td><td>{}</td><td>{}</td></tr>",
        seconds(r.native.seconds), seconds(r.povray.seconds),
        times(r.povray.seconds, r.native.seconds));
    h += fmt::format("<tr><td class=sub>parsing</td><td>{}</td><td>{}</td><td></td></tr>",
                     seconds(r.native.parseSeconds), seconds(r.povray.parseSeconds));
    h += fmt::format("<tr><td class=sub>tracing</td><td>{}</td><td>{}</td><td></td></tr>",
                     seconds(r.native.traceSeconds), seconds(r.povray.traceSeconds));
    if (r.native.imageWriteSeconds)
        h += fmt::format(
            "<tr><td class=sub>writing the image (<code>pcsg-image</code>, start-up "
            "included)</td><td>{}</td><td>-</td><td></td></tr>",
            seconds(r.native.imageWriteSeconds));
    if (r.raysPerSecond)
        h += fmt::format("<tr><td>rays per second</td><td>{}</td><td>-</td><td></td></tr>",
                         humanCount(*r.raysPerSecond));
    h += "</table><p class=note>Peak RSS is the largest resident set of each process, as the "
         "kernel counted it. Wall time is the whole process's, start-up and writing the image "
         "included; the indented parts are what each program measured of itself.</p>";
    return h;
}

// How many times to enlarge an image of this width on its page: integer steps, to about
// 400 pixels, drawn with sharp pixels.
int pageScale(int width) {
    return std::clamp(400 / std::max(width, 1), 1, 8);
}

void writeScenePage(const SceneResult& r, const VerifyOptions& o, const std::string& written,
                    const fs::path& root) {
    std::ofstream out(root / r.dir / "index.html");
    out << "<!DOCTYPE html><html lang=en><head><meta charset=utf-8><title>" << htmlEscape(r.name)
        << ": " << statusClass(r.status) << " &ndash; pcsg verify</title>" << kStyle
        << "</head><body><nav><a href=\"../index.html\">&larr; all scenes of this report</a></nav>";
    out << "<h1>" << htmlEscape(r.name) << " " << verdictBadge(r.status) << "</h1>";
    if (r.metrics.width > 0)
        out << "<p>Scene <code>" << htmlEscape(r.scene) << "</code>: " << htmlEscape(r.message)
            << ".</p>";
    else
        out << "<p>Scene <code>" << htmlEscape(r.scene) << "</code> could not be compared.</p>";
    out << settingsHtml(o);
    const auto& m = r.metrics;
    if (m.width > 0) {
        const int k = pageScale(m.width), w = k * m.width, h = k * m.height;
        const std::string shown =
            fmt::format("{}&times;{} pixels{}", m.width, m.height,
                        k > 1 ? fmt::format(", shown {} times enlarged", k) : "");
        out << "<h2>Images</h2><div class=figures>";
        out << "<figure><div class=frame><a href=\"native.png\">"
            << imgTag("native.png", "native render", w, h, "pixels")
            << "</a></div><figcaption><b>native</b>: pcsg's tracer on the cyclic graph; " << shown
            << "</figcaption></figure>";
        out << "<figure><div class=frame><a href=\"povray.png\">"
            << imgTag("povray.png", "POV-Ray render", w, h, "pixels")
            << "</a></div><figcaption><b>POV-Ray</b> on the expanded tree that <code>pcsg "
               "export-pov</code> wrote; "
            << shown << "</figcaption></figure>";
        out << "<figure><div class=frame><a href=\"diff.png\">"
            << imgTag("diff.png", "difference heat map", w, h, "pixels") << "</a>";
        if (m.maxError > 0)
            out << fmt::format("<span class=marker style=\"left:{:.2f}%;top:{:.2f}%\"></span>",
                               100.0 * (m.maxX + 0.5) / m.width, 100.0 * (m.maxY + 0.5) / m.height);
        out << "</div><figcaption><b>difference</b>: each pixel's largest channel difference "
               "between the two, black where they are equal"
            << (m.maxError > 0 ? fmt::format("; the cyan ring marks the largest, {} at ({}, {})",
                                             channel(m.maxError, 3), m.maxX, m.maxY)
                               : std::string(" (here everywhere: the images are identical)"))
            << ". The blue line on the scale is the threshold of an <em>off</em> pixel."
            << heatLegend(o.thresholds.pixelOff) << "</figcaption></figure></div>";
        out << "<h2>Image difference</h2>" << metricsTable(r, o.thresholds);
    } else {
        out << "<h2>What went wrong</h2><pre>" << htmlEscape(r.message) << "</pre>";
    }
    if (r.graphBytes || r.native.seconds > 0) out << "<h2>Memory and time</h2>" << costTable(r);
    if (m.width > 0 || !r.povFile.empty()) out << "<h2>Files</h2><p>";
    if (m.width > 0)
        out << "<a href=\"native.png\">native.png</a>, <a href=\"povray.png\">povray.png</a>, "
               "<a href=\"diff.png\">diff.png</a>, ";
    if (r.povInReport)
        out << "the exported POV-Ray scene <a href=\"" << htmlEscape(r.povFile) << "\">"
            << htmlEscape(r.povFile) << "</a>";
    else if (!r.povFile.empty())
        out << "the POV-Ray scene <code>" << htmlEscape(r.povFile) << "</code> (given with --pov)";
    if (m.width > 0 || !r.povFile.empty()) out << ".</p>";
    if (!r.source.empty())
        out << "<details><summary>The scene's source, <code>" << htmlEscape(r.scene)
            << "</code></summary><pre>" << htmlEscape(r.source) << "</pre></details>";
    out << "<footer>Written by <code>pcsg verify</code> on " << htmlEscape(written)
        << ".</footer></body></html>\n";
}

// The index of all scenes, rewritten after each one so that a long run can be watched;
// `pending` scenes are still to come.
void writeIndex(const std::vector<SceneResult>& results, size_t pending, const VerifyOptions& o,
                const std::string& written, const fs::path& root) {
    constexpr int kThumb = 96;  // thumbnail width in CSS pixels
    size_t agree = 0;
    for (const auto& r : results) agree += r.status == 0;
    std::ofstream out(root / "index.html");
    out << "<!DOCTYPE html><html lang=en><head><meta charset=utf-8><title>pcsg verify: " << agree
        << " of " << results.size() << " agree</title>" << kStyle << "</head><body>";
    out << "<h1>pcsg verify: " << agree << " of " << results.size()
        << (results.size() == 1 ? " scene agrees" : " scenes agree") << "</h1>";
    if (pending > 0)
        out << "<p class=note>" << pending << " more scene(s) still to verify: reload this page "
            << "to follow the run.</p>";
    out << "<p>Each scene is rendered twice: <b>native</b>, by pcsg's tracer walking the cyclic "
           "graph, and by <b>POV-Ray</b> from the expanded tree that <code>pcsg "
           "export-pov</code> writes. The <b>difference</b> image shows each pixel's largest "
           "channel difference; its scale:"
        << heatLegend(o.thresholds.pixelOff) << "</p>" << settingsHtml(o);
    out << "<div class=wide><table><tr><th rowspan=2>scene and verdict</th><th colspan=3>images "
           "(click for the scene's page)</th><th rowspan=2>mean absolute<br>error</th>"
           "<th rowspan=2>pixels<br>off</th><th colspan=2>scene in memory</th>"
           "<th colspan=2>peak RSS</th><th colspan=2>wall time</th></tr><tr><th>native</th>"
           "<th>POV-Ray</th><th>difference</th><th>graph</th><th>expanded tree</th>"
           "<th>native</th><th>POV-Ray</th><th>native</th><th>POV-Ray</th></tr>";
    for (const auto& r : results) {
        const std::string page = r.dir + "/index.html";
        out << "<tr><td class=scene><a href=\"" << htmlEscape(page) << "\">" << htmlEscape(r.name)
            << "</a> " << verdictBadge(r.status) << "<br><span class=path>" << htmlEscape(r.scene)
            << "</span></td>";
        const auto& m = r.metrics;
        if (m.width > 0) {
            const int h = int(std::lround(double(kThumb) * m.height / m.width));
            for (const char* img : {"native", "povray", "diff"})
                out << "<td class=text><a href=\"" << htmlEscape(page) << "\">"
                    << imgTag(r.dir + "/" + img + ".png", std::string(img) + " " + r.name, kThumb,
                              h, "thumb")
                    << "</a></td>";
            // A figure beyond its limit is marked as the reason for the verdict.
            const Thresholds& t = o.thresholds;
            out << fmt::format("<td{}>{:.5f}</td><td{}>{:.2f}%</td>",
                               m.meanAbsError > t.maxMeanError ? " class=no" : "", m.meanAbsError,
                               m.shareOff > t.maxShareOff ? " class=no" : "", 100 * m.shareOff);
        } else {
            out << "<td colspan=5 class=msg>" << htmlEscape(summary(r.message)) << "</td>";
        }
        out << "<td>" << opt(r.graphBytes) << "</td><td>" << opt(r.expandedBytes) << "</td><td>"
            << bytes(r.native.peakRssBytes) << "</td><td>" << bytes(r.povray.peakRssBytes)
            << "</td><td>" << seconds(r.native.seconds) << "</td><td>" << seconds(r.povray.seconds)
            << "</td></tr>";
    }
    out << "</table></div><p class=note>Mean absolute error and pixels off as defined above; peak "
           "RSS is each render process's largest resident set; wall time is each render "
           "process's, start-up included. A scene's page has the details.</p>";
    out << "<footer>Written by <code>pcsg verify</code> on " << htmlEscape(written)
        << ".</footer></body></html>\n";
}

int runVerify(VerifyOptions o) {
    if (!o.allDir.empty()) {
        std::error_code ec;
        std::vector<std::string> found;
        for (const auto& e : fs::directory_iterator(o.allDir, ec))
            if (e.path().extension() == ".pcsg") found.push_back(e.path().string());
        if (ec) {
            std::cerr << "pcsg verify: cannot read directory " << o.allDir << ": " << ec.message()
                      << "\n";
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
    const std::string written = localTime();
    std::set<std::string> dirs = {"index.html"};  // the report's own page is taken
    for (const auto& scene : o.scenes) {
        if (!o.json && o.scenes.size() > 1) std::cerr << "verifying " << scene << " ...\n";
        SceneResult r = verifyScene(scene, reportDirName(scene, dirs), o, root);
        if (!o.json) printResult(r, std::cout);
        status = std::max(status, r.status);
        results.push_back(std::move(r));
        if (!o.reportDir.empty()) {
            writeScenePage(results.back(), o, written, root);
            writeIndex(results, o.scenes.size() - results.size(), o, written, root);
        }
    }
    if (o.json) {
        nlohmann::json j = nlohmann::json::array();
        for (const auto& r : results) j.push_back(toJson(r));
        std::cout << (results.size() == 1 ? j[0] : j).dump(2) << "\n";
    } else {
        size_t agree = 0;
        for (const auto& r : results) agree += r.status == 0;
        std::cout << fmt::format("{} of {} scene(s) agree", agree, results.size());
        if (!o.reportDir.empty())
            std::cout << "; report: " << (root / "index.html").string();
        else if (o.keep)
            std::cout << "; images kept in " << root.string();
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
    cmd->add_option("--ss", o->ss, "Supersampling factor K: both render K*W x K*H")
        ->capture_default_str();
    cmd->add_option("--threads", o->threads, "Threads for both renderers (default: all cores)");
    cmd->add_option("--report", o->reportDir,
                    "Write an HTML report into this directory; open DIR/index.html");
    cmd->add_option("--pov", o->povFile, "Render this POV-Ray file instead of exporting the scene");
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
