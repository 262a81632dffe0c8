#include "image_helper.h"

#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>

namespace pcsg::tools {

namespace {

// The helper's standard error without its trailing newline; what happened when it was
// silent.
std::string helperError(const ChildResult& c) {
    std::string e = c.err;
    while (!e.empty() && (e.back() == '\n' || e.back() == '\r')) e.pop_back();
    if (!e.empty()) return e;
    if (!c.started) return fmt::format("{} could not be run", kImageHelperName);
    if (c.signal) return fmt::format("{} was killed by signal {}", kImageHelperName, c.signal);
    return fmt::format("{} failed with exit status {}", kImageHelperName, c.exitCode);
}

std::string formatNumber(double v) {
    return fmt::format("{}", v);
}

}  // namespace

std::optional<std::string> findImageHelper() {
    namespace fs = std::filesystem;
    const fs::path self = selfExecutable();
    if (self.has_parent_path()) {
        const fs::path beside = self.parent_path() / kImageHelperName;
        if (access(beside.c_str(), X_OK) == 0) return beside.string();
    }
    if (inPath(kImageHelperName)) return std::string(kImageHelperName);
    return std::nullopt;
}

std::string missingImageHelperMessage() {
    const std::filesystem::path self = selfExecutable();
    return fmt::format(
        "the image helper {} is missing: it was looked for beside {} and in PATH (it is built "
        "next to pcsg: `cmake --build build --target {}`)",
        kImageHelperName, self.string(), kImageHelperName);
}

ImageWriteResult writeImageWithHelper(const std::string& helper, const std::string& path, int width,
                                      int height, std::span<const float> rgb) {
    ImageWriteResult w;
    const ChildResult c = runChild(
        {helper, "write", path, std::to_string(width), std::to_string(height)}, std::as_bytes(rgb));
    w.seconds = c.seconds;
    w.peakRssBytes = c.peakRssBytes;
    w.ok = c.started && c.exitCode == 0;
    if (w.ok && c.inputWritten != rgb.size_bytes()) {
        // Cannot happen with pcsg-image (it reads everything or fails), but a helper that
        // stopped reading early must not pass for one that wrote the whole image.
        w.ok = false;
        w.error = fmt::format("{} exited after reading {} of {} bytes", kImageHelperName,
                              c.inputWritten, rgb.size_bytes());
    } else if (!w.ok) {
        w.error = helperError(c);
    }
    return w;
}

ImageCompareRun compareImagesWithHelper(const std::string& helper, const std::string& a,
                                        const std::string& b, const ImageCompareOptions& o) {
    ImageCompareRun r;
    std::vector<std::string> argv = {helper, "compare", a, b, "--ss", std::to_string(o.ss)};
    argv.insert(argv.end(), {"--pixel-threshold", formatNumber(o.thresholds.pixelOff), "--max-off",
                             formatNumber(o.thresholds.maxShareOff), "--max-mean-error",
                             formatNumber(o.thresholds.maxMeanError)});
    if (!o.heatMap.empty()) argv.insert(argv.end(), {"--heatmap", o.heatMap});
    if (!o.reducedA.empty()) argv.insert(argv.end(), {"--reduced-a", o.reducedA});
    if (!o.reducedB.empty()) argv.insert(argv.end(), {"--reduced-b", o.reducedB});
    r.child = runChild(argv);

    nlohmann::json j;
    try {
        j = nlohmann::json::parse(r.child.out);
    } catch (const nlohmann::json::exception&) {
        j = nullptr;
    }
    if (j.is_object()) {
        auto size = [&](const char* which, int& width, int& height) {
            if (!j.contains(which) || !j[which].is_object()) return;
            width = j[which].value("width", 0);
            height = j[which].value("height", 0);
        };
        size("a", r.widthA, r.heightA);
        size("b", r.widthB, r.heightB);
        r.metrics = metricsFromJson(j);
    }
    const bool compared = r.child.started && (r.child.exitCode == 0 || r.child.exitCode == 1);
    if (compared && r.metrics) {
        r.status = r.metrics->agree ? 0 : 1;
    } else {
        r.status = 2;
        r.error = compared ? fmt::format("{} printed no metrics", kImageHelperName)
                           : helperError(r.child);
    }
    return r;
}

}  // namespace pcsg::tools
