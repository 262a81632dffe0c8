// The colour ramp of verify's difference heat map, in one place for both of its users:
// `pcsg-image compare --heatmap` draws diff.png with heatColour() (image_compare.cpp),
// and the report's legend (tools/report/verify_report.cpp) draws its CSS gradient and its ticks
// from the same stops, so the legend always says what the picture shows. No OpenImageIO here.
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string>

namespace pcsg::tools {

// A pixel's largest sRGB-encoded channel difference d, from 0 to 1, is amplified so that
// small differences show: from kHeatFullScale up it is white.
inline constexpr float kHeatFullScale = 0.25f;

struct HeatRgb {
    float r, g, b;  // sRGB-encoded, 0..1
};

// The ramp's stops: black at 0, red at a third of the full scale, yellow at two thirds,
// white at the full scale; between two stops the colour is linear in d (in sRGB values,
// which is how a CSS linear-gradient interpolates, so the legend is exact).
struct HeatStop {
    float at;  // share of kHeatFullScale, 0..1
    HeatRgb colour;
};
inline constexpr std::array<HeatStop, 4> kHeatStops = {{
    {0.0f, {0, 0, 0}},
    {1.0f / 3, {1, 0, 0}},
    {2.0f / 3, {1, 1, 0}},
    {1.0f, {1, 1, 1}},
}};

// The heat-map colour of a difference d.
inline HeatRgb heatColour(float d) {
    const float h = std::clamp(d / kHeatFullScale, 0.0f, 1.0f);
    for (size_t i = 1; i < kHeatStops.size(); ++i) {
        const HeatStop& a = kHeatStops[i - 1];
        const HeatStop& b = kHeatStops[i];
        if (h <= b.at) {
            const float t = (h - a.at) / (b.at - a.at);
            return {a.colour.r + t * (b.colour.r - a.colour.r),
                    a.colour.g + t * (b.colour.g - a.colour.g),
                    a.colour.b + t * (b.colour.b - a.colour.b)};
        }
    }
    return kHeatStops.back().colour;
}

// The ramp as a CSS background, left (d = 0) to right (d = kHeatFullScale).
inline std::string heatCssGradient() {
    std::string css = "linear-gradient(to right";
    for (const HeatStop& s : kHeatStops) {
        const auto byte = [](float v) { return static_cast<int>(v * 255.0f + 0.5f); };
        css += fmt::format(",#{:02x}{:02x}{:02x} {:.2f}%", byte(s.colour.r), byte(s.colour.g),
                           byte(s.colour.b), 100.0 * s.at);
    }
    return css + ")";
}

}  // namespace pcsg::tools
