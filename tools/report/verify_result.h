// What `pcsg verify` found for one scene, and the settings it ran with: computed by
// tools/cli/verify_command.cpp, printed there as text or JSON, and drawn as HTML by the
// report (verify_report.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "image_metrics.h"
#include "stats.h"

namespace pcsg::tools {

// How the images were made and judged.
struct VerifySettings {
    int width = 320, height = 240, ss = 2;
    int threads = 0;
    Thresholds thresholds;
};

// One renderer's costs.
struct Side {
    double seconds = 0;  // wall time of the render command
    // Of the whole render command, as /usr/bin/time -v counts it (wait4's rusage: the
    // process and any it waited for).
    uint64_t peakRssBytes = 0;
    std::optional<double> parseSeconds, traceSeconds;
    std::optional<double> imageWriteSeconds;  // native: writing the PNG
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
    // A frame of `verify --frames`: its number, of how many, and its clock (frames 0: a still).
    int frame = 0, frames = 0;
    double clock = 0;
};

// An optional figure: bytes ("1.2 MB") or a plain count, "-" when it is missing.
inline std::string opt(const std::optional<uint64_t>& v, bool bytes = true) {
    if (!v) return "-";
    return bytes ? humanBytes(*v) : std::to_string(*v);
}

}  // namespace pcsg::tools
