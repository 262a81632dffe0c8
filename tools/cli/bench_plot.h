// `pcsg bench --plot FILE`: the paper's claim in one picture. The Sierpinski tetrahedron
// at orders 4 to 16, rendered by pcsg on the cyclic graph, by POV-Ray on the exported tree
// and by Embree on the expanded triangle mesh, each as one whole command (wall time and
// peak RSS as /usr/bin/time -v counts them), drawn against the order as an SVG: time on
// the left, memory on the right, both on log scales.
//
// POV-Ray's and Embree's memory grows fourfold per order, so each stops at the first order
// it would need more than the memory limit for (predicted from the order before), or at
// the first it fails; the plot shows where it stopped.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace pcsg::tools {

enum ScalingRenderer { kScalingNative = 0, kScalingPovray = 1, kScalingEmbree = 2 };

struct ScalingOptions {
    int fromOrder = 4, toOrder = 16;
    int width = 640, height = 480;
    double adaptive = 0.3;  // both pcsg and POV-Ray; Embree traces pixel centres
    int threads = 0;
    uint64_t memoryLimit = 0;  // bytes one renderer may take; 0: half the machine's memory
    uint64_t maxNodes = 20'000'000;
};

// One order: each renderer's whole-command time and peak RSS, when it ran.
struct ScalingPoint {
    int order = 0;
    std::array<std::optional<double>, 3> seconds;
    std::array<std::optional<uint64_t>, 3> rss;
};

// Runs the sweep in `work`, a line of progress per run on `log`.
std::vector<ScalingPoint> measureScaling(const ScalingOptions& o, const std::filesystem::path& work,
                                         std::ostream& log);

// The scene text of the tetrahedron at that order (the default scene's camera and lights).
std::string sierpinskiScene(int order);

// The SVG: two panels, three series each, a legend and `caption` under them.
std::string scalingSvg(const std::vector<ScalingPoint>& points, const std::string& caption);

}  // namespace pcsg::tools
