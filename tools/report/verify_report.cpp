#include "verify_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ctime>
#include <fstream>
#include <sstream>

#include "heat_ramp.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

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

// What every page says about how the images were made and judged.
std::string settingsHtml(const VerifySettings& o) {
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
        "<tr><td>peak RSS of the render command</td><td>{}</td><td>{}</td><td>{}</td></tr>",
        bytes(r.native.peakRssBytes), bytes(r.povray.peakRssBytes),
        times(double(r.povray.peakRssBytes), double(r.native.peakRssBytes)));
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
            "<tr><td class=sub>writing the PNG (libpng, in the render "
            "process)</td><td>{}</td><td>-</td><td></td></tr>",
            seconds(r.native.imageWriteSeconds));
    if (r.raysPerSecond)
        h += fmt::format("<tr><td>rays per second</td><td>{}</td><td>-</td><td></td></tr>",
                         humanCount(*r.raysPerSecond));
    h += "</table><p class=note>Peak RSS is the largest resident set of each render command, "
         "as the kernel counted it (and /usr/bin/time -v prints it). Wall time is the whole "
         "process's, start-up and writing the image "
         "included; the indented parts are what each program measured of itself.</p>";
    return h;
}

// How many times to enlarge an image of this width on its page: integer steps, to about
// 400 pixels, drawn with sharp pixels.
int pageScale(int width) {
    return std::clamp(400 / std::max(width, 1), 1, 8);
}

}  // namespace

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

std::string localTime() {
    const std::time_t now = std::time(nullptr);
    char buf[64];
    std::tm tm{};
    localtime_r(&now, &tm);
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M %Z", &tm);
    return buf;
}

void writeScenePage(const SceneResult& r, const VerifySettings& o, const std::string& written,
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
void writeIndex(const std::vector<SceneResult>& results, size_t pending, const VerifySettings& o,
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
           "RSS is each render command's largest resident set; wall time is each render "
           "process's, start-up included. A scene's page has the details.</p>";
    out << "<footer>Written by <code>pcsg verify</code> on " << htmlEscape(written)
        << ".</footer></body></html>\n";
}

}  // namespace pcsg::tools
