#include "renders.h"

#include <filesystem>
#include <regex>

namespace pcsg::tools {

std::string firstLines(const std::string& text, size_t n) {
    std::string out;
    size_t lines = 0, pos = 0;
    while (pos < text.size() && lines < n) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        out += "    " + text.substr(pos, end - pos) + "\n";
        pos = end + 1;
        ++lines;
    }
    return out;
}

namespace {

std::optional<nlohmann::json> parseJson(const std::string& text) {
    // The JSON object is the last thing printed; anything before it is ignored.
    const auto pos = text.find('{');
    if (pos == std::string::npos) return std::nullopt;
    try {
        return nlohmann::json::parse(text.substr(pos));
    } catch (const std::exception&) {
        return std::nullopt;
    }
}

RenderRun runPcsg(const std::string& what, std::vector<std::string> argv) {
    RenderRun r;
    argv.insert(argv.begin(), selfExecutable());
    r.child = runChild(argv);
    r.json = parseJson(r.child.out);
    r.ok = r.child.exitCode == 0;
    if (!r.ok) r.error = what + " failed:\n" + firstLines(r.child.err);
    return r;
}

// POV-Ray prints "Parse Time:    0 hours  0 minutes  1 seconds (1.234 seconds)".
std::optional<double> povrayTime(const std::string& err, const char* what) {
    const std::regex re(std::string(what) + R"(\s*Time:.*\(([0-9.]+) seconds\))");
    std::smatch m;
    if (std::regex_search(err, m, re)) return std::stod(m[1]);
    return std::nullopt;
}

}  // namespace

RenderRun renderNative(const std::string& scene, const std::string& out, int width, int height,
                       const std::vector<std::string>& extra) {
    std::vector<std::string> argv = {"render",   scene,
                                     "-o",       out,
                                     "--width",  std::to_string(width),
                                     "--height", std::to_string(height),
                                     "--json"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return runPcsg("the native render", argv);
}

RenderRun exportPov(const std::string& scene, const std::string& out, int width, int height,
                    const std::vector<std::string>& extra) {
    std::vector<std::string> argv = {
        "export-pov",          scene, "-o", out, "--width", std::to_string(width), "--height",
        std::to_string(height)};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return runPcsg("export-pov", argv);
}

RenderRun expandedStats(const std::string& scene, const std::vector<std::string>& extra) {
    std::vector<std::string> argv = {"stats", scene, "--json"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return runPcsg("stats", argv);
}

RenderRun renderPovray(const std::string& pov, const std::string& out, int width, int height,
                       const std::vector<std::string>& extra) {
    RenderRun r;
    std::vector<std::string> argv = {"povray",
                                     "+I" + pov,
                                     "+O" + out,
                                     "+W" + std::to_string(width),
                                     "+H" + std::to_string(height),
                                     "-D",
                                     "+FN",
                                     "-UA",
                                     "-P",
                                     "-V"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    r.child = runChild(argv);
    // POV-Ray 3.7 gives up when its worker thread is slow to start on a busy machine: that
    // is no verdict on the scene, so it gets one more try.
    if (r.child.exitCode != 0 &&
        r.child.err.find("Timed out waiting for worker thread startup") != std::string::npos)
        r.child = runChild(argv);
    if (!r.child.started) {
        r.error = kPovrayInstallHint;
        return r;
    }
    r.ok = r.child.exitCode == 0 && std::filesystem::exists(out);
    if (!r.ok) r.error = "POV-Ray could not render " + pov + ":\n" + firstLines(r.child.err, 20);
    r.parseSeconds = povrayTime(r.child.err, "Parse");
    r.traceSeconds = povrayTime(r.child.err, "Trace");
    return r;
}

}  // namespace pcsg::tools
