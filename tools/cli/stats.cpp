#include "stats.h"

#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>

namespace pcsg::tools {

uint64_t peakRssBytes() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<uint64_t>(usage.ru_maxrss) * 1024;  // Linux reports kilobytes
}

uint64_t wholeCommandPeakRssBytes() {
    rusage children{};
    getrusage(RUSAGE_CHILDREN, &children);
    return std::max(peakRssBytes(), static_cast<uint64_t>(children.ru_maxrss) * 1024);
}

std::string humanBytes(uint64_t bytes) {
    const char* units[] = {"B", "KB", "MB", "GB", "TB"};
    double v = static_cast<double>(bytes);
    int u = 0;
    while (v >= 1000 && u < 4) {
        v /= 1000;
        ++u;
    }
    return u == 0 ? fmt::format("{} B", bytes) : fmt::format("{:.1f} {}", v, units[u]);
}

nlohmann::json Stats::toJson() const {
    nlohmann::json j;
    if (!scene.empty()) j["scene"] = scene;
    auto put = [&j](const char* key, const auto& field) {
        if (field) j[key] = *field;
    };
    put("width", width);
    put("height", height);
    put("rays", rays);
    put("rays_per_second", raysPerSecond);
    put("primitive_equivalence", primitiveEquivalence);
    put("expanded_nodes", expandedNodes);
    put("graph_bytes", graphBytes);
    put("expanded_bytes", expandedBytes);
    put("peak_rss_bytes", peakRssBytes);
    put("seconds", seconds);
    put("parse_seconds", parseSeconds);
    if (graphBytes && expandedBytes && *graphBytes > 0)
        j["memory_ratio"] = static_cast<double>(*expandedBytes) / static_cast<double>(*graphBytes);
    return j;
}

void Stats::print(std::ostream& out) const {
    auto line = [&out](const char* label, const std::string& value) {
        out << fmt::format("{:<24}{}\n", label, value);
    };
    if (!scene.empty()) line("scene", scene);
    if (width && height) line("image", fmt::format("{} x {}", *width, *height));
    if (rays) line("rays", fmt::format("{}", *rays));
    if (raysPerSecond) line("rays per second", fmt::format("{:.0f}", *raysPerSecond));
    if (primitiveEquivalence)
        line("primitive equivalence", fmt::format("{}", *primitiveEquivalence));
    if (expandedNodes) line("expanded tree nodes", fmt::format("{}", *expandedNodes));
    if (graphBytes) line("graph bytes", humanBytes(*graphBytes));
    if (expandedBytes) line("expanded tree bytes", humanBytes(*expandedBytes));
    if (graphBytes && expandedBytes && *graphBytes > 0)
        line("memory saving", fmt::format("{:.1f}x", static_cast<double>(*expandedBytes) /
                                                         static_cast<double>(*graphBytes)));
    if (peakRssBytes) line("peak RSS", humanBytes(*peakRssBytes));
    if (parseSeconds) line("compile time", fmt::format("{:.3f} s", *parseSeconds));
    if (seconds) line("time", fmt::format("{:.3f} s", *seconds));
}

}  // namespace pcsg::tools
